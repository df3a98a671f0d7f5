// The reweighting estimator of renderer/metrics/weight_prediction.h on 1D and
// 2D integrands whose second moment, cost and best mixture weight are known by
// numerical integration: samples drawn at one weight must predict the curve at
// every other weight, its optimum, and each cell's own optimum.
#include "renderer/metrics/weight_prediction.h"
#include "renderer/metrics/weight_paths.h"

#include "renderer/error.h"
#include "renderer/integrator/integrator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
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

// The largest path's share of the predicted second moment (the max-to-sum
// ratio). B's pdf is 3x^2 here and f = 1: at w' = 0 a term is 1 / (p_w(x)
// 3x^2), P(term > t) ~ t^(-1/2), no finite mean, and one path keeps a large
// share however many are drawn; at every other weight the terms are bounded
// and the share falls like 1 / paths. A path that B alone cannot draw (b = 0)
// makes the moment at w' = 0 infinite: one path is all of it. Pooling parts
// keeps the verdict.
TEST(WeightPrediction, LargestShareFlagsTheInfiniteMoment) {
  const std::vector<double> grid = pdflab::weight_grid(11);
  const double w = 0.5;
  const auto pdf = [&](double weight, double x) { return weight + (1.0 - weight) * 3.0 * x * x; };
  std::vector<pdflab::WeightPrediction> parts;
  for (std::uint64_t seed : {21u, 22u}) {
    WeightPredictor p(1, grid, w, WeightFamily{1.0});
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int i = 0; i < 100000; ++i) {
      const double x = u(rng) < w ? u(rng) : std::cbrt(u(rng));
      const float value = static_cast<float>(1.0 / pdf(w, x));
      const float rgb[3] = {value, value, value};
      const MixtureVertex v{1.0f, static_cast<float>(3.0 * x * x), 0.0f};
      p.add_path(0, rgb, {&v, 1}, 1.0);
    }
    if (seed == 22u) {
      const float rgb[3] = {1.0f, 1.0f, 1.0f};
      const MixtureVertex v{1.0f, 0.0f, 0.0f};
      p.add_path(0, rgb, {&v, 1}, 1.0);
    }
    parts.push_back(p.predict({1.0f, 1.0f, 1.0f}, 0.0, 0.0));
  }
  const pdflab::WeightPrediction pooled = pdflab::pooled_prediction(parts, pdflab::kRaysAlone);
  for (const pdflab::WeightPrediction& p : {parts[0], parts[1], pooled}) {
    ASSERT_EQ(p.largest_share.size(), grid.size());
    EXPECT_GT(p.largest_share[0], pdflab::kDominantShare);
    for (std::size_t g = 1; g < grid.size(); ++g) EXPECT_LT(p.largest_share[g], 1e-3) << grid[g];
  }
  EXPECT_LT(parts[0].largest_share[0], 1.0);
  EXPECT_EQ(parts[1].largest_share[0], 1.0);
  EXPECT_EQ(pooled.largest_share[0], 1.0);
  // The pooled share is the largest path of both parts over their summed
  // terms, each part's in units of its own paths.
  const std::size_t red = 5 * 3;  // w' = 0.5, channel 0
  const double k0 = static_cast<double>(parts[0].paths), k1 = static_cast<double>(parts[1].paths);
  const double largest = std::max(parts[0].largest_term_rgb[red] * k0, parts[1].largest_term_rgb[red] * k1);
  EXPECT_NEAR(pooled.largest_share[5], largest / (parts[0].moment_rgb[red] * k0 + parts[1].moment_rgb[red] * k1), 1e-12);
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

// Russian roulette between two vertices: the second direction is drawn only
// with probability q = min(1, m), m = 1.2 f(x) / p_w(x) (the throughput times
// an albedo of 1.2), and a survivor's estimate is divided by q. At another
// weight w' the throughput, and so q, is another: q_w'(x) = min(1, 1.2 f(x) /
// p_w'(x)), cut to 1 for some x at some weights and not at others. Then
//     M(w') = int f(y)^2 / p_w'(y) dy * int f(x)^2 / (p_w'(x) q_w'(x)) dx,
//     C(w') = 2 + int p_w'(x) q_w'(x) dx  (two segments, a third if it survives).
// A predictor that ignored the checks would keep q_w in both.
TEST(WeightPrediction, RussianRouletteChecksAreReweighted) {
  const Mixture m;
  const double w = 0.4, albedo = 1.2;
  const auto q = [&](double weight, double x) { return std::min(1.0, albedo * f(x) / m.pdf(weight, x)); };
  const std::vector<double> grid = pdflab::weight_grid(6);
  WeightPredictor aware(1, grid, w, WeightFamily{1.0, true}), blind(1, grid, w, WeightFamily{1.0, false});
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 400000; ++i) {
    const double x = m.sample(w, rng);
    const double throughput = f(x) / m.pdf(w, x), survival = q(w, x);
    MixtureVertex v[2] = {m.vertex(x), {}};
    v[0].segments = 1;  // the camera ray reaches the first vertex
    const float zero[3] = {0.0f, 0.0f, 0.0f};
    if (!(u(rng) < survival)) {  // ended at the second vertex's check: no estimate, two segments
      aware.add_path(0, zero, {v, 1}, 2.0);
      blind.add_path(0, zero, {v, 1}, 2.0);
      continue;
    }
    const double y = m.sample(w, rng);
    v[1] = m.vertex(y);
    v[1].roulette = static_cast<float>(albedo * throughput);
    v[1].segments = 2;
    const float value = static_cast<float>(throughput / survival * f(y) / m.pdf(w, y));
    const float rgb[3] = {value, value, value};
    aware.add_path(0, rgb, v, 3.0);
    blind.add_path(0, rgb, v, 3.0);
  }
  const std::vector<float> mean = {1.0f, 1.0f, 1.0f};
  const pdflab::WeightPrediction aware_p = aware.predict(mean, 0.0, 0.01), blind_p = blind.predict(mean, 0.0, 0.01);
  int blind_off = 0;
  for (std::size_t k = 1; k < grid.size(); ++k) {  // k = 0: an infinite moment, as above
    const double wk = grid[k];
    const double exact = integrate([&](double y) { return f(y) * f(y) / m.pdf(wk, y); }) *
                         integrate([&](double x) { return f(x) * f(x) / (m.pdf(wk, x) * q(wk, x)); });
    const double exact_cost = 2.0 + integrate([&](double x) { return m.pdf(wk, x) * q(wk, x); });
    EXPECT_NEAR(aware.second_moment(0, k, 0), exact, 0.01 * exact) << wk;
    EXPECT_NEAR(aware_p.cost[k], exact_cost, 0.002 * exact_cost) << wk;
    if (std::fabs(blind.second_moment(0, k, 0) / exact - 1.0) > 0.03) ++blind_off;
  }
  // The checks matter here: ignoring them is off by 4-12 % at w' = 0.6 to 1,
  // with the estimates' own error near 0.1 %.
  EXPECT_GE(blind_off, 3);
  // At the sampling weight both are the plain means.
  const std::size_t at_w = 2;
  ASSERT_NEAR(grid[at_w], w, 1e-12);
  EXPECT_NEAR(aware_p.cost[at_w], aware_p.sampling_cost, 1e-9);
  EXPECT_DOUBLE_EQ(aware.second_moment(0, at_w, 0), blind.second_moment(0, at_w, 0));
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

// A cell whose paths pass no diffuse vertex (a light seen directly) has the
// same moment at every weight: no best weight, as a cell without paths.
TEST(WeightPrediction, BestWeightMapSkipsCellsWhereTheWeightDoesNotMatter) {
  const std::vector<double> grid = pdflab::weight_grid(21);
  WeightPredictor p(3, grid, 0.5, WeightFamily{1.0});
  const Mixture m;
  std::mt19937_64 rng(3);
  for (int i = 0; i < 1000; ++i) {
    const float seen[3] = {2.0f, 2.0f, 2.0f};
    p.add_path(0, seen, {}, 1.0);
    const double x = m.sample(0.5, rng);
    const float value = static_cast<float>(2.0 * x / m.pdf(0.5, x));
    const float rgb[3] = {value, value, value};
    const MixtureVertex v = m.vertex(x);
    p.add_path(1, rgb, {&v, 1}, 1.0);
  }
  const std::vector<float> map = p.best_weight_map({2, 2, 2, 1, 1, 1, 1, 1, 1}, 0.0);
  EXPECT_EQ(map[0], -1.0f) << "the weight does not matter here";
  EXPECT_GE(map[1], 0.0f);
  EXPECT_EQ(map[2], -1.0f) << "no paths";
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

// The cost model t = a + b * rays, fitted to runs at several weights: noisy
// times of a known fixed cost and cost per ray give both back.
TEST(CostFit, RecoversTheFixedCostAndTheCostPerRay) {
  const double a = 4e-4, b = 1.2e-3;  // seconds per pass: a fixed cost of a third of a ray
  pdflab::CostFit fit;
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 0.01);
  for (int i = 0; i < 40; ++i) {
    const double rays = 2.0 + 0.06 * i;  // 2 .. 4.3 rays a sample, as from w = 0.1 to 0.9
    fit.add(rays, (a + b * rays) * (1.0 + noise(rng)));
  }
  fit.add(0.0, 1.0);                                       // no rays: ignored
  fit.add(3.0, std::numeric_limits<double>::infinity());  // no time: ignored
  EXPECT_EQ(fit.points(), 40u);
  const pdflab::CostModel m = fit.fit(5.0);
  EXPECT_TRUE(m.fitted);
  EXPECT_NEAR(m.per_ray, b, 0.05 * b);
  EXPECT_NEAR(m.per_sample, a, 0.25 * a);
  EXPECT_NEAR(m.offset(), a / b, 0.1);
  EXPECT_NEAR(m.seconds(3.0), a + 3.0 * b, 0.01 * (a + 3.0 * b));
}

// Rays that barely vary cannot tell the two costs apart: the mean time is
// split by the prior. A negative fixed cost is cut to 0, and a time that falls
// as the rays grow (noise) is no fit.
TEST(CostFit, FallsBackToThePriorAndNeverGoesNegative) {
  pdflab::CostFit same;
  same.add(3.0, 1.0e-3);
  same.add(3.01, 1.2e-3);
  const pdflab::CostModel prior = same.fit(2.0);
  EXPECT_FALSE(prior.fitted);
  EXPECT_NEAR(prior.offset(), 2.0, 1e-12);
  EXPECT_NEAR(prior.seconds(3.005), 1.1e-3, 1e-12);

  pdflab::CostFit steep;  // t = -1 + rays: the fixed cost would be negative
  for (double rays : {2.0, 3.0, 4.0}) steep.add(rays, rays - 1.0);
  const pdflab::CostModel through_origin = steep.fit(2.0);
  EXPECT_TRUE(through_origin.fitted);
  EXPECT_EQ(through_origin.per_sample, 0.0);
  EXPECT_NEAR(through_origin.per_ray, (2.0 * 1.0 + 3.0 * 2.0 + 4.0 * 3.0) / (4.0 + 9.0 + 16.0), 1e-12);

  pdflab::CostFit falling;
  falling.add(2.0, 2.0);
  falling.add(4.0, 1.0);
  EXPECT_FALSE(falling.fit(1.0).fitted);
  EXPECT_NEAR(falling.fit(1.0).offset(), 1.0, 1e-12);
  EXPECT_EQ(pdflab::CostFit().fit(1.0).per_ray, 0.0);
}

// A fixed cost per sample makes the longer paths relatively cheaper, and the
// optimum of efficiency moves towards them; the re-priced prediction follows.
TEST(CostFit, FixedCostMovesThePredictedOptimum) {
  const Mixture m;
  const auto cost = [](double x) { return x < 0.2 ? 101.0 : 1.0; };
  const double mu = integrate(f);
  const auto exact_cost = [&](double w) { return integrate([&](double x) { return cost(x) * m.pdf(w, x); }); };
  const pdflab::CostModel model{60.0e-6, 1.0e-6, true};  // 60 rays of fixed cost
  const auto exact_efficiency = [&](double w, double offset) {
    return 1.0 / ((exact_second_moment(m, w) - mu * mu) * (exact_cost(w) + offset));
  };
  const double rays_only = argmax([&](double w) { return exact_efficiency(w, 0.0); });
  const double with_fixed = argmax([&](double w) { return exact_efficiency(w, model.offset()); });
  ASSERT_GT(std::fabs(with_fixed - rays_only), 0.04);

  const std::vector<double> grid = pdflab::weight_grid(101);
  const std::vector<float> mean = {static_cast<float>(mu), static_cast<float>(mu), static_cast<float>(mu)};
  pdflab::WeightPrediction pred = draw(m, 0.5, 200000, 3, grid, cost).predict(mean, 0.0, 0.0);
  EXPECT_NEAR(pred.best_weight(), rays_only, 0.02);
  EXPECT_NEAR(pred.sampling_cost, exact_cost(0.5), 0.02 * exact_cost(0.5));
  pdflab::apply_cost_model(pred, model);
  EXPECT_NEAR(pred.best_weight(), with_fixed, 0.02);
  // In the model's seconds.
  const double rv = pred.relative_variance[30];
  EXPECT_NEAR(pred.efficiency[30], 1.0 / (rv * model.seconds(pred.cost[30])), 1e-9 * pred.efficiency[30]);
}

// Auto weight fits the cost model to its passes' own timing (each pass's
// seconds per sample against its paths' mean rays), and picks the optimum
// under that model rather than under rays alone.
TEST(CostFit, AutoWeightLearnsTheCostFromItsPasses) {
  const Mixture m;
  const auto cost = [](double x) { return x < 0.2 ? 101.0 : 1.0; };
  const double mu = integrate(f);
  const auto exact_cost = [&](double w) { return integrate([&](double x) { return cost(x) * m.pdf(w, x); }); };
  const pdflab::CostModel truth{60.0e-6, 1.0e-6, true};
  const double with_fixed = argmax(
      [&](double w) { return 1.0 / ((exact_second_moment(m, w) - mu * mu) * truth.seconds(exact_cost(w))); });
  const std::vector<float> mean = {static_cast<float>(mu), static_cast<float>(mu), static_cast<float>(mu)};
  // A prior of no fixed cost: only the passes' timing can move the choice.
  pdflab::AutoWeight chooser(0.3, 101, 0.0);
  int pass = 0;
  for (double w : {0.3, 0.7, 0.5}) {
    const pdflab::WeightPrediction pred =
        draw(m, w, 100000, 20 + static_cast<std::uint64_t>(pass++), chooser.grid(), cost).predict(mean, 0.0, 0.0);
    chooser.add_pass(pred, truth.seconds(pred.sampling_cost));
  }
  EXPECT_TRUE(chooser.cost_model().fitted);
  EXPECT_NEAR(chooser.cost_model().offset(), truth.offset(), 0.05 * truth.offset());
  EXPECT_NEAR(chooser.weight(), with_fixed, 0.03);
}

// The viewer's curve is priced by AutoWeight::priced: before any fit, the
// prediction's own time split with the prior fixed cost, which is the model
// add_pass makes of a first pass, so the curve's best is auto weight's next
// weight; after a fit, the fitted model.
TEST(CostFit, PricedCurveIsWhatAutoWeightChoosesFrom) {
  const Mixture m;
  const auto cost = [](double x) { return x < 0.2 ? 101.0 : 1.0; };
  const double mu = integrate(f);
  const pdflab::CostModel truth{60.0e-6, 1.0e-6, true};
  const std::vector<float> mean = {static_cast<float>(mu), static_cast<float>(mu), static_cast<float>(mu)};
  pdflab::AutoWeight chooser(0.5, 101, truth.offset());  // the prior is the truth here
  const pdflab::WeightPrediction pred = draw(m, 0.5, 100000, 40, chooser.grid(), cost).predict(mean, 0.0, 0.0);
  const double seconds = truth.seconds(pred.sampling_cost);
  const pdflab::WeightPrediction curve = chooser.priced(pred, seconds);
  pdflab::WeightPrediction exact = pred;
  pdflab::apply_cost_model(exact, truth);
  for (std::size_t g = 0; g < curve.efficiency.size(); ++g)
    EXPECT_NEAR(curve.efficiency[g], exact.efficiency[g], 1e-9 * exact.efficiency[g]) << g;
  chooser.add_pass(pred, seconds);
  EXPECT_NEAR(chooser.weight(), pdflab::defended_weight(curve.best_weight()), 1e-12);
  // With no prior fixed cost the same prediction prices by rays alone, and its best moves.
  const pdflab::WeightPrediction rays_only = pdflab::AutoWeight(0.5, 101, 0.0).priced(pred, seconds);
  EXPECT_GT(std::fabs(rays_only.best_weight() - curve.best_weight()), 0.03);
}

// Auto weight stops predicting once two predictions in a row choose the same
// weight; the first pass's weight is a guess, so one prediction that keeps it
// does not settle anything, and a prediction that moves it unsettles it.
TEST(CostFit, AutoWeightSettlesWhenTwoPredictionsAgree) {
  const pdflab::AutoWeight probe(0.5, 21, 0.0);
  const auto peaked = [&](double at) {  // one sample's relative variance least at `at`, rays 1 everywhere
    pdflab::WeightPrediction p;
    p.weight = probe.grid();
    for (double w : p.weight) p.relative_variance.push_back(1.0 + 10.0 * (w - at) * (w - at));
    p.cost.assign(p.weight.size(), 1.0);
    p.efficiency.assign(p.weight.size(), 0.0);
    p.paths = 1000;
    p.sampling_cost = 1.0;
    return p;
  };
  pdflab::AutoWeight kept(0.5, 21, 0.0);
  kept.add_pass(peaked(0.5));
  EXPECT_DOUBLE_EQ(kept.weight(), 0.5);
  EXPECT_FALSE(kept.settled()) << "the first weight is a guess: one prediction agreeing with it settles nothing";
  kept.add_pass(peaked(0.5));
  EXPECT_TRUE(kept.settled());

  pdflab::AutoWeight moved(0.5, 21, 0.0);
  moved.add_pass(peaked(0.8));
  EXPECT_DOUBLE_EQ(moved.weight(), 0.8);
  EXPECT_FALSE(moved.settled());
  moved.add_pass(peaked(0.8));
  EXPECT_TRUE(moved.settled());
  // A pass whose paths (ten times as many) put the best elsewhere moves the pooled best: not settled.
  pdflab::WeightPrediction far = peaked(0.2);
  far.paths = 10000;
  moved.add_pass(far);
  EXPECT_LT(moved.weight(), 0.5);
  EXPECT_FALSE(moved.settled());

  // A pass that chooses nothing (no paths; or a pooled prediction with no
  // finite best) keeps the weight without agreeing with it.
  pdflab::WeightPrediction empty = peaked(0.5);
  empty.paths = 0;
  pdflab::AutoWeight guessed(0.5, 21, 0.0);
  guessed.add_pass(empty);
  guessed.add_pass(empty);
  EXPECT_DOUBLE_EQ(guessed.weight(), 0.5);
  EXPECT_FALSE(guessed.settled()) << "two passes without paths froze the first guess";
  pdflab::AutoWeight once(0.5, 21, 0.0);
  once.add_pass(peaked(0.7));
  once.add_pass(empty);
  EXPECT_DOUBLE_EQ(once.weight(), 0.7);
  EXPECT_FALSE(once.settled()) << "one choice and a pass without paths are not two choices";
  pdflab::WeightPrediction unbounded = peaked(0.7);
  unbounded.relative_variance.assign(unbounded.weight.size(), std::numeric_limits<double>::infinity());
  once.add_pass(unbounded);
  EXPECT_DOUBLE_EQ(once.weight(), 0.7);
  EXPECT_FALSE(once.settled()) << "a pooled prediction with no best chose nothing";
}

TEST(WeightPrediction, ForecastSeedIsAnotherSeed) {
  for (std::uint64_t seed : {0ull, 1ull, 2ull, 0x9e3779b97f4a7c15ull, ~0ull}) {
    EXPECT_NE(pdflab::forecast_seed(seed), seed);
    EXPECT_NE(pdflab::SampleSeed(pdflab::forecast_seed(seed)).rng_key, pdflab::SampleSeed(seed).rng_key);
  }
}

TEST(WeightPrediction, DefensiveFloor) {
  EXPECT_EQ(pdflab::defended_weight(0.0), pdflab::kDefensiveFloor);
  EXPECT_EQ(pdflab::defended_weight(1.0), 1.0 - pdflab::kDefensiveFloor);
  EXPECT_EQ(pdflab::defended_weight(0.3), 0.3);
}

}  // namespace
