// Support tests: every technique in the table, at its parameter's minimum,
// default and maximum, reaches all of its pdf's support from the extreme
// random numbers (u1 = 0 and u1 = 1 - 2^-24, with u1's last cell drawn further
// where the technique draws it: Shading::top_log2 from -24 down to -281). A
// sampler that cannot reach part of the support while its pdf claims it
// converges to the wrong limit, and no statistical test with affordable
// samples sees it (the missing mass was 2^-24); these compare the angles
// themselves.
#include "renderer/integrator/packet.h"
#include "renderer/sampling/mixture.h"
#include "renderer/sampling/rng.h"
#include "renderer/scene/scene_loader.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

namespace pdflab {
namespace {

const Scene& book() {
  static const Scene s = load_scene_file(PDFLAB_SOURCE_DIR "/assets/scenes/cornell_book.json");
  return s;
}

double degrees(double cosine) { return std::acos(std::clamp(cosine, -1.0, 1.0)) * 180.0 / std::numbers::pi; }

// The parameters a technique is tested at: min, default, max (or none).
std::vector<float> parameters(const TechniqueInfo& info) {
  if (info.parameter.empty()) return {0.0f};
  return {info.parameter_min, info.parameter_default, info.parameter_max};
}

SamplingPlan alone(Technique t, float p) {
  Strategy s = Strategy::single(t);
  s.parameters[static_cast<int>(t)] = p;
  return SamplingPlan::make(s, book());
}

const Vec3 kUp(0.0f, 0.0f, 1.0f);
const Vec3 kPoint(278.0f, 1.0f, 278.0f);  // where the book's targets are (the draws ignore it otherwise)

// A direction at `cosine` from the normal +z.
Vec3 at_cosine(double cosine) {
  const double s = std::sqrt(std::max(0.0, 1.0 - cosine * cosine));
  return Vec3(static_cast<float>(s), 0.0f, static_cast<float>(cosine));
}

// The lower edge of the pdf's support about +z: the smallest cos(theta) with
// a positive pdf (the pdf is positive on an interval [edge, 1] for every
// technique that draws about the normal), by bisection in cos, in log2(cos)
// near the horizon.
double support_edge(const SamplingPlan& plan) {
  auto positive = [&](double c) { return plan.pdf(kPoint, kUp, at_cosine(c)) > 0.0f; };
  if (positive(-1.0 + 1e-7)) return -1.0;
  if (positive(0x1.0p-149)) return 0.0;
  double lo = -149.0, hi = 0.0;  // log2(cos): positive at hi, not at lo
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (positive(std::exp2(mid)) ? hi : lo) = mid;
  }
  return std::exp2(hi);
}

// The cosine of a drawn direction with +z, in double: from its part across
// the normal where it is near the normal (float's z has steps of 6e-8 there).
double cosine_of(const Vec3& d) {
  const double x = d.x, y = d.y, z = d.z, n2 = x * x + y * y + z * z;
  if (std::fabs(z) * std::fabs(z) < 0.25 * n2) return z / std::sqrt(n2);
  return std::copysign(std::sqrt(std::max(0.0, 1.0 - (x * x + y * y) / n2)), z);
}

struct Reach {
  double smallest = 2.0, largest = -2.0;  // cos(theta) of the draws with a direction
};

// The cosines the technique draws about +z from the extreme random numbers:
// u1 = 0 and the largest u1, u2 at 0 and its largest, and for a technique that
// draws u1's last cell further, every log2(1 - u1) down to -281 (a fine scan).
Reach reach(const SamplingPlan& plan) {
  Reach r;
  auto take = [&](float u1, float u2, float top_log2) {
    const DirectionSample s = plan.sample_at(kPoint, kUp, u1, u2, 0, 0, nullptr, top_log2);
    if (s.none) return;
    r.smallest = std::min(r.smallest, cosine_of(s.direction));
    r.largest = std::max(r.largest, cosine_of(s.direction));
  };
  for (const float u2 : {0.0f, kLargestUniform}) {
    take(0.0f, u2, -24.0f);
    take(kLargestUniform, u2, -24.0f);
    take(kLargestUniform, u2, -281.0f);
    // The smallest log2(1 - u1) that still gives a direction (the draw is
    // monotonic in it), by bisection between the tail's ends.
    auto drawn = [&](float t) { return !plan.sample_at(kPoint, kUp, kLargestUniform, u2, 0, 0, nullptr, t).none; };
    if (drawn(-24.0f) && !drawn(-281.0f)) {
      float lo = -281.0f, hi = -24.0f;  // none at lo, a direction at hi
      while (std::nextafter(lo, 0.0f) < hi) {
        const float mid = 0.5f * (lo + hi);
        if (mid == lo || mid == hi) break;
        (drawn(mid) ? hi : lo) = mid;
      }
      take(kLargestUniform, u2, hi);
    }
  }
  return r;
}

// The part of the support between its edge and the smallest cosine drawn,
// as a share of what it weighs: of a diffuse surface's cosine-weighted light
// (c^2) above the horizon, of the sphere's solid angle below it.
double unreached_share(double edge, double smallest) {
  if (edge >= 0.0) return smallest * smallest - edge * edge;
  return (smallest - edge) / 2.0;
}

// Cosine's own sampler stops at cos = 2^-12, a sliver of 2^-24 of a diffuse
// surface's light: the standard "reaches the whole support" is held to.
constexpr double kResolution = 0x1.0p-24;

TEST(Support, EveryHemisphereTechniqueReachesItsPdfSupport) {
  std::printf("%-20s %10s %12s %14s %14s %14s\n", "technique", "parameter", "support edge", "smallest cos",
              "largest angle", "smallest angle");
  for (int i = 0; i < kTechniqueCount; ++i) {
    const auto t = static_cast<Technique>(i);
    const TechniqueInfo& info = technique_info(t);
    if (info.draws_target) continue;  // below
    if (t == Technique::EnvironmentMap) continue;  // the map's support, not the hemisphere's: test_chi_square's EnvironmentMap.ReachesBothPoles
    for (const float p : parameters(info)) {
      const SamplingPlan plan = alone(t, p);
      const double edge = support_edge(plan);
      const Reach r = reach(plan);
      std::printf("%-20s %10g %12.6g %14.6g %13.6g° %13.6g°\n", std::string(info.name).c_str(),
                  static_cast<double>(p), edge, r.smallest, degrees(r.smallest), degrees(r.largest));
      // The normal itself (u1 = 0) ...
      EXPECT_EQ(r.largest, 1.0) << info.name << ":" << p;
      // ... down to the support's edge, but for a sliver float cannot resolve.
      const bool within_float = r.smallest - edge <= 2.0 * (std::nextafter(static_cast<float>(edge), 2.0f) - edge);
      EXPECT_TRUE(within_float || unreached_share(edge, r.smallest) <= kResolution * (1.0 + 1e-6))
          << info.name << ":" << p << " reaches cos " << r.smallest << " of a support down to " << edge;
      // And never beyond it: every drawn direction has a positive pdf.
      EXPECT_GE(r.smallest, edge) << info.name << ":" << p;
    }
  }
}

// cosine-power at N = 0, 1, 8, 100, 1000: the smallest cos(theta) drawn is
// the support's declared edge, where cos^N reaches float's smallest normal
// number (what float can represent of the pdf and of the weight f cos / p);
// the plain 24-bit warp stopped at 2^(-24 / (N + 1)). Where that edge is
// further from the horizon than cosine's own reach (N > 10), the technique
// alone says it is biased, and how far it reaches.
TEST(Support, CosinePowerReachesWhatFloatCanRepresent) {
  std::printf("%6s %14s %14s %14s %14s\n", "N", "plain 24-bit", "reached", "declared edge", "cos^N there");
  for (const float n : {0.0f, 1.0f, 8.0f, 100.0f, 1000.0f}) {
    const SamplingPlan plan = alone(Technique::CosinePower, n);
    const Reach r = reach(plan);
    const double edge = support_edge(plan);
    const double declared = plan.constants[static_cast<int>(Technique::CosinePower)].value[0];
    const double plain = std::exp2(-24.0 / (n + 1.0));
    std::printf("%6g %14.6g %14.6g %14.6g %14.6g\n", static_cast<double>(n), plain, r.smallest, declared,
                std::pow(declared, static_cast<double>(n)));
    // The draws reach the declared edge, and the pdf's support is that edge.
    EXPECT_NEAR(r.smallest, declared, 1e-5 * declared + 1e-37) << n;
    EXPECT_NEAR(edge, declared, 1e-6 * declared + 1e-37) << n;
    EXPECT_LT(r.smallest, plain) << n;  // further than the 24-bit warp reached
    // The edge is where float's range ends: cos^N = FLT_MIN (N >= 1), cos = FLT_MIN (N = 0).
    if (n >= 1.0f) EXPECT_NEAR(std::pow(declared, static_cast<double>(n)) / FLT_MIN, 1.0, 1e-4) << n;
    else EXPECT_EQ(declared, static_cast<double>(FLT_MIN));
    const std::string bias = technique_info(Technique::CosinePower).bias_alone(n);
    EXPECT_EQ(bias.empty(), n <= 10.0f) << n << ": " << bias;
  }
  // N <= 10 alone is unbiased (its sliver is at most cosine's), N = 11 says how far it reaches.
  EXPECT_TRUE(Strategy::parse("cosine-power:10").is_unbiased());
  EXPECT_EQ(Strategy::parse("cosine-power:100").bias_reason(),
            "cosine-power:100 reaches only directions within 65.32 degrees of the normal (beyond, cos^N is below "
            "float's range)");
  EXPECT_TRUE(Strategy::parse("mix:cosine=1,cosine-power:1000=1").is_unbiased());
}

// The tail itself: uniform_tail_log2 maps its extreme words to the ends of
// u1's last cell, and its k is geometric.
TEST(Support, TailDrawsTheLastCellWithRelativePrecision) {
  EXPECT_EQ(uniform_tail_log2([] { return 0u; }), -281.0f);  // every bit zero
  EXPECT_NEAR(uniform_tail_log2([] { return 0xffffffffu; }), -24.0f, 1e-6f);
  EXPECT_EQ(uniform_tail_log2([] { return 0x80000000u; }), -24.0f - 1.0f + std::log2(1.5f));
  Rng rng(5, 5);
  int below[4] = {};
  constexpr int kDraws = 1 << 20;
  for (int i = 0; i < kDraws; ++i) {
    const float v = uniform_tail_log2([&] { return rng.next_u32(); });
    ASSERT_LE(v, -24.0f);
    ASSERT_GE(v, -281.0f);
    for (int k = 0; k < 4; ++k) below[k] += v < -24.0f - static_cast<float>(k + 1) ? 1 : 0;
  }
  // P(1 - u1 < 2^-(24 + k) | the last cell) = 2^-k.
  for (int k = 0; k < 4; ++k) {
    const double expected = kDraws * std::exp2(-(k + 1));
    EXPECT_NEAR(below[k], expected, 5.0 * std::sqrt(expected)) << k;
  }
}

// The limit itself, where the missing directions carry the light: a floor of
// albedo 0.5 under a band of light just above its horizon (cos theta in
// [2^-10, 2^-8.5], 0.22 to 0.06 degrees up) and a sky of 1 elsewhere, seen
// by cosine-power:2 alone (unbiased, finite variance) and mixed with
// uniform-cone:85 (which does not reach the band). The plain 24-bit warp
// stopped at cos = 2^-8, above the band: it converged to the sky alone. Every
// draw that reaches the band has u1 = 1 - 2^-24, one draw in 2^24, so a plain
// average would need some 10^9 draws to see it; the estimator's expectation is
// measured instead with u1's last cell as a stratum of its own (probability
// 2^-24, its draws with u1 = 1 - 2^-24 and the tail from the stream, as the
// tracers draw it), the rest as the other: the same limit, within 3 standard
// errors of the exact value, and the undrawn tail (log2(1 - u1) = -24, what
// the 24-bit warp did) caught far outside them.
TEST(Support, CosinePowerSeesLightJustAboveTheHorizon) {
  constexpr double kAlbedo = 0.5, c1 = 0x1.0p-10, c2 = 0.0027621358640099515;  // 2^-10, 2^-8.5
  // The band's radiance: half the floor's light comes from it.
  const double band = 1.0 + 1.0 / (c2 * c2 - c1 * c1);
  const double exact = kAlbedo * (1.0 + (band - 1.0) * (c2 * c2 - c1 * c1));  // rho / pi * E, E = pi sum L c^2
  auto radiance = [&](double cosine) { return cosine >= c1 && cosine < c2 ? band : 1.0; };
  for (const char* text : {"cosine-power:2", "mix:cosine-power:2=0.5,uniform-cone:85=0.5"}) {
    const SamplingPlan plan = SamplingPlan::make(Strategy::parse(text), book());
    struct Mean {
      double sum = 0, sum2 = 0;
      int n = 0;
      void add(double x) { sum += x, sum2 += x * x, ++n; }
      double mean() const { return sum / n; }
      double variance_of_mean() const { return (sum2 / n - mean() * mean()) / (n - 1); }
    };
    // One estimate: the floor's radiance rho / pi * L cos / p from one draw.
    auto estimate = [&](float u1, float u2, std::uint32_t u0, float top_log2) {
      const DirectionSample s = plan.sample_at(kPoint, kUp, u1, u2, u0, 0, nullptr, top_log2);
      if (s.none || !(s.direction.z > 0.0f)) return 0.0;
      return kAlbedo / std::numbers::pi * radiance(s.direction.z) * s.direction.z / s.pdf;
    };
    Rng rng(11, 11);
    Mean rest, last, last_undrawn;
    constexpr int kDraws = 1 << 20;
    for (int i = 0; i < kDraws; ++i) {
      float u1 = rng.uniform();
      while (u1 == kLargestUniform) u1 = rng.uniform();
      rest.add(estimate(u1, rng.uniform(), rng.next_u32(), -24.0f));
      const float u2 = rng.uniform();
      const std::uint32_t u0 = rng.next_u32();
      const float top_log2 = uniform_tail_log2([&] { return rng.next_u32(); });
      last.add(estimate(kLargestUniform, u2, u0, top_log2));
      last_undrawn.add(estimate(kLargestUniform, u2, u0, -24.0f));
    }
    const double p_last = 0x1.0p-24, p_rest = 1.0 - p_last;
    const double value = p_rest * rest.mean() + p_last * last.mean();
    const double se = std::sqrt(p_rest * p_rest * rest.variance_of_mean() + p_last * p_last * last.variance_of_mean());
    const double plain = p_rest * rest.mean() + p_last * last_undrawn.mean();
    std::printf("%s: exact %.6f, drawn tail %.6f +- %.6f (z %.2f), 24-bit warp %.6f (z %.1f)\n", text, exact, value,
                se, (value - exact) / se, plain, (plain - exact) / se);
    EXPECT_LT(std::fabs(value - exact), 3.0 * se) << text;
    EXPECT_GT(std::fabs(plain - exact), 20.0 * se) << text;  // the old limit is caught
  }
}

// The tail's draws give the packet kernel the one-path code's bits, alone and
// in a mixture, over the whole range of log2(1 - u1).
TEST(Support, TailDrawsAreTheSameBitsInPackets) {
  for (const char* text : {"cosine-power:0", "cosine-power:1", "cosine-power", "cosine-power:1000",
                           "mix:cosine=0.5,cosine-power:2=0.5"}) {
    const SamplingPlan plan = SamplingPlan::make(Strategy::parse(text), book());
    std::vector<PlanDraw> in;
    Rng rng(9, 9);
    for (int i = 0; i < 301; ++i) {
      PlanDraw d{kPoint, normalize(Vec3(rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f)),
                 rng.next_u32(), kLargestUniform, rng.uniform(), rng.next_u32()};
      d.top_log2 = -24.0f - 257.0f * static_cast<float>(i) / 300.0f;
      in.push_back(d);
    }
    for (const PacketIsa isa : available_packet_isas()) {
      std::vector<DirectionSample> packet(in.size());
      sample_plan(isa, plan, in.data(), in.size(), packet.data());
      for (std::size_t i = 0; i < in.size(); ++i) {
        const DirectionSample one = plan.sample_at(in[i].point, in[i].normal, in[i].u1, in[i].u2, in[i].u0,
                                                   in[i].u_choice, nullptr, in[i].top_log2);
        ASSERT_EQ(one.none, packet[i].none) << text << " " << i;
        EXPECT_EQ(std::memcmp(&one.direction, &packet[i].direction, sizeof one.direction), 0) << text << " " << i;
        EXPECT_EQ(std::memcmp(&one.pdf, &packet[i].pdf, sizeof one.pdf), 0) << text << " " << i;
      }
    }
  }
}

// The techniques that aim at targets reach every part of each target from
// the extreme u1, u2: a quad's four corners (by area and by solid angle), a
// sphere's whole cone, from its axis to its rim.
TEST(Support, EveryTargetTechniqueReachesItsTargetsOutlines) {
  const Vec3 point(278.0f, 1e-3f, 400.0f), normal(0.0f, 1.0f, 0.0f);
  for (int i = 0; i < kTechniqueCount; ++i) {
    const auto t = static_cast<Technique>(i);
    const TechniqueInfo& info = technique_info(t);
    if (!info.draws_target) continue;
    const SamplingPlan plan = alone(t, info.parameter_default);
    const TargetSet& set = t == Technique::Light             ? plan.book_targets
                           : t == Technique::LightSolidAngle ? plan.power_targets
                                                             : plan.specular_objects;
    ASSERT_FALSE(set.empty()) << info.name;
    const int nq = static_cast<int>(set.quads.size());
    for (int j = 0; j < set.size(); ++j) {
      const std::uint32_t u_target = set.first_choice_of(point, j);
      std::vector<Vec3> drawn;
      for (const float u1 : {0.0f, kLargestUniform})
        for (const float u2 : {0.0f, 0.25f, 0.5f, 0.75f, kLargestUniform}) {
          const DirectionSample s = plan.sample_at(point, normal, u1, u2, 0, u_target);
          if (!s.none) drawn.push_back(s.direction);
        }
      ASSERT_FALSE(drawn.empty()) << info.name << " target " << j;
      // The angle from each point of the outline to the nearest draw.
      auto nearest = [&](const glm::dvec3& to) {
        double best = 4.0;
        for (const Vec3& d : drawn) best = std::min(best, std::acos(std::clamp(glm::dot(glm::normalize(to), glm::dvec3(d)), -1.0, 1.0)));
        return best;
      };
      if (j < nq) {
        const Quad& q = *set.quads[static_cast<std::size_t>(j)].quad;
        const glm::dvec3 o(point), c(q.q), u(q.u), v(q.v);
        for (const glm::dvec3& corner : {c, c + u, c + v, c + u + v}) {
          const double tolerance = 4e-6 * std::max(glm::length(u), glm::length(v)) / glm::length(corner - o) + 2e-6;
          EXPECT_LT(nearest(corner - o), tolerance) << info.name << " quad " << j;
        }
      } else {
        const Sphere& sphere = *set.spheres[static_cast<std::size_t>(j - nq)].sphere;
        const glm::dvec3 axis = glm::dvec3(sphere.center) - glm::dvec3(point);
        const double theta_max = std::asin(sphere.radius / glm::length(axis));
        double smallest = 4.0, largest = 0.0;
        for (const Vec3& d : drawn) {
          const double a = std::acos(std::clamp(glm::dot(glm::normalize(axis), glm::dvec3(d)), -1.0, 1.0));
          smallest = std::min(smallest, a), largest = std::max(largest, a);
        }
        EXPECT_LT(smallest, 1e-3) << info.name << " sphere " << j;  // the axis (float's acos near 0)
        EXPECT_NEAR(largest, theta_max, 1e-5 * theta_max + 1e-6) << info.name << " sphere " << j;
      }
    }
  }
}

}  // namespace
}  // namespace pdflab
