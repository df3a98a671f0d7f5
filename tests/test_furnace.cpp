// White furnace: a convex white lambertian sphere (albedo a) under a uniform
// background B. Every path leaves the sphere after one bounce (it is convex),
// so the exact image is a*B on the sphere and B around it, for every unbiased
// strategy. Comparing per-pixel means with their standard errors catches any
// estimator that is not unbiased: a pdf off by a constant, a mixture weight
// not normalised, a sample whose pdf belongs to another direction.
#include "renderer/film/film.h"
#include "renderer/sampling/leaf.h"
#include "renderer/sampling/rng.h"
#include "renderer/sampling/strategy.h"
#include "renderer/scene/scene.h"
#include "renderer/scene/scene_loader.h"
#include "renderer/session/session.h"
#include "renderer/metrics/statistics.h"

#include "tests/render_support.h"
#include "tests/table_strategies.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

namespace pdflab {
namespace {

constexpr double kAlbedo = 0.8;
// A coloured background, so that a channel mixed up with another shows.
const double kBackground[3] = {1.0, 0.5, 0.25};
constexpr int kSide = 32;
// 4096 samples per pixel: the sample variance then estimates the true one to
// ~2%, so the per-pixel z-scores are as good as normal (a t distribution with
// 4095 degrees of freedom) even at the corrected threshold near z = 5.
constexpr std::uint32_t kSpp = 4096;
// The renderer computes in float: a throughput of albedo * (cos/pi) / pdf is
// exact only up to ~1e-7 relative, the same way in every sample, so it is a
// bias no standard error covers. Differences this small are accepted.
constexpr double kRounding = 1e-6;
constexpr double kFamilyAlpha = 0.01;

// The sphere is its own importance target: `light` from a point on it aims at
// directions into the sphere, or (when rounding puts the point inside) at the
// whole sphere; mixtures with a hemisphere technique stay unbiased either way.
constexpr const char* kSceneJson = R"({
  "name": "white furnace",
  "camera": { "width": 32, "height": 32, "vfov": 30,
              "lookfrom": [0, 0, 6], "lookat": [0, 0, 0], "vup": [0, 1, 0],
              "max_depth": 50, "background": [1.0, 0.5, 0.25] },
  "materials": { "white": { "type": "lambertian", "albedo": [0.8, 0.8, 0.8] } },
  "objects": [ { "type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "white",
                 "importance": true } ]
})";

// These, and every technique of the table alone (where unbiased) and mixed
// with cosine (tests/table_strategies.h).
const std::vector<std::string>& unbiased_strategies() {
  static const std::vector<std::string> s = testing::with_table_strategies(
      {
          "cosine",
          "uniform-hemisphere",
          "uniform-sphere",
          "mix:cosine=0.5,light=0.5",
          "mix:cosine=0.75,light=0.25",
          "mix:uniform-hemisphere=0.5,light=0.5",
          "mix:cosine=0.4,uniform-sphere=0.2,light=0.4",
      },
      [](const testing::TableStrategy& t) { return t.unbiased && !t.needs_environment; });
  return s;
}

std::shared_ptr<const Scene> furnace_scene() {
  static const std::shared_ptr<const Scene> scene =
      std::make_shared<const Scene>(load_scene_text(kSceneJson, "<furnace>"));
  return scene;
}

Film render(const std::string& strategy, std::uint64_t seed) {
  testing::Rendered r =
      testing::render_to_completion(furnace_scene(), strategy, kSpp, seed, 2, std::chrono::seconds(120));
  EXPECT_EQ(r.stats.dropped.total(), 0u);
  return std::move(r.film);
}

enum class Coverage { Sphere, Background, Edge };

// Which pixels lie wholly on the sphere or wholly off it. The directions that
// hit a sphere form a convex cone, so a pixel whose four corner rays all hit it
// lies wholly on it; one whose corner rays all pass more than a pixel's
// footprint (about 0.1 at this distance) outside it lies wholly off it.
Coverage coverage(const Scene& scene, int x, int y) {
  const Sphere& s = scene.spheres[0];
  int hits = 0, clear = 0;
  for (int dy = 0; dy <= 1; ++dy)
    for (int dx = 0; dx <= 1; ++dx) {
      const Ray ray = scene.camera.generate_ray(static_cast<float>(x + dx), static_cast<float>(y + dy));
      const Vec3 f = s.center - ray.origin;
      const float miss_distance = length(cross(f, ray.direction));
      if (miss_distance < 0.999f * s.radius) ++hits;
      if (miss_distance > 1.2f * s.radius) ++clear;
    }
  return hits == 4 ? Coverage::Sphere : clear == 4 ? Coverage::Background : Coverage::Edge;
}

std::size_t pixel_index(int x, int y) { return static_cast<std::size_t>(y) * kSide + static_cast<std::size_t>(x); }

struct FurnaceResult {
  int sphere_pixels = 0, background_pixels = 0;
  double worst_pixel_z = 0.0;     // largest |z| over sphere pixels and channels
  double aggregate_z[3] = {};     // mean over all sphere pixels vs a*B, per channel
  double aggregate_ratio[3] = {}; // that mean / (a*B)
  int background_wrong = 0;       // background pixels not exactly B
  int zero_variance_pixels = 0;
};

FurnaceResult analyse(const Film& film) {
  const Scene& scene = *furnace_scene();
  FurnaceResult r;
  double sum_diff[3] = {}, sum_var[3] = {}, sum_mean[3] = {};
  for (int y = 0; y < kSide; ++y)
    for (int x = 0; x < kSide; ++x) {
      const std::size_t p = pixel_index(x, y);
      double mean[3], var[3];
      film.mean(p, mean);
      film.variance_of_mean(p, var);
      switch (coverage(scene, x, y)) {
        case Coverage::Background:
          ++r.background_pixels;
          // A camera ray that misses returns the background times a throughput of 1: exact.
          for (int c = 0; c < 3; ++c)
            if (std::fabs(mean[c] - kBackground[c]) > 1e-6 || var[c] != 0.0) ++r.background_wrong;
          break;
        case Coverage::Sphere: {
          ++r.sphere_pixels;
          bool all_zero = true;
          for (int c = 0; c < 3; ++c) {
            const double expected = kAlbedo * kBackground[c];
            const double diff = mean[c] - expected;
            const double beyond_rounding = std::max(0.0, std::fabs(diff) - kRounding * expected);
            if (var[c] > 0.0) {
              all_zero = false;
              r.worst_pixel_z = std::max(r.worst_pixel_z, beyond_rounding / std::sqrt(var[c]));
            } else if (beyond_rounding > 0.0) {
              r.worst_pixel_z = INFINITY;  // no variance, yet not the exact answer
            }
            sum_diff[c] += diff;
            sum_var[c] += var[c];
            sum_mean[c] += mean[c];
          }
          if (all_zero) ++r.zero_variance_pixels;
          break;
        }
        case Coverage::Edge: break;
      }
    }
  for (int c = 0; c < 3; ++c) {
    // Pixels use independent random streams: the variances of their means add.
    const double exact = r.sphere_pixels * kAlbedo * kBackground[c];
    const double beyond_rounding = std::copysign(std::max(0.0, std::fabs(sum_diff[c]) - kRounding * exact), sum_diff[c]);
    r.aggregate_z[c] = beyond_rounding == 0.0 ? 0.0 : beyond_rounding / std::sqrt(sum_var[c]);
    r.aggregate_ratio[c] = sum_mean[c] / exact;
  }
  return r;
}

// Per-pixel tests: every sphere pixel, every channel, every strategy.
// Aggregate tests: one per channel and strategy.
int per_pixel_tests() { return 3 * kSide * kSide * static_cast<int>(unbiased_strategies().size()); }
int aggregate_tests() { return 3 * static_cast<int>(unbiased_strategies().size()); }

class Furnace : public ::testing::TestWithParam<int> {};

TEST_P(Furnace, SphereShowsAlbedoTimesBackground) {
  const std::string& strategy = unbiased_strategies()[GetParam()];
  const Film film = render(strategy, 17 + static_cast<std::uint64_t>(GetParam()));
  const FurnaceResult r = analyse(film);
  // Sidak over at most every pixel (an upper bound on the sphere pixels: conservative).
  const double z_pixel = stats::normal_two_sided_quantile(stats::sidak_alpha(kFamilyAlpha, per_pixel_tests()));
  const double z_total = stats::normal_two_sided_quantile(stats::sidak_alpha(kFamilyAlpha, aggregate_tests()));
  std::printf("[furnace] %-45s worst pixel |z| %.2f (limit %.2f); aggregate z %+.2f %+.2f %+.2f (limit %.2f), "
              "ratio %.5f; %d/%d sphere/background pixels\n",
              strategy.c_str(), r.worst_pixel_z, z_pixel, r.aggregate_z[0], r.aggregate_z[1], r.aggregate_z[2],
              z_total, r.aggregate_ratio[0], r.sphere_pixels, r.background_pixels);
  ASSERT_GT(r.sphere_pixels, 150);
  ASSERT_GT(r.background_pixels, 300);
  EXPECT_EQ(r.background_wrong, 0) << "background pixels must be exactly B";
  EXPECT_LT(r.worst_pixel_z, z_pixel);
  for (int c = 0; c < 3; ++c) EXPECT_LT(std::fabs(r.aggregate_z[c]), z_total) << "channel " << c;
  if (strategy != "cosine") {
    // Only cosine sampling cancels the integrand exactly; every other
    // strategy must show noise, or the per-pixel z-tests above were vacuous.
    EXPECT_EQ(r.zero_variance_pixels, 0);
  }
}

INSTANTIATE_TEST_SUITE_P(Strategies, Furnace, ::testing::Range(0, static_cast<int>(unbiased_strategies().size())),
                         [](const ::testing::TestParamInfo<int>& param_info) {
                           std::string name = unbiased_strategies()[param_info.param];
                           for (char& ch : name)
                             if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           return name;
                         });

// Cosine sampling makes albedo * (cos/pi) / pdf = albedo for every sample: the
// estimate is a*B with zero variance, up to float rounding (the cosine is
// recomputed from the world-space direction, ~1e-7 relative).
TEST(FurnaceCosine, ExactWithZeroVariance) {
  const Film film = render("cosine", 5);
  const Scene& scene = *furnace_scene();
  int checked = 0;
  for (int y = 0; y < kSide; ++y)
    for (int x = 0; x < kSide; ++x) {
      if (coverage(scene, x, y) != Coverage::Sphere) continue;
      const std::size_t p = pixel_index(x, y);
      double mean[3], var[3];
      film.mean(p, mean);
      film.variance_of_mean(p, var);
      for (int c = 0; c < 3; ++c) {
        const double expected = kAlbedo * kBackground[c];
        EXPECT_NEAR(mean[c], expected, kRounding * expected) << x << "," << y;
        EXPECT_LT(std::sqrt(var[c]), kRounding * expected) << x << "," << y;
      }
      ++checked;
    }
  EXPECT_GT(checked, 150);
}

// The furnace test can fail: pure `light` aims only at the sphere itself, i.e.
// (mostly) into it, so it misses the background light a diffuse point sees.
// Its image must be measurably darker than a*B.
TEST(FurnaceLight, PureLightIsBiasedDark) {
  const Film film = render("light", 3);
  const FurnaceResult r = analyse(film);
  const double z_total = stats::normal_two_sided_quantile(stats::sidak_alpha(kFamilyAlpha, aggregate_tests()));
  std::printf("[furnace] light: aggregate z %+.2f, ratio %.4f\n", r.aggregate_z[0], r.aggregate_ratio[0]);
  for (int c = 0; c < 3; ++c) {
    EXPECT_LT(r.aggregate_z[c], -z_total) << "channel " << c;
    EXPECT_LT(r.aggregate_ratio[c], 0.9) << "channel " << c;
  }
}

// ---- The microfacet conductor's furnaces ------------------------------------------

const float kAlphas[] = {1e-3f, 1e-2f, 0.05f, 0.2f, 0.5f, 1.0f};
const float kViewDegrees[] = {0.0f, 45.0f, 75.0f, 89.0f};

Vec3 view_at(float degrees) {
  const double t = degrees * 3.14159265358979323846 / 180.0;
  return {static_cast<float>(std::sin(t)), 0.0f, static_cast<float>(std::cos(t))};
}

// Heitz's weak white furnace: the masked distribution of visible normals,
// G1(wo) D(m) max(0, wo . m) / cos(theta_o), integrates to one over the
// normals for every alpha and view. Integrated deterministically in slope
// space, t = tan(theta_m) / alpha (where D dω is t sqrt(1 + alpha^2 t^2) /
// (pi (1 + t^2)^2) dt dphi whatever alpha), with leaf::ggx_d and
// leaf::ggx_lambda evaluated at each node: the library's own D and G1.
TEST(MicrofacetFurnace, WeakWhiteFurnaceIntegratesToOne) {
  constexpr int kT = 4000, kPhi = 512;
  const double pi = 3.14159265358979323846;
  for (const float alpha : kAlphas)
    for (const float view : kViewDegrees) {
      const Vec3 wo = view_at(view);
      const double g1 = 1.0 / (1.0 + leaf::ggx_lambda(wo, alpha));
      double sum = 0.0;
      for (int i = 0; i < kT; ++i) {
        // t = x / (1 - x), x in [0, 1): dt = dx / (1 - x)^2.
        const double x = (i + 0.5) / kT, t = x / (1.0 - x), dt = 1.0 / kT / ((1.0 - x) * (1.0 - x));
        const double theta = std::atan(alpha * t);
        for (int j = 0; j < kPhi; ++j) {
          const double phi = 2.0 * pi * (j + 0.5) / kPhi;
          const Vec3 m(static_cast<float>(std::sin(theta) * std::cos(phi)),
                       static_cast<float>(std::sin(theta) * std::sin(phi)), static_cast<float>(std::cos(theta)));
          // D dω in (t, phi): D(m) sin(theta) dtheta/dt.
          const double dtheta_dt = alpha / (1.0 + alpha * alpha * t * t);
          const double d_omega = leaf::ggx_d(m, alpha) * std::sin(theta) * dtheta_dt;
          const double visible = std::max(0.0, static_cast<double>(dot(wo, m))) / wo.z;
          sum += g1 * d_omega * visible * dt * (2.0 * pi / kPhi);
        }
      }
      EXPECT_NEAR(sum, 1.0, 2e-3) << "alpha " << alpha << ", view " << view << " degrees";
    }
}

// The full BSDF's albedo, f cos over the hemisphere, estimated by Monte
// Carlo with the VNDF sampler, is at most one (a perfect conductor, F = 1,
// loses only what the height-correlated G2 shadows) and below the perfect
// conductor's for aluminium; cross-checked against cosine sampling where
// that has the variance to tell (alpha >= 0.2).
TEST(MicrofacetFurnace, EnergyAtMostOne) {
  constexpr int kN = 200'000;
  const Vec3 white_eta(1.0f), white_k(1e4f);  // F = 1 to 1e-4
  const Vec3 al_eta(1.657f, 0.880f, 0.521f), al_k(9.224f, 6.270f, 4.837f);
  for (const float alpha : kAlphas)
    for (const float view : kViewDegrees) {
      const Vec3 wo = view_at(view);
      Rng rng(77, 5);
      double sum = 0.0, sum2 = 0.0, al = 0.0, cosine = 0.0, cosine2 = 0.0;
      for (int i = 0; i < kN; ++i) {
        const float u1 = rng.uniform(), u2 = rng.uniform();
        float s, c;
        sincos_2pi(u2, s, c);
        const Vec3 m = leaf::sample_vndf_normal(wo, alpha, u1, s, c);
        const Vec3 wi = leaf::reflect(-wo, m);
        const float pdf = leaf::vndf_reflection_pdf(wo, m, alpha);
        ASSERT_TRUE(pdf > 0.0f && std::isfinite(pdf)) << "alpha " << alpha << " view " << view;
        const double w = leaf::microfacet_value(wo, wi, alpha, white_eta, white_k).x / pdf;
        sum += w;
        sum2 += w * w;
        al += leaf::microfacet_value(wo, wi, alpha, al_eta, al_k).y / pdf;
        // The same integral by the cosine lobe.
        const float v1 = rng.uniform(), v2 = rng.uniform();
        sincos_2pi(v2, s, c);
        const Vec3 d = leaf::cosine_hemisphere_local(v1, s, c);
        const double wc = d.z > 0.0f ? leaf::microfacet_value(wo, d, alpha, white_eta, white_k).x /
                                           leaf::cosine_hemisphere_density(d.z)
                                     : 0.0;
        cosine += wc;
        cosine2 += wc * wc;
      }
      const double mean = sum / kN, se = std::sqrt(std::max(0.0, sum2 / kN - mean * mean) / kN);
      EXPECT_LE(mean, 1.0 + 4.0 * se + 1e-6) << "alpha " << alpha << ", view " << view;
      EXPECT_GT(mean, 0.3) << "alpha " << alpha << ", view " << view;
      EXPECT_LE(al / kN, mean) << "alpha " << alpha << ", view " << view;
      // Smooth enough, the conductor loses almost nothing to shadowing.
      if (alpha <= 0.05f && view <= 45.0f) {
        EXPECT_GT(mean, 0.97) << "alpha " << alpha << ", view " << view;
      }
      if (alpha >= 0.2f) {
        const double cm = cosine / kN, cse = std::sqrt(std::max(0.0, cosine2 / kN - cm * cm) / kN);
        EXPECT_NEAR(mean, cm, 5.0 * std::hypot(se, cse)) << "alpha " << alpha << ", view " << view;
      }
    }
}

// The rough dielectric (frosted glass), from outside (eta 1.5) and from
// inside (eta 1 / 1.5, total internal reflection past 41.8 degrees): its
// albedo, f |cos| over the whole sphere, estimated with its own sampler, is
// at most one; the reflected part and the transmitted part each agree with
// the same integrals by uniform sampling of the sphere where the lobes are
// wide enough for that; and near alpha 0 they are the smooth interface's
// exact Fresnel R and 1 - R (no 1 / eta^2: the book's glass convention).
TEST(RoughDielectricFurnace, EnergyAtMostOneAndSmoothLimit) {
  constexpr int kN = 100'000;
  const float etas[] = {1.5f, 1.0f / 1.5f};
  for (const float eta : etas)
    for (const float alpha : kAlphas)
      for (const float view : kViewDegrees) {
        const Vec3 wo = view_at(view);
        Rng rng(91, 7);
        double sum = 0.0, sum2 = 0.0, reflected = 0.0, uniform_r = 0.0, uniform_t = 0.0, ur2 = 0.0, ut2 = 0.0;
        for (int i = 0; i < kN; ++i) {
          const float u1 = rng.uniform(), u2 = rng.uniform(), u3 = rng.uniform();
          float s, c;
          sincos_2pi(u2, s, c);
          float pdf;
          const Vec3 wi = leaf::rough_dielectric_sample(wo, alpha, eta, u1, s, c, u3, pdf);
          ASSERT_TRUE(pdf > 0.0f && std::isfinite(pdf)) << "eta " << eta << " alpha " << alpha << " view " << view;
          const double w = leaf::rough_dielectric_value(wo, wi, alpha, eta) / pdf;
          sum += w;
          sum2 += w * w;
          if (wi.z > 0.0f) reflected += w;
          // The same integrals by uniform directions over the sphere.
          const float v1 = rng.uniform(), v2 = rng.uniform();
          sincos_2pi(v2, s, c);
          const Vec3 d = leaf::uniform_sphere_direction(v1, s, c);
          const double wu = leaf::rough_dielectric_value(wo, d, alpha, eta) * (4.0 * 3.14159265358979323846);
          (d.z > 0.0f ? uniform_r : uniform_t) += wu;
          (d.z > 0.0f ? ur2 : ut2) += wu * wu;
        }
        SCOPED_TRACE("eta " + std::to_string(eta) + ", alpha " + std::to_string(alpha) + ", view " +
                     std::to_string(view));
        const double mean = sum / kN, se = std::sqrt(std::max(0.0, sum2 / kN - mean * mean) / kN);
        EXPECT_LE(mean, 1.0 + 4.0 * se + 1e-6);
        EXPECT_GT(mean, 0.3);
        const double r = reflected / kN, t = mean - r;
        if (alpha >= 0.2f && view <= 75.0f) {
          const double mr = uniform_r / kN, mt = uniform_t / kN;
          const double sr = std::sqrt(std::max(0.0, ur2 / kN - mr * mr) / kN),
                       st = std::sqrt(std::max(0.0, ut2 / kN - mt * mt) / kN);
          // The sampler's split has its own noise: at most that of the total.
          EXPECT_NEAR(r, mr, 5.0 * std::hypot(sr, se));
          EXPECT_NEAR(t, mt, 5.0 * std::hypot(st, se));
        }
        if (alpha <= 1e-3f && view <= 75.0f) {
          const float cos_o = wo.z, ratio = 1.0f / eta;
          const float fresnel =
              leaf::fresnel_dielectric(cos_o, ratio, ratio * ratio * (1.0f - cos_o * cos_o));
          EXPECT_NEAR(r, fresnel, 0.01);
          EXPECT_NEAR(t, 1.0 - fresnel, 0.01);
        }
      }
}

// Reciprocity across the interface: with f = value / |cos_i|, the rough
// dielectric's f(wo, wi) = f(wi, wo) for a reflection and eta^2 f(wi, wo) for a
// refraction (the adjoint of the radiance BTDF, which divides by eta^2), seen
// from wi's side with the surface turned over (z negated, eta inverted).
TEST(RoughDielectricFurnace, Reciprocity) {
  Rng rng(5, 11);
  int refractions = 0, reflections = 0;
  for (const float eta : {1.5f, 1.0f / 1.33f})
    for (const float alpha : {0.05f, 0.3f, 1.0f})
      for (int i = 0; i < 4000; ++i) {
        float s, c;
        sincos_2pi(rng.uniform(), s, c);
        Vec3 wo = leaf::uniform_sphere_direction(rng.uniform(), s, c);
        wo.z = std::fabs(wo.z);
        sincos_2pi(rng.uniform(), s, c);
        const Vec3 wi = leaf::uniform_sphere_direction(rng.uniform(), s, c);
        if (wo.z < 0.05f || std::fabs(wi.z) < 0.05f) continue;
        const double forward = leaf::rough_dielectric_value(wo, wi, alpha, eta) / std::fabs(wi.z);
        const bool refracts = wi.z < 0.0f;
        const Vec3 back_wo = refracts ? Vec3(wi.x, wi.y, -wi.z) : wi;
        const Vec3 back_wi = refracts ? Vec3(wo.x, wo.y, -wo.z) : wo;
        const float back_eta = refracts ? 1.0f / eta : eta;
        const double backward = leaf::rough_dielectric_value(back_wo, back_wi, alpha, back_eta) / wo.z;
        const double expected = refracts ? eta * eta * backward : backward;
        if (forward < 1e-4 && expected < 1e-4) continue;
        (refracts ? refractions : reflections) += 1;
        // (plus float's rounding near the critical angle, where 1 - F is all that is left)
        EXPECT_NEAR(forward, expected, 2e-3 * std::max(forward, expected) + 3e-6)
            << "eta " << eta << " alpha " << alpha << " wo " << wo.x << "," << wo.y << "," << wo.z << " wi " << wi.x
            << "," << wi.y << "," << wi.z;
      }
  EXPECT_GT(refractions, 1000);
  EXPECT_GT(reflections, 1000);
}

}  // namespace
}  // namespace pdflab
