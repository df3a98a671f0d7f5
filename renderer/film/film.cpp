#include "renderer/film/film.h"

#include "renderer/error.h"

#include <algorithm>
#include <cstdio>
#include <stdexcept>

namespace pdflab {

std::string image_size_problem(std::int64_t width, std::int64_t height) {
  const std::string size = std::to_string(width) + "x" + std::to_string(height);
  if (width < 1 || width > kMaxImageSide || height < 1 || height > kMaxImageSide)
    return "image size " + size + " is outside 1.." + std::to_string(kMaxImageSide) + " per side";
  const std::int64_t pixels = width * height;
  if (pixels <= kMaxImagePixels) return {};
  char gib[32];
  std::snprintf(gib, sizeof gib, "%.1f", static_cast<double>(pixels * kFilmBytesPerPixel) / (1 << 30));
  return "image size " + size + " has " + std::to_string(pixels) + " pixels, more than the limit of " +
         std::to_string(kMaxImagePixels) + " (4096x4096); its film alone would need " + gib + " GiB";
}

void check_image_size(std::int64_t width, std::int64_t height, const std::string& what) {
  const std::string problem = image_size_problem(width, height);
  if (!problem.empty()) throw InputError(what + ": " + problem);
}

void Film::reset(int width, int height) {
  check_image_size(width, height, "film");
  width_ = width;
  height_ = height;
  sum_.assign(3 * pixel_count(), 0.0);
  sum_sq_.assign(3 * pixel_count(), 0.0);
  count_.assign(pixel_count(), 0);
  drop_mask_.assign(pixel_count(), 0);
}

void Film::clear() {
  std::fill(sum_.begin(), sum_.end(), 0.0);
  std::fill(sum_sq_.begin(), sum_sq_.end(), 0.0);
  std::fill(count_.begin(), count_.end(), 0u);
  std::fill(drop_mask_.begin(), drop_mask_.end(), std::uint8_t{0});
}

void Film::add_film(const Film& other) {
  if (other.width_ != width_ || other.height_ != height_) throw std::invalid_argument("Film::add_film: sizes differ");
  for (std::size_t i = 0; i < sum_.size(); ++i) {
    sum_[i] += other.sum_[i];
    sum_sq_[i] += other.sum_sq_[i];
  }
  for (std::size_t p = 0; p < count_.size(); ++p) {
    count_[p] += other.count_[p];
    drop_mask_[p] |= other.drop_mask_[p];
  }
}

std::vector<float> Film::mean_rgb() const {
  std::vector<float> out;
  mean_rgb(out);
  return out;
}

void Film::mean_rgb(std::vector<float>& out) const {
  out.resize(3 * pixel_count());
  for (std::size_t p = 0; p < pixel_count(); ++p) {
    double m[3];
    mean(p, m);
    for (int c = 0; c < 3; ++c) out[3 * p + c] = static_cast<float>(m[c]);
  }
}

}  // namespace pdflab
