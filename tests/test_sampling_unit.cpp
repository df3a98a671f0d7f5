// Deterministic unit checks of the sampling building blocks: the ONB, the
// sphere cone and quad area pdfs at hand-checkable points, strategy parsing,
// and the mixture's technique selection. Distribution shape is the chi-square
// suite's job; here every expectation is a number we can derive by hand.
#include "renderer/error.h"
#include "renderer/sampling/mixture.h"
#include "renderer/sampling/onb.h"
#include "renderer/sampling/rng.h"
#include "renderer/sampling/strategy.h"
#include "renderer/sampling/techniques.h"
#include "renderer/scene/scene.h"
#include "renderer/scene/scene_loader.h"

#include <gtest/gtest.h>
#include <pcg_random.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

namespace pdflab {
namespace {

// ---- ONB ------------------------------------------------------------------------

void expect_right_handed_orthonormal(const Vec3& n) {
  const Onb f(n);
  constexpr float kTol = 2e-6f;
  EXPECT_NEAR(length(f.s), 1.0f, kTol) << "n=(" << n.x << "," << n.y << "," << n.z << ")";
  EXPECT_NEAR(length(f.t), 1.0f, kTol) << "n=(" << n.x << "," << n.y << "," << n.z << ")";
  EXPECT_NEAR(dot(f.s, f.t), 0.0f, kTol) << "n=(" << n.x << "," << n.y << "," << n.z << ")";
  EXPECT_NEAR(dot(f.s, n), 0.0f, kTol) << "n=(" << n.x << "," << n.y << "," << n.z << ")";
  EXPECT_NEAR(dot(f.t, n), 0.0f, kTol) << "n=(" << n.x << "," << n.y << "," << n.z << ")";
  // Right-handed: s x t is n itself, not -n.
  const Vec3 c = cross(f.s, f.t);
  EXPECT_NEAR(c.x, n.x, kTol);
  EXPECT_NEAR(c.y, n.y, kTol);
  EXPECT_NEAR(c.z, n.z, kTol);
  // The local frame's +z is the normal, and to_local undoes to_world.
  const Vec3 up = f.to_world(Vec3(0.0f, 0.0f, 1.0f));
  EXPECT_NEAR(length(up - n), 0.0f, kTol);
  const Vec3 v(0.3f, -0.5f, 0.8f);
  EXPECT_NEAR(length(f.to_local(f.to_world(v)) - v), 0.0f, 4e-6f);
}

TEST(Onb, AxisNormals) {
  for (const Vec3& n : {Vec3(1, 0, 0), Vec3(-1, 0, 0), Vec3(0, 1, 0), Vec3(0, -1, 0), Vec3(0, 0, 1),
                        Vec3(0, 0, -1)})
    expect_right_handed_orthonormal(n);
  // The branch in the construction keys on the sign bit of z: -0 must work too.
  expect_right_handed_orthonormal(Vec3(1.0f, 0.0f, -0.0f));
  expect_right_handed_orthonormal(Vec3(0.0f, -1.0f, -0.0f));
}

TEST(Onb, NearlyAxisNormals) {
  for (const Vec3& n : {Vec3(1e-7f, 0, -1), Vec3(0, 1e-7f, -1), Vec3(-1e-7f, -1e-7f, -1), Vec3(1e-7f, 0, 1),
                        Vec3(1e-4f, 0, -1), Vec3(0, 1e-3f, -1), Vec3(1, 1e-7f, 1e-7f), Vec3(1e-7f, -1, -1e-7f),
                        Vec3(-1, 0, -1e-7f)})
    expect_right_handed_orthonormal(normalize(n));
}

// Rng is PCG32 written out; pcg-cpp's pcg32 is the oracle.
TEST(Rng, SameNumbersAsPcgCpp) {
  for (std::uint64_t seed : {0ull, 1ull, 42ull, 0x9e3779b97f4a7c15ull, ~0ull})
    for (std::uint64_t stream : {0ull, 7ull, 0x632be59bd9b4e019ull, ~0ull}) {
      Rng ours(seed, stream);
      pcg32 theirs(seed, stream);
      for (int i = 0; i < 1000; ++i) ASSERT_EQ(ours.next_u32(), theirs()) << seed << " " << stream << " " << i;
    }
  Rng a(3, 4);
  const std::uint64_t state = a.state();
  const std::uint32_t first = a.next_u32();
  EXPECT_EQ(first, Rng::output(state));
  EXPECT_EQ(a.state(), state * Rng::kMultiplier + a.increment());
}

TEST(Onb, RandomNormals) {
  Rng rng(12345, 678);
  for (int i = 0; i < 2000; ++i) {
    const float u1 = rng.uniform(), u2 = rng.uniform();
    expect_right_handed_orthonormal(sample_uniform_sphere(u1, u2).direction);
  }
}

// ---- Sphere cone ------------------------------------------------------------------

// 1 - cos(theta_max) in double, from the same float inputs the renderer sees.
double reference_one_minus_cos(const Sphere& s, const Vec3& origin) {
  const double dx = double(s.center.x) - origin.x, dy = double(s.center.y) - origin.y,
               dz = double(s.center.z) - origin.z;
  const double d2 = dx * dx + dy * dy + dz * dz;
  const double sin2 = double(s.radius) * s.radius / d2;
  return sin2 / (1.0 + std::sqrt(1.0 - sin2));
}

TEST(SphereCone, SmallAndFarSpheresKeepPrecision) {
  const Vec3 dir = normalize(Vec3(1.0f, 2.0f, 3.0f));
  const struct {
    float radius, distance;
  } cases[] = {{1.0f, 1e3f}, {1.0f, 1e6f}, {1e-3f, 10.0f}, {1.0f, 1.5f}, {2.0f, 1e5f}};
  for (const auto& c : cases) {
    const Vec3 origin(0.5f, -0.25f, 1.0f);
    const Sphere sphere{origin + dir * c.distance, c.radius, 0};
    const SphereCone cone = sphere_cone(sphere, origin);
    const double expected = reference_one_minus_cos(sphere, origin);
    ASSERT_FALSE(cone.inside);
    EXPECT_LT(std::fabs(cone.one_minus_cos_max - expected) / expected, 1e-4)
        << "r=" << c.radius << " d=" << c.distance << " got " << cone.one_minus_cos_max << " want " << expected;

    const Vec3 to_centre = normalize(sphere.center - origin);
    const float p = sphere_cone_pdf(sphere, origin, to_centre);
    EXPECT_TRUE(std::isfinite(p) && p > 0.0f) << "pdf towards the centre: " << p;
    EXPECT_LT(std::fabs(p - 1.0 / (2.0 * std::numbers::pi * expected)) * (2.0 * std::numbers::pi * expected), 1e-4);

    // A direction far outside the cone has density zero.
    EXPECT_EQ(sphere_cone_pdf(sphere, origin, -to_centre), 0.0f);
  }
}

TEST(SphereCone, SamplesStayInsideTheConeAndAgreeWithThePdf) {
  const Vec3 origin(0.0f);
  const Sphere sphere{Vec3(0.0f, 0.0f, 1e3f), 1.0f, 0};
  Rng rng(7, 9);
  for (int i = 0; i < 5000; ++i) {
    const float u1 = rng.uniform(), u2 = rng.uniform();
    const DirectionSample ds = sample_sphere_cone(sphere, origin, u1, u2);
    ASSERT_TRUE(std::isfinite(ds.pdf) && ds.pdf > 0.0f);
    EXPECT_NEAR(length(ds.direction), 1.0f, 1e-5f);
    const float p = sphere_cone_pdf(sphere, origin, ds.direction);
    EXPECT_NEAR(p / ds.pdf, 1.0f, 1e-4f) << "u=(" << u1 << "," << u2 << ")";
  }
}

// The mixture and MIS evaluate sphere_cone_pdf on directions other techniques
// drew; if it says 0 for directions the cone sampler itself produces, the
// light's share of the estimator loses those paths. A naive 1 - dot(w, axis)
// in float cannot resolve a cone narrower than ~1e-4 rad at all, so this fails
// wholesale if the evaluator loses its cancellation-free form. Only a thin
// outer ring may be lost to the ~6e-8 rounding of a float direction.
// (At 1e6 the cone is 1e-6 wide and that ring is a few percent: a limit of
// float directions, not checked here.)
TEST(SphereCone, FarSphereSamplesKeepTheirDensity) {
  const Vec3 origin(0.0f);
  for (float distance : {1e3f, 1e4f, 1e5f}) {
    const Sphere sphere{normalize(Vec3(1.0f, 2.0f, 3.0f)) * distance, 1.0f, 0};
    Rng rng(7, 9);
    constexpr int kSamples = 20000;
    int rejected = 0;
    for (int i = 0; i < kSamples; ++i) {
      const float u1 = rng.uniform(), u2 = rng.uniform();
      const DirectionSample ds = sample_sphere_cone(sphere, origin, u1, u2);
      ASSERT_TRUE(std::isfinite(ds.pdf) && ds.pdf > 0.0f);
      if (sphere_cone_pdf(sphere, origin, ds.direction) == 0.0f) ++rejected;
    }
    EXPECT_LT(rejected, kSamples / 100) << "distance " << distance << ": " << rejected << " of " << kSamples
                                         << " cone samples evaluate to pdf 0";
  }
}

TEST(SphereCone, InsideTheSphereIsUniform) {
  const Sphere sphere{Vec3(1.0f, 2.0f, 3.0f), 2.0f, 0};
  const float expected = 1.0f / (4.0f * std::numbers::pi_v<float>);
  for (const Vec3& origin : {Vec3(1.0f, 2.0f, 3.0f), Vec3(1.5f, 2.0f, 3.5f), Vec3(1.0f, 0.0f, 3.0f)}) {
    EXPECT_TRUE(sphere_cone(sphere, origin).inside);
    for (const Vec3& d : {Vec3(0, 0, 1), Vec3(0, -1, 0), normalize(Vec3(1, -2, 0.5f))})
      EXPECT_FLOAT_EQ(sphere_cone_pdf(sphere, origin, d), expected);
    EXPECT_FLOAT_EQ(sample_sphere_cone(sphere, origin, 0.3f, 0.6f).pdf, expected);
  }
}

// ---- Quad area pdf ------------------------------------------------------------------

// A 2 x 2 square in the plane y = 10 centred above the origin; area 4.
Quad ceiling_square() { return make_quad(Vec3(-1, 10, -1), Vec3(2, 0, 0), Vec3(0, 0, 2), 0); }

TEST(QuadAreaPdf, HandComputedCases) {
  const Quad q = ceiling_square();
  const Vec3 origin(0.0f);
  // Straight up: d = 10, cos = 1: 100 / 4.
  EXPECT_FLOAT_EQ(quad_area_pdf(q, origin, Vec3(0, 1, 0)), 25.0f);
  // Towards (0.5, 10, 0.5): d^2 = 100.5, cos = 10 / sqrt(100.5): d^2 / (cos A) = 100.5^1.5 / 40.
  const Vec3 d = normalize(Vec3(0.5f, 10.0f, 0.5f));
  EXPECT_NEAR(quad_area_pdf(q, origin, d), std::pow(100.5, 1.5) / 40.0, 1e-3);
  // The density is the same from behind the quad (|cos|).
  EXPECT_FLOAT_EQ(quad_area_pdf(q, Vec3(0, 20, 0), Vec3(0, -1, 0)), 25.0f);
  // The sampler reports the same density as the evaluator at the sampled point.
  const DirectionSample ds = sample_quad_area(q, origin, 0.5f, 0.5f);
  EXPECT_NEAR(ds.direction.y, 1.0f, 1e-6f);
  EXPECT_FLOAT_EQ(ds.pdf, 25.0f);
  const DirectionSample corner = sample_quad_area(q, origin, 0.75f, 0.75f);  // the point (0.5, 10, 0.5)
  EXPECT_NEAR(corner.pdf, std::pow(100.5, 1.5) / 40.0, 1e-3);
}

TEST(QuadAreaPdf, MissingRaysHaveZeroDensity) {
  const Quad q = ceiling_square();
  const Vec3 origin(0.0f);
  EXPECT_EQ(quad_area_pdf(q, origin, Vec3(0, -1, 0)), 0.0f);              // pointing away
  EXPECT_EQ(quad_area_pdf(q, origin, Vec3(1, 0, 0)), 0.0f);               // parallel to the plane
  EXPECT_EQ(quad_area_pdf(q, origin, normalize(Vec3(5, 10, 0))), 0.0f);   // beside the square
  EXPECT_EQ(quad_area_pdf(q, origin, normalize(Vec3(0, 10, -1.5f))), 0.0f);
}

// ---- Strategy parsing -----------------------------------------------------------------

std::string parse_error(const std::string& text) {
  try {
    (void)Strategy::parse(text);
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "'" << text << "' parsed";
  return {};
}

float weight_of(const Strategy& s, Technique t) { return s.weights[static_cast<int>(t)]; }

TEST(StrategyParse, SingleTechniques) {
  const struct {
    const char* text;
    Technique t;
  } cases[] = {{"cosine", Technique::Cosine},
               {"uniform-hemisphere", Technique::UniformHemisphere},
               {"uniform-sphere", Technique::UniformSphere},
               {"light", Technique::Light},
               {"light-sa", Technique::LightSolidAngle},
               {"  light ", Technique::Light}};
  for (const auto& c : cases) {
    const Strategy s = Strategy::parse(c.text);
    for (int i = 0; i < kTechniqueCount; ++i)
      EXPECT_EQ(s.weights[i], i == static_cast<int>(c.t) ? 1.0f : 0.0f) << c.text << " technique " << i;
  }
}

TEST(StrategyParse, NextEventEstimation) {
  const Strategy power = Strategy::parse("nee-mis");
  EXPECT_TRUE(power.nee_mis);
  EXPECT_EQ(power.heuristic, MisHeuristic::Power);
  EXPECT_EQ(Strategy::parse("nee-mis:power"), power);
  const Strategy balance = Strategy::parse("nee-mis:balance");
  EXPECT_TRUE(balance.nee_mis);
  EXPECT_EQ(balance.heuristic, MisHeuristic::Balance);
  EXPECT_EQ(Strategy::parse(balance.to_string()), balance);
  EXPECT_EQ(Strategy::parse(power.to_string()), power);
  EXPECT_TRUE(power.is_unbiased());
}

TEST(StrategyParse, Mixtures) {
  Strategy s = Strategy::parse("mix:cosine=0.5,light=0.5");
  EXPECT_EQ(weight_of(s, Technique::Cosine), 0.5f);
  EXPECT_EQ(weight_of(s, Technique::Light), 0.5f);
  EXPECT_EQ(weight_of(s, Technique::UniformSphere), 0.0f);

  s = Strategy::parse("mix:cosine=1,light=0");
  EXPECT_EQ(weight_of(s, Technique::Cosine), 1.0f);
  EXPECT_EQ(weight_of(s, Technique::Light), 0.0f);

  s = Strategy::parse(" mix: cosine = 0.25 ,  light=0.75 , uniform-sphere = 0 ");
  EXPECT_EQ(weight_of(s, Technique::Cosine), 0.25f);
  EXPECT_EQ(weight_of(s, Technique::Light), 0.75f);
  EXPECT_EQ(weight_of(s, Technique::UniformSphere), 0.0f);

  s = Strategy::parse("mix:uniform-hemisphere=2,uniform-sphere=6");
  EXPECT_EQ(weight_of(s, Technique::UniformHemisphere), 2.0f);
  EXPECT_EQ(weight_of(s, Technique::UniformSphere), 6.0f);
}

void expect_rejected(const std::string& text, std::initializer_list<const char*> needles) {
  const std::string message = parse_error(text);
  for (const char* needle : needles)
    EXPECT_NE(message.find(needle), std::string::npos) << "for '" << text << "': '" << message << "' lacks '"
                                                       << needle << "'";
}

// nee-mis continued by a mixture, Russian roulette, fastest: their parts,
// canonical forms that parse back, what is unbiased, and clear refusals.
TEST(StrategyParse, ContinuationsRouletteAndFastest) {
  const Strategy nm = Strategy::parse("nee-mis+mix:cosine=0.5,light=0.5");
  EXPECT_TRUE(nm.nee_mis);
  EXPECT_FALSE(nm.cosine_continuation());
  EXPECT_TRUE(nm.uses(Technique::Light));
  EXPECT_EQ(nm.to_string(), "nee-mis+mix:cosine=0.5,light=0.5");
  EXPECT_TRUE(nm.is_unbiased());
  EXPECT_FALSE(Strategy::parse("nee-mis+light").is_unbiased());  // the continuation never sees indirect light
  EXPECT_EQ(Strategy::parse("nee-mis+cosine"), Strategy::parse("nee-mis"));
  EXPECT_EQ(Strategy::parse("nee-mis").to_string(), "nee-mis");
  EXPECT_EQ(Strategy::parse("cosine").roulette_depth, 0);
  EXPECT_EQ(Strategy::parse("cosine+rr").roulette_depth, kDefaultRouletteDepth);
  EXPECT_EQ(Strategy::parse("nee-mis:balance+light-sa+rr:7").roulette_depth, 7);
  EXPECT_TRUE(Strategy::parse("nee-mis:balance+light-sa+rr:7").is_unbiased() == false);
  for (const char* text : {"cosine+rr", "cosine+rr:1", "mix:cosine=1,light=3+rr:12", "nee-mis+rr",
                           "nee-mis:balance+mix:cosine=0.3,light-sa=0.7+rr:2", "nee-mis+uniform-sphere",
                           "nee-mis+mix:cosine=0.5,guided=0.5+rr:guided", "mix:cosine=0.5,guided:3=0.5+sobol+rr:guided:4"}) {
    const Strategy s = Strategy::parse(text);
    const Strategy back = Strategy::parse(s.to_string());
    EXPECT_EQ(back.to_string(), s.to_string()) << text;
    EXPECT_EQ(back.roulette_depth, s.roulette_depth) << text;
    EXPECT_EQ(back.guided_roulette, s.guided_roulette) << text;
    EXPECT_EQ(back.nee_mis, s.nee_mis) << text;
  }
  // +rr:guided: the roulette by the guide's learned light, the throughput
  // rule from D (default kDefaultRouletteDepth) where it learned nothing.
  const Strategy guided = Strategy::parse("nee-mis+mix:cosine=0.5,guided=0.5+rr:guided");
  EXPECT_TRUE(guided.guided_roulette);
  EXPECT_EQ(guided.roulette_depth, kDefaultRouletteDepth);
  EXPECT_TRUE(guided.is_unbiased());
  EXPECT_EQ(guided.to_string(), "nee-mis+mix:cosine=0.5,guided:5=0.5+rr:guided");
  const Strategy from_four = Strategy::parse("mix:cosine=0.5,guided=0.5+rr:guided:4");
  EXPECT_EQ(from_four.roulette_depth, 4);
  EXPECT_EQ(from_four.to_string(), "mix:cosine=0.5,guided:5=0.5+rr:guided:4");
  EXPECT_FALSE(Strategy::parse("mix:cosine=0.5,guided=0.5+rr:4").guided_roulette);
  expect_rejected("nee-mis+rr:guided", {"+rr:guided", "no guided technique"});
  expect_rejected("fastest+rr:guided", {"+rr:guided", "no guided technique"});
  expect_rejected("mix:cosine=0.5,guided=0.5+rr:guided:0", {"'rr:guided:0'", "1..10000"});
  expect_rejected("mix:cosine=0.5,guided=0.5+rr:guide", {"'rr:guide'"});
  expect_rejected("cosine+rr:5:3", {"'rr:5:3'"});
  EXPECT_EQ(with_roulette(Strategy::parse("cosine"), 5).to_string(), "cosine+rr:5");
  EXPECT_EQ(with_roulette(Strategy::parse("cosine+rr:2"), 0).to_string(), "cosine+rr:2");
  const Strategy fastest = Strategy::parse("fastest");
  EXPECT_TRUE(fastest.fastest);
  EXPECT_TRUE(fastest.is_unbiased());
  EXPECT_EQ(fastest.to_string(), Strategy::parse(kFastestStrategy).to_string());  // what it expanded to
  EXPECT_EQ(Strategy::parse("fastest+rr:4").roulette_depth, 4);
  expect_rejected("cosine+rr:0", {"'rr:0'", "1..10000"});
  expect_rejected("cosine+rr:x", {"'rr:x'"});
  expect_rejected("cosine+light", {"'+' joins only"});
  expect_rejected("nee-mis+", {"mixture is empty"});
  expect_rejected("nee-mis+nee-mis", {"cannot be mixed"});
  expect_rejected("nee-mis:fast+cosine", {"'power' or 'balance'"});
}

// specular-objects aims at the glass and metal objects, found by material;
// where a scene has none it gets no weight, and fastest's continuation is
// then cosine alone (the bits of nee-mis+sobol+rr:5); alone there it is refused.
// `fastest` runs as path guiding where the scene says its light is hard to
// find (door_ajar.json), keeping what was given to fastest; elsewhere, and
// any other strategy anywhere, as parsed.
TEST(SamplingPlan, FastestUsesGuidingWhereTheSceneSaysSo) {
  const auto scene = [](const char* file) {
    return load_scene_file(std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes/" + file);
  };
  const Scene door = scene("door_ajar.json"), book = scene("cornell_book.json");
  ASSERT_TRUE(door.fastest_uses_guiding);
  EXPECT_FALSE(book.fastest_uses_guiding);
  const Strategy fastest = Strategy::parse("fastest");
  EXPECT_EQ(for_scene(fastest, book), fastest);
  const Strategy guided = for_scene(fastest, door);
  EXPECT_TRUE(guided.fastest);
  EXPECT_TRUE(guided.uses(Technique::Guided));
  EXPECT_TRUE(guided.guided_roulette);
  EXPECT_TRUE(guided.is_unbiased());
  EXPECT_EQ(guided.to_string(), Strategy::parse(kFastestGuidedStrategy).to_string());
  EXPECT_GT(SamplingPlan::make(guided, door).weight[static_cast<int>(Technique::Guided)], 0.0f);
  // +rr:D given to fastest is the guided roulette's fallback depth.
  const Strategy from_five = for_scene(Strategy::parse("fastest+rr:5"), door);
  EXPECT_EQ(from_five.roulette_depth, 5);
  EXPECT_TRUE(from_five.guided_roulette);
  EXPECT_EQ(for_scene(Strategy::parse("fastest+lights:uniform"), door).light_choice, LightChoice::Uniform);
  // Anything else is left as it is, on the door scene too.
  const Strategy nee = Strategy::parse("nee-mis+sobol+rr:10");
  EXPECT_EQ(for_scene(nee, door), nee);
  // A strategy written out (what a film or sidecar records) reads back as itself.
  EXPECT_EQ(for_scene(Strategy::parse(guided.to_string()), door).to_string(), guided.to_string());
}

TEST(SamplingPlan, SpecularObjectsAreTheGlassAndMetalObjects) {
  const auto scene = [](const char* file) {
    return load_scene_file(std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes/" + file);
  };
  const Strategy fastest = Strategy::parse("fastest");
  const int spec = static_cast<int>(Technique::SpecularObjects), cos = static_cast<int>(Technique::Cosine);

  const Scene book = scene("cornell_book.json");  // the glass sphere
  const SamplingPlan in_book = SamplingPlan::make(fastest, book);
  ASSERT_EQ(in_book.specular_objects.spheres.size(), 1u);
  EXPECT_TRUE(in_book.specular_objects.quads.empty());
  EXPECT_EQ(book.materials[in_book.specular_objects.spheres[0].sphere->material].type, MaterialType::Dielectric);
  EXPECT_NEAR(in_book.weight[spec], 0.2f, 1e-6f);
  EXPECT_FALSE(in_book.cosine_continuation);
  EXPECT_TRUE(in_book.continuation_mixes);

  const Scene glossy = scene("glossy_metal.json");  // a metal box (six faces) and a metal sphere, none marked
  const SamplingPlan in_glossy = SamplingPlan::make(fastest, glossy);
  EXPECT_EQ(in_glossy.specular_objects.quads.size(), 6u);
  EXPECT_EQ(in_glossy.specular_objects.spheres.size(), 1u);
  for (const auto& q : in_glossy.specular_objects.quads) EXPECT_NEAR(q.probability, 1.0f / 7.0f, 1e-6f);

  const Scene small = scene("small_light.json");  // no glass, no metal
  const SamplingPlan in_small = SamplingPlan::make(fastest, small);
  EXPECT_TRUE(in_small.specular_objects.empty());
  EXPECT_EQ(in_small.weight[spec], 0.0f);
  EXPECT_EQ(in_small.weight[cos], 1.0f);
  EXPECT_TRUE(in_small.cosine_continuation);
  EXPECT_FALSE(in_small.continuation_mixes);
  try {
    SamplingPlan::make(Strategy::parse("specular-objects"), small);
    ADD_FAILURE() << "specular-objects alone in a scene without glass or metal was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("specular-objects"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("has none"), std::string::npos) << e.what();
  }
}

TEST(StrategyParse, Rejections) {
  expect_rejected("phong", {"unknown strategy 'phong'", "cosine"});
  expect_rejected("Cosine", {"unknown strategy"});
  expect_rejected("mix:cosine=0.5,glossy=0.5", {"unknown technique 'glossy'"});
  expect_rejected("mix:cosine=0.5,cosine=0.5", {"'cosine' appears twice"});
  expect_rejected("mix:cosine=-1,light=1", {"weight '-1'"});
  expect_rejected("mix:cosine=nan,light=1", {"weight 'nan'"});
  expect_rejected("mix:cosine=inf,light=1", {"weight 'inf'"});
  expect_rejected("mix:cosine=,light=1", {"weight ''"});
  expect_rejected("mix:cosine=0.5x,light=1", {"weight '0.5x'"});
  expect_rejected("mix:cosine=1e60,light=1", {"weight '1e60'"});  // not a finite float
  expect_rejected("mix:cosine=0,light=0", {"all weights are zero"});
  expect_rejected("mix:", {"no technique"});
  expect_rejected("mix:cosine", {"TECHNIQUE=WEIGHT"});
  expect_rejected("mix:cosine=1,", {"TECHNIQUE=WEIGHT"});
  expect_rejected("", {"empty strategy"});
  expect_rejected("   ", {"empty strategy"});
  expect_rejected("mix:cosine=0.5,nee-mis=0.5", {"cannot be mixed"});
  expect_rejected("nee-mis:fast", {"'power' or 'balance'"});
}

TEST(StrategyParse, ToStringRoundTrips) {
  for (const char* text : {"cosine", "uniform-hemisphere", "uniform-sphere", "light", "mix:cosine=0.5,light=0.5",
                           "mix:cosine=1,light=3", "mix:cosine=1,uniform-hemisphere=1,uniform-sphere=1,light=1",
                           "mix:cosine=1,light=0", "mix:light=0.001,cosine=0.999", "mix:cosine=1e-30,light=1",
                           // Large but finite float weights are accepted by parse, so they must print too.
                           "mix:cosine=3e38,light=3e38"}) {
    const Strategy s = Strategy::parse(text);
    const std::string canonical = s.to_string();
    Strategy back;
    ASSERT_NO_THROW(back = Strategy::parse(canonical)) << text << " -> '" << canonical << "'";
    EXPECT_EQ(back.to_string(), canonical) << text;
    // Same normalised weights: the canonical form is a fixed point of parse/print.
    double total_a = 0.0, total_b = 0.0;
    for (int i = 0; i < kTechniqueCount; ++i) total_a += s.weights[i], total_b += back.weights[i];
    for (int i = 0; i < kTechniqueCount; ++i)
      EXPECT_NEAR(s.weights[i] / total_a, back.weights[i] / total_b, 1e-6) << text << " technique " << i;
  }
  EXPECT_EQ(Strategy::parse("mix:cosine=1,light=0").to_string(), "cosine");
  EXPECT_EQ(Strategy::parse("mix:cosine=1,light=3").to_string(), "mix:cosine=0.25,light=0.75");
}

// Issue 33, item 12: a strategy's text (a film's header, a sidecar) parses
// back to the very estimator: its parameters to the bit (shortest exact
// decimals, not six digits: cosine-power:3.1415926 came back as 3.14159) and
// its weights in exactly the same proportions, so the sampler's choice is the
// same bits (1:2 came back as 0.333333:0.666667). Weights are printed as
// shares where their total is a power of two (dividing is exact), else as
// given.
TEST(StrategyParse, ToStringRoundTripsToTheSameEstimator) {
  const Scene scene = load_scene_file(std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes/cornell_book.json");
  const auto same_plan = [&](const Strategy& a, const Strategy& b, const std::string& text) {
    const SamplingPlan pa = SamplingPlan::make(a, scene), pb = SamplingPlan::make(b, scene);
    EXPECT_EQ(pa.choice_threshold, pb.choice_threshold) << text;
    EXPECT_EQ(pa.weight, pb.weight) << text;
    EXPECT_EQ(pa.parameter, pb.parameter) << text;
  };
  for (const char* text :
       {"cosine-power:3.1415926", "cosine-power:0.1", "mix:cosine=1,light=2", "mix:cosine=0.1,light=0.7",
        "mix:cosine=3,light=7,uniform-sphere=11", "mix:cosine=0.3,light=0.7", "nee-mis+mix:cosine=1,light=2+rr:7",
        "mix:cosine-power:2.71828182=1,light=1e-9", "mix:cosine=1e-30,light=1", "mix:cosine=2e38,light=3e38",
        "mix:cosine=1,light=3", "fastest"}) {
    const Strategy s = Strategy::parse(text);
    const std::string once = s.to_string();
    Strategy back;
    ASSERT_NO_THROW(back = Strategy::parse(once)) << text << " -> '" << once << "'";
    EXPECT_EQ(back.to_string(), once) << text;
    EXPECT_EQ(back.parameters, s.parameters) << text << " -> " << once;
    if (std::string(text).find("e-30") == std::string::npos && std::string(text).find("e38") == std::string::npos)
      same_plan(s, back, std::string(text) + " -> " + once);  // (those two cannot be sampled: below 2^-32, or no light)
  }
  EXPECT_EQ(Strategy::parse("cosine-power:3.1415926").to_string(), "cosine-power:3.1415925");  // the float's shortest
  EXPECT_EQ(Strategy::parse("mix:cosine=1,light=2").to_string(), "mix:cosine=1,light=2");
  EXPECT_EQ(Strategy::parse("mix:cosine=2,light=2").to_string(), "mix:cosine=0.5,light=0.5");
  EXPECT_EQ(Strategy::parse("mix:cosine=0.3,light=0.7").to_string(), "mix:cosine=0.3,light=0.7");
  EXPECT_EQ(Strategy::parse("mix:cosine=2e38,light=3e38").to_string(), "mix:cosine=2e38,light=3e38")
      << "no '+' in an exponent: it would split the strategy";
}

// ---- SamplingPlan -------------------------------------------------------------------------

// A shading point at the origin (normal +y) and one small importance target: a
// light quad below it (y = -5) when `below`, else above it (y = +5).
Scene one_target_scene(bool below) {
  Scene scene;
  scene.name = "one target";
  Material lamp;
  lamp.type = MaterialType::DiffuseLight;
  lamp.emit = Vec3(1.0f);
  scene.materials.push_back(lamp);
  scene.material_names.push_back("lamp");
  const float y = below ? -5.0f : 5.0f;
  scene.quads.push_back(make_quad(Vec3(-0.5f, y, -0.5f), Vec3(1, 0, 0), Vec3(0, 0, 1), 0));
  scene.targets.push_back({Target::Kind::Quad, 0});
  return scene;
}

TEST(SamplingPlan, NormalisesWeights) {
  const Scene scene = one_target_scene(false);
  const SamplingPlan plan = SamplingPlan::make(Strategy::parse("mix:cosine=1,light=3"), scene);
  EXPECT_FLOAT_EQ(plan.weight[static_cast<int>(Technique::Cosine)], 0.25f);
  EXPECT_FLOAT_EQ(plan.weight[static_cast<int>(Technique::Light)], 0.75f);
  EXPECT_EQ(plan.weight[static_cast<int>(Technique::UniformSphere)], 0.0f);
  float sum = 0.0f;
  for (float w : plan.weight) sum += w;
  EXPECT_FLOAT_EQ(sum, 1.0f);
  // A quarter of the 2^32 numbers choose cosine, the rest light.
  EXPECT_EQ(plan.choice_threshold[static_cast<int>(Technique::Cosine)], 0x40000000u);
  EXPECT_EQ(plan.last_technique, static_cast<int>(Technique::Light));
}

TEST(SamplingPlan, MixturePdfIsTheWeightedSum) {
  const Scene scene = one_target_scene(false);
  const SamplingPlan plan = SamplingPlan::make(Strategy::parse("mix:cosine=1,light=3"), scene);
  const Vec3 origin(0.0f), normal(0, 1, 0);
  const Vec3 up(0, 1, 0);  // hits the target: d = 5, cos = 1, area 1 -> 25
  EXPECT_NEAR(plan.pdf(origin, normal, up), 0.25f * std::numbers::inv_pi_v<float> + 0.75f * 25.0f, 1e-4f);
  const Vec3 side = normalize(Vec3(1, 1, 0));  // misses the target
  EXPECT_NEAR(plan.pdf(origin, normal, side), 0.25f * side.y * std::numbers::inv_pi_v<float>, 1e-6f);
}

// With the target below the horizon, the light technique is the only one that
// can produce a downward direction, and the hemisphere techniques the only ones
// that produce upward directions: the side of each sample says who drew it.
TEST(SamplingPlan, ZeroWeightTechniqueIsNeverSampled) {
  const Scene scene = one_target_scene(true);
  const Vec3 origin(0.0f), normal(0, 1, 0);
  constexpr int kSamples = 20000;

  const SamplingPlan only_cosine = SamplingPlan::make(Strategy::parse("mix:cosine=1,light=0"), scene);
  Rng rng(1, 2);
  for (int i = 0; i < kSamples; ++i) {
    const DirectionSample ds = only_cosine.sample(origin, normal, rng);
    ASSERT_GT(ds.direction.y, 0.0f) << "sample " << i << " went below the horizon: the light technique was used";
    ASSERT_NEAR(ds.pdf, cosine_hemisphere_pdf(normal, ds.direction), 1e-4f);
  }

  const SamplingPlan only_light = SamplingPlan::make(Strategy::parse("mix:cosine=0,light=1"), scene);
  for (int i = 0; i < kSamples; ++i) {
    const DirectionSample ds = only_light.sample(origin, normal, rng);
    ASSERT_LT(ds.direction.y, 0.0f) << "sample " << i << " went up: the cosine technique was used";
  }

  // A zero weight in the middle of the list: uniform-sphere would send some
  // directions below the horizon that miss the small target.
  const SamplingPlan middle =
      SamplingPlan::make(Strategy::parse("mix:cosine=0.5,uniform-sphere=0,light=0.5"), scene);
  int down = 0;
  for (int i = 0; i < kSamples; ++i) {
    const DirectionSample ds = middle.sample(origin, normal, rng);
    if (ds.direction.y < 0.0f) {
      ++down;
      ASSERT_GT(quad_hit_distance(scene.quads[0], origin, ds.direction), 0.0f)
          << "a downward sample missed the target: uniform-sphere was used";
    }
  }
  // Half the samples come from the light technique: 10000 +- 4 sigma (sigma = 71).
  EXPECT_NEAR(down, kSamples / 2, 4 * 71);
}

// A weight of 1e-9 is chosen for exactly 4 of the 2^32 numbers, and the
// mixture's pdf uses exactly that share: no bias however rare the technique.
TEST(SamplingPlan, TinyWeightsAreRealisedExactlyOrRefused) {
  const Scene scene = one_target_scene(false);
  const SamplingPlan plan = SamplingPlan::make(Strategy::parse("mix:cosine=1e-9,light=1"), scene);
  constexpr int cosine = static_cast<int>(Technique::Cosine), light = static_cast<int>(Technique::Light);
  EXPECT_EQ(plan.weight[cosine], static_cast<float>(4.0 * 0x1.0p-32));
  EXPECT_EQ(plan.choice_threshold[cosine], 4u);
  EXPECT_EQ(leaf::choose_technique(plan, 3), cosine);
  EXPECT_EQ(leaf::choose_technique(plan, 4), light);
  EXPECT_EQ(leaf::choose_technique(plan, -1), light);  // 2^32 - 1
  // The mixture's pdf for a cosine direction carries exactly that weight.
  const Vec3 origin(0.0f), normal(0, 1, 0), away = normalize(Vec3(1, 0.2f, 0));  // misses the light
  EXPECT_FLOAT_EQ(plan.pdf(origin, normal, away), plan.weight[cosine] * cosine_hemisphere_pdf(normal, away));
  // Below 2^-32 the sampler has no share to give: refused, naming the technique
  // (issue 33, item 13: also between 2^-33 and 2^-32, which rounded up to
  // one count and so was realised up to twice as large as asked).
  for (const char* text : {"mix:cosine=1e-45,light=1", "mix:light=1,uniform-hemisphere=1e-11",
                           "mix:cosine=1.2e-10,light=1", "mix:cosine=2.2e-10,light=1"}) {
    try {
      (void)SamplingPlan::make(Strategy::parse(text), scene);
      ADD_FAILURE() << text << " was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("below 2^-32"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(std::string(text).find("cosine") != std::string::npos ? "cosine" : "uniform-hemisphere"),
                std::string::npos)
          << e.what();
    }
  }
}

// A light a billion times dimmer than another is still chosen, as often as
// its power says, whether it is listed first or last (a float CDF never
// chose it when it came after the bright one).
TEST(SamplingPlan, TheSmallestShareIsTwoToTheMinus32) {
  const Scene scene = one_target_scene(false);
  constexpr int cosine = static_cast<int>(Technique::Cosine);
  // Just above 2^-32 of the total (light 2^32 - 256): one count; just below
  // (light 2^32: 1 / (2^32 + 1), which rounds to one count too): refused.
  const SamplingPlan plan = SamplingPlan::make(Strategy::parse("mix:cosine=1,light=4294967040"), scene);
  EXPECT_EQ(plan.choice_threshold[cosine], 1u);
  EXPECT_THROW((void)SamplingPlan::make(Strategy::parse("mix:cosine=1,light=4294967296"), scene), InputError)
      << "a share a hair below 2^-32";
}

// Two unit lamps at height 5, the first at x = -3, the second at x = 2, of
// emission `first` and `second`, facing down (the second facing up where asked).
Scene two_lamps(float first, float second, bool second_faces_up = false) {
  Scene scene;
  scene.name = "two lamps";
  Material a, b;
  a.type = b.type = MaterialType::DiffuseLight;
  a.emit = Vec3(first);
  b.emit = Vec3(second);
  scene.materials = {a, b};
  scene.material_names = {"a", "b"};
  scene.quads.push_back(make_quad(Vec3(-3.0f, 5, -0.5f), Vec3(1, 0, 0), Vec3(0, 0, 1), 0));  // u x v = -y
  scene.quads.push_back(second_faces_up ? make_quad(Vec3(2.0f, 5, -0.5f), Vec3(0, 0, 1), Vec3(1, 0, 0), 1)
                                        : make_quad(Vec3(2.0f, 5, -0.5f), Vec3(1, 0, 0), Vec3(0, 0, 1), 1));
  scene.targets = {{Target::Kind::Quad, 0}, {Target::Kind::Quad, 1}};
  return scene;
}

TEST(SamplingPlan, PowerRatiosOfABillionAreRealisedInEitherOrder) {
  for (const bool dim_first : {true, false}) {
    const Scene scene = dim_first ? two_lamps(1.0f, 1e9f) : two_lamps(1e9f, 1.0f);
    const SamplingPlan plan = SamplingPlan::make(Strategy::parse("light-sa"), scene);
    const int dim_index = dim_first ? 0 : 1;
    const float p_dim = plan.power_targets.quads[static_cast<std::size_t>(dim_index)].probability;
    EXPECT_NEAR(p_dim, 1e-9, 0x1.0p-32) << (dim_first ? "dim first" : "dim last");
    // The numbers that choose the dim lamp: the first ones when it is listed
    // first, the last ones otherwise; the direction then points at it.
    const std::uint32_t u = dim_first ? 0u : 0xffffffffu;
    const DirectionSample ds = plan.power_targets.sample(Vec3(0.0f), u, 0.5f, 0.5f);
    EXPECT_EQ(ds.aimed_quad, dim_index);
    EXPECT_EQ(ds.direction.x < 0.0f, dim_first);
    EXPECT_GT(ds.pdf, 0.0f);
  }
}

// Light choice by what the point receives (TargetSet::by_point): a dim lamp
// facing down and one 1e9 times as bright facing up, side by side.
TEST(SamplingPlan, LightChoiceFollowsWhatThePointReceives) {
  const Scene scene = two_lamps(1.0f, 1e9f, true);
  for (const char* strategy : {"light-sa", "nee-mis"}) {
    SCOPED_TRACE(strategy);
    const SamplingPlan plan = SamplingPlan::make(Strategy::parse(strategy), scene);
    const TargetSet& set = std::string(strategy) == "nee-mis" ? plan.emitters : plan.power_targets;
    ASSERT_TRUE(set.by_point);
    const float floor_share = kLightChoiceFloor / 2.0f;
    const auto multiple_of_2_24 = [](float p) { return std::ldexp(p, 24) == std::floor(std::ldexp(p, 24)); };
    // Below them a point receives from the dim lamp only, above them from the
    // bright one only, in their plane from neither (then each keeps its share
    // by power, and the dim lamp has only the floor's).
    struct At {
      Vec3 point;
      float dim;  // the dim lamp's probability there
    };
    for (const At& at : {At{Vec3(0.0f, 0.0f, 0.0f), 1.0f - floor_share}, At{Vec3(0.0f, 9.0f, 0.0f), floor_share},
                         At{Vec3(0.0f, 5.0f, 0.0f), floor_share}}) {
      const std::vector<float> p = set.probabilities_at(at.point);
      ASSERT_EQ(p.size(), 2u);
      EXPECT_NEAR(p[0], at.dim, 0x1.0p-23f) << at.point.y;
      EXPECT_EQ(static_cast<double>(p[0]) + p[1], 1.0) << at.point.y;
      EXPECT_TRUE(multiple_of_2_24(p[0]) && multiple_of_2_24(p[1])) << at.point.y;
      EXPECT_EQ(set.receives(at.point, 0), at.point.y < 5.0f);
      // The numbers that choose each lamp from there are where first_choice_of
      // says; the sample's density is the set's.
      for (int j = 0; j < 2; ++j) {
        const std::uint32_t first = set.first_choice_of(at.point, j);
        for (const std::uint32_t u : {first, first + 255u}) {
          const DirectionSample ds = set.sample(at.point, u, 0.5f, 0.5f);
          if (ds.none) continue;
          EXPECT_EQ(ds.aimed_quad, j) << at.point.y << " u " << u;
          EXPECT_NEAR(ds.pdf, set.pdf(at.point, ds.direction, ds.aimed_quad, ds.aimed_distance), 1e-5f * ds.pdf);
        }
        if (j > 0) {
          EXPECT_EQ(set.sample(at.point, first - 1u, 0.5f, 0.5f).aimed_quad, j - 1);
        }
      }
    }
  }
}

TEST(SamplingPlan, LightWithoutTargetsIsAnInputError) {
  Scene scene = one_target_scene(false);
  scene.targets.clear();
  try {
    (void)SamplingPlan::make(Strategy::parse("light"), scene);
    FAIL() << "`light` on a scene without targets was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("one target"), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)SamplingPlan::make(Strategy::parse("mix:light=1,cosine=0"), scene), InputError);
  // With another technique the light's share moves to it.
  const SamplingPlan plan = SamplingPlan::make(Strategy::parse("mix:cosine=0.5,light=0.5"), scene);
  EXPECT_EQ(plan.weight[static_cast<int>(Technique::Cosine)], 1.0f);
  EXPECT_EQ(plan.weight[static_cast<int>(Technique::Light)], 0.0f);
}

}  // namespace
}  // namespace pdflab

namespace pdflab {
namespace {

TEST(FastTrig, SinCos2PiMatchesLibmToFloatPrecision) {
  double worst = 0.0;
  for (int i = 0; i <= 1 << 20; ++i) {
    const float u = static_cast<float>(i) / static_cast<float>(1 << 20);
    float s, c;
    sincos_2pi(u, s, c);
    const double angle = 2.0 * std::numbers::pi * static_cast<double>(u);
    worst = std::max({worst, std::fabs(s - std::sin(angle)), std::fabs(c - std::cos(angle))});
  }
  EXPECT_LT(worst, 1e-6);
  float s, c;
  sincos_2pi(0.0f, s, c);
  EXPECT_EQ(c, 1.0f);
  EXPECT_EQ(s, 0.0f);
}

}  // namespace
}  // namespace pdflab
