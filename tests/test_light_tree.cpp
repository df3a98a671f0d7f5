// The light tree (renderer/sampling/light_tree.h): its choice is exactly its
// probabilities (every 24-bit number counted), the probabilities sum to 1 and
// keep the floor, they follow distance and orientation, and the strategy term
// and scene key that select it.
#include "renderer/error.h"
#include "renderer/metrics/probe.h"
#include "renderer/sampling/light_tree.h"
#include "renderer/sampling/strategy.h"
#include "renderer/sampling/target_set.h"
#include "renderer/scene/scene_loader.h"

#include <gtest/gtest.h>
#include <pcg_random.hpp>

#include <cmath>
#include <random>
#include <string>
#include <vector>

namespace pdflab {
namespace {

// n emitters scattered over a 10 x 4 x 10 room: flat quads facing down, up or
// sideways (some two-sided) and spheres, of powers over a factor 100.
std::vector<LightTree::Emitter> scattered(int n, std::uint64_t seed) {
  pcg32 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const Vec3 normals[] = {Vec3(0, -1, 0), Vec3(0, 1, 0), Vec3(1, 0, 0), Vec3(0, 0, -1)};
  std::vector<LightTree::Emitter> out;
  for (int i = 0; i < n; ++i) {
    const Vec3 c(10.0f * u(rng), 4.0f * u(rng), 10.0f * u(rng));
    const float r = 0.02f + 0.2f * u(rng);
    LightTree::Emitter e;
    e.lo = c - Vec3(r);
    e.hi = c + Vec3(r);
    e.power = std::pow(100.0f, u(rng));
    if (i % 3 == 2) {
      e.axis = Vec3(0, 0, 1);
      e.cos_spread = -1.0f;  // a sphere
    } else {
      e.axis = normals[i % 4];
      e.cos_spread = 1.0f;
      e.two_sided = i % 5 == 0;
    }
    out.push_back(e);
  }
  return out;
}

double floor_probability(int n) { return std::floor(kLightChoiceFloor * 0x1.0p24 / n) * 0x1.0p-24; }

struct Where {
  Vec3 point, normal;
};

// The numbers the choice reads (the top 24 bits of u) from a few points,
// with and without a normal: the first floor(F 2^24 / n) for each emitter in
// turn (the floor), then for each emitter one run of numbers as long as its
// probability says less the floor's part (the descent splits ranges of
// numbers, so what reaches a leaf is one run). Walking the runs from run end
// to run end crosses the whole range exactly: each emitter is chosen by
// exactly probability * 2^24 of the numbers, and the sample reports that
// probability.
TEST(LightTree, ChoiceRealisesExactlyItsProbabilities) {
  for (const int n : {13, 200}) {
    const std::vector<LightTree::Emitter> emitters = scattered(n, 3);
    const LightTree tree(emitters, kLightChoiceFloor);
    const auto floor_count = static_cast<std::uint32_t>(std::ldexp(floor_probability(n), 24));
    for (const Where& at : {Where{Vec3(5, 0, 5), Vec3(0, 1, 0)}, Where{Vec3(0.5f, 3.5f, 9.0f), Vec3(0)},
                            Where{Vec3(9, 2, 1), normalize(Vec3(-1, 1, 1))}}) {
      const std::vector<float> p = tree.probabilities(at.point, at.normal);
      const auto chosen = [&](std::uint32_t v) {
        const LightTree::Choice c = tree.sample(at.point, at.normal, (v << 8) | (v & 0xffu));
        EXPECT_EQ(c.probability, p[static_cast<std::size_t>(c.light)]) << "v " << v;
        return c.light;
      };
      for (int j = 0; j < n; ++j) {
        EXPECT_EQ(chosen(static_cast<std::uint32_t>(j) * floor_count), j);
        EXPECT_EQ(chosen((static_cast<std::uint32_t>(j) + 1) * floor_count - 1), j);
      }
      std::vector<int> runs(static_cast<std::size_t>(n), 0);
      std::uint32_t v = floor_count * static_cast<std::uint32_t>(n);
      while (v < (1u << 24)) {
        const int j = chosen(v);
        const double count = std::ldexp(static_cast<double>(p[static_cast<std::size_t>(j)]), 24) - floor_count;
        ASSERT_GE(count, 1.0) << "emitter " << j << " chosen by a number its probability leaves it none of";
        const auto end = v + static_cast<std::uint32_t>(count);
        ASSERT_LE(end, 1u << 24);
        EXPECT_EQ(chosen(end - 1), j) << "emitter " << j << "'s run is shorter than its probability";
        if (end < (1u << 24)) {
          EXPECT_NE(chosen(end), j) << "emitter " << j << "'s run is longer than its probability";
        }
        ++runs[static_cast<std::size_t>(j)];
        v = end;
      }
      EXPECT_EQ(v, 1u << 24);
      for (int j = 0; j < n; ++j)
        EXPECT_EQ(runs[static_cast<std::size_t>(j)], p[static_cast<std::size_t>(j)] > floor_probability(n) ? 1 : 0)
            << "emitter " << j;
    }
  }
}

// From random points, with and without a normal: the probabilities are
// multiples of 2^-24 summing to exactly 1, none below the floor's share.
TEST(LightTree, ProbabilitiesSumToOneAndKeepTheFloor) {
  for (const int n : {2, 3, 300}) {
    const LightTree tree(scattered(n, 7 + static_cast<std::uint64_t>(n)), kLightChoiceFloor);
    EXPECT_LE(tree.depth(), 64) << n;  // a path fits its bits
    pcg32 rng(11);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    for (int k = 0; k < 100; ++k) {
      const Vec3 point(5.0f + 6.0f * u(rng), 2.0f + 3.0f * u(rng), 5.0f + 6.0f * u(rng));
      const Vec3 normal = k % 2 ? normalize(Vec3(u(rng), u(rng), u(rng))) : Vec3(0.0f);
      const std::vector<float> p = tree.probabilities(point, normal);
      double sum = 0.0;
      for (const float x : p) {
        sum += x;
        EXPECT_GE(static_cast<double>(x), floor_probability(n));
        EXPECT_EQ(std::ldexp(static_cast<double>(x), 24), std::floor(std::ldexp(static_cast<double>(x), 24)));
      }
      EXPECT_EQ(sum, 1.0) << n << " emitters, point " << k;
    }
  }
}

// Two equal rows of emitters facing down, far apart: under one row, its
// emitters take nearly all the choices, and from a point whose normal faces
// away from every emitter (or behind them all), each keeps its floor at least.
TEST(LightTree, ChoosesByDistanceAndOrientation) {
  std::vector<LightTree::Emitter> emitters;
  for (int row = 0; row < 2; ++row)
    for (int i = 0; i < 16; ++i) {
      LightTree::Emitter e;
      const Vec3 c(static_cast<float>(row) * 100.0f + static_cast<float>(i) * 0.5f, 3.0f, 0.0f);
      e.lo = c - Vec3(0.1f, 0.0f, 0.1f);
      e.hi = c + Vec3(0.1f, 0.0f, 0.1f);
      e.axis = Vec3(0, -1, 0);
      e.cos_spread = 1.0f;
      e.power = 1.0f;
      emitters.push_back(e);
    }
  const LightTree tree(emitters, kLightChoiceFloor);
  const std::vector<float> under_first = tree.probabilities(Vec3(4.0f, 0.0f, 0.0f), Vec3(0, 1, 0));
  double first = 0.0;
  for (int i = 0; i < 16; ++i) first += under_first[static_cast<std::size_t>(i)];
  // By power alone 0.5; here all but the other row's floor (16 x 2% / 32).
  EXPECT_GT(first, 0.985);
  // Above the rows (behind every emitter) and facing down below them, nothing
  // reaches the point: the floor, and the rest split by power.
  for (const Where& at : {Where{Vec3(4.0f, 6.0f, 0.0f), Vec3(0, 1, 0)}, Where{Vec3(4.0f, 0.0f, 0.0f), Vec3(0, -1, 0)}}) {
    for (const float x : tree.probabilities(at.point, at.normal)) EXPECT_GE(static_cast<double>(x), floor_probability(32));
  }
}

// Two spheres of nearly float's largest power, one on each side of the point
// at the same distance: each child's importance is finite, their sum is not,
// and the split still gives each half of the numbers (halved before they are
// added). The root's power, their sum, is infinite and is never used.
TEST(LightTree, SplitsEvenlyAtFloatsLargestPowers) {
  std::vector<LightTree::Emitter> emitters;
  for (const float x : {-1.0f, 1.0f}) {
    LightTree::Emitter e;
    e.lo = Vec3(x - 0.1f, -0.1f, -0.1f);
    e.hi = Vec3(x + 0.1f, 0.1f, 0.1f);
    e.axis = Vec3(0, 0, 1);
    e.cos_spread = -1.0f;
    e.power = 3e38f;
    emitters.push_back(e);
  }
  const LightTree tree(emitters, kLightChoiceFloor);
  for (const Vec3& normal : {Vec3(0.0f), Vec3(0, 1, 0)}) {
    const std::vector<float> p = tree.probabilities(Vec3(0.0f), normal);
    EXPECT_EQ(static_cast<double>(p[0]) + p[1], 1.0);
    EXPECT_NEAR(p[0], 0.5f, 1e-6f);
    EXPECT_NEAR(p[1], 0.5f, 1e-6f);
  }
}

Scene many_lamps_scene(const char* light_choice) {
  std::string text = R"({"camera": {"width": 8, "height": 8, "vfov": 40, "lookfrom": [0, 1, -9], "lookat": [0, 1, 0]},
    "materials": {"white": {"type": "lambertian", "albedo": [0.5, 0.5, 0.5]},
                  "lamp": {"type": "diffuse_light", "emit": [4, 4, 4]},
                  "bright": {"type": "diffuse_light", "emit": [40, 40, 40], "two_sided": true}},
    "objects": [{"type": "quad", "q": [-5, 0, -5], "u": [0, 0, 10], "v": [10, 0, 0], "material": "white"})";
  for (int i = 0; i < 24; ++i)
    text += R"(, {"type": "sphere", "center": [)" + std::to_string(-4.0 + i * 0.35) + ", 3, " +
            std::to_string((i % 5) - 2.0) + R"(], "radius": 0.05, "material": "lamp"})";
  text += R"(, {"type": "quad", "q": [3, 2, 3], "u": [0.5, 0, 0], "v": [0, 0, 0.5], "material": "bright"}])";
  if (light_choice) text += std::string(R"(, "light_choice": ")") + light_choice + "\"";
  text += "}";
  return load_scene_text(text, "many lamps");
}

// `+lights:tree` (or the scene's light_choice) gives nee-mis's emitters a
// tree; the set's sample and pdf agree, and the choice reads the normal.
TEST(LightTree, StrategyAndSceneSelectIt) {
  const Scene plain = many_lamps_scene(nullptr);
  EXPECT_EQ(plain.light_choice, LightChoice::Power);
  EXPECT_EQ(SamplingPlan::make(Strategy::parse("nee-mis"), plain).emitters.tree, nullptr);
  const SamplingPlan by_tree = SamplingPlan::make(Strategy::parse("nee-mis+lights:tree"), plain);
  ASSERT_NE(by_tree.emitters.tree, nullptr);
  EXPECT_EQ(by_tree.emitters.tree->size(), 25);
  const Scene keyed = many_lamps_scene("tree");
  EXPECT_EQ(keyed.light_choice, LightChoice::Tree);
  EXPECT_NE(SamplingPlan::make(Strategy::parse("nee-mis"), keyed).emitters.tree, nullptr);
  // The strategy's choice comes before the scene's.
  EXPECT_EQ(SamplingPlan::make(Strategy::parse("nee-mis+lights:power"), keyed).emitters.tree, nullptr);

  const TargetSet& set = by_tree.emitters;
  for (const Vec3& point : {Vec3(0, 0.01f, 0), Vec3(-3, 1, 1), Vec3(3.2f, 0.5f, 3.2f)}) {
    const std::vector<float> p = set.probabilities_at(point);
    double sum = 0.0;
    for (const float x : p) sum += x;
    EXPECT_EQ(sum, 1.0);
    for (int j = 0; j < set.size(); ++j) {
      const std::uint32_t u = set.first_choice_of(point, j);
      const DirectionSample ds = set.sample(point, u, 0.3f, 0.6f);
      if (ds.none) continue;
      EXPECT_NEAR(ds.pdf, set.pdf(point, ds.direction, ds.aimed_quad, ds.aimed_distance), 1e-4f * ds.pdf) << j;
    }
  }
  // Facing down under the lamps, the bright quad below them (its lower side
  // lit) takes more of the choice than facing up.
  const Vec3 below(3.2f, 1.0f, 3.2f);
  EXPECT_GT(set.probabilities_at(below, Vec3(0, -1, 0)).back(), set.probabilities_at(below, Vec3(0, 1, 0)).back());
}

// The probe's light choice at a point is the tree's, with the point's normal.
TEST(LightTree, ProbeShowsTheTreesProbabilities) {
  const Scene scene = many_lamps_scene("tree");
  const SamplingPlan plan = SamplingPlan::make(Strategy::parse("nee-mis"), scene);
  ProbePoint at;
  at.found = true;
  at.point = Vec3(3.2f, 1.0f, 3.2f);
  at.normal = Vec3(0, -1, 0);
  const ProbeLightChoice c = probe_light_choice(scene, plan, at);
  EXPECT_EQ(c.choice, "tree");
  const std::vector<float> p = plan.emitters.tree->probabilities(at.point, at.normal);
  ASSERT_EQ(c.rows.size(), p.size());
  for (std::size_t j = 0; j < p.size(); ++j) EXPECT_EQ(c.rows[j].probability, p[j]) << j;
}

TEST(LightTree, StrategyTermParsesBack) {
  for (const char* text : {"nee-mis+lights:tree", "nee-mis+mix:cosine=0.5,bsdf=0.5+sobol+lights:uniform",
                           "nee-mis+rr+lights:power"}) {
    const Strategy s = Strategy::parse(text);
    ASSERT_TRUE(s.light_choice.has_value()) << text;
    EXPECT_EQ(Strategy::parse(s.to_string()), s) << text << " -> " << s.to_string();
  }
  EXPECT_EQ(Strategy::parse("nee-mis+lights:tree").to_string(), "nee-mis+lights:tree");
  EXPECT_FALSE(Strategy::parse("nee-mis").light_choice.has_value());
  EXPECT_EQ(Strategy::parse("fastest+lights:tree").light_choice, LightChoice::Tree);
  for (const auto& [text, needle] : {std::pair{"nee-mis+lights:bogus", "light choice must be"},
                                     std::pair{"cosine+lights:tree", "+lights"}}) {
    try {
      (void)Strategy::parse(text);
      ADD_FAILURE() << text << " was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  }
}

TEST(LightTree, SceneKeyRefusesAnUnknownChoice) {
  try {
    (void)many_lamps_scene("nearest");
    FAIL() << "light_choice 'nearest' was accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("light_choice"), std::string::npos) << what;
    EXPECT_NE(what.find("'nearest'"), std::string::npos) << what;
    EXPECT_NE(what.find("power, uniform, tree"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace pdflab
