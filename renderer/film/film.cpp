#include "renderer/film/film.h"

#include <algorithm>

namespace pdflab {

void Film::reset(int width, int height) {
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

void Film::mean(std::size_t pixel, double out[3]) const {
  const std::uint32_t n = count_[pixel];
  const double inv = n > 0 ? 1.0 / n : 0.0;
  for (int c = 0; c < 3; ++c) out[c] = sum_[3 * pixel + c] * inv;
}

void Film::variance_of_mean(std::size_t pixel, double out[3]) const {
  const std::uint32_t n = count_[pixel];
  for (int c = 0; c < 3; ++c) {
    if (n < 2) {
      out[c] = 0.0;
      continue;
    }
    const double m = sum_[3 * pixel + c] / n;
    const double var = std::max(0.0, (sum_sq_[3 * pixel + c] / n - m * m)) * n / (n - 1.0);
    out[c] = var / n;
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
