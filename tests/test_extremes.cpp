// Numbers at the extremes: weights of exactly 0 and 1, shading points in a
// light's plane, on a light, inside a target sphere, grazing angles, tiny,
// huge and distant lights, large coordinates; and no dropped samples on any
// shipped scene.
#include "renderer/error.h"
#include "renderer/sampling/target_set.h"
#include "renderer/scene/scene_loader.h"
#include "renderer/session/session.h"

#include "tests/render_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

namespace pdflab {
namespace {

namespace fs = std::filesystem;

using testing::Rendered;

Rendered render(const std::shared_ptr<const Scene>& scene, const std::string& strategy, std::uint32_t spp,
                std::uint64_t seed = 5, int threads = 2) {
  return testing::render_to_completion(scene, strategy, spp, seed, threads, std::chrono::seconds(300));
}

std::shared_ptr<Scene> load(const std::string& name, int width, int height) {
  auto scene = std::make_shared<Scene>(load_scene_file(std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes/" + name));
  scene->camera.width = width;
  scene->camera.height = height;
  scene->prepare();
  return scene;
}

bool same_film(const Film& a, const Film& b) {
  const auto x = a.mean_rgb(), y = b.mean_rgb();
  return x.size() == y.size() && std::memcmp(x.data(), y.data(), x.size() * sizeof(float)) == 0;
}

// ---- Weights of exactly 0 and 1 ------------------------------------------------------

TEST(Extremes, WeightOneIsTheTechniqueItself) {
  // A mixture with weight 1 on a technique draws the same random numbers and
  // the same directions with the same pdf: the images are bit-identical.
  const auto scene = load("cornell_book.json", 24, 24);
  EXPECT_TRUE(same_film(render(scene, "cosine", 4).film, render(scene, "mix:cosine=1,light=0", 4).film));
  EXPECT_TRUE(same_film(render(scene, "light", 4).film, render(scene, "mix:cosine=0,light=1", 4).film));
  EXPECT_TRUE(same_film(render(scene, "light-sa", 4).film, render(scene, "mix:light-sa=1,uniform-sphere=0", 4).film));
  // And weights are normalised: 2:2 is 1:1.
  EXPECT_TRUE(same_film(render(scene, "mix:cosine=0.5,light=0.5", 4).film, render(scene, "mix:cosine=2,light=2", 4).film));
}

// ---- Shading points in a light's plane, on it, inside a target sphere ------------------

Quad unit_light() { return make_quad(Vec3(0, 10, 0), Vec3(1, 0, 0), Vec3(0, 0, 1), 0); }

TEST(Extremes, PointInTheLightsPlaneOffersNoDirection) {
  const Quad q = unit_light();
  for (const Vec3 origin : {Vec3(-3, 10, 0.5f), Vec3(0.5f, 10, 0.5f) /* on the light itself */}) {
    const DirectionSample a = sample_quad_area(q, origin, 0.3f, 0.6f);
    EXPECT_TRUE(a.none);
    EXPECT_EQ(a.pdf, 0.0f);
    const DirectionSample s = sample_quad_solid_angle(q, origin, 0.3f, 0.6f);
    EXPECT_TRUE(s.none);
    // No direction from the plane reaches the quad: its density is zero everywhere.
    for (const Vec3 d : {Vec3(1, 0, 0), normalize(Vec3(1, 1e-7f, 0)), Vec3(0, 1, 0), Vec3(0, -1, 0)}) {
      EXPECT_EQ(quad_area_pdf(q, origin, d), 0.0f);
      EXPECT_EQ(quad_solid_angle_pdf(q, origin, d), 0.0f);
    }
  }
}

TEST(Extremes, InsideATargetSphereEveryDirectionHasDensityOneOverFourPi) {
  const Sphere s{Vec3(1, 2, 3), 2.0f, 0};
  for (const Vec3 origin : {Vec3(1, 2, 3), Vec3(1.5f, 2, 3), Vec3(1, 3.999f, 3)}) {
    Rng rng(3, 4);
    for (int i = 0; i < 100; ++i) {
      const DirectionSample ds = sample_sphere_cone(s, origin, rng.uniform(), rng.uniform());
      EXPECT_NEAR(length(ds.direction), 1.0f, 1e-5f);
      EXPECT_FLOAT_EQ(ds.pdf, 0.25f * kInvPi);
      EXPECT_FLOAT_EQ(sphere_cone_pdf(s, origin, ds.direction), 0.25f * kInvPi);
    }
  }
}

TEST(Extremes, NoDroppedSamplesWhenShadingPointsLieInTheLightsPlane) {
  // A floor in the plane of a two-sided light quad: every floor point is in
  // the light's plane. The light is seen edge-on from all of them; nothing is
  // dropped, and the floor stays unlit by direct light (only the wall lights it).
  const std::string text = R"({
    "camera": {"width": 16, "height": 16, "vfov": 60, "lookfrom": [0, 5, -10], "lookat": [0, 0, 0]},
    "materials": {"white": {"type": "lambertian", "albedo": [0.7, 0.7, 0.7]},
                  "lamp": {"type": "diffuse_light", "emit": [4, 4, 4], "two_sided": true}},
    "objects": [
      {"type": "quad", "q": [-5, 0, -5], "u": [10, 0, 0], "v": [0, 0, 10], "material": "white"},
      {"type": "quad", "q": [-1, 0, 1], "u": [2, 0, 0], "v": [0, 0, 1], "material": "lamp"},
      {"type": "quad", "q": [-5, 0, 5], "u": [10, 0, 0], "v": [0, 5, 0], "material": "white"}
    ]})";
  auto scene = std::make_shared<Scene>(load_scene_text(text, "plane.json"));
  for (const char* strategy : {"light", "light-sa", "mix:cosine=0.5,light=0.5", "mix:cosine=0.5,light-sa=0.5", "nee-mis"}) {
    const Rendered r = render(scene, strategy, 8);
    EXPECT_EQ(r.stats.dropped.total(), 0u) << strategy;
  }
}

TEST(Extremes, NextEventEstimationWithoutEmittersIsPlainCosineSampling) {
  // A furnace: no emitter, only the sky. nee-mis has no light to sample, so it
  // must behave exactly like cosine sampling (same random numbers aside).
  const std::string text = R"({
    "camera": {"width": 8, "height": 8, "vfov": 30, "lookfrom": [0, 0, -5], "lookat": [0, 0, 0],
               "background": [1, 1, 1]},
    "materials": {"white": {"type": "lambertian", "albedo": [0.5, 0.5, 0.5]}},
    "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "white"}]})";
  auto scene = std::make_shared<Scene>(load_scene_text(text, "furnace.json"));
  const SamplingPlan plan = SamplingPlan::make(Strategy::parse("nee-mis"), *scene);
  EXPECT_TRUE(plan.emitters.empty());
  EXPECT_TRUE(plan.emitters.sample(Vec3(0), 0x80000000u, 0.5f, 0.5f).none);
  const Rendered r = render(scene, "nee-mis", 4);
  EXPECT_EQ(r.stats.dropped.total(), 0u);
  double m[3];
  r.film.mean(static_cast<std::size_t>(4 * 8 + 4), m);  // the centre pixel sees the sphere
  EXPECT_NEAR(m[0], 0.5, 1e-6);
}

// ---- Grazing angles ---------------------------------------------------------------

TEST(Extremes, GrazingAnglesGiveFinitePositiveDensities) {
  const Quad q = unit_light();
  // A point 1e-7 above the light's plane, beside it: the light is seen at cos ~ 1e-7.
  const Vec3 origin(-1.0f, 10.0f - 1e-6f, 0.5f);
  for (float u : {0.01f, 0.5f, 0.99f}) {
    const DirectionSample a = sample_quad_area(q, origin, u, 0.5f);
    ASSERT_FALSE(a.none);
    EXPECT_TRUE(std::isfinite(a.pdf) && a.pdf > 0.0f) << a.pdf;
    const DirectionSample s = sample_quad_solid_angle(q, origin, u, 0.5f);  // falls back to area here
    EXPECT_TRUE(std::isfinite(s.pdf) && s.pdf > 0.0f) << s.pdf;
  }
  // The cosine lobe at cos theta = 1e-7.
  const Vec3 n(0, 0, 1);
  const Vec3 grazing = normalize(Vec3(1.0f, 0.0f, 1e-7f));
  EXPECT_GT(cosine_hemisphere_pdf(n, grazing), 0.0f);
  EXPECT_NEAR(cosine_hemisphere_pdf(n, grazing), 1e-7f * kInvPi, 1e-9f);
}

// ---- Tiny, huge and distant lights ----------------------------------------------------

// Solid angle of a w x h rectangle centred under a point at distance d.
double centred_rectangle_solid_angle(double w, double h, double d) {
  const double a = w / 2, b = h / 2;
  return 4.0 * std::asin(a * b / std::sqrt((a * a + d * d) * (b * b + d * d)));
}

TEST(Extremes, SphericalRectangleMatchesTheAnalyticSolidAngle) {
  for (const double size : {1e-2, 1.0, 10.0, 1e4}) {
    const Quad q = make_quad(Vec3(-static_cast<float>(size / 2), 1, -static_cast<float>(size / 2)),
                             Vec3(static_cast<float>(size), 0, 0), Vec3(0, 0, static_cast<float>(size)), 0);
    const SphericalRectangle r = spherical_rectangle(q, Vec3(0, 0, 0));
    ASSERT_TRUE(r.usable) << size;
    EXPECT_NEAR(r.solid_angle / centred_rectangle_solid_angle(size, size, 1.0), 1.0, 1e-5) << size;
  }
}

// The float set-up (leaf::spherical_rectangle) against the double form, on
// rectangles and origins at scales 1e-3 to 1e6, near and far, head-on and
// grazing: where it takes a rectangle (`fast`) its solid angle agrees to 1e-5,
// and a sample's point agrees with the double form's for the same random
// numbers to 1e-3 of the rectangle's extent (leaf_math.inc's error analysis).
// Lanes outside the domain are left to the double form, which both tracers use.
TEST(Extremes, FloatSphericalRectangleAgreesWithTheDoubleForm) {
  Rng rng(31, 7);
  int fast = 0, total = 0;
  double worst_s = 0.0, worst_point = 0.0;
  for (const float scale : {1e-3f, 1.0f, 555.0f, 1e6f}) {
    for (int i = 0; i < 3000; ++i) {
      const float w = scale * (0.01f + 2.0f * rng.uniform()), h = scale * (0.01f + 2.0f * rng.uniform());
      const Vec3 corner(scale * (rng.uniform() - 0.5f), scale * (rng.uniform() - 0.5f), scale * (rng.uniform() - 0.5f));
      // Axis-aligned like the shipped scenes, or turned about y.
      const float turn = i % 2 ? 0.0f : 6.2831853f * rng.uniform();
      const Vec3 u(w * std::cos(turn), 0.0f, w * std::sin(turn));
      const Vec3 v = i % 3 ? Vec3(-h * std::sin(turn), 0.0f, h * std::cos(turn)) : Vec3(0.0f, h, 0.0f);
      const Quad q = make_quad(corner, u, v, 0);
      const float reach = scale * (i % 5 == 0 ? 40.0f : 3.0f);
      const Vec3 origin(reach * (rng.uniform() - 0.5f), reach * (rng.uniform() - 0.5f), reach * (rng.uniform() - 0.5f));
      const SphericalRectangle d = spherical_rectangle(q, origin);
      const RectangleAxes axes = rectangle_axes(q);
      const leaf::SphericalRectangle f = leaf::spherical_rectangle(axes, origin, true);
      ++total;
      if (!f.fast) continue;
      ++fast;
      ASSERT_TRUE(d.usable);
      const double es = std::fabs(f.solid_angle / d.solid_angle - 1.0);
      worst_s = std::max(worst_s, es);
      ASSERT_LT(es, 1e-5) << i << " scale " << scale;
      const double extent = std::max(static_cast<double>(w), static_cast<double>(h));
      for (int k = 0; k < 8; ++k) {
        const float u1 = rng.uniform(), u2 = rng.uniform();
        const DirectionSample ds = sample_quad_solid_angle(q, origin, u1, u2);
        const Vec3 fp = leaf::spherical_rectangle_point(f, axes, u1, u2);
        const Vec3 dp = ds.direction * ds.aimed_distance;
        const double e = static_cast<double>(length(fp - dp)) / extent;
        worst_point = std::max(worst_point, e);
        ASSERT_LT(e, 1e-3) << i << " scale " << scale << " u " << u1 << " " << u2;
      }
    }
  }
  std::printf("float set-up: %d of %d rectangles, worst solid angle error %.2g, worst point error %.2g of the extent\n",
              fast, total, worst_s, worst_point);
  EXPECT_GT(fast, total / 3);  // the float form is the common case
}

// nee-mis samples a light by area from where it looks flat (its farthest point
// at most kEmitterFlatDistanceRatio times as far as its nearest): the test's
// nearest and farthest distances are the true extremes over the rectangle
// (checked against a fine grid of its points), behind a one-sided light it is
// always true, and over the rectangle itself (nearest distance 0) never.
TEST(Extremes, AreaSamplingFromWhereALightLooksFlat) {
  Rng rng(41, 3);
  int flat = 0, curved = 0;
  for (int i = 0; i < 400; ++i) {
    const float w = 0.2f + 2.0f * rng.uniform(), h = 0.2f + 2.0f * rng.uniform(), turn = 6.2831853f * rng.uniform();
    const Vec3 corner(rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f);
    const Quad q = make_quad(corner, Vec3(w * std::cos(turn), 0.0f, w * std::sin(turn)),
                             Vec3(-h * std::sin(turn) * 0.6f, h * 0.8f, h * std::cos(turn) * 0.6f), 0);
    RectangleAxes axes = rectangle_axes(q);
    axes.flat_distance_ratio = kEmitterFlatDistanceRatio;
    const float reach = i % 3 == 0 ? 30.0f : 4.0f;
    const Vec3 origin(reach * (rng.uniform() - 0.5f), reach * (rng.uniform() - 0.5f), reach * (rng.uniform() - 0.5f));
    double nearest = 1e30, farthest = 0.0;
    const int n = 200;
    for (int a = 0; a <= n; ++a)
      for (int b = 0; b <= n; ++b) {
        const Vec3 p = q.q + q.u * (static_cast<float>(a) / n) + q.v * (static_cast<float>(b) / n);
        const double d = static_cast<double>(length(p - origin));
        nearest = std::min(nearest, d), farthest = std::max(farthest, d);
      }
    const double ratio = farthest / nearest;
    const bool expected = ratio <= kEmitterFlatDistanceRatio;
    // A grid's nearest point may lie a little farther than the true nearest:
    // judge only where the ratio is clear of the bound.
    if (std::fabs(ratio / kEmitterFlatDistanceRatio - 1.0) > 0.02) {
      EXPECT_EQ(leaf::area_suffices(axes, origin), expected) << i << " distance ratio " << ratio;
    }
    (expected ? flat : curved) += 1;
    axes.flat_distance_ratio = 0.0f;  // never, but for the one-sided rule
    EXPECT_FALSE(leaf::area_suffices(axes, origin));
  }
  EXPECT_GT(flat, 50);
  EXPECT_GT(curved, 50);

  // The book's light (one-sided, facing down): from behind, always; from the
  // floor below it, flat; from 24 units under it, not; in its plane over it, not.
  const Quad light = make_quad(Vec3(213, 554, 227), Vec3(130, 0, 0), Vec3(0, 0, 105), 0);
  RectangleAxes axes = rectangle_axes(light);
  axes.one_sided = true;
  axes.flat_distance_ratio = kEmitterFlatDistanceRatio;
  EXPECT_TRUE(leaf::area_suffices(axes, Vec3(278, 554.9f, 279)));
  EXPECT_TRUE(leaf::area_suffices(axes, Vec3(278, 0, 279)));
  EXPECT_FALSE(leaf::area_suffices(axes, Vec3(278, 530, 279)));
  axes.one_sided = false;
  EXPECT_FALSE(leaf::area_suffices(axes, Vec3(278, 554, 279)));
  EXPECT_FALSE(leaf::area_suffices(axes, Vec3(278, 554.9f, 279)));
  // Where every lane is sampled by area nothing is set up, and the result says so.
  const leaf::SphericalRectangle r = leaf::spherical_rectangle(axes, Vec3(278, 0, 279), true);
  EXPECT_TRUE(r.area);
  EXPECT_FALSE(r.fast);
}

TEST(Extremes, TinyLightFallsBackToAreaSamplingConsistently) {
  // 1e-4 units wide at distance 1: 1e-8 sr, below the spherical method's threshold.
  const Quad q = make_quad(Vec3(-5e-5f, 1, -5e-5f), Vec3(1e-4f, 0, 0), Vec3(0, 0, 1e-4f), 0);
  const Vec3 origin(0, 0, 0);
  EXPECT_FALSE(spherical_rectangle(q, origin).usable);
  Rng rng(8, 9);
  for (int i = 0; i < 100; ++i) {
    const float u1 = rng.uniform(), u2 = rng.uniform();
    const DirectionSample s = sample_quad_solid_angle(q, origin, u1, u2);
    const DirectionSample a = sample_quad_area(q, origin, u1, u2);
    EXPECT_EQ(s.direction, a.direction);
    EXPECT_EQ(s.pdf, a.pdf);
    EXPECT_TRUE(std::isfinite(s.pdf) && s.pdf > 0.0f);
    EXPECT_NEAR(s.pdf, 1.0 / 1e-8, 1e-8 * 1e8 * 1e3);  // ~ 1 / solid angle
  }
}

TEST(Extremes, HugeLightIsSampledUniformlyInSolidAngle) {
  // 1e4 wide at distance 1: almost a hemisphere. Every sample lies on the
  // light, has pdf 1/S, and the mean of the sample's cosine to the normal
  // matches its analytic expectation (the light's projected solid angle / S).
  const float half = 5e3f;
  const Quad q = make_quad(Vec3(-half, 1, -half), Vec3(2 * half, 0, 0), Vec3(0, 0, 2 * half), 0);
  const Vec3 origin(0, 0, 0);
  const SphericalRectangle r = spherical_rectangle(q, origin);
  ASSERT_TRUE(r.usable);
  Rng rng(1, 2);
  double sum_cos = 0.0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const DirectionSample s = sample_quad_solid_angle(q, origin, rng.uniform(), rng.uniform());
    ASSERT_GT(quad_hit_distance(q, origin, s.direction), 0.0f);
    ASSERT_FLOAT_EQ(s.pdf, static_cast<float>(1.0 / r.solid_angle));
    sum_cos += s.direction.y;
  }
  // Projected solid angle of a large square seen from distance 1 is close to pi
  // (pi for an infinite plane); computed here by fine quadrature in double.
  double projected = 0.0;
  const int m = 2000;
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j) {
      // Quadrature over the square in tan-space keeps the far field accurate.
      const double ta = std::atan(static_cast<double>(half));
      const double ax = -ta + (i + 0.5) * 2 * ta / m, az = -ta + (j + 0.5) * 2 * ta / m;
      const double x = std::tan(ax), z = std::tan(az);
      const double jac = (1 + x * x) * (1 + z * z) * (2 * ta / m) * (2 * ta / m);
      const double d2 = x * x + z * z + 1;
      projected += jac / (d2 * d2);  // cos_at_origin * cos_at_light / d^2 with both cosines 1/sqrt(d2)
    }
  const double expected_mean_cos = projected / r.solid_angle;
  const double se = std::sqrt(0.25 / n);  // cos in [0, 1]: variance at most 1/4
  EXPECT_NEAR(sum_cos / n, expected_mean_cos, 5 * se);
}

TEST(Extremes, DistantSphereHasAStableConeAndPositiveDensity) {
  const Sphere s{Vec3(0, 1e6f, 0), 1.0f, 0};
  const Vec3 origin(0, 0, 0);
  const SphereCone cone = sphere_cone(s, origin);
  EXPECT_NEAR(cone.one_minus_cos_max / 5e-13, 1.0, 1e-4);  // r^2 / (2 d^2)
  Rng rng(4, 4);
  for (int i = 0; i < 1000; ++i) {
    const DirectionSample ds = sample_sphere_cone(s, origin, rng.uniform(), rng.uniform());
    EXPECT_TRUE(std::isfinite(ds.pdf) && ds.pdf > 0.0f);
    EXPECT_GT(ds.direction.y, 0.99999f);
  }
}

TEST(Extremes, DistantQuadLightOneMillionUnitsAway) {
  const Quad q = make_quad(Vec3(-50, 1e6f, -50), Vec3(100, 0, 0), Vec3(0, 0, 100), 0);
  const Vec3 origin(0, 0, 0);
  const DirectionSample a = sample_quad_area(q, origin, 0.5f, 0.5f);
  EXPECT_TRUE(std::isfinite(a.pdf) && a.pdf > 0.0f);
  EXPECT_NEAR(a.pdf, 1e12 / 1e4, 1e8 * 1e-3);  // d^2 / A
  const DirectionSample s = sample_quad_solid_angle(q, origin, 0.5f, 0.5f);
  EXPECT_TRUE(std::isfinite(s.pdf) && s.pdf > 0.0f);
  EXPECT_NEAR(s.pdf / a.pdf, 1.0, 1e-3);
}

// ---- Large coordinates: offsets avoid self-intersection, walls do not leak ------------

TEST(Extremes, FurnaceAtLargeCoordinatesHasNoSelfIntersection) {
  // A tilted lambertian floor of albedo 0.5 around y = 1e5 under a uniform sky
  // of 2: with cosine sampling every floor pixel is exactly 1.0 unless a ray
  // hits the floor it starts from. (Tilted, so that hit points round off the plane.)
  const std::string text = R"({
    "camera": {"width": 16, "height": 16, "vfov": 30, "lookfrom": [100000, 100050, 99900],
               "lookat": [100000, 100000, 100000], "background": [2, 2, 2]},
    "materials": {"grey": {"type": "lambertian", "albedo": [0.5, 0.5, 0.5]}},
    "objects": [
      {"type": "quad", "q": [99000, 99900, 101000], "u": [2000, 37, 0], "v": [0, 213, -2000], "material": "grey"}
    ]})";
  auto scene = std::make_shared<Scene>(load_scene_text(text, "far.json"));
  const Rendered r = render(scene, "cosine", 16);
  for (std::size_t p = 0; p < r.film.pixel_count(); ++p) {
    double m[3];
    r.film.mean(p, m);
    ASSERT_NEAR(m[0], 1.0, 1e-6) << "pixel " << p;
  }
}

TEST(Extremes, ThinWallAtLargeCoordinatesDoesNotLeakLight) {
  // A closed room around coordinates 1e5 whose ceiling is a wall 0.25 units
  // thick; above it, a strong light facing down. Nothing may get inside.
  const std::string text = R"({
    "camera": {"width": 12, "height": 12, "vfov": 60, "lookfrom": [100000, 100002, 100000],
               "lookat": [100000, 100000, 100003], "background": [0, 0, 0]},
    "materials": {"white": {"type": "lambertian", "albedo": [0.9, 0.9, 0.9]},
                  "lamp": {"type": "diffuse_light", "emit": [1000, 1000, 1000]}},
    "objects": [
      {"type": "box", "min": [99995, 99998, 99995], "max": [100005, 100004, 100005], "material": "white"},
      {"type": "box", "min": [99990, 100004.05, 99990], "max": [100010, 100004.3, 100010], "material": "white"},
      {"type": "quad", "q": [99994, 100004.6, 99994], "u": [12, 0, 0], "v": [0, 0, 12], "material": "lamp"}
    ]})";
  auto scene = std::make_shared<Scene>(load_scene_text(text, "room.json"));
  ASSERT_EQ(scene->quads.size(), 13u);
  ASSERT_LT(scene->quads[12].normal.y, 0.0f);  // the lamp faces the room
  for (const char* strategy : {"cosine", "mix:cosine=0.5,light=0.5", "nee-mis"}) {
    const Rendered r = render(scene, strategy, 16);
    for (std::size_t p = 0; p < r.film.pixel_count(); ++p) {
      double m[3];
      r.film.mean(p, m);
      ASSERT_EQ(m[0] + m[1] + m[2], 0.0) << strategy << ": light leaked into pixel " << p;
    }
  }
}

TEST(Extremes, ShadowRayFindsAShadeJustInFrontOfASphereLight) {
  // A small sphere lamp inside a closed box whose walls stand 1e-4 of its
  // radius off it, over a floor: every light sample's shadow ray, which leaves
  // its own sphere untested and searches up to the point drawn on it
  // (PathTracer::intersect_shadow), must find the box in front. Nothing lit.
  const std::string text = R"({
    "camera": {"width": 10, "height": 10, "vfov": 60, "lookfrom": [0, 3, 3], "lookat": [0, 0, 0], "background": [0, 0, 0]},
    "materials": {"white": {"type": "lambertian", "albedo": [0.8, 0.8, 0.8]},
                  "lamp": {"type": "diffuse_light", "emit": [400, 400, 400]}},
    "objects": [
      {"type": "quad", "q": [-5, 0, -5], "u": [10, 0, 0], "v": [0, 0, 10], "material": "white"},
      {"type": "box", "min": [-0.050005, 0.949995, -0.050005], "max": [0.050005, 1.050005, 0.050005], "material": "white"},
      {"type": "sphere", "center": [0, 1, 0], "radius": 0.05, "material": "lamp"}
    ]})";
  auto scene = std::make_shared<Scene>(load_scene_text(text, "shade.json"));
  for (const char* strategy : {"nee-mis", "nee-mis+lights:tree", "mix:cosine=0.5,light-sa=0.5"}) {
    const Rendered r = render(scene, strategy, 16);
    for (std::size_t p = 0; p < r.film.pixel_count(); ++p) {
      double m[3];
      r.film.mean(p, m);
      ASSERT_EQ(m[0] + m[1] + m[2], 0.0) << strategy << ": light passed the shade into pixel " << p;
    }
  }
}

TEST(Extremes, SpheresLargeAgainstTheSceneAreTestedInFloat) {
  const Scene book = load_scene_file(std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes/cornell_book.json");
  ASSERT_EQ(book.spheres.size(), 1u);
  EXPECT_TRUE(book.spheres[0].float_test);  // radius 90 in a scene 800 across
  const Scene far = load_scene_file(std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes/far_light.json");
  ASSERT_EQ(far.spheres.size(), 1u);
  EXPECT_FALSE(far.spheres[0].float_test);  // radius 3000 at 1e5: double
  // A ground sphere through the origin, 1e3 wide under a scene 1 wide: double.
  const Scene ground = load_scene_text(R"({"camera": {"width": 4, "height": 4, "vfov": 40, "lookfrom": [0, 1, -1], "lookat": [0, 0, 0]},
    "materials": {"white": {"type": "lambertian", "albedo": [0.5, 0.5, 0.5]}},
    "objects": [{"type": "sphere", "center": [0, -1000, 0], "radius": 1000, "material": "white"}]})",
                                       "ground.json");
  ASSERT_EQ(ground.spheres.size(), 1u);
  EXPECT_FALSE(ground.spheres[0].float_test);
}

TEST(Extremes, FloatSphereTestStaysWithinItsHitErrorBound) {
  // Spheres tested in float (Sphere::float_test) at scales 1e-3 to 1e6, with
  // centres and ray origins anywhere within the 16 radii that Scene::prepare
  // allows: every hit point lies within its error bound of the sphere
  // (measured in long double), a ray leaving it outward from its offset origin
  // never meets the sphere again, and one leaving inward meets its far side.
  Rng rng(5, 9);
  double worst = 0.0;  // the largest distance from the sphere over the float test's share of the bound
  int hits = 0;
  for (int i = 0; i < 100000; ++i) {
    const float r = std::pow(10.0f, -3.0f + 9.0f * rng.uniform());
    const float extent = 16.0f * r;
    const auto inside = [&](float half) {
      return Vec3((2.0f * rng.uniform() - 1.0f) * half, (2.0f * rng.uniform() - 1.0f) * half,
                  (2.0f * rng.uniform() - 1.0f) * half);
    };
    Sphere s{inside(extent - r), r, 0};
    s.float_test = true;
    const Vec3 o = inside(extent);
    // Aimed at a point near the sphere's silhouette or across it, grazing included.
    const Vec3 aim = s.center + sample_uniform_sphere(rng.uniform(), rng.uniform()).direction * (r * (0.9f + 0.11f * rng.uniform()));
    if (aim == o) continue;
    const Vec3 d = normalize(aim - o);
    bool hit = false;
    const float t = leaf::sphere_hit_distance(s, o, d, kInf, hit);
    if (!hit) continue;
    ++hits;
    const Vec3 p = o + d * t;
    const float error = leaf::sphere_hit_error(o, t, p, r);
    const auto ld = [](float x) { return static_cast<long double>(x); };
    const long double dx = ld(p.x) - ld(s.center.x), dy = ld(p.y) - ld(s.center.y), dz = ld(p.z) - ld(s.center.z);
    const long double off = std::fabs(std::sqrt(dx * dx + dy * dy + dz * dz) - ld(r));
    ASSERT_LE(off, ld(error)) << i;
    worst = std::max(worst, static_cast<double>(off / (ld(64.0f * leaf::kFloatEpsilon) * (ld(t) + ld(r)))));
    const Vec3 n = normalize(p - s.center);
    // Leaving outward: a convex sphere is never met again.
    const Vec3 out = sample_cosine_hemisphere(Onb(n), rng.uniform(), rng.uniform()).direction;
    bool again = false;
    leaf::sphere_hit_distance(s, leaf::offset_origin(p, n, error), out, kInf, again);
    ASSERT_FALSE(again) << i;
    // Leaving inward: the far side, a chord of 2 r cos away, not the point left.
    const Vec3 in = sample_cosine_hemisphere(Onb(-n), rng.uniform(), rng.uniform()).direction;
    const float chord = 2.0f * r * dot(in, -n);
    if (chord < 1e3f * error) continue;
    bool far_side = false;
    const float t_in = leaf::sphere_hit_distance(s, leaf::offset_origin(p, -n, error), in, kInf, far_side);
    ASSERT_TRUE(far_side) << i;
    ASSERT_GT(t_in, 0.5f * chord) << i;  // the offset itself moves the far side a little
  }
  EXPECT_GT(hits, 50000);
  EXPECT_LT(worst, 0.5);  // 64 eps (t + r) has room
  std::printf("float sphere test: worst distance from the sphere %.3f of 64 eps (t + r), %d hits\n", worst, hits);
}


TEST(Extremes, SphereCullNeverClearsARayTheDoubleTestHits) {
  // Spheres tested in double (small against the scene) from radius 1e-6 to
  // 1e5, centres up to 1e6 from the origin and ray origins up to 1e4 radii
  // away: rays aimed within a few float roundings of the silhouette, across
  // the sphere, away from it and from inside. leaf::sphere_may_be_hit may only
  // clear a ray the double test does not hit, and it clears most of the rays
  // aimed away (where it saves the double test).
  Rng rng(11, 3);
  int hits = 0, cleared = 0, away = 0;
  for (int i = 0; i < 200000; ++i) {
    const float r = std::pow(10.0f, -6.0f + 11.0f * rng.uniform());
    const float far = std::pow(10.0f, 6.0f * rng.uniform());
    const Vec3 c = sample_uniform_sphere(rng.uniform(), rng.uniform()).direction * (far * rng.uniform());
    const float distance = r * std::pow(10.0f, -0.5f + 4.5f * rng.uniform());  // inside too
    const Vec3 o = c + sample_uniform_sphere(rng.uniform(), rng.uniform()).direction * distance;
    Sphere s{c, r, 0};
    s.float_test = false;
    Vec3 aim;
    const int kind = i % 4;
    if (kind == 0) {  // within about 2^-20 of the silhouette, either side
      aim = c + sample_uniform_sphere(rng.uniform(), rng.uniform()).direction *
                    (r * (1.0f + std::ldexp(2.0f * rng.uniform() - 1.0f, -20)));
    } else if (kind == 1) {  // across the sphere
      aim = c + sample_uniform_sphere(rng.uniform(), rng.uniform()).direction * (r * rng.uniform());
    } else {  // anywhere
      aim = o + sample_uniform_sphere(rng.uniform(), rng.uniform()).direction;
    }
    if (aim == o) continue;
    const Vec3 d = normalize(aim - o);
    bool hit = false;
    leaf::sphere_hit_distance_in<leaf::Double>(s, o, d, kInf, hit);
    const bool may = leaf::sphere_may_be_hit(s, o, d);
    if (hit) {
      ++hits;
      ASSERT_TRUE(may) << i << " r " << r << " |f| " << distance << " kind " << kind;
    }
    if (kind >= 2 && !hit) {
      ++away;
      if (!may) ++cleared;
    }
    bool through_cull = false;
    leaf::sphere_hit_distance(s, o, d, kInf, through_cull);
    ASSERT_EQ(through_cull, hit) << i;
  }
  EXPECT_GT(hits, 50000);
  EXPECT_GT(cleared, away / 2);
  std::printf("sphere cull: %d hits, %d of %d rays that miss cleared in float\n", hits, cleared, away);
}
TEST(Extremes, IntersectionIsTheSameWithAndWithoutTheSimdBatch) {
  // A scene edited by hand after prepare() falls back to the scalar loop; both must agree.
  Scene prepared = load_scene_file(std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes/cornell_book.json");
  Scene stale = prepared;
  stale.quad_batch = QuadBatch{};
  stale.quad_batch.count = -1;  // never equal to quads.size(): the batch is out of date
  Rng rng(21, 4);
  for (int i = 0; i < 20000; ++i) {
    const Vec3 o(rng.uniform() * 555.0f, rng.uniform() * 555.0f, rng.uniform() * 555.0f);
    const Ray ray{o, sample_uniform_sphere(rng.uniform(), rng.uniform()).direction};
    Hit a, b;
    const bool ha = intersect(prepared, ray, kInf, a), hb = intersect(stale, ray, kInf, b);
    ASSERT_EQ(ha, hb) << i;
    if (!ha) continue;
    ASSERT_EQ(a.material, b.material) << i;
    ASSERT_NEAR(a.t, b.t, 1e-3f * a.t) << i;
  }
}

// ---- Shipped scenes never drop a sample ------------------------------------------------

TEST(Extremes, NoShippedSceneDropsASample) {
  const char* strategies[] = {"cosine", "uniform-hemisphere", "uniform-sphere", "light", "light-sa",
                              "mix:cosine=0.5,light=0.5", "mix:cosine=0.5,light-sa=0.5", "nee-mis",
                              "nee-mis:balance", "environment", "mix:cosine=0.5,environment=0.5"};
  int scenes = 0;
  for (const auto& entry : fs::directory_iterator(std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes")) {
    if (entry.path().extension() != ".json") continue;
    ++scenes;
    const auto scene = load(entry.path().filename().string(), 32, 32);
    for (const char* strategy : strategies) {
      try {
        (void)SamplingPlan::make(Strategy::parse(strategy), *scene);
      } catch (const InputError&) {
        continue;  // light without targets (the sun and sky), environment without a map
      }
      const Rendered r = render(scene, strategy, 8);
      EXPECT_EQ(r.stats.dropped.total(), 0u) << entry.path().filename() << " with " << strategy;
    }
  }
  EXPECT_GE(scenes, 6);
}

}  // namespace
}  // namespace pdflab

namespace pdflab {
namespace {

// A ball of albedo 0.5 inside a two-sided emitting dome of radius R (emission
// 1): the ball's radiance is exactly 0.5 (it sees only the dome), the dome's
// 1. The float sphere test squared the radius past FLT_MAX from R = 1.84e19
// (2^64), and the dome vanished: a black image. Every radius the loader
// accepts, up to 1e30, now renders the closed form: cosine exactly (its weight
// is the albedo), nee-mis and light-sa (the dome, their target, sampled from
// inside it: the whole sphere of directions) within 3 standard errors.
TEST(Extremes, BallInsideADomeOfAnyRadius) {
  for (const double radius : {1.8e19, 1.85e19, 1e20, 1e25, 1e30}) {
    char text[1024];
    std::snprintf(text, sizeof text, R"({
      "camera": {"width": 9, "height": 9, "vfov": 30, "lookfrom": [0, 0, -5], "lookat": [0, 0, 0], "max_depth": 4},
      "materials": {"ball": {"type": "lambertian", "albedo": [0.5, 0.5, 0.5]},
                    "dome": {"type": "diffuse_light", "emit": [1, 1, 1], "two_sided": true}},
      "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "ball"},
                  {"type": "sphere", "center": [0, 0, 0], "radius": %.17g, "material": "dome", "importance": true}]})",
                  radius);
    auto scene = std::make_shared<Scene>(load_scene_text(text, "dome.json"));
    const std::size_t centre = 4 * 9 + 4, corner = 0;
    for (const char* strategy : {"cosine", "nee-mis", "light-sa"}) {
      const Rendered r = render(scene, strategy, strategy == std::string("cosine") ? 4u : 256u);
      EXPECT_EQ(r.stats.dropped.total(), 0u) << strategy << " R = " << radius;
      double m[3], v[3];
      r.film.mean(corner, m);
      EXPECT_NEAR(m[0], 1.0, 1e-6) << strategy << " R = " << radius << ": the dome";
      r.film.mean(centre, m);
      r.film.variance_of_mean(centre, v);
      if (strategy == std::string("cosine")) EXPECT_NEAR(m[0], 0.5, 1e-6) << "R = " << radius;
      else EXPECT_NEAR(m[0], 0.5, 3.0 * std::sqrt(v[0]) + 1e-6) << strategy << " R = " << radius;
    }
  }
}

}  // namespace
}  // namespace pdflab
