// The reweighting estimator of renderer/metrics/weight_prediction.h on 1D and
// 2D integrands whose second moment, cost and best mixture weight are known by
// numerical integration: samples drawn at one weight must predict the curve at
// every other weight, its optimum, and each cell's own optimum.
#include "renderer/metrics/weight_prediction.h"

#include "renderer/error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>
#include <vector>

namespace {

using pdflab::MixtureVertex;
using pdflab::WeightFamily;
using pdflab::WeightPredictor;

// Technique A: uniform on [0, 1]. Technique B: p(x) = 2x. Technique C (held
// fixed where used): p(x) = 3x^2.
double pdf_a(double) { return 1.0; }
double pdf_b(double x) { return 2.0 * x; }
double pdf_c(double x) { return 3.0 * x * x; }

struct Mixture {
  double share = 1.0;  // A and B together
  double c = 0.0;      // C's weight; share + c = 1
  double pdf(double w, double x) const { return share * (w * pdf_a(x) + (1.0 - w) * pdf_b(x)) + c * pdf_c(x); }
  double sample(double w, std::mt19937_64& rng) const {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const double pick = u(rng), v = u(rng);
    if (pick < share * w) return v;
    if (pick < share) return std::sqrt(v);
    return std::cbrt(v);
  }
  MixtureVertex vertex(double x) const {
    return {static_cast<float>(pdf_a(x)), static_cast<float>(pdf_b(x)), static_cast<float>(c * pdf_c(x))};
  }
};

// Midpoint rule: plenty for these smooth integrands (the 1/(2x) of B alone is
// never integrated where f(0) != 0 at w = 0; see the callers).
double integrate(const std::function<double(double)>& g, int n = 20000) {
  double sum = 0.0;
  for (int i = 0; i < n; ++i) sum += g((i + 0.5) / n);
  return sum / n;
}

// The integrand of the main test: its best weight lies inside (0, 1) and is no
// zero-variance point (the relative variance there is about 7 %).
double f(double x) { return 0.2 + x * x * x; }

double exact_second_moment(const Mixture& m, double w) {
  return integrate([&](double x) { return f(x) * f(x) / m.pdf(w, x); });
}

// argmax over a fine grid of a function of the weight.
double argmax(const std::function<double(double)>& g, double lo = 0.0, double hi = 1.0) {
  double best = lo, best_value = -1e300;
  for (int i = 0; i <= 1000; ++i) {
    const double w = lo + (hi - lo) * i / 1000.0;
    const double v = g(w);
    if (v > best_value) best_value = v, best = w;
  }
  return best;
}

WeightPredictor draw(const Mixture& m, double w, int paths, std::uint64_t seed, const std::vector<double>& grid,
                     const std::function<double(double)>& cost = [](double) { return 1.0; }) {
  WeightPredictor predictor(1, grid, w, WeightFamily{m.share});
  std::mt19937_64 rng(seed);
  for (int i = 0; i < paths; ++i) {
    const double x = m.sample(w, rng);
    const float value = static_cast<float>(f(x) / m.pdf(w, x));
    const float rgb[3] = {value, value, value};
    const MixtureVertex v = m.vertex(x);
    predictor.add_path(0, rgb, {&v, 1}, cost(x));
  }
  return predictor;
}

TEST(WeightPrediction, SecondMomentAtOtherWeightsMatchesQuadrature) {
  const Mixture m;
  const std::vector<double> grid = pdflab::weight_grid(11);
  for (double w : {0.3, 0.5, 0.8}) {
    const WeightPredictor p = draw(m, w, 200000, 11, grid);
    for (std::size_t g = 1; g < grid.size(); ++g) {  // w' = 0: f(0) > 0 and p_B(0) = 0, infinite moment
      const double exact = exact_second_moment(m, grid[g]);
      EXPECT_NEAR(p.second_moment(0, g, 0), exact, 0.01 * exact) << "drawn at " << w << ", predicted at " << grid[g];
    }
    // At w' = 0 the true second moment is infinite; the estimate must at least be far above the minimum.
    EXPECT_GT(p.second_moment(0, 0, 0), 1.3 * exact_second_moment(m, 0.2));
  }
}

TEST(WeightPrediction, PredictedOptimumIsTheTrueOne) {
  const Mixture m;
  const double mu = integrate(f);
  const double truth = argmax([&](double w) { return 1.0 / (exact_second_moment(m, w) - mu * mu); });
  ASSERT_GT(truth, 0.15);
  ASSERT_LT(truth, 0.3);
  const std::vector<double> grid = pdflab::weight_grid(101);
  const std::vector<float> mean = {static_cast<float>(mu), static_cast<float>(mu), static_cast<float>(mu)};
  for (double w : {0.2, 0.5, 0.8}) {
    const WeightPredictor p = draw(m, w, 200000, 7, grid);
    const pdflab::WeightPrediction pred = p.predict(mean, 0.0, 0.0);
    EXPECT_NEAR(pred.best_weight(), truth, 0.02) << "drawn at " << w;
    // The relative variance curve itself, where it is finite.
    for (std::size_t g = 10; g < grid.size(); g += 10) {
      const double exact = (exact_second_moment(m, grid[g]) - mu * mu) / (mu * mu);
      EXPECT_NEAR(pred.relative_variance[g], exact, 0.1 * exact) << "drawn at " << w << ", predicted at " << grid[g];
    }
  }
}

// A path's cost that depends on where it went: the efficiency's optimum moves
// away from the variance's optimum, and the prediction must follow it.
TEST(WeightPrediction, CostMovesTheOptimum) {
  const Mixture m;
  const auto cost = [](double x) { return x < 0.2 ? 101.0 : 1.0; };
  const double mu = integrate(f);
  const auto exact_cost = [&](double w) { return integrate([&](double x) { return cost(x) * m.pdf(w, x); }); };
  const double by_variance = argmax([&](double w) { return 1.0 / (exact_second_moment(m, w) - mu * mu); });
  const double by_efficiency =
      argmax([&](double w) { return 1.0 / ((exact_second_moment(m, w) - mu * mu) * exact_cost(w)); });
  ASSERT_GT(by_variance - by_efficiency, 0.04);

  const std::vector<double> grid = pdflab::weight_grid(101);
  const std::vector<float> mean = {static_cast<float>(mu), static_cast<float>(mu), static_cast<float>(mu)};
  const WeightPredictor p = draw(m, 0.5, 200000, 3, grid, cost);
  const double seconds_per_sample = 2e-6;
  const pdflab::WeightPrediction pred = p.predict(mean, seconds_per_sample, 0.0);
  for (std::size_t g = 0; g < grid.size(); g += 10)
    EXPECT_NEAR(pred.cost[g], exact_cost(grid[g]), 0.02 * exact_cost(grid[g])) << grid[g];
  EXPECT_NEAR(pred.best_weight(), by_efficiency, 0.02);
  // In seconds: at the sampling weight the time per sample is the measured one.
  const double rv_half = pred.relative_variance[50];
  EXPECT_NEAR(pred.efficiency[50], 1.0 / (rv_half * seconds_per_sample), 1e-9 / (rv_half * seconds_per_sample));
}

// Two diffuse vertices, a third technique held at a fixed weight: the path
// ratio is the product over vertices, and only the pair's share varies.
TEST(WeightPrediction, PathRatioIsTheProductOverVertices) {
  Mixture m;
  m.share = 0.8;
  m.c = 0.2;
  const auto g = [](double x) { return 0.3 + x; };
  const auto exact = [&](double w) {
    const double one = integrate([&](double x) { return g(x) * g(x) / m.pdf(w, x); });
    return one * one;  // f(x, y) = g(x) g(y) and p(x, y) = p(x) p(y)
  };
  const std::vector<double> grid = pdflab::weight_grid(6);
  WeightPredictor p(1, grid, 0.4, WeightFamily{m.share});
  std::mt19937_64 rng(5);
  for (int i = 0; i < 300000; ++i) {
    const double x = m.sample(0.4, rng), y = m.sample(0.4, rng);
    const float value = static_cast<float>(g(x) * g(y) / (m.pdf(0.4, x) * m.pdf(0.4, y)));
    const float rgb[3] = {value, 0.0f, value};
    const MixtureVertex v[2] = {m.vertex(x), m.vertex(y)};
    p.add_path(0, rgb, v, 2.0);
  }
  // k = 0: g(0) > 0 and p_0(x) ~ x near 0, an infinite moment.
  for (std::size_t k = 1; k < grid.size(); ++k) {
    EXPECT_NEAR(p.second_moment(0, k, 0), exact(grid[k]), 0.02 * exact(grid[k])) << grid[k];
  }
  for (std::size_t k = 0; k < grid.size(); ++k) EXPECT_EQ(p.second_moment(0, k, 1), 0.0);
  // Every path traced two segments, at any weight.
  const std::vector<float> mean = {1.0f, 0.0f, 1.0f};
  const pdflab::WeightPrediction pred = p.predict(mean, 0.0, 0.01);
  for (double c : pred.cost) EXPECT_NEAR(c, 2.0, 1e-9);
}

// Cells are independent: a constant integrand is sampled without variance by
// A (w = 1), a linear one by B (w = 0), and the map says so per cell.
TEST(WeightPrediction, BestWeightMapPerCell) {
  const Mixture m;
  const std::vector<double> grid = pdflab::weight_grid(21);
  WeightPredictor p(3, grid, 0.5, WeightFamily{1.0});
  std::mt19937_64 rng(9);
  const std::function<double(double)> integrands[3] = {[](double) { return 1.0; }, [](double x) { return 2.0 * x; },
                                                       [](double x) { return 0.2 + x * x * x; }};
  for (int i = 0; i < 60000; ++i)
    for (int cell = 0; cell < 3; ++cell) {
      const double x = m.sample(0.5, rng);
      const float value = static_cast<float>(integrands[cell](x) / m.pdf(0.5, x));
      const float rgb[3] = {value, value, value};
      const MixtureVertex v = m.vertex(x);
      p.add_path(cell, rgb, {&v, 1}, 1.0);
    }
  const std::vector<float> mean = {1, 1, 1, 1, 1, 1, 0.45f, 0.45f, 0.45f};
  const std::vector<float> map = p.best_weight_map(mean, 0.0);
  ASSERT_EQ(map.size(), 3u);
  EXPECT_EQ(map[0], 1.0f);
  EXPECT_EQ(map[1], 0.0f);
  EXPECT_NEAR(map[2], 0.2f, 0.051f);
  // The image-wide prediction weighs the cells by their relative variance.
  const pdflab::WeightPrediction pred = p.predict(mean, 0.0, 0.0);
  EXPECT_GT(pred.best_weight(), 0.0);
  EXPECT_LT(pred.best_weight(), 1.0);
}

TEST(WeightPrediction, MergeEqualsOneAccumulation) {
  const Mixture m;
  const std::vector<double> grid = pdflab::weight_grid(5);
  WeightPredictor whole(2, grid, 0.5, WeightFamily{1.0}), first(2, grid, 0.5, WeightFamily{1.0}),
      second(2, grid, 0.5, WeightFamily{1.0});
  std::mt19937_64 rng(1);
  for (int i = 0; i < 1000; ++i) {
    const double x = m.sample(0.5, rng);
    const float rgb[3] = {static_cast<float>(x), 1.0f, 2.0f};
    const MixtureVertex v = m.vertex(x);
    whole.add_path(i % 2, rgb, {&v, 1}, 1.0 + x);
    (i < 400 ? first : second).add_path(i % 2, rgb, {&v, 1}, 1.0 + x);
  }
  first.merge(second);
  EXPECT_EQ(first.paths(), whole.paths());
  for (int cell = 0; cell < 2; ++cell)
    for (std::size_t g = 0; g < grid.size(); ++g)
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(first.second_moment(cell, g, c), whole.second_moment(cell, g, c),
                    1e-12 * whole.second_moment(cell, g, c));
  const WeightPredictor other(2, grid, 0.25, WeightFamily{1.0});
  EXPECT_THROW(first.merge(other), pdflab::InputError);
}

// A direction only B can draw has density 0 at w' = 1: the path could not
// occur there, the second moment is infinite and that weight is never "best".
TEST(WeightPrediction, WeightThatCannotDrawAPathHasNoEfficiency) {
  const std::vector<double> grid = {0.0, 0.5, 1.0};
  WeightPredictor p(1, grid, 0.5, WeightFamily{1.0});
  const MixtureVertex only_b{0.0f, 2.0f, 0.0f};
  const MixtureVertex both{1.0f, 1.0f, 0.0f};
  const float rgb[3] = {1.0f, 1.0f, 1.0f};
  p.add_path(0, rgb, {&only_b, 1}, 1.0);
  p.add_path(0, rgb, {&both, 1}, 1.0);
  EXPECT_TRUE(std::isinf(p.second_moment(0, 2, 0)));
  const pdflab::WeightPrediction pred = p.predict({0.5f, 0.5f, 0.5f}, 1.0, 0.0);
  EXPECT_EQ(pred.efficiency[2], 0.0);
  EXPECT_NE(pred.best, 2);
  EXPECT_GT(pred.efficiency[0], 0.0);
  EXPECT_TRUE(std::isfinite(pred.efficiency[0]));
}

TEST(WeightPrediction, DefensiveFloor) {
  EXPECT_EQ(pdflab::defended_weight(0.0), pdflab::kDefensiveFloor);
  EXPECT_EQ(pdflab::defended_weight(1.0), 1.0 - pdflab::kDefensiveFloor);
  EXPECT_EQ(pdflab::defended_weight(0.3), 0.3);
}

}  // namespace
