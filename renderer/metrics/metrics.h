#pragma once
// Error and noise figures: how far an estimate is from a reference, how noisy
// it is by its own account, and what that costs in time.
#include "renderer/film/film.h"

#include <cstdint>
#include <utility>
#include <vector>

namespace pdflab {

// relMSE = mean over pixels and channels of (x - r)^2 / (r^2 + epsilon). The
// epsilon keeps black reference pixels from dominating; 1e-2 is the value
// commonly used for relative MSE in rendering papers.
inline constexpr double kRelMseEpsilon = 1e-2;

// Root mean squared error over all pixels and channels. Images are float RGB of equal size.
double rmse(const std::vector<float>& image, const std::vector<float>& reference);
double relmse(const std::vector<float>& image, const std::vector<float>& reference,
              double epsilon = kRelMseEpsilon);

// relMSE against a reference that is itself noisy. With r = mu + e_r, the
// expected (x - r)^2 is (x - mu)^2 + Var(r): a noisy reference adds its own
// variance to every pixel's error. Subtracting the reference's estimated
// variance of the mean leaves an unbiased estimate of the error against the
// true image (docs/measuring.md). Each pixel's term is
//   t_p = mean over channels of ((x - r)^2 - v_r) / (r^2 + epsilon)
// and the interval is 1.96 standard errors of their mean over pixels (pixels
// are independent: each has its own random numbers).
struct RelMseMeasure {
  double raw = 0.0;        // mean (x - r)^2 / (r^2 + eps), as relmse()
  double corrected = 0.0;  // raw minus the reference's noise; may dip below 0 by chance
  double interval = 0.0;   // 95% half width of `corrected`
  double reference_noise = 0.0;  // mean v_r / (r^2 + eps): the reference's own relMSE
  bool reference_corrected = false;  // false: no reference variance, corrected == raw
  // With the image's own variance: corrected minus the image's noise, an
  // estimate of the squared bias alone (0 for an unbiased render), and its interval.
  bool has_excess = false;
  double image_noise = 0.0, excess = 0.0, excess_interval = 0.0;
  // The part of the raw error that is the reference's own noise (0..1).
  double reference_share() const { return raw > 0.0 ? reference_noise / raw : 0.0; }
};
// `reference_variance` and `image_variance` may be empty (unknown); otherwise
// of the images' size.
RelMseMeasure measure_relmse(const std::vector<float>& image, const std::vector<float>& reference,
                             const std::vector<float>& reference_variance,
                             const std::vector<float>& image_variance = {}, double epsilon = kRelMseEpsilon);

// Efficiency = 1 / (relMSE * seconds): higher is better; independent of the
// render time for an unbiased estimator whose error falls as 1/N.
double efficiency(double relmse_value, double seconds);

// The film's relMSE estimate over one render. For an unbiased strategy it
// falls as 1/spp, so estimate * spp (the variance of one sample) stays about
// flat; when that product grows by more than 2x over a doubling of the samples
// (the estimate did not fall at all), rare bright paths are still being found
// and the estimate says little: unreliable() stays true for the render.
// unreliable_now() judges the latest doubling alone: it clears again once the
// product holds still, as a viewer showing the render as it goes needs.
class EstimateHistory {
 public:
  static constexpr double kGrowthLimit = 2.0;
  void clear() { *this = EstimateHistory(); }
  void add(std::uint32_t spp, double estimated_relmse);
  bool unreliable() const { return unreliable_; }
  bool unreliable_now() const { return growth_ > kGrowthLimit; }
  // estimate * spp now over the same at half the samples or fewer (0 before then).
  double growth() const { return growth_; }
  // The points kept: (spp, estimate * spp), at least 2% apart in spp.
  const std::vector<std::pair<std::uint32_t, double>>& points() const { return points_; }

 private:
  std::vector<std::pair<std::uint32_t, double>> points_;  // spp, estimate * spp
  bool unreliable_ = false;
  double growth_ = 0.0;
};

// The film's own estimate of its noise, no reference needed: per pixel
// sqrt(luminance of the per-channel variances of the mean) over (mean
// luminance + epsilon), averaged over pixels with at least two samples. The
// film keeps no luminance sum of squares, so for coloured samples this bounds
// the standard error of the mean luminance from above (Cauchy-Schwarz, then
// Jensen with weights summing to 1); for grey samples it is equal.
// Like any sample variance it cannot see what the samples missed: a pixel whose
// few samples never found a small light reports little noise.
double mean_relative_standard_error(const Film& film, double epsilon = kRelMseEpsilon);

// The film's estimate of the relMSE it would have against the true image: the
// variance of the mean over (mean^2 + epsilon), averaged like relmse. For an
// unbiased strategy this is the expected relMSE, so it stands in when there is no reference.
double estimated_relmse(const Film& film, double epsilon = kRelMseEpsilon);

// Per-pixel relative standard error (the heat map's values), luminance-based.
std::vector<float> relative_standard_error_map(const Film& film, double epsilon = kRelMseEpsilon);

// The three above in one sweep over the film, as a session publishes them after
// every pass: the map goes to `map` (resized), the two figures are returned.
struct NoiseSummary {
  double mean_relative_standard_error = 0.0;
  double estimated_relmse = 0.0;
};
// With `mean_rgb`, the same sweep also writes the mean image (Film::mean_rgb's values).
NoiseSummary noise_summary(const Film& film, std::vector<float>& map, double epsilon = kRelMseEpsilon,
                           std::vector<float>* mean_rgb = nullptr);

// The sweep's running sums over some of the pixels: sweeps of disjoint parts,
// added in a fixed order, make the summary of their union (a render session
// sweeps each tile as soon as a pass has rendered it, on the worker that did).
struct NoiseSums {
  double relative_standard_error = 0.0;  // sum over the pixels with two samples or more
  double relative_variance = 0.0;        // sum over those pixels and the three channels
  std::size_t pixels = 0;
  void add(const NoiseSums& other);
  NoiseSummary summary() const;
};
// The pixels of rows [y0, y1) and columns [x0, x1) of the film: their sums;
// where given, their entries of a map and a mean image that cover the whole
// film (indexed by pixel, as above).
NoiseSums sweep_noise_rect(const Film& film, int x0, int y0, int x1, int y1, double epsilon, float* map,
                           float* mean_rgb);

}  // namespace pdflab
