#include "renderer/metrics/metrics.h"

#include <cmath>
#include <stdexcept>

namespace pdflab {

namespace {

void check_sizes(const std::vector<float>& a, const std::vector<float>& b) {
  if (a.size() != b.size() || a.empty()) throw std::invalid_argument("images differ in size or are empty");
}

// Rec. 709 luminance: the noise a viewer sees.
double luminance(const double rgb[3]) { return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]; }

}  // namespace

double rmse(const std::vector<float>& image, const std::vector<float>& reference) {
  check_sizes(image, reference);
  double sum = 0.0;
  for (std::size_t i = 0; i < image.size(); ++i) {
    const double d = static_cast<double>(image[i]) - reference[i];
    sum += d * d;
  }
  return std::sqrt(sum / static_cast<double>(image.size()));
}

double relmse(const std::vector<float>& image, const std::vector<float>& reference, double epsilon) {
  check_sizes(image, reference);
  double sum = 0.0;
  for (std::size_t i = 0; i < image.size(); ++i) {
    const double r = reference[i];
    const double d = static_cast<double>(image[i]) - r;
    sum += d * d / (r * r + epsilon);
  }
  return sum / static_cast<double>(image.size());
}

double efficiency(double relmse_value, double seconds) {
  if (!(relmse_value > 0.0) || !(seconds > 0.0)) return 0.0;
  return 1.0 / (relmse_value * seconds);
}

// The three film-only figures share one pass over the pixels (noise_summary).
double mean_relative_standard_error(const Film& film, double epsilon) {
  std::vector<float> map;
  return noise_summary(film, map, epsilon).mean_relative_standard_error;
}

double estimated_relmse(const Film& film, double epsilon) {
  std::vector<float> map;
  return noise_summary(film, map, epsilon).estimated_relmse;
}

std::vector<float> relative_standard_error_map(const Film& film, double epsilon) {
  std::vector<float> map;
  (void)noise_summary(film, map, epsilon);
  return map;
}

NoiseSummary noise_summary(const Film& film, std::vector<float>& map, double epsilon, std::vector<float>* mean_rgb) {
  const std::size_t pixels = film.pixel_count();
  map.assign(pixels, 0.0f);
  if (mean_rgb) mean_rgb->resize(3 * pixels);
  double rse_sum = 0.0, rel_sum = 0.0;
  std::size_t n = 0;
  std::uint32_t count = 0;  // after a full pass every pixel has the same count
  Film::Reciprocals r = Film::reciprocals(count);
  for (std::size_t p = 0; p < pixels; ++p) {
    if (film.count(p) != count) r = Film::reciprocals(count = film.count(p));
    double m[3], v[3];
    film.moments(p, r, m, v);
    if (mean_rgb)
      for (int c = 0; c < 3; ++c) (*mean_rgb)[3 * p + c] = static_cast<float>(m[c]);
    if (count < 2) continue;
    const double rse = std::sqrt(luminance(v) > 0.0 ? luminance(v) : 0.0) / (luminance(m) + epsilon);
    map[p] = static_cast<float>(rse);
    rse_sum += rse;
    for (int c = 0; c < 3; ++c) rel_sum += v[c] / (m[c] * m[c] + epsilon);
    ++n;
  }
  NoiseSummary out;
  if (n) {
    out.mean_relative_standard_error = rse_sum / static_cast<double>(n);
    out.estimated_relmse = rel_sum / (3.0 * static_cast<double>(n));
  }
  return out;
}

}  // namespace pdflab
