#include "renderer/metrics/metrics.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace pdflab {

namespace {

void check_sizes(const std::vector<float>& a, const std::vector<float>& b) {
  if (a.size() != b.size() || a.empty()) throw std::invalid_argument("images differ in size or are empty");
}

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

RelMseMeasure measure_relmse(const std::vector<float>& image, const std::vector<float>& reference,
                             const std::vector<float>& reference_variance, const std::vector<float>& image_variance,
                             double epsilon) {
  check_sizes(image, reference);
  const bool with_ref_var = !reference_variance.empty();
  const bool with_image_var = !image_variance.empty();
  if (with_ref_var) check_sizes(reference_variance, reference);
  if (with_image_var) check_sizes(image_variance, image);
  const std::size_t pixels = image.size() / 3;
  double raw = 0.0, ref_noise = 0.0, img_noise = 0.0;
  double t_sum = 0.0, t_sq = 0.0, e_sum = 0.0, e_sq = 0.0;
  for (std::size_t p = 0; p < pixels; ++p) {
    double d2 = 0.0, vr = 0.0, vx = 0.0;
    for (std::size_t c = 3 * p; c < 3 * p + 3; ++c) {
      const double r = reference[c];
      const double w = 1.0 / (r * r + epsilon);
      const double d = static_cast<double>(image[c]) - r;
      d2 += d * d * w;
      if (with_ref_var) vr += reference_variance[c] * w;
      if (with_image_var) vx += image_variance[c] * w;
    }
    d2 /= 3.0;
    vr /= 3.0;
    vx /= 3.0;
    raw += d2;
    ref_noise += vr;
    img_noise += vx;
    const double t = d2 - vr, e = t - vx;
    t_sum += t;
    t_sq += t * t;
    e_sum += e;
    e_sq += e * e;
  }
  const double n = static_cast<double>(pixels);
  // 1.96 standard errors of a mean over n terms, from their sample variance.
  const auto half_width = [n](double sum, double sq) {
    if (n < 2.0) return 0.0;
    const double mean = sum / n;
    const double var = std::max(0.0, (sq / n - mean * mean) * n / (n - 1.0));
    return 1.96 * std::sqrt(var / n);
  };
  RelMseMeasure m;
  m.raw = raw / n;
  m.reference_corrected = with_ref_var;
  m.reference_noise = ref_noise / n;
  m.corrected = t_sum / n;
  m.interval = half_width(t_sum, t_sq);
  if (with_image_var) {
    m.has_excess = true;
    m.image_noise = img_noise / n;
    m.excess = e_sum / n;
    m.excess_interval = half_width(e_sum, e_sq);
  }
  return m;
}

void EstimateHistory::add(std::uint32_t spp, double estimated_relmse) {
  if (spp < 2 || !(estimated_relmse > 0.0) || !std::isfinite(estimated_relmse)) return;
  if (!points_.empty() && spp <= points_.back().first) return;
  const double per_sample = estimated_relmse * spp;
  // The latest point at half the samples or fewer.
  for (auto it = points_.rbegin(); it != points_.rend(); ++it)
    if (2 * static_cast<std::uint64_t>(it->first) <= spp) {
      growth_ = per_sample / it->second;
      if (growth_ > kGrowthLimit) unreliable_ = true;
      break;
    }
  // Points 2% apart in spp at least: a long render keeps a few hundred.
  if (points_.empty() || static_cast<double>(spp) >= 1.02 * points_.back().first) points_.emplace_back(spp, per_sample);
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

void NoiseSums::add(const NoiseSums& other) {
  relative_standard_error += other.relative_standard_error;
  relative_variance += other.relative_variance;
  pixels += other.pixels;
}

NoiseSummary NoiseSums::summary() const {
  NoiseSummary out;
  if (pixels) {
    out.mean_relative_standard_error = relative_standard_error / static_cast<double>(pixels);
    out.estimated_relmse = relative_variance / (3.0 * static_cast<double>(pixels));
  }
  return out;
}

NoiseSums sweep_noise_rect(const Film& film, int x0, int y0, int x1, int y1, double epsilon, float* map,
                           float* mean_rgb) {
  NoiseSums sums;
  std::uint32_t count = 0;  // after a full pass every pixel has the same count
  Film::Reciprocals r = Film::reciprocals(count);
  const auto width = static_cast<std::size_t>(film.width());
  for (int y = y0; y < y1; ++y) {
    const std::size_t row = static_cast<std::size_t>(y) * width;
    for (std::size_t p = row + static_cast<std::size_t>(x0); p < row + static_cast<std::size_t>(x1); ++p) {
      if (film.count(p) != count) r = Film::reciprocals(count = film.count(p));
      double m[3], v[3];
      film.moments(p, r, m, v);
      if (mean_rgb)
        for (int c = 0; c < 3; ++c) mean_rgb[3 * p + c] = static_cast<float>(m[c]);
      if (count < 2) {
        if (map) map[p] = 0.0f;
        continue;
      }
      const double rse = std::sqrt(luminance(v) > 0.0 ? luminance(v) : 0.0) / (luminance(m) + epsilon);
      if (map) map[p] = static_cast<float>(rse);
      sums.relative_standard_error += rse;
      for (int c = 0; c < 3; ++c) sums.relative_variance += v[c] / (m[c] * m[c] + epsilon);
      ++sums.pixels;
    }
  }
  return sums;
}

namespace {

// The sweep behind noise_summary; `map` and `mean_rgb` may be null (then no
// image-sized buffer is touched: a headless render's estimate).
NoiseSummary sweep_noise(const Film& film, std::vector<float>* map, double epsilon, std::vector<float>* mean_rgb) {
  const std::size_t pixels = film.pixel_count();
  if (map) map->resize(pixels);  // every pixel is written below
  if (mean_rgb) mean_rgb->resize(3 * pixels);
  return sweep_noise_rect(film, 0, 0, film.width(), film.height(), epsilon, map ? map->data() : nullptr,
                          mean_rgb ? mean_rgb->data() : nullptr)
      .summary();
}

}  // namespace

double estimated_relmse(const Film& film, double epsilon) {
  return sweep_noise(film, nullptr, epsilon, nullptr).estimated_relmse;
}

std::vector<float> relative_standard_error_map(const Film& film, double epsilon) {
  std::vector<float> map;
  (void)noise_summary(film, map, epsilon);
  return map;
}

NoiseSummary noise_summary(const Film& film, std::vector<float>& map, double epsilon, std::vector<float>* mean_rgb) {
  return sweep_noise(film, &map, epsilon, mean_rgb);
}

}  // namespace pdflab
