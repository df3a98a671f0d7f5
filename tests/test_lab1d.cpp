// The 1D lab: each inverse CDF against its CDF, estimators of known
// integrals, zero variance when p is proportional to f, and stratified pi
// estimates whose error falls faster than 1/sqrt(N); f(x) typed as an
// expression, and adaptive quadrature against closed forms.
#include "renderer/error.h"
#include "renderer/lab/expression.h"
#include "renderer/lab/lab1d.h"
#include "renderer/sampling/rng.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
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

// --- f(x) typed as an expression, and the exact integral by quadrature ---

namespace {

std::string parse_error(const std::string& text) {
  try {
    (void)pdflab::lab::Expression::parse(text);
  } catch (const pdflab::InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(LabExpression, EvaluatesLikeTheFixedIntegrands) {
  using namespace pdflab::lab;
  const Expression square = Expression::parse("x^2");
  const Expression cosine = Expression::parse("cos(x)");
  for (double x : {0.0, 0.3, 1.0, 1.7, 2.0}) {
    EXPECT_NEAR(square(x), integrand(Integrand::Square, x), 1e-14);
    EXPECT_NEAR(cosine(x), integrand(Integrand::Cosine, x), 1e-14);
  }
  EXPECT_NEAR(Expression::parse("pi")(0.0), std::numbers::pi, 1e-15);
  // A copy of the function evaluates on its own parser: the original's x is untouched.
  const auto f = square.function();
  EXPECT_DOUBLE_EQ(f(3.0), 9.0);
  EXPECT_DOUBLE_EQ(square(0.5), 0.25);
}

TEST(LabExpression, BadTextGetsAMessageNamingIt) {
  EXPECT_NE(parse_error("sin(").find("f(x) = 'sin('"), std::string::npos) << parse_error("sin(");
  EXPECT_NE(parse_error("y*2").find("'y*2'"), std::string::npos);
  EXPECT_NE(parse_error("x +* 2"), "");
  EXPECT_NE(parse_error("   ").find("empty"), std::string::npos);
  EXPECT_NE(parse_error("1/0").find("no finite value"), std::string::npos) << parse_error("1/0");
  EXPECT_EQ(parse_error("exp(-x)*x^3"), "");
}

TEST(LabQuadrature, MatchesClosedForms) {
  using namespace pdflab::lab;
  for (int i = 0; i < static_cast<int>(Integrand::Count); ++i) {
    const auto f = static_cast<Integrand>(i);
    EXPECT_NEAR(integrate([f](double x) { return integrand(f, x); }, kLow, kHigh), exact_integral(f), 1e-7)
        << integrand_name(f);
  }
  // sin^2(pi x) over [0, 2] is 1; x^3 e^-x over [0, 2] is 6 - 38/e^2.
  EXPECT_NEAR(integrate(Expression::parse("sin(pi*x)^2").function(), 0.0, 2.0), 1.0, 1e-9);
  EXPECT_NEAR(integrate(Expression::parse("exp(-x)*x^3").function(), 0.0, 2.0), 6.0 - 38.0 / std::exp(2.0), 1e-9);
  // A jump: the adaptive splitting finds it.
  EXPECT_NEAR(integrate(Expression::parse("x < 0.3 ? 1 : 0").function(), 0.0, 2.0), 0.3, 1e-6);
  // Not finite somewhere sampled: NaN, for the caller to say so.
  EXPECT_TRUE(std::isnan(integrate([](double x) { return 1.0 / x; }, 0.0, 2.0)));
  // A wildly oscillating f ends within the evaluation budget.
  const double fast = integrate([](double x) { return std::sin(1e6 * x); }, 0.0, 2.0);
  EXPECT_TRUE(std::isfinite(fast));
}

TEST(LabExpression, TheEstimatorOfATypedFMatchesTheFixedOne) {
  using namespace pdflab::lab;
  Estimator fixed(Integrand::Square, Pdf::Linear);
  Estimator typed(Expression::parse("x*x").function(), Pdf::Linear);
  for (int i = 1; i < 1000; ++i) {
    const double u = (i * 0.6180339887498949) - std::floor(i * 0.6180339887498949);
    EXPECT_NEAR(fixed.add(u), typed.add(u), 1e-12);
  }
  EXPECT_NEAR(fixed.mean(), typed.mean(), 1e-12);
}
