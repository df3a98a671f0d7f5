// The weight predictor fed by real paths (renderer/metrics/weight_paths.h): the
// tracer's record does not change a path, and the second moment predicted at
// one weight from paths drawn at another equals the one measured from paths
// drawn at that weight, on the book's box.
#include "renderer/error.h"
#include "renderer/integrator/integrator.h"
#include "renderer/metrics/weight_paths.h"
#include "renderer/sampling/guiding.h"
#include "renderer/scene/scene_loader.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

namespace {

using namespace pdflab;

// Short paths keep the second moments finite and their estimates tame: with
// depth 50 a small cosine share makes the moment grow geometrically with depth
// (about albedo^2 / w a bounce), and no finite run measures it well.
Scene small_box(int size, int depth = 4) {
  Scene scene = load_scene_file(std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes/cornell_book.json");
  scene.max_depth = depth;
  scene.camera.width = size;
  scene.camera.height = size;
  scene.prepare();
  return scene;
}

MixtureFamily cosine_light() {
  MixtureFamily f;
  f.a = Strategy::parse("cosine");
  f.b = Strategy::parse("light");
  return f;
}

TEST(WeightPaths, RecordingLeavesThePathAlone) {
  const Scene scene = small_box(8);
  const SamplingPlan plan = SamplingPlan::make(Strategy::parse("mix:cosine=0.5,light=0.5"), scene);
  const SampleSeed seed(3);
  PathRecord record;
  int with_vertices = 0;
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x)
      for (std::uint32_t i = 0; i < 8; ++i) {
        PixelSampleStart a = begin_pixel_sample(scene, seed, x, y, i), b = a;
        DropCounts da, db;
        const Vec3 plain = trace_path(scene, plan, a.ray, a.rng, da);
        const Vec3 recorded = trace_path(scene, plan, b.ray, b.rng, db, &record);
        EXPECT_EQ(std::memcmp(&plain, &recorded, sizeof plain), 0);
        EXPECT_GE(record.segments, 1);
        EXPECT_LE(static_cast<int>(record.vertices.size()), record.segments);
        with_vertices += record.vertices.empty() ? 0 : 1;
        for (const PathRecord::Vertex& v : record.vertices)
          EXPECT_GT(plan.pdf(v.point, v.normal, v.direction), 0.0f);
      }
  EXPECT_GT(with_vertices, 8 * 8 * 8 / 2);
}

// Image-wide second moment relative to the reference, one number per weight.
double image_moment(const WeightPredictor& p, std::size_t g, const std::vector<float>& mean) {
  double sum = 0.0;
  for (int cell = 0; cell < static_cast<int>(mean.size() / 3); ++cell)
    for (int c = 0; c < 3; ++c) {
      const double mu = mean[static_cast<std::size_t>(cell) * 3 + static_cast<std::size_t>(c)];
      sum += p.second_moment(cell, g, c) / (mu * mu + 0.01);
    }
  return sum / static_cast<double>(mean.size());
}

// Each pixel's mean from 1024 samples of the book mixture (the mean does not
// depend on the weight, nor on roulette).
std::vector<float> mean_image(const Scene& scene) {
  const int width = scene.camera.width, height = scene.camera.height;
  std::vector<float> mean(static_cast<std::size_t>(width * height * 3), 0.0f);
  const SamplingPlan plan = SamplingPlan::make(Strategy::parse("mix:cosine=0.5,light=0.5"), scene);
  DropCounts drops;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      Vec3 sum(0.0f);
      for (std::uint32_t i = 0; i < 1024; ++i) sum += render_pixel_sample(scene, plan, 99, x, y, i, drops);
      const std::size_t k = static_cast<std::size_t>(y * width + x) * 3;
      mean[k] = sum.x / 1024, mean[k + 1] = sum.y / 1024, mean[k + 2] = sum.z / 1024;
    }
  return mean;
}

// Paths drawn at cosine's share w of cosine and light, `suffix` after the
// mixture (e.g. "+rr:1").
WeightPredictor drawn_at(const Scene& scene, double w, const std::string& suffix, const std::vector<double>& grid,
                         const WeightPathOptions& o) {
  char text[64];
  std::snprintf(text, sizeof text, "mix:cosine=%g,light=%g", w, 1.0 - w);
  return record_weight_paths(scene, cosine_light(), Strategy::parse(text + suffix), w, grid, o);
}

TEST(WeightPaths, PredictedMomentMatchesTheMeasuredOne) {
  const Scene scene = small_box(12);
  WeightPathOptions o;
  o.samples = 512;
  o.threads = 2;
  // The mean per pixel: from many paths at 0.5 (it does not depend on the weight).
  const std::vector<double> grid = {0.25, 0.5, 0.8};
  o.seed = 11;
  const WeightPredictor drawn_half = drawn_at(scene, 0.5, "", grid, o);
  const std::vector<float> mean = mean_image(scene);
  for (double w : {0.25, 0.8}) {
    o.seed = 21;
    const WeightPredictor drawn_there = drawn_at(scene, w, "", grid, o);
    const std::size_t g = w < 0.5 ? 0 : 2;
    const double predicted = image_moment(drawn_half, g, mean);
    const double measured = image_moment(drawn_there, g, mean);
    EXPECT_NEAR(predicted, measured, 0.1 * measured) << "at " << w;
    // And the difference between weights is real, so the test can tell them apart.
    EXPECT_GT(std::fabs(image_moment(drawn_half, 1, mean) - measured), 0.1 * measured) << "at " << w;
  }
}

// A mixture of cosine and a trained `guided`: with the distribution frozen
// (WeightPathOptions::guiding, as a render's replay passes it), the moment
// predicted at w from paths drawn at 0.5 matches the one measured from paths
// drawn at w, without roulette and with the roulette by the learned light
// from the first vertex on (whose q, like the throughput rule's, scales with
// the throughput); the untrained sphere in its place predicts another.
TEST(WeightPaths, PredictionWithAFrozenGuideMatchesTheMeasuredOne) {
  const Scene scene = small_box(12);
  GuidingTrainer trainer(scene);
  const Vec3 lo = trainer.distribution()->lo(), hi = trainer.distribution()->hi();
  Rng rng(4, 4);
  for (int pass = 0; pass < 2; ++pass) {
    for (int i = 0; i < 200000; ++i) {
      const Vec3 p = lo + (hi - lo) * Vec3(rng.uniform(), rng.uniform(), rng.uniform());
      const Vec3 d = direction_from_square(rng.uniform(), rng.uniform());
      const double energy = d.y > 0.85f ? 50.0 : 1.0;  // light from above, as the book's lamp gives
      trainer.record(p, Vec3(0.0f, 1.0f, 0.0f), d, energy * 4.0 * 3.14159265358979);
    }
    trainer.finish_pass();
  }
  const std::shared_ptr<const GuidingDistribution> guide = trainer.distribution();
  ASSERT_GT(guide->leaves(), kGuidingNormalBins);
  MixtureFamily family;
  family.a = Strategy::parse("cosine");
  family.b = Strategy::parse("guided");
  for (const char* roulette : {"", "+rr:guided:1"}) {
    SCOPED_TRACE(roulette);
    const auto drawn = [&](double w, std::uint64_t seed, const GuidingDistribution* g) {
      char text[64];
      std::snprintf(text, sizeof text, "mix:cosine=%g,guided=%g%s", w, 1.0 - w, roulette);
      WeightPathOptions o;
      o.samples = 2048;
      o.threads = 2;
      o.seed = seed;
      o.guiding = g;
      return record_weight_paths(scene, family, Strategy::parse(text), w, {0.25, 0.5, 0.8}, o);
    };
    const std::vector<float> mean = mean_image(scene);
    const WeightPredictor drawn_half = drawn(0.5, 11, guide.get());
    const WeightPredictor untrained_half = drawn(0.5, 11, nullptr);
    for (double w : {0.25, 0.8}) {
      const std::size_t g = w < 0.5 ? 0 : 2;
      const double measured = image_moment(drawn(w, 21, guide.get()), g, mean);
      EXPECT_NEAR(image_moment(drawn_half, g, mean), measured, 0.1 * measured) << "at " << w;
      EXPECT_GT(std::fabs(image_moment(untrained_half, g, mean) - measured), 0.1 * measured) << "at " << w;
    }
  }
}

// A sweep's family keeps the roulette by the learned light in every member
// that has the guided technique, and knows its members by it.
TEST(WeightPaths, AFamilyKeepsTheRouletteByTheLearnedLight) {
  const TechniquePair pair = parse_technique_pair("cosine,guided", "mix:cosine=0.5,guided=0.5+rr:guided");
  EXPECT_TRUE(pair.guided_roulette);
  const Strategy member = pair.at(0.3);
  EXPECT_TRUE(member.guided_roulette);
  EXPECT_EQ(member.roulette_depth, kDefaultRouletteDepth);
  EXPECT_NEAR(pair.weight_of(member), 0.3, 1e-6);
  EXPECT_FALSE(pair.at(1.0).guided_roulette) << "no guided technique at w = 1";
  EXPECT_NEAR(pair.weight_of(pair.at(1.0)), 1.0, 1e-6);
  EXPECT_LT(pair.weight_of(Strategy::parse("mix:cosine=0.3,guided=0.7+rr")), 0.0)
      << "the throughput's roulette makes another family";
  EXPECT_FALSE(parse_technique_pair("cosine,guided", "mix:cosine=0.5,guided=0.5+rr").at(0.3).guided_roulette);
}

// With Russian roulette the survival probability depends on the weight the
// path was drawn at (through its throughput): the prediction reweighs each
// check, and its second moment and cost at another weight match those
// measured there, with roulette from the first vertex on.
TEST(WeightPaths, PredictionWithRussianRouletteMatchesTheMeasuredOne) {
  const Scene scene = small_box(12, 4);
  WeightPathOptions o;
  o.samples = 2048;  // the moments of 512 spread by 5-10 % from seed to seed
  o.threads = 2;
  const std::vector<double> grid = {0.25, 0.5, 0.8};
  o.seed = 11;
  const WeightPredictor drawn_half = drawn_at(scene, 0.5, "+rr:1", grid, o);
  const std::vector<float> mean = mean_image(scene);
  const WeightPrediction half = drawn_half.predict(mean, 0.0, 0.01);
  for (double w : {0.25, 0.8}) {
    o.seed = 21;
    const WeightPredictor drawn_there = drawn_at(scene, w, "+rr:1", grid, o);
    const std::size_t g = w < 0.5 ? 0 : 2;
    const double measured = image_moment(drawn_there, g, mean);
    EXPECT_NEAR(image_moment(drawn_half, g, mean), measured, 0.1 * measured) << "at " << w;
    EXPECT_GT(std::fabs(image_moment(drawn_half, 1, mean) - measured), 0.1 * measured) << "at " << w;
    // The cost is what ignoring the checks gets most wrong here: 4 % too dear
    // at 0.8 (the moments agree to 4 % either way, from seed to seed), where
    // its own error is 0.1-0.2 %.
    const double measured_cost = drawn_there.predict(mean, 0.0, 0.01).sampling_cost;
    EXPECT_NEAR(half.cost[g], measured_cost, 0.015 * measured_cost) << "at " << w;
  }
}

}  // namespace

namespace {

// Auto weight: passes whose weights come from earlier passes' predictions sum
// to the same image as a fixed weight (a chi-square over pixels and channels of
// the difference in units of its standard error), and the weight did move.
// As sweep --auto does: one seed, each pass continuing the sample indices; a
// pass renders its samples, then the prediction traces the next ones, which
// join the image, predicted against the mean of the samples before them.
TEST(WeightPaths, AutoWeightConvergesToTheFixedWeightsImage) {
  const Scene scene = small_box(8);
  const MixtureFamily family = cosine_light();
  const std::size_t pixels = 64;

  Film automatic(8, 8);
  // Start far from this box's best weight (about 0.5 at depth 4).
  AutoWeight chooser(0.15, 21);
  WeightPathOptions o;
  o.threads = 2;
  o.film = &automatic;
  o.seed = 100;
  std::uint32_t next = 0;
  for (int pass = 0; pass < 4; ++pass) {
    const double w = chooser.weight();
    char text[64];
    std::snprintf(text, sizeof text, "mix:cosine=%.9g,light=%.9g", w, 1.0 - w);
    // The pass itself: its prediction is not used.
    o.first_sample = next;
    o.samples = 256;
    o.relative_to = nullptr;
    (void)record_weight_paths(scene, family, Strategy::parse(text), w, {w}, o);
    next += o.samples;
    // The prediction: the next samples, against the mean before them (what a
    // render knows; no reference), one image-wide cell.
    std::vector<float> mean;
    automatic.mean_rgb(mean);
    o.first_sample = next;
    o.relative_to = &mean;
    o.relative_epsilon = 0.01;
    const WeightPredictor p = record_weight_paths(scene, family, Strategy::parse(text), w, chooser.grid(), o);
    next += o.samples;
    chooser.add_pass(predict_image_wide(p, mean, 1e-4, 0.01), 1e-4);
  }
  ASSERT_EQ(chooser.history().size(), 5u);
  EXPECT_GT(chooser.history()[1], 0.3) << "the prediction did not move the weight";
  EXPECT_GT(chooser.history()[4], 0.3);
  for (double w : chooser.history()) {
    EXPECT_GE(w, kDefensiveFloor);
    EXPECT_LE(w, 1.0 - kDefensiveFloor);
  }

  Film fixed(8, 8);
  o.film = &fixed;
  o.relative_to = nullptr;
  o.samples = 2048;
  o.first_sample = 0;
  o.seed = 7;
  (void)record_weight_paths(scene, family, Strategy::parse("mix:cosine=0.5,light=0.5"), 0.5, {0.5}, o);

  double chi2 = 0.0;
  int terms = 0;
  for (std::size_t i = 0; i < pixels; ++i) {
    double ma[3], mb[3], va[3], vb[3];
    automatic.mean(i, ma);
    fixed.mean(i, mb);
    automatic.variance_of_mean(i, va);
    fixed.variance_of_mean(i, vb);
    for (int c = 0; c < 3; ++c)
      if (va[c] + vb[c] > 0.0) {
        chi2 += (ma[c] - mb[c]) * (ma[c] - mb[c]) / (va[c] + vb[c]);
        ++terms;
      }
  }
  ASSERT_GT(terms, 150);
  // Mean of z^2 over ~190 terms: 1 +- 0.1 for equal expectations; heavy-tailed
  // pixels make it noisier, so allow [0.5, 1.6].
  EXPECT_GT(chi2 / terms, 0.5);
  EXPECT_LT(chi2 / terms, 1.6) << "the two images differ by more than their noise";
}

}  // namespace

namespace {

// One image-wide cell of paths divided by sqrt(mu^2 + eps) predicts the same
// relative variance and cost as one cell per pixel with the same means.
TEST(WeightPaths, ImageWideCellEqualsPerPixelCells) {
  const Scene scene = small_box(8);
  const MixtureFamily family = cosine_light();
  const Strategy mixture = Strategy::parse("mix:cosine=0.4,light=0.6");
  const std::vector<double> grid = weight_grid(11);
  WeightPathOptions o;
  o.threads = 2;
  o.seed = 9;
  o.samples = 64;
  Film film(8, 8);
  o.film = &film;
  (void)record_weight_paths(scene, family, mixture, 0.4, {0.4}, o);
  std::vector<float> mean;
  film.mean_rgb(mean);
  o.film = nullptr;
  o.seed = 10;  // paths independent of the mean
  const WeightPrediction per_pixel =
      record_weight_paths(scene, family, mixture, 0.4, grid, o).predict(mean, 1e-3, 0.01);
  o.relative_to = &mean;
  o.relative_epsilon = 0.01;
  const WeightPredictor wide = record_weight_paths(scene, family, mixture, 0.4, grid, o);
  EXPECT_EQ(wide.paths(), per_pixel.paths);
  const WeightPrediction image_wide = predict_image_wide(wide, mean, 1e-3, 0.01);
  ASSERT_EQ(image_wide.relative_variance.size(), grid.size());
  for (std::size_t g = 1; g < grid.size(); ++g) {
    EXPECT_NEAR(image_wide.relative_variance[g], per_pixel.relative_variance[g],
                1e-4 * per_pixel.relative_variance[g]) << grid[g];
    EXPECT_NEAR(image_wide.cost[g], per_pixel.cost[g], 1e-9 * per_pixel.cost[g]);
  }
  EXPECT_GT(per_pixel.relative_variance[5], 0.0);
  EXPECT_EQ(image_wide.best, per_pixel.best);
  std::vector<float> wrong(3, 0.5f);
  o.relative_to = &wrong;
  EXPECT_THROW((void)record_weight_paths(scene, family, mixture, 0.4, grid, o), InputError);
}

// "Which technique found the light": the shares of every path with light sum
// to the luminance it carried, and cosine's share of the light found through a
// diffuse vertex is larger at w = 0.95 than at w = 0.05.
TEST(WeightPaths, TechniqueSharesSplitWhatThePathsCarried) {
  const Scene scene = small_box(8);
  const MixtureFamily family = cosine_light();
  double share_of_cosine[2] = {0.0, 0.0};
  int k = 0;
  for (double w : {0.05, 0.95}) {
    Film film(8, 8);
    std::vector<double> share;
    WeightPathOptions o;
    o.threads = 2;
    o.samples = 64;
    o.film = &film;
    o.technique_share = &share;
    char text[64];
    std::snprintf(text, sizeof text, "mix:cosine=%.9g,light=%.9g", w, 1.0 - w);
    (void)record_weight_paths(scene, family, Strategy::parse(text), w, {w}, o);
    ASSERT_EQ(share.size(), 64u * kShareKinds);
    double carried = 0.0, shared = 0.0, by_cosine = 0.0, found = 0.0;
    for (std::size_t p = 0; p < 64; ++p) {
      double m[3];
      film.mean(p, m);
      carried += (0.2126 * m[0] + 0.7152 * m[1] + 0.0722 * m[2]) * 64.0;  // film means times the sample count
      for (int kind = 0; kind < kShareKinds; ++kind) shared += share[p * kShareKinds + static_cast<std::size_t>(kind)];
      by_cosine += share[p * kShareKinds + kShareA];
      found += share[p * kShareKinds + kShareA] + share[p * kShareKinds + kShareB];
      EXPECT_EQ(share[p * kShareKinds + kShareRest], 0.0) << "no third technique";
    }
    EXPECT_NEAR(shared, carried, 1e-3 * carried);
    ASSERT_GT(found, 0.0);
    share_of_cosine[k++] = by_cosine / found;
  }
  // In expectation cosine's share is the integral of f/p_w * w a/p_w' weight:
  // w a / (w a + (1 - w) b) grows with w at every direction, so its share does.
  EXPECT_LT(share_of_cosine[0], share_of_cosine[1]);
}

}  // namespace
