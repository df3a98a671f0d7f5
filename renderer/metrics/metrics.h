#pragma once
// Error and noise figures: how far an estimate is from a reference, how noisy
// it is by its own account, and what that costs in time.
#include "renderer/film/film.h"

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

// Efficiency = 1 / (relMSE * seconds): higher is better; independent of the
// render time for an unbiased estimator whose error falls as 1/N.
double efficiency(double relmse_value, double seconds);

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

}  // namespace pdflab
