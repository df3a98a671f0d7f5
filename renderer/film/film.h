#pragma once
// Per-pixel accumulation: sum and sum of squares in double, and a sample count.
// Tiles are disjoint, so workers write without locks; one sample order per pixel
// (by sample index) keeps sums bit-identical for any thread count.
#include "renderer/math.h"

#include <cstdint>
#include <string>
#include <vector>

namespace pdflab {

// Image size limits. A side may be up to 16384 pixels, but the film costs
// kFilmBytesPerPixel (sum and sum of squares in double, a count) plus a drop
// mask byte, and a headless render holds little else (bench/bench_memory), so
// 16384 x 16384 would need about 14 GiB. The pixel budget caps a render near
// 1 GiB: 4096 x 4096, 8192 x 2048, ...
inline constexpr int kMaxImageSide = 16384;
inline constexpr std::int64_t kMaxImagePixels = std::int64_t{1} << 24;
inline constexpr std::int64_t kFilmBytesPerPixel = 6 * sizeof(double) + sizeof(std::uint32_t);

// Empty when width x height is within 1..kMaxImageSide per side and at most
// kMaxImagePixels; otherwise what is wrong, with the memory it would take.
std::string image_size_problem(std::int64_t width, std::int64_t height);
// Throws InputError "what: problem". Called before anything of that size is allocated.
void check_image_size(std::int64_t width, std::int64_t height, const std::string& what);

class Film {
 public:
  Film() = default;
  Film(int width, int height) { reset(width, height); }

  void reset(int width, int height);
  void clear();

  int width() const { return width_; }
  int height() const { return height_; }
  std::size_t pixel_count() const { return static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_); }

  void add(std::size_t pixel, const Vec3& value) {
    double* s = &sum_[3 * pixel];
    double* q = &sum_sq_[3 * pixel];
    const double r = value.x, g = value.y, b = value.z;
    s[0] += r; s[1] += g; s[2] += b;
    q[0] += r * r; q[1] += g * g; q[2] += b * b;
    ++count_[pixel];
  }

  std::uint32_t count(std::size_t pixel) const { return count_[pixel]; }
  // Mean radiance per channel (zero where no sample landed yet).
  void mean(std::size_t pixel, double out[3]) const {
    double unused[3];
    moments(pixel, reciprocals(count_[pixel]), out, unused);
  }
  // Variance of the mean per channel: (E[x^2] - E[x]^2) / (n - 1); zero for n < 2.
  void variance_of_mean(std::size_t pixel, double out[3]) const {
    double unused[3];
    moments(pixel, reciprocals(count_[pixel]), unused, out);
  }
  // Both at once, with 1/n and 1/(n - 1) given: a sweep over the film (the
  // session makes one after every pass) computes them once for the many
  // pixels that share a count.
  struct Reciprocals {
    double inv_n = 0.0, inv_dof = 0.0;  // 1/n (0 for n = 0), 1/(n - 1) (0 for n < 2)
  };
  static Reciprocals reciprocals(std::uint32_t n) {
    return {n > 0 ? 1.0 / n : 0.0, n > 1 ? 1.0 / (n - 1.0) : 0.0};
  }
  void moments(std::size_t pixel, const Reciprocals& r, double mean_out[3], double variance_of_mean_out[3]) const {
    for (int c = 0; c < 3; ++c) {
      const double m = sum_[3 * pixel + c] * r.inv_n;
      const double excess = sum_sq_[3 * pixel + c] * r.inv_n - m * m;
      mean_out[c] = m;
      variance_of_mean_out[c] = (excess > 0.0 ? excess : 0.0) * r.inv_dof;
    }
  }

  // The mean image as float RGB, row 0 at the top.
  std::vector<float> mean_rgb() const;
  void mean_rgb(std::vector<float>& out) const;

  // Which drop reasons occurred among a pixel's samples: bit r for DropReason r.
  // Kept per pixel so a viewer can show where invalid samples come from, not
  // only how many there were. Written by the worker that owns the pixel's tile.
  void mark_drops(std::size_t pixel, std::uint8_t reasons) { drop_mask_[pixel] |= reasons; }
  std::uint8_t drop_mask(std::size_t pixel) const { return drop_mask_[pixel]; }
  const std::vector<std::uint8_t>& drop_masks() const { return drop_mask_; }

  // The accumulation itself, for film files (film_file.h): 3 sums and 3 sums of
  // squares per pixel (RGB), one count and one drop mask per pixel.
  const std::vector<double>& sums() const { return sum_; }
  const std::vector<double>& squares() const { return sum_sq_; }
  const std::vector<std::uint32_t>& counts() const { return count_; }
  std::vector<double>& sums() { return sum_; }
  std::vector<double>& squares() { return sum_sq_; }
  std::vector<std::uint32_t>& counts() { return count_; }
  std::vector<std::uint8_t>& drop_masks() { return drop_mask_; }

  // Adds another film of the same size pixel by pixel: sums, squares and counts
  // add, drop masks combine. Throws std::invalid_argument on a size mismatch.
  void add_film(const Film& other);

 private:
  int width_ = 0, height_ = 0;
  std::vector<double> sum_, sum_sq_;
  std::vector<std::uint32_t> count_;
  std::vector<std::uint8_t> drop_mask_;
};

}  // namespace pdflab
