// The technique table and the leaf math, checked exactly and fast (no
// statistics; these also run under the sanitizers): every technique's sample
// agrees with its own pdf, the warps invert back to their random numbers, the
// packet kernel draws the one-path code's bits, and the table is what the
// parser and its messages know.
#include "renderer/error.h"
#include "renderer/integrator/packet.h"
#include "renderer/sampling/mixture.h"
#include "renderer/sampling/rng.h"
#include "renderer/scene/environment.h"
#include "renderer/scene/scene_loader.h"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <memory>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace pdflab {
namespace {

// The book's box, with the shipped sky as its environment so that the
// environment technique has a map to draw from.
const Scene& book() {
  static const Scene s = [] {
    Scene scene = load_scene_file(std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes/cornell_book.json");
    int w = 0, h = 0;
    std::vector<float> rgb =
        read_environment_image(std::string(PDFLAB_SOURCE_DIR) + "/assets/environments/sun_sky.hdr", w, h);
    scene.environment = std::make_shared<Environment>(std::move(rgb), w, h, 1.0f, 40.0f);
    return scene;
  }();
  return s;
}

// Each technique alone and mixed half and half with another.
std::vector<Strategy> strategies() {
  std::vector<Strategy> out;
  for (int i = 0; i < kTechniqueCount; ++i) {
    const std::string name(technique_info(static_cast<Technique>(i)).name);
    out.push_back(Strategy::parse(name));
    out.push_back(Strategy::parse("mix:" + std::string(name == "cosine" ? "light" : "cosine") + "=0.5," + name + "=0.5"));
  }
  return out;
}

// Shading points inside the book's box with random normals, and draws.
std::vector<PlanDraw> draws(std::size_t n, std::uint64_t seed) {
  Rng rng(seed, 7);
  std::vector<PlanDraw> out(n);
  for (PlanDraw& d : out) {
    d.point = Vec3(555.0f * rng.uniform(), 555.0f * rng.uniform(), 555.0f * rng.uniform());
    d.normal = normalize(Vec3(rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f));
    d.u0 = rng.next_u32(), d.u1 = rng.uniform(), d.u2 = rng.uniform(), d.u_choice = rng.next_u32();
  }
  return out;
}

bool same_bits(const DirectionSample& a, const DirectionSample& b) {
  return std::memcmp(&a.direction, &b.direction, sizeof a.direction) == 0 &&
         std::memcmp(&a.pdf, &b.pdf, sizeof a.pdf) == 0 && a.none == b.none;
}

DirectionSample one_path(const SamplingPlan& plan, const PlanDraw& d) {
  const int chosen = leaf::choose_technique(plan, static_cast<std::int32_t>(d.u0));
  const leaf::Shading at(plan, d.point, d.normal, d.u1, d.u2, static_cast<std::int32_t>(d.u_choice));
  return to_direction_sample(leaf::sample_mixture(plan, at, chosen, true));
}

TEST(Techniques, PacketDrawsTheOnePathBits) {
  const std::vector<PlanDraw> in = draws(203, 1);  // not a multiple of the lanes
  for (const Strategy& strategy : strategies()) {
    const SamplingPlan plan = SamplingPlan::make(strategy, book());
    for (const PacketIsa isa : available_packet_isas()) {
      std::vector<DirectionSample> packet(in.size());
      sample_plan(isa, plan, in.data(), in.size(), packet.data());
      std::vector<Vec3> directions;
      for (const DirectionSample& s : packet) directions.push_back(s.direction);
      std::vector<float> pdf(in.size());
      plan_pdf(isa, plan, in.data(), directions.data(), in.size(), pdf.data());
      int differing = 0, pdf_differing = 0;
      for (std::size_t i = 0; i < in.size(); ++i) {
        differing += !same_bits(one_path(plan, in[i]), packet[i]);
        const float scalar_pdf = plan.pdf(in[i].point, in[i].normal, directions[i]);
        pdf_differing += std::memcmp(&scalar_pdf, &pdf[i], sizeof scalar_pdf) != 0;
      }
      EXPECT_EQ(differing, 0) << strategy.to_string() << " with " << packet_isa_name(isa);
      EXPECT_EQ(pdf_differing, 0) << strategy.to_string() << " with " << packet_isa_name(isa);
    }
  }
}

// sample then pdf: the density a technique reports for its own sample is its
// pdf at that direction (up to float rounding of two formulas for one value).
TEST(Techniques, SampleAgreesWithPdf) {
  const std::vector<PlanDraw> in = draws(2000, 2);
  for (const Strategy& strategy : strategies()) {
    const SamplingPlan plan = SamplingPlan::make(strategy, book());
    int checked = 0;
    for (const PlanDraw& d : in) {
      const DirectionSample s = one_path(plan, d);
      if (s.none) continue;
      ASSERT_GT(s.pdf, 0.0f) << strategy.to_string();
      const float p = plan.pdf(d.point, d.normal, s.direction);
      // The light's targets: a sample on a target's very edge may miss it on re-intersection.
      if (p == 0.0f && !strategy.is_unbiased()) continue;
      EXPECT_NEAR(p, s.pdf, 2e-4f * s.pdf) << strategy.to_string();
      ++checked;
    }
    EXPECT_GT(checked, 1000) << strategy.to_string();
  }
}

// The warps' inverses: the random numbers come back from the direction.
TEST(Techniques, HemisphereWarpsInvert) {
  Rng rng(3, 3);
  for (int i = 0; i < 10000; ++i) {
    const float u1 = rng.uniform(), u2 = rng.uniform();
    float s, c;
    leaf::sincos_2pi(u2, s, c);
    auto azimuth = [](const Vec3& v) {
      const double phi = std::atan2(static_cast<double>(v.y), static_cast<double>(v.x)) / (2.0 * std::numbers::pi);
      return phi < 0.0 ? phi + 1.0 : phi;
    };
    auto same_azimuth = [&](const Vec3& v) {
      const double d = std::fabs(azimuth(v) - u2);
      return std::min(d, 1.0 - d) < 2e-5 || std::hypot(v.x, v.y) < 1e-3f;
    };
    const Vec3 cosine = leaf::cosine_hemisphere_local(u1, s, c);
    EXPECT_NEAR(cosine.x * cosine.x + cosine.y * cosine.y, u1, 2e-6f);
    EXPECT_TRUE(same_azimuth(cosine)) << u2;
    const Vec3 hemisphere = leaf::uniform_hemisphere_local(u1, s, c);
    EXPECT_NEAR(1.0f - hemisphere.z, u1, 1e-6f);
    EXPECT_TRUE(same_azimuth(hemisphere)) << u2;
    const Vec3 sphere = leaf::uniform_sphere_direction(u1, s, c);
    EXPECT_NEAR((1.0f - sphere.z) * 0.5f, u1, 1e-6f);
    EXPECT_TRUE(same_azimuth(sphere)) << u2;
  }
}

TEST(Techniques, CosinePowerInvertsAndMatchesItsNeighbours) {
  // N = 0 is the uniform hemisphere's density, N = 1 the cosine lobe's.
  for (const float c : {0.01f, 0.3f, 0.7f, 1.0f}) {
    EXPECT_NEAR(leaf::CosinePower::density(0.0f, c), leaf::uniform_hemisphere_density(c), 1e-7f);
    EXPECT_NEAR(leaf::CosinePower::density(1.0f, c), leaf::cosine_hemisphere_density(c), 1e-7f);
  }
  EXPECT_EQ(leaf::CosinePower::density(8.0f, -0.1f), 0.0f);
  const Scene& scene = book();
  for (const float n : {0.0f, 1.0f, 8.0f, 100.0f}) {
    Strategy strategy = Strategy::parse("cosine-power");
    strategy.parameters[static_cast<int>(Technique::CosinePower)] = n;
    const SamplingPlan plan = SamplingPlan::make(strategy, scene);
    Rng rng(4, 4);
    for (int i = 0; i < 2000; ++i) {
      const float u1 = rng.uniform();
      const leaf::Shading at(plan, Vec3(0.0f), Vec3(0, 0, 1), u1, rng.uniform(), 0.0f);
      const leaf::Sampled s = leaf::CosinePower::sample(plan, at, true);
      // cos = (1 - u1)^(1 / (N + 1)) inverts to u1 = 1 - cos^(N + 1).
      EXPECT_NEAR(1.0f - std::pow(s.direction.z, n + 1.0f), u1, 3e-5f) << n;
      EXPECT_GT(s.direction.z, 0.0f);
      EXPECT_NEAR(length(s.direction), 1.0f, 1e-5f);
    }
  }
}

// The table is what the parser knows and what its messages list.
TEST(Techniques, TableDrivesParserAndMessages) {
  std::string unknown_message;
  try {
    (void)Strategy::parse("no-such-technique");
  } catch (const InputError& e) {
    unknown_message = e.what();
  }
  for (int i = 0; i < kTechniqueCount; ++i) {
    const auto t = static_cast<Technique>(i);
    const TechniqueInfo& info = technique_info(t);
    const Strategy s = Strategy::parse(info.name);
    EXPECT_EQ(s.weights[i], 1.0f) << info.name;
    EXPECT_EQ(Strategy::parse(s.to_string()), s) << info.name;
    // Alone, biased exactly where the row gives a reason, and the strategy's
    // reason names the technique with it.
    const std::string reason = info.bias_alone(info.parameter_default);
    EXPECT_EQ(s.is_unbiased(), reason.empty()) << info.name;
    EXPECT_EQ(s.bias_reason().empty(), reason.empty()) << info.name;
    if (!reason.empty()) {
      EXPECT_NE(s.bias_reason().find(std::string(info.name)), std::string::npos) << s.bias_reason();
      EXPECT_NE(s.bias_reason().find(reason), std::string::npos) << s.bias_reason();
      EXPECT_NE(strategy_help().find(reason), std::string::npos) << info.name;
    }
    // Mixed with cosine, which covers the hemisphere, every technique is unbiased.
    if (t != Technique::Cosine) {
      const Strategy mixed = Strategy::parse("mix:cosine=1," + std::string(info.name) + "=1");
      EXPECT_TRUE(mixed.is_unbiased()) << info.name;
      EXPECT_TRUE(mixed.bias_reason().empty()) << mixed.bias_reason();
    }
    EXPECT_NE(unknown_message.find(std::string(info.name)), std::string::npos) << info.name;
    EXPECT_NE(strategy_help().find(std::string(info.name)), std::string::npos) << info.name;
    EXPECT_FALSE(info.draws.empty());
    if (info.parameter.empty()) {
      EXPECT_THROW((void)Strategy::parse(std::string(info.name) + ":2"), InputError) << info.name;
    }
  }
  const Strategy p = Strategy::parse("mix:cosine-power:20=1,light=1");
  EXPECT_EQ(p.parameters[static_cast<int>(Technique::CosinePower)], 20.0f);
  EXPECT_EQ(Strategy::parse(p.to_string()).to_string(), p.to_string());
  EXPECT_THROW((void)Strategy::parse("cosine-power:-1"), InputError);
  EXPECT_THROW((void)Strategy::parse("cosine-power:1e9"), InputError);
  EXPECT_THROW((void)Strategy::parse("cosine-power:"), InputError);
}

// A technique's bias can depend on its parameter: uniform-cone covers the
// hemisphere at 90 degrees alone, and the reason it gives below says how far
// it reaches, in --help, in the strategy's reason and in `reference`'s refusal.
TEST(Techniques, BiasFollowsTheParameter) {
  EXPECT_TRUE(Strategy::parse("uniform-cone:90").is_unbiased());
  EXPECT_TRUE(Strategy::parse("uniform-cone:90").bias_reason().empty());
  const Strategy narrow = Strategy::parse("uniform-cone:45");
  EXPECT_FALSE(narrow.is_unbiased());
  EXPECT_EQ(narrow.bias_reason(), "uniform-cone:45 reaches only directions within 45 degrees of the normal");
  EXPECT_NE(strategy_help().find("uniform-cone[:ANGLE]"), std::string::npos);
  EXPECT_NE(strategy_help().find("(biased alone: it reaches only directions within 30 degrees of the normal; "
                                 "unbiased at ANGLE = 90)"),
            std::string::npos)
      << strategy_help();
  const Strategy both = Strategy::parse("mix:light=1,uniform-cone:10=1");
  EXPECT_EQ(both.bias_reason(),
            "light sees only its targets, uniform-cone:10 reaches only directions within 10 degrees of the normal");
  EXPECT_EQ(Strategy::parse("nee-mis+light").bias_reason(), "its continuation misses light: light sees only its targets");
  EXPECT_TRUE(Strategy::parse("nee-mis+mix:light=1,uniform-cone:90=1").is_unbiased());
}

// The README's grammar line and technique table are the table's own
// (technique_grammar, technique_table_markdown), and its "Where is X" table
// has a row for every technique naming files that exist: a new technique is
// in the README, or this test says what to paste there.
TEST(Techniques, ReadmeHoldsTheTable) {
  std::ifstream in(std::string(PDFLAB_SOURCE_DIR) + "/README.md");
  ASSERT_TRUE(in) << "README.md";
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string readme = buffer.str();
  EXPECT_NE(readme.find(technique_grammar() + "\n"), std::string::npos) << "the grammar line should read\n"
                                                                       << technique_grammar();
  const std::string begin = "<!-- the technique table: ", end = "<!-- end of the technique table -->";
  const std::size_t b = readme.find(begin), e = readme.find(end);
  ASSERT_NE(b, std::string::npos);
  ASSERT_NE(e, std::string::npos);
  const std::size_t first_row = readme.find('\n', b) + 1;
  EXPECT_EQ(readme.substr(first_row, e - first_row), technique_table_markdown())
      << "README.md's technique table should read\n" << technique_table_markdown();
  const std::size_t where = readme.find("### Where is X");
  ASSERT_NE(where, std::string::npos);
  const std::string section = readme.substr(where, readme.find("\n### ", where + 1) - where);
  for (int i = 0; i < kTechniqueCount; ++i) {
    const std::string row = "\n| `" + std::string(technique_info(static_cast<Technique>(i)).name) + "` | `";
    const std::size_t at = section.find(row);
    ASSERT_NE(at, std::string::npos) << "no row in \"Where is X\" for " << technique_info(static_cast<Technique>(i)).name;
    const std::size_t path = at + row.size(), path_end = section.find('`', path);
    EXPECT_TRUE(std::filesystem::exists(std::string(PDFLAB_SOURCE_DIR) + "/" + section.substr(path, path_end - path)))
        << section.substr(path, path_end - path);
  }
}

}  // namespace
}  // namespace pdflab
