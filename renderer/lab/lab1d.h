#pragma once
// The book's first chapters in one dimension: an integrand f on [0, 2], a pdf
// p to sample it with (by inverting its CDF), the Monte Carlo estimate
// mean(f(x) / p(x)) with its standard error, and estimating pi with and
// without stratification. The viewer's 1D lab draws these; tests check them.
#include <array>
#include <cstdint>
#include <functional>
#include <string_view>
#include <vector>

namespace pdflab::lab {

inline constexpr double kLow = 0.0, kHigh = 2.0;  // every integrand and pdf lives on [0, 2]

enum class Integrand : std::uint8_t { Square, Cosine, Step, NarrowPeak, Count };
enum class Pdf : std::uint8_t { Uniform, Linear, Quadratic, Mismatched, Count };

std::string_view integrand_name(Integrand f);  // "x^2", ...
std::string_view pdf_name(Pdf p);              // "uniform", ...

double integrand(Integrand f, double x);
double exact_integral(Integrand f);  // over [0, 2]

// Whether f(x)/p(x) has a finite variance: where p falls to zero faster than f
// (the linear and quadratic pdfs at 0, the mismatched one at 2), the
// estimator stays unbiased but its variance is infinite: its error does not
// fall like 1/sqrt(N), which the lab shows. Worked out by hand per pair: the
// integral of f^2/p diverges like the integral of 1/x (or 1/x^2) near that end.
bool has_finite_variance(Integrand f, Pdf p);

double pdf(Pdf p, double x);
double cdf(Pdf p, double x);
double inverse_cdf(Pdf p, double u);  // u in [0, 1): the sample

// Running estimate of the integral of f with samples from p.
class Estimator {
 public:
  Estimator(Integrand f, Pdf p) : f_([f](double x) { return integrand(f, x); }), p_(p) {}
  // Any f on [kLow, kHigh], e.g. a typed Expression's function().
  Estimator(std::function<double(double)> f, Pdf p) : f_(std::move(f)), p_(p) {}
  // Adds the sample x = inverse_cdf(p, u); returns f(x) / p(x).
  double add(double u);
  std::uint64_t count() const { return n_; }
  double mean() const { return n_ ? sum_ / static_cast<double>(n_) : 0.0; }
  double variance() const;        // of one sample f(x)/p(x)
  double standard_error() const;  // of the mean
  void reset() { n_ = 0, sum_ = 0.0, sum_sq_ = 0.0; }

 private:
  std::function<double(double)> f_;
  Pdf p_;
  std::uint64_t n_ = 0;
  double sum_ = 0.0, sum_sq_ = 0.0;
};

// Estimates of pi from n points in the unit square (the quarter disc's area,
// times 4): plain uniform points, or one jittered point per cell of a
// sqrt(n) x sqrt(n) grid (n rounded down to a square).
double estimate_pi(std::uint64_t n, std::uint64_t seed);
double estimate_pi_stratified(std::uint64_t n, std::uint64_t seed);

}  // namespace pdflab::lab
