// Glass's Fresnel term: the book's Schlick approximation, and the exact
// reflectance of unpolarised light that a dielectric material asks for with
// "fresnel": "exact". The exact term against its closed forms (normal
// incidence, total internal reflection, Brewster's angle), Schlick's error
// against it, and the tracers: a glass pane seen at a known angle reflects a
// light in exactly the share of samples the chosen term says, in the packet
// tracer and the one-path tracer alike, bit for bit.
#include "renderer/error.h"
#include "renderer/integrator/integrator.h"
#include "renderer/integrator/packet.h"
#include "renderer/sampling/leaf.h"
#include "renderer/scene/scene_loader.h"

#include "tests/render_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>

namespace pdflab {
namespace {

constexpr double kPiD = 3.14159265358979323846;

// The reflectance at angle of incidence `degrees` for eta = n_incident / n_transmitted.
float exact_at(double degrees, float eta) {
  const float c = static_cast<float>(std::cos(degrees * kPiD / 180.0));
  return leaf::fresnel_dielectric(c, eta, eta * eta * (1.0f - c * c));
}
float schlick_at(double degrees, float eta) {
  return leaf::fresnel_schlick(static_cast<float>(std::cos(degrees * kPiD / 180.0)), eta);
}

TEST(Fresnel, ExactAtNormalIncidenceIsR0) {
  for (const float ior : {1.0f, 1.1f, 1.33f, 1.5f, 2.0f, 2.42f, 4.0f}) {
    const float r0 = ((ior - 1.0f) / (ior + 1.0f)) * ((ior - 1.0f) / (ior + 1.0f));
    // From outside (eta = 1 / ior) and from inside (eta = ior): the same R0.
    EXPECT_NEAR(exact_at(0.0, 1.0f / ior), r0, 1e-6f) << ior;
    EXPECT_NEAR(exact_at(0.0, ior), r0, 1e-6f) << ior;
    EXPECT_NEAR(schlick_at(0.0, 1.0f / ior), r0, 1e-6f) << ior;
  }
  EXPECT_NEAR(exact_at(0.0, 1.0f / 1.5f), 0.04f, 1e-6f);
}

TEST(Fresnel, ExactIsOneBeyondTheCriticalAngleAndRisesToIt) {
  for (const float ior : {1.33f, 1.5f, 2.0f}) {
    const double critical = std::asin(1.0 / ior) * 180.0 / kPiD;  // 41.8 degrees at 1.5
    for (double d = critical + 0.01; d < 90.0; d += 0.5) EXPECT_EQ(exact_at(d, ior), 1.0f) << ior << " at " << d;
    // Below it the reflectance climbs to 1: at 1.5, 0.55 at 41.5 degrees.
    EXPECT_LT(exact_at(critical - 1.0, ior), exact_at(critical - 0.3, ior));
    EXPECT_GT(exact_at(critical - 0.05, ior), 0.6f) << ior;
    EXPECT_LT(exact_at(critical - 0.05, ior), 1.0f) << ior;
  }
  EXPECT_NEAR(exact_at(41.5, 1.5f), 0.5416f, 2e-3f);
  // Grazing from outside: everything is reflected.
  EXPECT_NEAR(exact_at(90.0, 1.0f / 1.5f), 1.0f, 1e-5f);
}

TEST(Fresnel, ExactAtBrewstersAngleIsHalfOfTheSReflectance) {
  // At tan(theta_B) = n the p-polarised reflectance vanishes: F = R_s / 2 with
  // R_s = ((n^2 - 1) / (n^2 + 1))^2 there.
  for (const float ior : {1.33f, 1.5f, 2.0f}) {
    const double brewster = std::atan(ior) * 180.0 / kPiD;
    const double n2 = static_cast<double>(ior) * ior;
    const double rs = ((n2 - 1.0) / (n2 + 1.0)) * ((n2 - 1.0) / (n2 + 1.0));
    EXPECT_NEAR(exact_at(brewster, 1.0f / ior), 0.5 * rs, 1e-5) << ior;
  }
}

// Schlick's error, measured over every tenth of a degree: from outside the
// glass it stays within a few hundredths (largest near grazing: 0.0357 at 85
// degrees for ior 1.5); from inside, the book's Schlick (evaluated at the
// inside angle) misses the rise to total internal reflection entirely.
TEST(Fresnel, SchlickAgreesWithExactWithinAKnownBoundFromOutside) {
  struct Bound {
    float ior;
    double below_45, everywhere;
  };
  // The largest |exact - Schlick| at each index (computed in double, plus a
  // margin for float): below 45 degrees, and over the whole quarter circle.
  const Bound bounds[] = {{1.33f, 0.0054, 0.0600}, {1.5f, 0.0082, 0.0357}, {2.0f, 0.0097, 0.0445}};
  for (const Bound& b : bounds) {
    double worst = 0.0, worst_low = 0.0, worst_at = 0.0;
    for (int t = 0; t <= 900; ++t) {
      const double d = t / 10.0;
      const double e = std::fabs(static_cast<double>(exact_at(d, 1.0f / b.ior)) - schlick_at(d, 1.0f / b.ior));
      if (e > worst) worst = e, worst_at = d;
      if (d <= 45.0) worst_low = std::max(worst_low, e);
    }
    std::printf("[fresnel] ior %.2f from outside: |exact - Schlick| at most %.4f (at %.1f degrees), %.4f up to 45\n",
                static_cast<double>(b.ior), worst, worst_at, worst_low);
    EXPECT_LE(worst, b.everywhere + 5e-4) << b.ior;
    EXPECT_GE(worst, b.everywhere - 2e-3) << b.ior;  // the bound is the real largest error, not a loose one
    EXPECT_LE(worst_low, b.below_45 + 5e-4) << b.ior;
    EXPECT_GT(worst_at, 80.0) << b.ior;
  }
  // Inside ior 1.5 just below the critical angle: exact 0.54, Schlick 0.041.
  EXPECT_NEAR(schlick_at(41.5, 1.5f), 0.041f, 1e-3f);
  EXPECT_GT(exact_at(41.5, 1.5f) - schlick_at(41.5, 1.5f), 0.45f);
}

TEST(Fresnel, SceneFilesNameTheTerm) {
  const auto glass = [](const std::string& fresnel) {
    return std::string(R"({"camera": {"width": 4, "height": 4, "vfov": 40, "lookfrom": [0, 0, 5], "lookat": [0, 0, 0]},
      "materials": {"g": {"type": "dielectric", "ior": 1.5)") +
           fresnel + R"(}},
      "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "g"}]})";
  };
  EXPECT_FALSE(load_scene_text(glass(""), "t").materials[0].exact_fresnel);
  EXPECT_FALSE(load_scene_text(glass(R"(, "fresnel": "schlick")"), "t").materials[0].exact_fresnel);
  EXPECT_TRUE(load_scene_text(glass(R"(, "fresnel": "exact")"), "t").materials[0].exact_fresnel);
  try {
    load_scene_text(glass(R"(, "fresnel": "fast")"), "t");
    ADD_FAILURE() << "an unknown Fresnel term was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("materials.g.fresnel"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("schlick, exact"), std::string::npos) << e.what();
  }
  EXPECT_THROW(load_scene_text(glass(R"(, "fresnel": 1)"), "t"), InputError);
  // Only glass has a Fresnel term to choose.
  EXPECT_THROW(load_scene_text(R"({"camera": {"width": 4, "height": 4, "vfov": 40, "lookfrom": [0, 0, 5], "lookat": [0, 0, 0]},
      "materials": {"m": {"type": "metal", "albedo": [1, 1, 1], "fresnel": "exact"}},
      "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}]})",
                               "t"),
               InputError);
}

// One pixel looking at a glass pane at `degrees` from its normal (from the
// air, or from inside the glass: the pane's back face), a light above that only
// the mirror direction reaches, black below: each sample is 1 (reflected) or 0
// (refracted), so the pixel's mean is the Fresnel reflectance the tracer used.
std::shared_ptr<const Scene> pane(double degrees, bool from_inside, const char* fresnel) {
  const double t = degrees * kPiD / 180.0;
  char text[2048];
  // The pane lies in y = -1; u x v is +y (front, the camera in the air) or -y.
  std::snprintf(text, sizeof text, R"({"camera": {"width": 1, "height": 1, "vfov": 0.01,
      "lookfrom": [0, 0, 0], "lookat": [%.17g, %.17g, 0], "max_depth": 2},
      "materials": {"glass": {"type": "dielectric", "ior": 1.5, "fresnel": "%s"},
                    "sky": {"type": "diffuse_light", "emit": [1, 1, 1], "two_sided": true}},
      "objects": [{"type": "quad", "q": [-1000, -1, -1000], "u": %s, "v": %s, "material": "glass"},
                  {"type": "quad", "q": [-100000, 50, -100000], "u": [200000, 0, 0], "v": [0, 0, 200000], "material": "sky"}]})",
                std::sin(t), -std::cos(t), fresnel, from_inside ? "[2000, 0, 0]" : "[0, 0, 2000]",
                from_inside ? "[0, 0, 2000]" : "[2000, 0, 0]");
  return std::make_shared<const Scene>(load_scene_text(text, "pane"));
}

TEST(Fresnel, TheTracerReflectsInTheShareTheTermSays) {
  struct Case {
    double degrees;
    bool inside;
  };
  // From the air at 60 degrees (exact 0.0892, Schlick 0.0700); from inside
  // the glass at 40 degrees (exact 0.245, Schlick 0.041) and at 45 degrees
  // (total internal reflection: 1 for both).
  const Case cases[] = {{60.0, false}, {40.0, true}, {45.0, true}};
  constexpr std::uint32_t kSpp = 1u << 18;
  for (const Case& c : cases) {
    const float eta = c.inside ? 1.5f : 1.0f / 1.5f;
    for (const char* fresnel : {"schlick", "exact"}) {
      const bool exact = std::strcmp(fresnel, "exact") == 0;
      const auto scene = pane(c.degrees, c.inside, fresnel);
      const Film film = testing::render_to_completion(scene, "cosine", kSpp, 17, 2, std::chrono::seconds(300)).film;
      double mean[3];
      film.mean(0, mean);
      // Beyond the critical angle both reflect every ray (total internal
      // reflection comes before either term).
      const double s = std::sin(c.degrees * kPiD / 180.0) * eta;
      const double schlick = s > 1.0 ? 1.0 : schlick_at(c.degrees, eta);
      const double f = exact ? exact_at(c.degrees, eta) : schlick;
      const double other = exact ? schlick : exact_at(c.degrees, eta);
      const double se = std::sqrt(std::max(f * (1.0 - f), 1e-12) / kSpp);
      std::printf("[fresnel] %s at %.0f degrees from %s: reflected %.5f, %s says %.5f (se %.5f), the other term %.5f\n",
                  fresnel, c.degrees, c.inside ? "inside" : "the air", mean[0], fresnel, f, se, other);
      EXPECT_NEAR(mean[0], f, 5.0 * se + 1e-6) << fresnel << " at " << c.degrees;
      if (std::fabs(other - f) > 1e-3) {
        EXPECT_GT(std::fabs(mean[0] - other), 20.0 * se) << fresnel;
      }
    }
  }
}

// The packet tracer gives the one-path tracer's bits with exact Fresnel, on
// the book's box with its glass sphere switched to the exact term.
TEST(Fresnel, PacketTracerGivesTheOnePathTracersBits) {
  Scene scene = load_scene_file(PDFLAB_SOURCE_DIR "/assets/scenes/cornell_book.json");
  scene.camera.width = 24;
  scene.camera.height = 24;
  int glass = 0;
  for (Material& m : scene.materials)
    if (m.type == MaterialType::Dielectric) m.exact_fresnel = true, ++glass;
  ASSERT_EQ(glass, 1);
  scene.prepare();
  std::size_t samples = 0, nonzero = 0;
  for (const char* text : {"mix:cosine=0.5,light=0.5", "nee-mis", "nee-mis+mix:cosine=0.8,specular-objects=0.2+sobol"}) {
    const SamplingPlan plan = SamplingPlan::make(Strategy::parse(text), scene);
    for (PacketIsa isa : available_packet_isas()) {
      const SampleBlock block{0, 0, 24, 24, 0, 4};
      std::vector<SampleResult> packet(block.size());
      trace_block(isa, scene, plan, 7, block, packet.data());
      std::size_t j = 0, differing = 0;
      for (int y = 0; y < 24; ++y)
        for (int x = 0; x < 24; ++x)
          for (std::uint32_t k = 0; k < block.spp; ++k, ++j) {
            DropCounts drops;
            const Vec3 one = render_pixel_sample(scene, plan, 7, x, y, k, drops);
            differing += std::memcmp(&one, &packet[j].radiance, sizeof one) != 0;
            nonzero += one != Vec3(0.0f);
            ++samples;
          }
      EXPECT_EQ(differing, 0u) << text << ", " << packet_isa_name(isa);
    }
  }
  EXPECT_GT(nonzero, 1000u) << "of " << samples;
}

}  // namespace
}  // namespace pdflab
