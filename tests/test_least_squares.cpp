// Linear least squares (renderer/metrics/statistics.h): known lines and
// parabolas come back, noisy points give the closed-form regression, and
// points that do not determine the coefficients are refused.
#include "renderer/metrics/statistics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

using pdflab::stats::least_squares;
using pdflab::stats::polynomial_fit;

TEST(LeastSquares, ExactParabolaComesBack) {
  std::vector<double> x, y;
  for (double v = -0.2; v <= 0.2 + 1e-9; v += 0.1) x.push_back(v), y.push_back(3.0 - 2.0 * v - 40.0 * v * v);
  const auto c = polynomial_fit(x, y, 2);
  ASSERT_TRUE(c.has_value());
  EXPECT_NEAR((*c)[0], 3.0, 1e-10);
  EXPECT_NEAR((*c)[1], -2.0, 1e-9);
  EXPECT_NEAR((*c)[2], -40.0, 1e-8);
}

TEST(LeastSquares, NoisyLineMatchesTheClosedForm) {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 5e6);
  std::vector<double> x, y;
  for (int i = 0; i < 12; ++i) {  // widely scaled, as bench_memory's sizes and bytes
    x.push_back(600.0 + 200.0 * i);
    y.push_back(4e7 + 3e4 * x.back() + noise(rng));
  }
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const double n = static_cast<double>(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) sx += x[i], sy += y[i], sxx += x[i] * x[i], sxy += x[i] * y[i];
  const double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx), intercept = (sy - slope * sx) / n;
  const auto c = polynomial_fit(x, y, 1);
  ASSERT_TRUE(c.has_value());
  EXPECT_NEAR((*c)[1], slope, 1e-9 * std::fabs(slope));
  EXPECT_NEAR((*c)[0], intercept, 1e-6 * std::fabs(intercept));
  EXPECT_NEAR((*c)[1], 3e4, 3e3);  // and near the truth
}

TEST(LeastSquares, ThroughTheOriginIsSumXyOverSumXx) {
  const std::vector<double> x = {1.0, 2.0, 4.0}, y = {2.5, 3.5, 9.0};
  const auto c = least_squares(x, 1, y);
  ASSERT_TRUE(c.has_value());
  EXPECT_NEAR((*c)[0], (2.5 + 7.0 + 36.0) / (1.0 + 4.0 + 16.0), 1e-14);
}

TEST(LeastSquares, GeneralDesignMatrix) {
  // y = 1 a + 2 b - 3 c over points whose basis values are not powers.
  const std::vector<double> design = {1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1, 2, -1, 0.5};
  std::vector<double> y;
  for (std::size_t i = 0; i < 5; ++i) y.push_back(design[i * 3] + 2.0 * design[i * 3 + 1] - 3.0 * design[i * 3 + 2]);
  const auto c = least_squares(design, 3, y);
  ASSERT_TRUE(c.has_value());
  EXPECT_NEAR((*c)[0], 1.0, 1e-12);
  EXPECT_NEAR((*c)[1], 2.0, 1e-12);
  EXPECT_NEAR((*c)[2], -3.0, 1e-12);
}

TEST(LeastSquares, UndeterminedFitsAreRefused) {
  EXPECT_FALSE(polynomial_fit(std::vector<double>{1.0, 1.0, 1.0}, std::vector<double>{1.0, 2.0, 3.0}, 1));  // one x
  EXPECT_FALSE(polynomial_fit(std::vector<double>{0.0, 1.0}, std::vector<double>{1.0, 2.0}, 2));  // too few points
  EXPECT_FALSE(polynomial_fit(std::vector<double>{0.0, 1.0, 2.0}, std::vector<double>{1.0, 2.0}, 1));  // sizes
  EXPECT_FALSE(least_squares(std::vector<double>{0.0, 0.0}, 1, std::vector<double>{1.0, 2.0}));       // zero column
  EXPECT_FALSE(polynomial_fit(std::vector<double>{0.0, 1.0, NAN}, std::vector<double>{1.0, 2.0, 3.0}, 1));
  EXPECT_FALSE(least_squares(std::vector<double>{}, 0, std::vector<double>{}));
  // Two points, two coefficients: the line through them.
  const auto c = polynomial_fit(std::vector<double>{1.0, 3.0}, std::vector<double>{2.0, 6.0}, 1);
  ASSERT_TRUE(c.has_value());
  EXPECT_NEAR((*c)[0], 0.0, 1e-12);
  EXPECT_NEAR((*c)[1], 2.0, 1e-12);
}
