// The packet tracer (four, eight or sixteen paths per SIMD step) against the
// one-path tracer: both are the path tracer of renderer/integrator/path.inc,
// on SIMD lanes and on plain scalars, so the same samples must give the same
// bits, for every shipped scene and every strategy, with every instruction set.
#include "renderer/error.h"
#include "renderer/integrator/integrator.h"
#include "renderer/integrator/packet.h"
#include "renderer/scene/object_room.h"
#include "renderer/scene/scene_loader.h"
#include "tests/table_strategies.h"

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <iterator>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

namespace pdflab {
namespace {

const char* const kScenes[] = {"cornell_book.json", "small_light.json",  "large_light.json",      "two_lights.json",
                               "far_light.json",    "glossy_metal.json", "cornell_aluminium.json",
                               "veach_mis.json",    "starved_light.json", "sun_sky.json",
                               "frosted_glass.json"};
// The strategies of the options and their combinations; every technique of
// the table, alone and mixed with cosine, is added (tests/table_strategies.h).
const char* const kStrategies[] = {"mix:cosine=0.5,light=0.5",
                                   "mix:cosine=0.3,light-sa=0.7",
                                   "mix:light=1,light-sa=1",
                                   "nee-mis",
                                   "nee-mis:balance",
                                   "mix:cosine=1,uniform-hemisphere=1,uniform-sphere=1,light=2,light-sa=1",
                                   "mix:cosine=0.5,light=0.5+rr",
                                   "cosine+rr:1",
                                   "nee-mis+rr",
                                   "nee-mis+mix:cosine=0.5,light=0.5",
                                   "nee-mis+bsdf",
                                   "nee-mis:balance+mix:bsdf=0.5,light-sa=0.5+rr:2",
                                   "nee-mis:balance+mix:cosine=0.3,light-sa=0.7+rr:2",
                                   "nee-mis+mix:uniform-sphere=0.5,light=0.5",
                                   "fastest",
                                   "mix:cosine=0.5,light=0.5+sobol",
                                   "nee-mis+sobol",
                                   "nee-mis+mix:cosine=0.5,light=0.5+sobol+rr:1",
                                   "light-sa+sobol",
                                   "mix:cosine=0.6,specular-objects=0.4",
                                   "nee-mis+mix:cosine=0.8,specular-objects=0.2+sobol+rr:3",
                                   "nee-mis+mix:cosine=0.4,light=0.3,specular-objects=0.3",
                                   "nee-mis+lights:tree"};

Scene small_scene(const std::string& file, int width, int height) {
  Scene scene = load_scene_file(std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes/" + file);
  scene.camera.width = width;
  scene.camera.height = height;
  scene.prepare();
  return scene;
}

bool same_bits(const Vec3& a, const Vec3& b) { return std::memcmp(&a, &b, sizeof a) == 0; }

std::uint8_t drop_bits(const DropCounts& d) {
  std::uint8_t bits = 0;
  for (int r = 0; r < kDropReasonCount; ++r)
    if (d.by_reason[r]) bits |= static_cast<std::uint8_t>(1u << r);
  return bits;
}

struct Comparison {
  std::size_t samples = 0, differing = 0, nonzero = 0;
  std::string first_difference;
};

// Every sample of `block` through trace_block and through render_pixel_sample.
Comparison compare(PacketIsa isa, const Scene& scene, const SamplingPlan& plan, std::uint64_t seed,
                   const SampleBlock& block) {
  std::vector<SampleResult> packet(block.size());
  trace_block(isa, scene, plan, seed, block, packet.data());
  Comparison c;
  std::size_t j = 0;
  for (int y = block.y0; y < block.y1; ++y)
    for (int x = block.x0; x < block.x1; ++x)
      for (std::uint32_t k = 0; k < block.spp; ++k, ++j) {
        DropCounts drops;
        const Vec3 scalar = render_pixel_sample(scene, plan, seed, x, y, block.first_sample + k, drops);
        ++c.samples;
        if (scalar != Vec3(0.0f)) ++c.nonzero;
        if (!same_bits(scalar, packet[j].radiance) || drop_bits(drops) != packet[j].drops) {
          if (c.differing++ == 0)
            c.first_difference = "pixel (" + std::to_string(x) + ", " + std::to_string(y) + ") sample " +
                                 std::to_string(block.first_sample + k) + ": scalar (" + std::to_string(scalar.x) +
                                 ", " + std::to_string(scalar.y) + ", " + std::to_string(scalar.z) + "), packet (" +
                                 std::to_string(packet[j].radiance.x) + ", " + std::to_string(packet[j].radiance.y) +
                                 ", " + std::to_string(packet[j].radiance.z) + ")";
        }
      }
  return c;
}

const std::vector<std::string>& strategies() {
  static const std::vector<std::string> s = testing::with_table_strategies(
      std::vector<std::string>(std::begin(kStrategies), std::end(kStrategies)), [](const testing::TableStrategy&) {
        return true;
      });
  return s;
}

class SameBits : public ::testing::TestWithParam<std::string> {};

// One strategy on every shipped scene (where the scene has what it aims at),
// through every instruction set.
TEST_P(SameBits, AsTheOnePathTracerOnEveryScene) {
  std::size_t samples = 0, nonzero = 0;
  for (const char* file : kScenes) {
    const Scene scene = small_scene(file, 24, 20);
    SamplingPlan plan;
    try {
      plan = SamplingPlan::make(Strategy::parse(GetParam()), scene);
    } catch (const InputError&) {
      continue;  // specular-objects alone in a scene without glass or metal
    }
    for (PacketIsa isa : available_packet_isas()) {
      const Comparison c = compare(isa, scene, plan, 5, SampleBlock{0, 0, 24, 20, 3, 4});
      SCOPED_TRACE(std::string(file) + ", " + std::string(packet_isa_name(isa)));
      EXPECT_EQ(c.differing, 0u) << c.differing << " of " << c.samples << " differ; first at " << c.first_difference;
      samples += c.samples;
      nonzero += c.nonzero;
    }
  }
  ASSERT_GT(samples, 0u) << "no scene can take the strategy";
  // Hundreds of samples that found light at least: a comparison of black samples would prove little.
  EXPECT_GE(nonzero, 500u) << "of " << samples;
}

INSTANTIATE_TEST_SUITE_P(Strategies, SameBits, ::testing::ValuesIn(strategies()),
                         [](const ::testing::TestParamInfo<std::string>& param) { return testing::test_name(param.param); });

TEST(Packet, BlocksAnywhereInTheImage) {
  // An offset block with one sample per pixel, and one pixel with many.
  const Scene scene = small_scene("cornell_book.json", 40, 30);
  const SamplingPlan plan = SamplingPlan::make(Strategy::parse("mix:cosine=0.5,light=0.5"), scene);
  for (PacketIsa isa : available_packet_isas()) {
    Comparison c = compare(isa, scene, plan, 9, SampleBlock{17, 11, 30, 29, 0, 1});
    EXPECT_EQ(c.differing, 0u) << c.first_difference;
    c = compare(isa, scene, plan, 9, SampleBlock{20, 15, 21, 16, 100, 333});
    EXPECT_EQ(c.differing, 0u) << c.first_difference;
    EXPECT_EQ(c.samples, 333u);
  }
}

TEST(Packet, DepthLimitsAndDropsAsTheScalarTracer) {
  Scene scene = small_scene("cornell_book.json", 16, 16);
  for (int depth : {0, 1, 2, 3})
    for (const char* text : {"mix:cosine=0.5,light=0.5", "nee-mis"}) {
      scene.max_depth = depth;
      const SamplingPlan plan = SamplingPlan::make(Strategy::parse(text), scene);
      for (PacketIsa isa : available_packet_isas()) {
        const Comparison c = compare(isa, scene, plan, 2, SampleBlock{0, 0, 16, 16, 0, 2});
        EXPECT_EQ(c.differing, 0u) << text << ", depth " << depth << ": " << c.first_difference;
      }
    }
  // A light seen edge-on from the floor it lies in: the book's `light` offers
  // no direction there (a valid zero), and pure `light` with its area density
  // is what test_extremes checks drop-free; here only agreement matters.
  Scene flat = small_scene("large_light.json", 16, 16);
  const SamplingPlan plan = SamplingPlan::make(Strategy::parse("light"), flat);
  for (PacketIsa isa : available_packet_isas()) {
    const Comparison c = compare(isa, flat, plan, 4, SampleBlock{0, 0, 16, 16, 0, 4});
    EXPECT_EQ(c.differing, 0u) << c.first_difference;
  }
}

// A shipped scene's text, to be edited (insert_after) before it is loaded.
std::string shipped_scene_text(const std::string& name) {
  std::ifstream in(std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes/" + name);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// `what` inserted just after the first `after` in `text`, which must hold it.
void insert_after(std::string& text, const std::string& after, const std::string& what) {
  const std::size_t at = text.find(after);
  ASSERT_NE(at, std::string::npos) << after;
  text.insert(at + after.size(), what);
}

// nee-mis's light sample choosing between an environment map and an area
// light (environment_light_share), and every strategy's misses reading the
// map: the packet tracer gives the one-path tracer's bits.
TEST(Packet, EnvironmentAndAreaLight) {
  const std::string dir = std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes";
  std::string text = shipped_scene_text("sun_sky.json");
  const auto put = [&](const std::string& after, const std::string& what) { insert_after(text, after, what); };
  put("\"materials\": {", R"( "lamp": { "type": "diffuse_light", "emit": [40, 30, 20] },)");
  put("\"objects\": [", R"( { "type": "quad", "q": [-2.5, 2.6, -1.2], "u": [0.6, 0, 0], "v": [0, 0, 0.6], "material": "lamp" },)");
  Scene scene = load_scene_text(text, "sun_sky.json", dir);
  scene.camera.width = 24;
  scene.camera.height = 20;
  scene.prepare();
  for (const char* strategy : {"nee-mis", "nee-mis+mix:cosine=0.5,environment=0.5+sobol", "mix:cosine=0.5,light-sa=0.5",
                               "mix:light-sa=0.5,environment=0.5"}) {
    const SamplingPlan plan = SamplingPlan::make(Strategy::parse(strategy), scene);
    EXPECT_GT(plan.environment_share, 0.0f);
    EXPECT_LT(plan.environment_share, 1.0f);
    for (PacketIsa isa : available_packet_isas()) {
      const Comparison c = compare(isa, scene, plan, 5, SampleBlock{0, 0, 24, 20, 0, 4});
      EXPECT_EQ(c.differing, 0u) << strategy << ", " << packet_isa_name(isa) << ": " << c.first_difference;
      EXPECT_GE(c.nonzero, 1000u);
    }
  }
}

// A scene of many objects rendered with the tree over them (Scene::bvh) and
// without: the same bits through the one-path tracer and every packet width,
// shadow rays, aimed light samples and bounces included.
TEST(Packet, TheTreeOverObjectsGivesTheFlatLoopsBits) {
  constexpr int kWidth = 24, kHeight = 20;
  Scene flat = object_room(300, 2, BvhUse::Never), tree = object_room(300, 2, BvhUse::Always);
  for (Scene* scene : {&flat, &tree}) {
    scene->camera.width = kWidth;
    scene->camera.height = kHeight;
    scene->prepare();
  }
  ASSERT_TRUE(flat.bvh.empty());
  ASSERT_FALSE(tree.bvh.empty());
  std::size_t nonzero = 0, samples = 0;
  for (const char* strategy : {"nee-mis", "cosine+rr", "nee-mis:balance+mix:cosine=0.5,light-sa=0.5"}) {
    SCOPED_TRACE(strategy);
    const SamplingPlan flat_plan = SamplingPlan::make(Strategy::parse(strategy), flat);
    const SamplingPlan tree_plan = SamplingPlan::make(Strategy::parse(strategy), tree);
    const SampleBlock block{0, 0, kWidth, kHeight, 0, 3};
    for (PacketIsa isa : available_packet_isas()) {
      std::vector<SampleResult> a(block.size()), b(block.size());
      trace_block(isa, flat, flat_plan, 5, block, a.data());
      trace_block(isa, tree, tree_plan, 5, block, b.data());
      std::size_t differing = 0;
      for (std::size_t j = 0; j < a.size(); ++j) {
        differing += !same_bits(a[j].radiance, b[j].radiance) || a[j].drops != b[j].drops;
        nonzero += a[j].radiance != Vec3(0.0f);
      }
      samples += a.size();
      EXPECT_EQ(differing, 0u) << packet_isa_name(isa);
      // And the one-path tracer with the tree gives the packets' bits.
      const Comparison c = compare(isa, tree, tree_plan, 5, block);
      EXPECT_EQ(c.differing, 0u) << packet_isa_name(isa) << ": " << c.first_difference;
    }
  }
  // Thousands of samples found light (nee-mis's light samples): no comparison of black images.
  EXPECT_GE(nonzero, samples / 3);
}

// The light tree's choice, made one lane at a time, and its light densities
// (each emitter's own, found from the one a continuation reaches): on the
// many-lights room, on the sun-and-sky scene with two lamps (the map's
// share beside the tree's) and on the frosted box with a second lamp, the
// packet tracer gives the one-path tracer's bits.
TEST(Packet, LightTree) {
  const std::string dir = std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes";
  std::string text = shipped_scene_text("sun_sky.json");
  const auto put = [&](const std::string& after, const std::string& what) { insert_after(text, after, what); };
  put("\"materials\": {", R"( "lamp": { "type": "diffuse_light", "emit": [40, 30, 20] },)");
  put("\"objects\": [", R"( { "type": "quad", "q": [-2.5, 2.6, -1.2], "u": [0.6, 0, 0], "v": [0, 0, 0.6], "material": "lamp" },)"
                         R"( { "type": "sphere", "center": [-0.2, 0.4, -1.6], "radius": 0.15, "material": "lamp" },)");
  Scene sky = load_scene_text(text, "sun_sky.json", dir);
  sky.camera.width = 24;
  sky.camera.height = 20;
  sky.prepare();
  Scene room = small_scene("many_lights.json", 16, 12);
  room.max_depth = 4;
  // The frosted box with a second lamp: the tree's choice without the normal
  // at the rough dielectric, its continuations' densities from the vertex they left.
  text = shipped_scene_text("frosted_glass.json");
  put("\"materials\": {", R"( "lamp": { "type": "diffuse_light", "emit": [15, 15, 15] },)");
  put("\"objects\": [", R"( { "type": "sphere", "center": [400, 60, 120], "radius": 20, "material": "lamp" },)");
  Scene frosted = load_scene_text(text, "frosted_glass.json", dir);
  frosted.camera.width = 24;
  frosted.camera.height = 20;
  frosted.prepare();
  for (const Scene* scene : {&room, &sky, &frosted})
    for (const char* strategy : {"nee-mis+lights:tree", "nee-mis+mix:cosine=0.5,light-sa=0.5+sobol+rr:2+lights:tree"}) {
      const SamplingPlan plan = SamplingPlan::make(Strategy::parse(strategy), *scene);
      ASSERT_NE(plan.emitters.tree, nullptr);
      for (PacketIsa isa : available_packet_isas()) {
        const Comparison c = compare(isa, *scene, plan, 5, SampleBlock{0, 0, scene->camera.width, scene->camera.height, 0, 2});
        EXPECT_EQ(c.differing, 0u) << scene->name << ", " << strategy << ", " << packet_isa_name(isa) << ": "
                                   << c.first_difference;
        EXPECT_GE(c.nonzero, 300u) << scene->name;
      }
    }
}

// The instruction sets: the baseline always, narrowest first, each wider than
// the last; the tracer uses the widest unless PDFLAB_ISA names another. What
// this machine ran is in the test's output (the bit comparisons above ran each).
TEST(Packet, InstructionSetsAreListedWidestLast) {
  const std::vector<PacketIsa> here = available_packet_isas();
  ASSERT_FALSE(here.empty());
  EXPECT_EQ(here.front(), PacketIsa::Generic);
  for (std::size_t i = 1; i < here.size(); ++i)
    EXPECT_GT(packet_lanes(here[i]), packet_lanes(here[i - 1])) << packet_isa_name(here[i]);
  std::string names;
  for (const PacketIsa isa : here) names += std::string(names.empty() ? "" : ", ") + std::string(packet_isa_name(isa));
  std::printf("instruction sets run here: %s\n", names.c_str());
  const char* requested = std::getenv("PDFLAB_ISA");
  if (!requested) {
    EXPECT_EQ(best_packet_isa(), here.back());
  }
  if (std::find(here.begin(), here.end(), PacketIsa::Avx512) != here.end()) {
    EXPECT_EQ(packet_lanes(PacketIsa::Avx512), 16);
  }
}

// PDFLAB_ISA picks an instruction set this machine runs; a name it does not
// know, or one the machine lacks, falls back to the widest with a warning
// naming the value (a mistyped name must not pass for a comparison).
TEST(Packet, RequestedInstructionSetIsHonouredOrWarnedAbout) {
  const std::vector<PacketIsa> here = available_packet_isas();
  std::string warning;
  EXPECT_EQ(choose_packet_isa(nullptr, here, warning), here.back());
  EXPECT_TRUE(warning.empty());
  EXPECT_EQ(choose_packet_isa("", here, warning), here.back());
  EXPECT_TRUE(warning.empty());
  for (const PacketIsa isa : here) {
    EXPECT_EQ(choose_packet_isa(std::string(packet_isa_name(isa)).c_str(), here, warning), isa);
    EXPECT_TRUE(warning.empty()) << warning;
  }
  EXPECT_EQ(choose_packet_isa("avx-512", here, warning), here.back());
  EXPECT_NE(warning.find("PDFLAB_ISA=avx-512 is not an instruction set"), std::string::npos) << warning;
  EXPECT_NE(warning.find("generic, avx2, avx512"), std::string::npos) << warning;
  // A machine without AVX-512, as the generic-only list stands in for.
  const std::vector<PacketIsa> baseline{PacketIsa::Generic};
  EXPECT_EQ(choose_packet_isa("avx512", baseline, warning), PacketIsa::Generic);
  EXPECT_NE(warning.find("does not run it; using generic"), std::string::npos) << warning;
}

}  // namespace
}  // namespace pdflab
