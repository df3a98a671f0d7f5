#include "renderer/lab/lab1d.h"

#include "renderer/sampling/rng.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace pdflab::lab {

namespace {
constexpr double kPeakCentre = 1.5, kPeakWidth = 0.05;
constexpr double kStepEnd = 0.5;
}  // namespace

std::string_view integrand_name(Integrand f) {
  switch (f) {
    case Integrand::Square: return "x^2";
    case Integrand::Cosine: return "cos(x)";
    case Integrand::Step: return "step (1 below 0.5)";
    case Integrand::NarrowPeak: return "narrow peak at 1.5";
    default: return "?";
  }
}

std::string_view pdf_name(Pdf p) {
  switch (p) {
    case Pdf::Uniform: return "uniform: 1/2";
    case Pdf::Linear: return "linear: x/2";
    case Pdf::Quadratic: return "quadratic: 3x^2/8";
    case Pdf::Mismatched: return "mismatched: (2-x)/2";
    default: return "?";
  }
}

double integrand(Integrand f, double x) {
  switch (f) {
    case Integrand::Square: return x * x;
    case Integrand::Cosine: return std::cos(x);
    case Integrand::Step: return x < kStepEnd ? 1.0 : 0.0;
    case Integrand::NarrowPeak: {
      const double t = (x - kPeakCentre) / kPeakWidth;
      return std::exp(-t * t);
    }
    default: return 0.0;
  }
}

double exact_integral(Integrand f) {
  switch (f) {
    case Integrand::Square: return 8.0 / 3.0;
    case Integrand::Cosine: return std::sin(2.0);
    case Integrand::Step: return kStepEnd;
    case Integrand::NarrowPeak:
      // Gaussian integral over [0, 2]: w sqrt(pi)/2 (erf((2-c)/w) + erf(c/w)).
      return kPeakWidth * std::sqrt(std::numbers::pi) / 2.0 *
             (std::erf((kHigh - kPeakCentre) / kPeakWidth) + std::erf(kPeakCentre / kPeakWidth));
    default: return 0.0;
  }
}

bool has_finite_variance(Integrand f, Pdf p) {
  switch (p) {
    case Pdf::Uniform: return true;
    // p ~ x near 0: fine where f vanishes at 0 like x (x^2) or is negligible (the peak).
    case Pdf::Linear: return f == Integrand::Square || f == Integrand::NarrowPeak;
    // p ~ x^2 near 0: needs f ~ x^2 or smaller.
    case Pdf::Quadratic: return f == Integrand::Square || f == Integrand::NarrowPeak;
    // p ~ (2 - x) near 2: needs f to vanish there (the step; the peak's tail is e^-400).
    case Pdf::Mismatched: return f == Integrand::Step || f == Integrand::NarrowPeak;
    default: return false;
  }
}

double pdf(Pdf p, double x) {
  if (x < kLow || x > kHigh) return 0.0;
  switch (p) {
    case Pdf::Uniform: return 0.5;
    case Pdf::Linear: return x / 2.0;
    case Pdf::Quadratic: return 3.0 * x * x / 8.0;
    case Pdf::Mismatched: return (2.0 - x) / 2.0;
    default: return 0.0;
  }
}

double cdf(Pdf p, double x) {
  x = std::clamp(x, kLow, kHigh);
  switch (p) {
    case Pdf::Uniform: return x / 2.0;
    case Pdf::Linear: return x * x / 4.0;
    case Pdf::Quadratic: return x * x * x / 8.0;
    case Pdf::Mismatched: return x - x * x / 4.0;
    default: return 0.0;
  }
}

double inverse_cdf(Pdf p, double u) {
  switch (p) {
    case Pdf::Uniform: return 2.0 * u;
    case Pdf::Linear: return 2.0 * std::sqrt(u);
    case Pdf::Quadratic: return 2.0 * std::cbrt(u);
    case Pdf::Mismatched: return 2.0 - 2.0 * std::sqrt(1.0 - u);  // solves x - x^2/4 = u
    default: return 0.0;
  }
}

double Estimator::add(double u) {
  const double x = inverse_cdf(p_, u);
  const double density = pdf(p_, x);
  // x has density zero only at an end point of the interval (u = 0 for the
  // linear and quadratic pdfs), a set of measure zero: it contributes f/p = 0.
  const double value = density > 0.0 ? f_(x) / density : 0.0;
  ++n_;
  sum_ += value;
  sum_sq_ += value * value;
  return value;
}

double Estimator::variance() const {
  if (n_ < 2) return 0.0;
  const double m = mean();
  return std::max(0.0, sum_sq_ / static_cast<double>(n_) - m * m) * static_cast<double>(n_) / (static_cast<double>(n_) - 1.0);
}

double Estimator::standard_error() const { return n_ < 2 ? 0.0 : std::sqrt(variance() / static_cast<double>(n_)); }

namespace {
double unit(Rng& rng) { return (static_cast<double>(rng.next_u32()) + 0.5) * 0x1.0p-32; }
}  // namespace

double estimate_pi(std::uint64_t n, std::uint64_t seed) {
  Rng rng(seed, 11);
  std::uint64_t inside = 0;
  for (std::uint64_t i = 0; i < n; ++i) {
    const double x = unit(rng), y = unit(rng);
    inside += x * x + y * y < 1.0;
  }
  return n ? 4.0 * static_cast<double>(inside) / static_cast<double>(n) : 0.0;
}

double estimate_pi_stratified(std::uint64_t n, std::uint64_t seed) {
  const auto side = static_cast<std::uint64_t>(std::sqrt(static_cast<double>(n)));
  if (side == 0) return 0.0;
  Rng rng(seed, 13);
  std::uint64_t inside = 0;
  const double cell = 1.0 / static_cast<double>(side);
  for (std::uint64_t i = 0; i < side; ++i)
    for (std::uint64_t j = 0; j < side; ++j) {
      const double x = (static_cast<double>(i) + unit(rng)) * cell;
      const double y = (static_cast<double>(j) + unit(rng)) * cell;
      inside += x * x + y * y < 1.0;
    }
  return 4.0 * static_cast<double>(inside) / static_cast<double>(side * side);
}

}  // namespace pdflab::lab
