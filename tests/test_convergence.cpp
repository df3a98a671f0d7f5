// Every unbiased strategy converges to the same image. On the book's scene at
// 48x48, the 8x8-pixel block means of each strategy are compared with a
// longer render of the book's mixture; a difference beyond what the standard
// errors allow means one of them estimates something else. Pure `light`,
// which cannot reach indirect light, must fail the same comparison.
#include "renderer/film/film.h"
#include "renderer/sampling/strategy.h"
#include "renderer/scene/scene.h"
#include "renderer/scene/scene_loader.h"
#include "renderer/session/session.h"
#include "renderer/metrics/statistics.h"

#include "tests/render_support.h"
#include "tests/table_strategies.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

namespace pdflab {
namespace {

constexpr int kSide = 48;
constexpr int kBlock = 8;
constexpr int kBlocksPerSide = kSide / kBlock;
constexpr int kBlockCount = kBlocksPerSide * kBlocksPerSide;
constexpr double kFamilyAlpha = 0.01;

// Why blocks, and why these sample counts. Through the glass sphere, diffuse
// points see the light as a caustic that only a small fraction of paths finds,
// and the uniform techniques multiply a path's throughput by up to 2 a cos
// (hemisphere) or 4 a cos (sphere) per bounce, so a few long paths carry large
// values: the estimates are skewed and heavy-tailed. A sample variance then
// usually underestimates the true one (the rare bright paths are what it
// misses), and z-scores get a heavier negative tail than a normal. Averaging
// 8 x 8 pixels pools 64 x spp paths per block (32768 at least) so that the
// caustic reaches every block many times and block means are close to
// normal; the uniform techniques, the heaviest-tailed and also the cheapest
// (their paths die young), get 2x and 4x the samples. Measured over 3-4 seeds
// per strategy (324-432 block-channels each), the unscaled block z-scores have
// a variance of 0.96 to 1.17 (not 1) and reach -3.4 at worst (uniform-sphere
// at 512 spp reached -3.6, hence its extra samples). Standard errors are scaled by
// kHeavyTail = sqrt(1.2) to absorb that excess, and the Sidak-corrected
// threshold (about 4.3 for 648 tests) keeps the family's false-alarm rate
// near 1%.
struct StrategyRun {
  std::string strategy;
  std::uint32_t spp;
};
const std::vector<StrategyRun>& unbiased_strategies() {
  static const std::vector<StrategyRun> s = {
      {"cosine", 512},
      {"uniform-hemisphere", 1024},
      {"uniform-sphere", 2048},
      {"mix:cosine=0.5,light=0.5", 512},
      {"mix:cosine=0.75,light=0.25", 512},
      {"mix:cosine=0.4,uniform-hemisphere=0.2,light=0.4", 512},
      {"mix:cosine=0.5,light-sa=0.5", 512},
      {"nee-mis", 256},
      {"nee-mis:balance", 256},
      // Russian roulette, and nee-mis continued by a mixture that keeps aiming at the glass sphere.
      {"mix:cosine=0.5,light=0.5+rr", 512},
      {"cosine+rr:1", 1024},
      {"nee-mis+rr", 256},
      {"nee-mis+mix:cosine=0.5,light=0.5", 256},
      {"nee-mis:balance+mix:cosine=0.5,light-sa=0.5+rr", 256},
      {"fastest", 256},
      // Continuations aimed at the glass sphere as a glass object (specular-objects).
      {"mix:cosine=0.75,specular-objects=0.25", 512},
      {"nee-mis+mix:cosine=0.8,specular-objects=0.2+rr", 256},
      // The +sobol sampler's stratified draws.
      {"mix:cosine=0.5,light=0.5+sobol", 512},
      {"nee-mis+mix:cosine=0.5,light=0.5+sobol", 256},
      {"mix:cosine=0.5,light-sa=0.5+sobol+rr", 512},
      // nee-mis continued by path guiding, trained in four passes before the render.
      {"nee-mis+mix:cosine=0.5,guided:4=0.5", 256},
      {"nee-mis+mix:cosine=0.5,guided:4=0.5+rr:guided:2", 256},
  };
  // And every technique of the table alone (where unbiased) and mixed with
  // cosine (tests/table_strategies.h); alone, a technique gets the uniform
  // techniques' extra samples.
  static const std::vector<StrategyRun> with_table = [] {
    std::vector<StrategyRun> runs = s;
    for (const testing::TableStrategy& t : testing::table_strategies()) {
      if (!t.unbiased || t.needs_environment) continue;
      if (std::any_of(runs.begin(), runs.end(), [&](const StrategyRun& r) { return t.text == r.strategy; })) continue;
      const bool alone = t.text.rfind("mix:", 0) != 0;
      runs.push_back({t.text, alone ? 2048u : 512u});
    }
    return runs;
  }();
  return with_table;
}
// The reference has 8x the samples of most runs, so its own noise is a small
// part of each comparison's variance (and correlates the comparisons weakly).
constexpr std::uint32_t kReferenceSpp = 4096;
constexpr const char* kReferenceStrategy = "mix:cosine=0.5,light=0.5";
const double kHeavyTail = std::sqrt(1.2);

std::shared_ptr<const Scene> book_scene() {
  static const std::shared_ptr<const Scene> scene = [] {
    auto s = std::make_shared<Scene>(load_scene_file(PDFLAB_SOURCE_DIR "/assets/scenes/cornell_book.json"));
    s->camera.width = kSide;
    s->camera.height = kSide;
    s->camera.prepare();
    return std::shared_ptr<const Scene>(std::move(s));
  }();
  return scene;
}

// Mean and variance of the mean of every block and channel.
struct BlockImage {
  std::vector<double> mean, variance;  // [block * 3 + channel]
};

BlockImage render_blocks(const std::string& strategy, std::uint64_t seed, std::uint32_t spp,
                         std::shared_ptr<const Scene> scene = book_scene()) {
  const Film film = testing::render_to_completion(scene, strategy, spp, seed, 2, std::chrono::seconds(300)).film;

  BlockImage b;
  constexpr double kPixels = kBlock * kBlock;
  const int side = scene->camera.width;
  b.mean.assign(3 * static_cast<std::size_t>((side / kBlock) * (side / kBlock)), 0.0);
  b.variance.assign(b.mean.size(), 0.0);
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x) {
      const std::size_t p = static_cast<std::size_t>(y) * side + static_cast<std::size_t>(x);
      EXPECT_EQ(film.count(p), spp);
      double m[3], v[3];
      film.mean(p, m);
      film.variance_of_mean(p, v);
      const int block = (y / kBlock) * (side / kBlock) + x / kBlock;
      // Pixels have independent streams: the block mean's variance is the
      // sum of the pixel means' variances over the pixel count squared.
      for (int c = 0; c < 3; ++c) {
        b.mean[3 * block + c] += m[c] / kPixels;
        b.variance[3 * block + c] += v[c] / (kPixels * kPixels);
      }
    }
  return b;
}

struct Comparison {
  std::vector<double> z;  // per block and channel; NaN where both are exact (zero variance)
  double most_negative = 0.0, most_positive = 0.0;
};

Comparison compare(const BlockImage& a, const BlockImage& ref) {
  Comparison cmp;
  for (std::size_t i = 0; i < a.mean.size(); ++i) {
    const double se = kHeavyTail * std::sqrt(a.variance[i] + ref.variance[i]);
    const double diff = a.mean[i] - ref.mean[i];
    // Zero variance on both sides: only blocks that see nothing but the
    // background (black here) or the light's face; they must agree exactly.
    const double z = se > 0.0 ? diff / se : (diff == 0.0 ? 0.0 : std::copysign(INFINITY, diff));
    cmp.z.push_back(z);
    cmp.most_negative = std::min(cmp.most_negative, z);
    cmp.most_positive = std::max(cmp.most_positive, z);
  }
  return cmp;
}

double threshold() {
  const int tests = static_cast<int>(unbiased_strategies().size()) * kBlockCount * 3;
  return stats::normal_two_sided_quantile(stats::sidak_alpha(kFamilyAlpha, tests));
}

// One test for all strategies: they share the expensive reference render,
// and ctest runs every test in its own process.
TEST(Convergence, UnbiasedStrategiesAgreeOnBookScene) {
  const BlockImage reference = render_blocks(kReferenceStrategy, 1, kReferenceSpp);
  const double limit = threshold();
  for (std::size_t s = 0; s < unbiased_strategies().size(); ++s) {
    const StrategyRun& run = unbiased_strategies()[s];
    SCOPED_TRACE(run.strategy);
    ASSERT_TRUE(Strategy::parse(run.strategy).is_unbiased());
    const Comparison cmp = compare(render_blocks(run.strategy, 100 + s, run.spp), reference);
    std::printf("[convergence] %-48s block z in [%+.2f, %+.2f] (limit %.2f)\n", run.strategy.c_str(), cmp.most_negative,
                cmp.most_positive, limit);
    for (std::size_t i = 0; i < cmp.z.size(); ++i)
      EXPECT_LT(std::fabs(cmp.z[i]), limit) << "block " << i / 3 << " channel " << i % 3;
  }
}

// The comparison can fail: pure `light` samples only the light and the glass
// sphere, so it misses every path that bounces off a wall towards another
// wall (the ceiling, lit only indirectly, goes black). Its blocks must come
// out significantly darker than an unbiased render, and never brighter.
TEST(Convergence, PureLightIsBiasedDark) {
  ASSERT_FALSE(Strategy::parse("light").is_unbiased());
  const BlockImage reference = render_blocks("cosine", 2, 256);
  const Comparison cmp = compare(render_blocks("light", 3, 256), reference);
  const double limit = threshold();
  int darker = 0, brighter = 0;
  for (double z : cmp.z) {
    if (z < -limit) ++darker;
    if (z > limit) ++brighter;
  }
  std::printf("[convergence] light: %d of %zu block-channels darker beyond %.2f, most negative z %.1f\n", darker,
              cmp.z.size(), limit, cmp.most_negative);
  EXPECT_GE(darker, 20);
  EXPECT_EQ(brighter, 0);
}

// Every other shipped scene, at 24x24 (nine 8x8 blocks): each unbiased
// strategy against a long render of the light-sa mixture. These scenes have no
// glass, so the tails are lighter than the book's, except for the far light's
// small sun, which cosine and uniform sampling find rarely: they get more
// samples there (scene-specific multiplier below). The Sidak threshold covers
// every comparison of this test.
struct SceneCase {
  const char* file;
  std::uint32_t rare_light_factor;  // extra samples for the techniques that ignore the lights
};

TEST(Convergence, UnbiasedStrategiesAgreeOnEveryShippedScene) {
  const SceneCase scenes[] = {{"cornell_aluminium.json", 1}, {"glossy_metal.json", 1}, {"large_light.json", 1},
                              {"two_lights.json", 8},        {"small_light.json", 8},  {"far_light.json", 8}};
  struct Run {
    const char* strategy;
    std::uint32_t spp;
    bool ignores_lights;
  };
  const Run runs[] = {{"cosine", 256, true},
                      {"uniform-hemisphere", 512, true},
                      {"uniform-sphere", 1024, true},
                      {"mix:cosine=0.5,light=0.5", 256, false},
                      {"mix:cosine=0.5,light-sa=0.5", 256, false},
                      {"nee-mis", 128, false},
                      {"nee-mis:balance", 128, false},
                      {"mix:cosine=0.5,light-sa=0.5+rr", 256, false},
                      {"nee-mis+mix:cosine=0.5,light=0.5", 128, false},
                      {"fastest", 128, false},  // nee-mis continued by cosine and specular-objects: nee-mis's spp
                      {"mix:cosine=0.75,specular-objects=0.25", 256, true},  // cosine where there is no metal
                      {"nee-mis+mix:cosine=0.7,specular-objects=0.3+rr", 128, false},
                      {"mix:cosine=0.5,light=0.5+sobol", 256, false},
                      {"nee-mis+mix:cosine=0.5,light=0.5+sobol", 256, false}};  // today the book mixture: its spp
  constexpr int kSmall = 24;
  const int tests = static_cast<int>(std::size(scenes) * std::size(runs)) * (kSmall / kBlock) * (kSmall / kBlock) * 3;
  const double limit = stats::normal_two_sided_quantile(stats::sidak_alpha(kFamilyAlpha, tests));
  std::uint64_t seed = 500;
  for (const SceneCase& sc : scenes) {
    const std::string path = std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes/" + sc.file;
    if (!std::ifstream(path)) {
      ADD_FAILURE() << "missing shipped scene " << sc.file;
      continue;
    }
    auto scene = std::make_shared<Scene>(load_scene_file(path));
    scene->camera.width = kSmall;
    scene->camera.height = kSmall;
    scene->prepare();
    const BlockImage reference = render_blocks("mix:cosine=0.5,light-sa=0.5", seed++, 4096, scene);
    for (const Run& run : runs) {
      SCOPED_TRACE(std::string(sc.file) + " " + run.strategy);
      const std::uint32_t spp = run.spp * (run.ignores_lights ? sc.rare_light_factor : 1);
      const Comparison cmp = compare(render_blocks(run.strategy, seed++, spp, scene), reference);
      std::printf("[convergence] %-24s %-30s block z in [%+.2f, %+.2f] (limit %.2f)\n", sc.file, run.strategy,
                  cmp.most_negative, cmp.most_positive, limit);
      for (std::size_t i = 0; i < cmp.z.size(); ++i)
        EXPECT_LT(std::fabs(cmp.z[i]), limit) << "block " << i / 3 << " channel " << i % 3;
    }
  }
}

}  // namespace
}  // namespace pdflab

namespace pdflab {
namespace {

// nee-mis with the light tree converges to the image nee-mis gives with the
// choice by power: on the many-lights room (16x16, two 8x8 blocks of
// four, paths of at most three segments: direct light and one bounce, so
// that both the light sample and the continuation's MIS weight, found from
// the emitter it reaches, are tested), with an environment light on the
// sun-and-sky scene with three lamps added (the tree's light density shared
// with the map's), and on the frosted-glass box with a second lamp. At these
// sample counts a continuation's light density off by a factor 4 (its MIS
// weights wrong, the image biased by a few percent) fails the room and the sky.
TEST(Convergence, LightTreeAgreesWithPowerChoice) {
  constexpr int kSide16 = 16;
  const auto room = [] {
    auto scene = std::make_shared<Scene>(load_scene_file(PDFLAB_SOURCE_DIR "/assets/scenes/many_lights.json"));
    scene->camera.width = scene->camera.height = kSide16;
    scene->max_depth = 3;
    scene->prepare();
    return scene;
  }();
  // A shipped scene with lamps added (materials and objects put first in their lists).
  const auto with_lamps = [](const char* file, const std::string& materials, const std::string& objects, int depth) {
    const std::string dir = PDFLAB_SOURCE_DIR "/assets/scenes/";
    std::ifstream in(dir + file);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const auto insert_after = [&](const std::string& key, const std::string& what) {
      const std::size_t at = text.find(key);
      EXPECT_NE(at, std::string::npos) << key;
      if (at != std::string::npos) text.insert(at + key.size(), what);
    };
    insert_after("\"materials\": {", materials);
    insert_after("\"objects\": [", objects);
    auto scene = std::make_shared<Scene>(load_scene_text(text, std::string(file) + " with lamps", dir));
    scene->camera.width = scene->camera.height = kSide16;
    scene->max_depth = depth;
    scene->prepare();
    return scene;
  };
  const auto sky = with_lamps(
      "sun_sky.json",
      R"("lamp": {"type": "diffuse_light", "emit": [30, 24, 18]},)"
      R"("panel": {"type": "diffuse_light", "emit": [3, 3, 4], "two_sided": true},)",
      R"({"type": "sphere", "center": [-2.8, 1.2, -1.0], "radius": 0.1, "material": "lamp"},)"
      R"({"type": "sphere", "center": [-0.2, 0.4, -1.6], "radius": 0.15, "material": "lamp"},)"
      R"({"type": "quad", "q": [-0.5, 2.0, -0.5], "u": [1, 0, 0], "v": [0, 0, 1], "material": "panel"},)",
      3);
  // A rough dielectric, where the tree chooses without the normal (light
  // arrives from both sides) and a continuation's density is found from the
  // vertex it left, not the far side it starts from.
  const auto frosted = with_lamps("frosted_glass.json", R"("lamp": {"type": "diffuse_light", "emit": [15, 15, 15]},)",
                                  R"({"type": "sphere", "center": [400, 60, 120], "radius": 20, "material": "lamp"},)", 4);
  const int tests = 3 * (kSide16 / kBlock) * (kSide16 / kBlock) * 3;
  const double limit = stats::normal_two_sided_quantile(stats::sidak_alpha(kFamilyAlpha, tests));
  std::uint64_t seed = 950;
  for (const auto& scene : {room, sky, frosted}) {
    SCOPED_TRACE(scene->name);
    ASSERT_NE(SamplingPlan::make(Strategy::parse("nee-mis+lights:tree"), *scene).emitters.tree, nullptr);
    const BlockImage reference = render_blocks("nee-mis+lights:power", seed++, 512, scene);
    const Comparison cmp = compare(render_blocks("nee-mis+lights:tree", seed++, 256, scene), reference);
    std::printf("[convergence] %-28s nee-mis+lights:tree block z in [%+.2f, %+.2f] (limit %.2f)\n", scene->name.c_str(),
                cmp.most_negative, cmp.most_positive, limit);
    for (std::size_t i = 0; i < cmp.z.size(); ++i)
      EXPECT_LT(std::fabs(cmp.z[i]), limit) << "block " << i / 3 << " channel " << i % 3;
  }
}

// A shipped scene at 24x24 (the convergence tests' size) with at most `depth` segments a path.
std::shared_ptr<Scene> small_shipped_scene(const char* file, int depth) {
  auto scene = std::make_shared<Scene>(load_scene_file(std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes/" + file));
  scene->camera.width = 24;
  scene->camera.height = 24;
  scene->max_depth = depth;
  scene->prepare();
  return scene;
}

// max_depth means the same for every strategy: a path has at most max_depth
// segments, the camera ray included (max_depth 1: the lights seen directly;
// 2: direct light; 3: one indirect bounce). Next-event estimation's shadow ray
// is a segment too, so nee-mis must agree with the mixtures at every depth.
TEST(Convergence, MaxDepthMeansTheSameForEveryStrategy) {
  constexpr int kSmall = 24;
  const char* strategies[] = {"cosine", "mix:cosine=0.5,light-sa=0.5", "nee-mis", "nee-mis:balance"};
  const int tests = 3 * static_cast<int>(std::size(strategies)) * (kSmall / kBlock) * (kSmall / kBlock) * 3;
  const double limit = stats::normal_two_sided_quantile(stats::sidak_alpha(kFamilyAlpha, tests));
  std::uint64_t seed = 900;
  for (const int depth : {1, 2, 3}) {
    const auto scene = small_shipped_scene("small_light.json", depth);
    const BlockImage reference = render_blocks("mix:cosine=0.5,light=0.5", seed++, 2048, scene);
    for (const char* strategy : strategies) {
      SCOPED_TRACE(std::string(strategy) + " at max_depth " + std::to_string(depth));
      const std::uint32_t spp = std::string(strategy) == "cosine" ? 4096 : 512;
      const Comparison cmp = compare(render_blocks(strategy, seed++, spp, scene), reference);
      std::printf("[convergence] max_depth %d %-30s block z in [%+.2f, %+.2f] (limit %.2f)\n", depth, strategy,
                  cmp.most_negative, cmp.most_positive, limit);
      for (std::size_t i = 0; i < cmp.z.size(); ++i)
        EXPECT_LT(std::fabs(cmp.z[i]), limit) << "block " << i / 3 << " channel " << i % 3;
    }
  }
}

// Path guiding on the scene made for it (door_ajar.json, 24x24, paths of at
// most 12 segments): the guided mixtures, trained as the session trains them
// (four passes), with the throughput's roulette or the learned light's
// (+rr:guided), converge to the image `fastest` gives. The light reaches the
// near room only through the gap, so these are the paths the guided half aims at.
TEST(Convergence, GuidedMixturesAgreeOnTheDoorScene) {
  const char* strategies[] = {"mix:cosine=0.5,guided:4=0.5+rr:6", "nee-mis+mix:cosine=0.5,guided:4=0.5+rr:6",
                              "nee-mis+mix:cosine=0.7,guided:6=0.3", "nee-mis+mix:cosine=0.5,guided:4=0.5+rr:guided",
                              "mix:cosine=0.5,guided:4=0.5+rr:guided:3"};
  constexpr int kSmall = 24;
  const int tests = static_cast<int>(std::size(strategies)) * (kSmall / kBlock) * (kSmall / kBlock) * 3;
  const double limit = stats::normal_two_sided_quantile(stats::sidak_alpha(kFamilyAlpha, tests));
  const auto scene = small_shipped_scene("door_ajar.json", 12);
  const BlockImage reference = render_blocks("fastest", 1500, 8192, scene);
  std::uint64_t seed = 1501;
  for (const char* strategy : strategies) {
    SCOPED_TRACE(strategy);
    const Comparison cmp = compare(render_blocks(strategy, seed++, 2048, scene), reference);
    std::printf("[convergence] door_ajar %-44s block z in [%+.2f, %+.2f] (limit %.2f)\n", strategy, cmp.most_negative,
                cmp.most_positive, limit);
    for (std::size_t i = 0; i < cmp.z.size(); ++i)
      EXPECT_LT(std::fabs(cmp.z[i]), limit) << "block " << i / 3 << " channel " << i % 3;
  }
}

// The book's box as it ships, scaled by 1e-3 and 1e4 and translated by 1e6:
// radiance does not depend on the unit of length, so every strategy renders
// the same image (within the block standard errors) at every scale.
std::shared_ptr<Scene> transformed_book(float scale, float shift, int side) {
  auto scene = std::make_shared<Scene>(load_scene_file(PDFLAB_SOURCE_DIR "/assets/scenes/cornell_book.json"));
  const Vec3 t(shift, shift, shift);
  for (Quad& q : scene->quads) q = make_quad(q.q * scale + t, q.u * scale, q.v * scale, q.material);
  for (Sphere& s : scene->spheres) s = Sphere{s.center * scale + t, s.radius * scale, s.material};
  scene->camera.lookfrom = scene->camera.lookfrom * scale + t;
  scene->camera.lookat = scene->camera.lookat * scale + t;
  scene->camera.width = side;
  scene->camera.height = side;
  scene->prepare();
  return scene;
}

TEST(Convergence, BookBoxGivesTheSameImageAtEveryScaleAndPosition) {
  constexpr int kSmall = 24;
  struct Placement {
    float scale, shift;
  };
  const Placement placements[] = {{1e-3f, 0.0f}, {1e4f, 0.0f}, {1.0f, 1e6f}};
  const char* strategies[] = {"cosine", "mix:cosine=0.5,light=0.5", "mix:cosine=0.5,light-sa=0.5", "nee-mis"};
  const int tests = static_cast<int>(std::size(placements) * std::size(strategies)) * (kSmall / kBlock) *
                    (kSmall / kBlock) * 3;
  const double limit = stats::normal_two_sided_quantile(stats::sidak_alpha(kFamilyAlpha, tests));
  std::uint64_t seed = 1300;
  const auto unit_scene = transformed_book(1.0f, 0.0f, kSmall);
  for (const char* strategy : strategies) {
    const std::uint32_t spp = std::string(strategy) == "cosine" ? 2048 : 1024;
    const BlockImage reference = render_blocks(strategy, seed++, spp, unit_scene);
    for (const Placement& p : placements) {
      SCOPED_TRACE(std::string(strategy) + " scale " + std::to_string(p.scale) + " shift " + std::to_string(p.shift));
      const Comparison cmp = compare(render_blocks(strategy, seed++, spp, transformed_book(p.scale, p.shift, kSmall)),
                                     reference);
      std::printf("[convergence] scale %-6g shift %-6g %-30s block z in [%+.2f, %+.2f] (limit %.2f)\n", p.scale,
                  p.shift, strategy, cmp.most_negative, cmp.most_positive, limit);
      for (std::size_t i = 0; i < cmp.z.size(); ++i)
        EXPECT_LT(std::fabs(cmp.z[i]), limit) << "block " << i / 3 << " channel " << i % 3;
    }
  }
}

// Veach's scene (assets/scenes/veach_mis.json: microfacet plates from alpha
// 0.01 to 0.35, sphere lights from radius 0.03 to 0.9): every unbiased
// strategy, the bsdf technique alone and in mixtures and as nee-mis's
// continuation, converges to one image.
TEST(Convergence, VeachSceneEveryUnbiasedStrategyAgrees) {
  constexpr int kSmall = 24;
  struct Run {
    const char* strategy;
    std::uint32_t spp;
  };
  const Run runs[] = {{"bsdf", 2048},
                      {"mix:cosine=0.5,bsdf=0.5", 2048},
                      {"mix:bsdf=0.5,light-sa=0.5", 2048},
                      {"mix:bsdf=0.5,light=0.5+rr:3", 512},
                      {"nee-mis", 2048},  // cosine continues: heavy-tailed on the sharp plates
                      {"nee-mis+bsdf", 256},
                      {"nee-mis:balance+bsdf", 256},
                      {"nee-mis+mix:bsdf=0.5,light-sa=0.5+sobol", 256}};
  const int tests = 2 * static_cast<int>(std::size(runs)) * (kSmall / kBlock) * (kSmall / kBlock) * 3;
  const double limit = stats::normal_two_sided_quantile(stats::sidak_alpha(kFamilyAlpha, tests));
  std::uint64_t seed = 3900;
  // The scene's depth (2: direct light, Veach's figure), and 5: light between
  // the plates and the backdrop, microfacet vertices past the first, roulette.
  for (const int depth : {2, 5}) {
    const auto scene = small_shipped_scene("veach_mis.json", depth);
    const BlockImage reference = render_blocks("nee-mis+mix:bsdf=0.5,light-sa=0.5", seed++, 8192, scene);
    for (const Run& run : runs) {
      SCOPED_TRACE(std::string(run.strategy) + " at max_depth " + std::to_string(depth));
      const Comparison cmp = compare(render_blocks(run.strategy, seed++, run.spp, scene), reference);
      std::printf("[convergence] veach_mis.json depth %d %-40s block z in [%+.2f, %+.2f] (limit %.2f)\n", depth,
                  run.strategy, cmp.most_negative, cmp.most_positive, limit);
      for (std::size_t i = 0; i < cmp.z.size(); ++i)
        EXPECT_LT(std::fabs(cmp.z[i]), limit) << "block " << i / 3 << " channel " << i % 3;
    }
  }
}

// The sun-and-sky scene (assets/scenes/sun_sky.json: an environment map with
// a sun of 6e-4 sr and no area light), and the same with a small lamp beside
// the sphere, where nee-mis's light sample chooses between the map and the
// lamp (environment_light_share): the environment technique alone (the map has
// light everywhere) and in mixtures, nee-mis with the map as its light, and
// cosine, which finds the sun only by chance, converge to one image.
std::shared_ptr<Scene> sun_sky(bool lamp) {
  const std::string dir = std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes";
  std::ifstream in(dir + "/sun_sky.json");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (lamp) {
    const auto put = [&](const std::string& after, const std::string& what) {
      const std::size_t at = text.find(after);
      EXPECT_NE(at, std::string::npos) << after;
      if (at != std::string::npos) text.insert(at + after.size(), what);
    };
    put("\"materials\": {", R"( "lamp": { "type": "diffuse_light", "emit": [40, 30, 20] },)");
    put("\"objects\": [", R"( { "type": "quad", "q": [-2.5, 2.6, -1.2], "u": [0.6, 0, 0], "v": [0, 0, 0.6], "material": "lamp" },)");
  }
  auto scene = std::make_shared<Scene>(load_scene_text(text, "sun_sky.json", dir));
  scene->camera.width = 24;
  scene->camera.height = 24;
  scene->max_depth = 5;
  scene->prepare();
  return scene;
}

TEST(Convergence, SunAndSkyEveryUnbiasedStrategyAgrees) {
  struct Run {
    const char* strategy;
    std::uint32_t spp;
  };
  const Run runs[] = {{"cosine", 8192},
                      {"environment", 256},
                      {"mix:cosine=0.5,environment=0.5", 256},
                      {"mix:cosine=0.5,light-sa=0.5", 8192},  // light-sa aims at the lamp alone: cosine's share finds the sun
                      {"nee-mis", 128},
                      {"nee-mis:balance", 128},
                      {"nee-mis+mix:cosine=0.5,environment=0.5+sobol", 128}};
  const int tests = 2 * static_cast<int>(std::size(runs)) * (24 / kBlock) * (24 / kBlock) * 3;
  const double limit = stats::normal_two_sided_quantile(stats::sidak_alpha(kFamilyAlpha, tests));
  std::uint64_t seed = 7100;
  for (const bool lamp : {false, true}) {
    const auto scene = sun_sky(lamp);
    const SamplingPlan plan = SamplingPlan::make(Strategy::parse("nee-mis"), *scene);
    EXPECT_EQ(plan.environment_share, lamp ? 1.0f - kEnvironmentShareFloor : 1.0f);
    const BlockImage reference = render_blocks("nee-mis+mix:cosine=0.5,environment=0.5", seed++, 2048, scene);
    for (const Run& run : runs) {
      if (!lamp && std::string(run.strategy).find("light-sa") != std::string::npos) continue;
      SCOPED_TRACE(std::string(run.strategy) + (lamp ? " with the lamp" : ""));
      const Comparison cmp = compare(render_blocks(run.strategy, seed++, run.spp, scene), reference);
      std::printf("[convergence] sun_sky.json%s %-44s block z in [%+.2f, %+.2f] (limit %.2f)\n", lamp ? "+lamp" : "",
                  run.strategy, cmp.most_negative, cmp.most_positive, limit);
      for (std::size_t i = 0; i < cmp.z.size(); ++i)
        EXPECT_LT(std::fabs(cmp.z[i]), limit) << "block " << i / 3 << " channel " << i % 3;
    }
  }
}

// The book's box with its glass sphere frosted (assets/scenes/frosted_glass.json:
// a rough dielectric, GGX alpha 0.2, ior 1.5): every unbiased strategy
// converges to one image, those with bsdf drawing the sphere's reflection and
// refraction in their mixture, those without drawing there with its own lobe,
// nee-mis weighing the light sample (also through the sphere) against the
// continuation. Depth 4: light refracted into the sphere and out again.
TEST(Convergence, FrostedGlassEveryUnbiasedStrategyAgrees) {
  constexpr int kSmall = 24;
  struct Run {
    const char* strategy;
    std::uint32_t spp;
  };
  const Run runs[] = {{"bsdf", 1024},
                      {"cosine", 1024},
                      {"mix:cosine=0.5,light=0.5", 512},
                      {"mix:bsdf=0.5,light-sa=0.5+rr:2", 512},
                      {"nee-mis", 256},
                      {"nee-mis:balance+bsdf", 256},
                      {"nee-mis+mix:bsdf=0.5,light-sa=0.5+sobol", 256}};
  const int tests = static_cast<int>(std::size(runs)) * (kSmall / kBlock) * (kSmall / kBlock) * 3;
  const double limit = stats::normal_two_sided_quantile(stats::sidak_alpha(kFamilyAlpha, tests));
  std::uint64_t seed = 4300;
  const auto scene = small_shipped_scene("frosted_glass.json", 4);
  const BlockImage reference = render_blocks("nee-mis+bsdf", seed++, 4096, scene);
  for (const Run& run : runs) {
    SCOPED_TRACE(run.strategy);
    const Comparison cmp = compare(render_blocks(run.strategy, seed++, run.spp, scene), reference);
    std::printf("[convergence] frosted_glass.json depth 4 %-40s block z in [%+.2f, %+.2f] (limit %.2f)\n",
                run.strategy, cmp.most_negative, cmp.most_positive, limit);
    for (std::size_t i = 0; i < cmp.z.size(); ++i)
      EXPECT_LT(std::fabs(cmp.z[i]), limit) << "block " << i / 3 << " channel " << i % 3;
  }
}

// The book's box with its glass sphere on the exact Fresnel term
// ("fresnel": "exact"): every unbiased strategy, the ones aimed at the glass
// sphere among them, converges to one image. (At this size the Schlick image
// is within the blocks' noise of it; test_fresnel's glass pane shows that the
// tracers use the term the material names.)
TEST(Convergence, ExactFresnelGlassEveryUnbiasedStrategyAgrees) {
  constexpr int kSmall = 24;
  const auto glass_scene = [] {
    auto scene = std::make_shared<Scene>(load_scene_file(PDFLAB_SOURCE_DIR "/assets/scenes/cornell_book.json"));
    scene->camera.width = kSmall;
    scene->camera.height = kSmall;
    for (Material& m : scene->materials)
      if (m.type == MaterialType::Dielectric) m.exact_fresnel = true;
    scene->prepare();
    return std::shared_ptr<const Scene>(std::move(scene));
  };
  const auto exact = glass_scene();
  struct Run {
    const char* strategy;
    std::uint32_t spp;
  };
  const Run runs[] = {{"cosine", 1024},
                      {"uniform-hemisphere", 2048},
                      {"mix:cosine=0.5,light=0.5", 1024},
                      {"mix:cosine=0.5,light-sa=0.5+rr", 1024},
                      {"nee-mis", 512},
                      {"nee-mis:balance+bsdf", 512},
                      {"nee-mis+mix:cosine=0.8,specular-objects=0.2+rr", 512},
                      {"mix:cosine=0.5,light=0.5+sobol", 1024},
                      {"fastest", 512}};
  const int tests = static_cast<int>(std::size(runs)) * (kSmall / kBlock) * (kSmall / kBlock) * 3;
  const double limit = stats::normal_two_sided_quantile(stats::sidak_alpha(kFamilyAlpha, tests));
  std::uint64_t seed = 4100;
  const BlockImage reference = render_blocks("mix:cosine=0.5,light=0.5", seed++, 8192, exact);
  for (const Run& run : runs) {
    SCOPED_TRACE(run.strategy);
    const Comparison cmp = compare(render_blocks(run.strategy, seed++, run.spp, exact), reference);
    std::printf("[convergence] exact Fresnel %-48s block z in [%+.2f, %+.2f] (limit %.2f)\n", run.strategy,
                cmp.most_negative, cmp.most_positive, limit);
    for (std::size_t i = 0; i < cmp.z.size(); ++i)
      EXPECT_LT(std::fabs(cmp.z[i]), limit) << "block " << i / 3 << " channel " << i % 3;
  }
}

}  // namespace
}  // namespace pdflab
