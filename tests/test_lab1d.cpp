// The 1D lab: each inverse CDF against its CDF, estimators of known
// integrals, zero variance when p is proportional to f, and stratified pi
// estimates whose error falls faster than 1/sqrt(N).
#include "renderer/lab/lab1d.h"
#include "renderer/sampling/rng.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

namespace pdflab::lab {
namespace {

constexpr int kPdfs = static_cast<int>(Pdf::Count);
constexpr int kIntegrands = static_cast<int>(Integrand::Count);

TEST(Lab1d, InverseCdfInvertsTheCdf) {
  for (int i = 0; i < kPdfs; ++i) {
    const Pdf p = static_cast<Pdf>(i);
    for (int k = 0; k <= 1000; ++k) {
      const double u = k / 1000.0 * (1.0 - 1e-12);
      const double x = inverse_cdf(p, u);
      ASSERT_GE(x, kLow) << pdf_name(p);
      ASSERT_LE(x, kHigh) << pdf_name(p);
      EXPECT_NEAR(cdf(p, x), u, 1e-12) << pdf_name(p) << " at u = " << u;
    }
    EXPECT_DOUBLE_EQ(cdf(p, kLow), 0.0);
    EXPECT_DOUBLE_EQ(cdf(p, kHigh), 1.0);
  }
}

TEST(Lab1d, PdfIsTheCdfsDerivativeAndIntegratesToOne) {
  for (int i = 0; i < kPdfs; ++i) {
    const Pdf p = static_cast<Pdf>(i);
    double integral = 0.0;
    const int n = 100000;
    for (int k = 0; k < n; ++k) {
      const double x = (k + 0.5) / n * (kHigh - kLow);
      integral += pdf(p, x) * (kHigh - kLow) / n;
      if (k % 1000 == 500) {
        const double h = 1e-6;
        EXPECT_NEAR((cdf(p, x + h) - cdf(p, x - h)) / (2 * h), pdf(p, x), 1e-6) << pdf_name(p) << " at " << x;
      }
    }
    EXPECT_NEAR(integral, 1.0, 1e-8) << pdf_name(p);
    EXPECT_EQ(pdf(p, -0.1), 0.0);
    EXPECT_EQ(pdf(p, 2.1), 0.0);
  }
}

TEST(Lab1d, ExactIntegralsMatchQuadrature) {
  for (int i = 0; i < kIntegrands; ++i) {
    const Integrand f = static_cast<Integrand>(i);
    double sum = 0.0;
    const int n = 2000000;
    for (int k = 0; k < n; ++k) sum += integrand(f, (k + 0.5) / n * 2.0) * 2.0 / n;
    EXPECT_NEAR(sum, exact_integral(f), 1e-6) << integrand_name(f);
  }
}

TEST(Lab1d, EstimatorsConvergeToTheIntegralWithinTheirStandardError) {
  int checked = 0;
  for (int i = 0; i < kIntegrands; ++i)
    for (int j = 0; j < kPdfs; ++j) {
      const Integrand f = static_cast<Integrand>(i);
      const Pdf p = static_cast<Pdf>(j);
      if (!has_finite_variance(f, p)) continue;  // unbiased, but a z-test needs a finite variance
      Estimator e(f, p);
      Rng rng(static_cast<std::uint64_t>(100 + 10 * i + j), 3);
      for (int k = 0; k < 200000; ++k) e.add((static_cast<double>(rng.next_u32()) + 0.5) * 0x1.0p-32);
      const double se = e.standard_error();
      const double z = se > 0.0 ? (e.mean() - exact_integral(f)) / se : 0.0;
      EXPECT_LT(std::fabs(z), 4.5) << integrand_name(f) << " with " << pdf_name(p) << ": mean " << e.mean()
                                   << " vs " << exact_integral(f) << " (se " << se << ")";
      if (se == 0.0) {
        EXPECT_NEAR(e.mean(), exact_integral(f), 1e-9);  // zero variance: only summation rounding
      }
      ++checked;
    }
  EXPECT_GE(checked, 9);
}

TEST(Lab1d, ZeroVarianceWhenThePdfIsProportionalToTheIntegrand) {
  Estimator e(Integrand::Square, Pdf::Quadratic);
  Rng rng(5, 5);
  for (int k = 0; k < 10000; ++k) {
    const double value = e.add((static_cast<double>(rng.next_u32()) + 0.5) * 0x1.0p-32);
    ASSERT_NEAR(value, 8.0 / 3.0, 1e-12);
  }
  EXPECT_LT(e.variance(), 1e-20);
  // A mismatched pdf on the same integrand has a much larger spread.
  Estimator uniform(Integrand::Square, Pdf::Uniform);
  for (int k = 0; k < 10000; ++k) uniform.add((static_cast<double>(rng.next_u32()) + 0.5) * 0x1.0p-32);
  EXPECT_GT(uniform.variance(), 1.0);  // exact: 256/45 - 64/9 ... = 64/45 * 4 - ... > 1
}

// Root-mean-square error of an estimator of pi over `runs` seeds.
template <class F>
double rms_error(F estimate, std::uint64_t n, int runs) {
  double sum = 0.0;
  for (int r = 0; r < runs; ++r) {
    const double e = estimate(n, static_cast<std::uint64_t>(1000 + r)) - std::numbers::pi;
    sum += e * e;
  }
  return std::sqrt(sum / runs);
}

TEST(Lab1d, StratifiedPiErrorFallsFasterThanOneOverSqrtN) {
  // Plain Monte Carlo: error ~ N^-1/2. Jittered strata: only the cells the
  // circle crosses contribute variance, ~ N^-3/4. Slopes over N = 100 .. 40000,
  // each the RMS over 40 seeds (fixed, so the test is deterministic).
  const std::uint64_t n1 = 100, n2 = 40000;
  const int runs = 40;
  const double plain_slope = std::log(rms_error(estimate_pi, n2, runs) / rms_error(estimate_pi, n1, runs)) /
                             std::log(static_cast<double>(n2) / n1);
  const double strat_slope =
      std::log(rms_error(estimate_pi_stratified, n2, runs) / rms_error(estimate_pi_stratified, n1, runs)) /
      std::log(static_cast<double>(n2) / n1);
  std::printf("[pi] error slope: plain %.3f, stratified %.3f\n", plain_slope, strat_slope);
  EXPECT_NEAR(plain_slope, -0.5, 0.1);
  EXPECT_LT(strat_slope, -0.65);
  EXPECT_GT(strat_slope, -0.9);
  EXPECT_NEAR(estimate_pi_stratified(1000000, 7), std::numbers::pi, 1e-3);
}

}  // namespace
}  // namespace pdflab::lab
