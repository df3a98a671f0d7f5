// The `pdflab render` contract from README.md, checked on the real binary:
// each class of bad input exits 2 with one message naming the problem and
// writes nothing; a small render writes the image, the stats JSON and a summary.
#include "renderer/film/image_io.h"
#include "renderer/integrator/packet.h"
#include "tests/command_test.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <regex>
#include <string>
#include <vector>

namespace pdflab {
namespace {

namespace fs = std::filesystem;

const std::string kBookScene = std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes/cornell_book.json";
const std::string kBadInput = std::string(PDFLAB_SOURCE_DIR) + "/tests/bad_input/";

using testing::ChildResult;
using testing::slurp;

// Each test gets an empty working folder (the child's cwd and where outputs
// go) and a separate folder for the captured streams, so that "nothing was
// written" can be checked by listing the working folder.
class RenderCommand : public testing::CommandTest {
 protected:
  RenderCommand() : CommandTest("pdflab-cli") {}


  // A render command line that is valid except for what `overrides` changes.
  std::vector<std::string> render_args(std::initializer_list<std::string> extra = {}) const {
    std::vector<std::string> a = {"render",  "--scene", kBookScene, "--strategy", "mix:cosine=0.5,light=0.5",
                                  "--spp",   "4",       "--out",    in_work("image.png"),
                                  "--width", "16",      "--height", "16", "--threads", "2"};
    a.insert(a.end(), extra);
    return a;
  }

  static std::vector<std::string> replace(std::vector<std::string> args, const std::string& flag,
                                          const std::string& value) {
    const auto it = std::find(args.begin(), args.end(), flag);
    if (it == args.end() || it + 1 == args.end()) {
      ADD_FAILURE() << "no " << flag << " to replace";
      return args;
    }
    *(it + 1) = value;
    return args;
  }

  // Bad input: status 2, a message on stderr that contains `needle`, no trace
  // of a crash or an internal error, and nothing written to the working folder.
  void expect_bad_input(const std::vector<std::string>& args, const std::string& needle) const {
    std::string line;
    for (const auto& a : args) line += " " + a;
    SCOPED_TRACE("pdflab" + line);
    const ChildResult r = run(args);
    ASSERT_TRUE(r.exited) << "killed by a signal; stderr:\n" << r.err;
    EXPECT_EQ(r.status, 2) << "stderr:\n" << r.err;
    EXPECT_EQ(r.err.rfind("pdflab: error: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << "stderr lacks '" << needle << "':\n" << r.err;
    for (const char* crash : {"internal error", "terminate called", "what()", "Aborted", "core dumped", "Segmentation"})
      EXPECT_EQ(r.err.find(crash), std::string::npos) << "stderr shows '" << crash << "':\n" << r.err;
    EXPECT_LE(std::count(r.err.begin(), r.err.end(), '\n'), 2) << "more than a short message:\n" << r.err;
    EXPECT_EQ(r.out, "") << "bad input printed a result";
    EXPECT_TRUE(work_entries().empty()) << "files were written: " << ::testing::PrintToString(work_entries());
  }
};

TEST_F(RenderCommand, ValidBaseCommandSucceeds) {
  // Every bad-input test changes one thing in this command: it must work as is.
  const ChildResult r = run(render_args());
  ASSERT_TRUE(r.exited);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(work_entries(), std::vector<std::string>{"image.png"});
}

TEST_F(RenderCommand, UnknownFlag) { expect_bad_input(render_args({"--bogus"}), "--bogus"); }

TEST_F(RenderCommand, MissingRequiredOption) {
  std::vector<std::string> args = render_args();
  args.erase(std::find(args.begin(), args.end(), "--out"), std::find(args.begin(), args.end(), "--width"));
  expect_bad_input(args, "--out");
}

TEST_F(RenderCommand, UnknownStrategy) {
  expect_bad_input(replace(render_args(), "--strategy", "phong"), "unknown strategy 'phong'");
  expect_bad_input(replace(render_args(), "--strategy", "mix:cosine=1,cosine=1"), "appears twice");
  expect_bad_input(replace(render_args(), "--strategy", "mix:cosine=-1,light=1"), "weight '-1'");
}

TEST_F(RenderCommand, StrategyNeedsTargetsTheSceneLacks) {
  std::vector<std::string> args = replace(render_args(), "--strategy", "light");
  expect_bad_input(replace(args, "--scene", kBadInput + "no_targets.json"), "has none");
}

TEST_F(RenderCommand, BadNumbers) {
  expect_bad_input(replace(render_args(), "--spp", "abc"), "--spp");
  expect_bad_input(replace(render_args(), "--spp", "-3"), "--spp");
  expect_bad_input(replace(render_args(), "--spp", "0"), "--spp");
  expect_bad_input(replace(render_args(), "--spp", "4x"), "--spp");
  expect_bad_input(replace(render_args(), "--width", "0"), "--width");
  expect_bad_input(replace(render_args(), "--height", "16385"), "--height");
  expect_bad_input(replace(render_args(), "--threads", "-1"), "--threads");
  expect_bad_input(render_args({"--seed", "seven"}), "--seed");
}

TEST_F(RenderCommand, MissingSceneFile) {
  const std::string missing = in_work("nope.json");
  expect_bad_input(replace(render_args(), "--scene", missing), "cannot read scene '" + missing + "'");
}

TEST_F(RenderCommand, SceneWithSyntaxError) {
  expect_bad_input(replace(render_args(), "--scene", kBadInput + "syntax_error.json"), "syntax_error.json: JSON syntax error at line 5");
}

TEST_F(RenderCommand, SceneThatFailsValidation) {
  expect_bad_input(replace(render_args(), "--scene", kBadInput + "negative_radius.json"), "objects[1].radius");
}

TEST_F(RenderCommand, SceneWithOverflowingNumber) {
  // 1e999 is the closest JSON gets to an infinite number: bad input, not an internal error.
  expect_bad_input(replace(render_args(), "--scene", kBadInput + "overflow_number.json"), "1e999");
}

TEST_F(RenderCommand, UnknownOutputExtension) {
  expect_bad_input(replace(render_args(), "--out", in_work("image.jpg")), "unknown image format '.jpg'");
  expect_bad_input(replace(render_args(), "--out", in_work("image")), "unknown image format");
}

TEST_F(RenderCommand, OutputFolderMissing) {
  expect_bad_input(replace(render_args(), "--out", in_work("missing/image.png")), "does not exist");
  expect_bad_input(render_args({"--stats-json", in_work("missing/stats.json")}), "does not exist");
}

// ---- Successful renders ---------------------------------------------------------

std::vector<std::string> small_render(const std::string& out, std::initializer_list<std::string> extra = {}) {
  std::vector<std::string> a = {"render", "--scene", kBookScene, "--strategy", "mix:cosine=0.5,light=0.5",
                                "--spp", "4", "--out", out, "--width", "32", "--height", "32", "--threads", "2"};
  a.insert(a.end(), extra);
  return a;
}

// On the door scene `fastest` runs as path guiding (for_scene), and the
// sidecar and the statistics say so: the guided expansion, from fastest.
TEST_F(RenderCommand, FastestRunsAsGuidingWhereTheSceneSaysSo) {
  const std::string door = std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes/door_ajar.json";
  const ChildResult r = run({"render", "--scene", door, "--strategy", "fastest", "--spp", "2", "--width", "24",
                             "--height", "18", "--threads", "2", "--out", in_work("door.pfm"), "--film-out",
                             in_work("door.film"), "--stats-json", in_work("stats.json")});
  ASSERT_TRUE(r.exited);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("path guiding: 5 training passes"), std::string::npos) << r.out;
  const nlohmann::json sidecar = nlohmann::json::parse(slurp(work() / "door.json"));
  EXPECT_EQ(sidecar.at("strategy").get<std::string>(), Strategy::parse(kFastestGuidedStrategy).to_string());
  const nlohmann::json stats = nlohmann::json::parse(slurp(work() / "stats.json"));
  EXPECT_EQ(stats.at("strategy"), sidecar.at("strategy"));
  EXPECT_EQ(stats.at("expanded_from").get<std::string>(), "fastest");
  // Resumed with --strategy fastest, the film's strategy is what fastest is there.
  const ChildResult again = run({"render", "--resume", in_work("door.film"), "--strategy", "fastest", "--spp", "2",
                                 "--threads", "2", "--out", in_work("door2.pfm")});
  ASSERT_TRUE(again.exited);
  EXPECT_EQ(again.status, 0) << again.err;
  const std::vector<std::string> before = work_entries();
  const ChildResult other = run({"render", "--resume", in_work("door.film"), "--strategy", "nee-mis", "--spp", "2",
                                 "--out", in_work("door3.pfm")});
  EXPECT_EQ(other.status, 2) << other.err;
  EXPECT_NE(other.err.find("was rendered with strategy"), std::string::npos) << other.err;
  EXPECT_EQ(work_entries(), before) << "a refused resume wrote files";
}

TEST_F(RenderCommand, RendersPfmAndStatsJson) {
  const ChildResult r = run(small_render(in_work("image.pfm"), {"--stats-json", in_work("stats.json"), "--seed", "5"}));
  ASSERT_TRUE(r.exited);
  ASSERT_EQ(r.status, 0) << r.err;
  // The PFM's sidecar says what it is an estimate of (issue 33, item 5).
  EXPECT_EQ(work_entries(), (std::vector<std::string>{"image.json", "image.pfm", "stats.json"}));
  const nlohmann::json sidecar = nlohmann::json::parse(slurp(work() / "image.json"));
  EXPECT_EQ(sidecar.at("format").get<std::string>(), "pdflab-render");
  EXPECT_EQ(sidecar.at("seed").get<int>(), 5);
  EXPECT_EQ(sidecar.at("seeds"), nlohmann::json::array({5}));
  EXPECT_EQ(sidecar.at("sample_ranges").get<std::string>(), "seed 5 samples [0, 4)");
  EXPECT_EQ(sidecar.at("strategy").get<std::string>(), "mix:cosine=0.5,light=0.5");

  int w = 0, h = 0;
  const std::vector<float> rgb = read_pfm(in_work("image.pfm"), w, h);
  EXPECT_EQ(w, 32);
  EXPECT_EQ(h, 32);
  double total = 0.0;
  for (float v : rgb) {
    ASSERT_TRUE(std::isfinite(v) && v >= 0.0f) << v;
    total += v;
  }
  EXPECT_GT(total / static_cast<double>(rgb.size()), 0.01) << "the Cornell box rendered black";

  const nlohmann::json stats = nlohmann::json::parse(slurp(work() / "stats.json"));
  EXPECT_EQ(stats.at("spp").get<int>(), 4);
  EXPECT_EQ(stats.at("width").get<int>(), 32);
  EXPECT_EQ(stats.at("height").get<int>(), 32);
  EXPECT_EQ(stats.at("seed").get<int>(), 5);
  EXPECT_EQ(stats.at("threads").get<int>(), 2);
  EXPECT_EQ(stats.at("strategy").get<std::string>(), "mix:cosine=0.5,light=0.5");
  EXPECT_EQ(stats.at("sampler").get<std::string>(), "independent");
  EXPECT_EQ(stats.at("tracer").get<std::string>(), packet_isa_name(best_packet_isa()));
  EXPECT_EQ(stats.at("tracer_lanes").get<int>(), packet_lanes(best_packet_isa()));
  EXPECT_EQ(stats.at("samples").get<std::uint64_t>(), 32u * 32u * 4u);
  const double seconds = stats.at("seconds").get<double>();
  const double rate = stats.at("samples_per_second").get<double>();
  EXPECT_GT(seconds, 0.0);
  EXPECT_NEAR(rate, 32.0 * 32.0 * 4.0 / seconds, 1e-6 * rate);
  const auto& dropped = stats.at("dropped");
  std::uint64_t sum = 0;
  for (const char* reason : {"pdf_zero", "pdf_not_finite", "radiance_not_finite"}) {
    ASSERT_TRUE(dropped.contains(reason)) << reason;
    sum += dropped.at(reason).get<std::uint64_t>();
  }
  EXPECT_EQ(dropped.at("total").get<std::uint64_t>(), sum);
  EXPECT_LE(sum, 32u * 32u * 4u);

  // The one-line summary carries the same numbers; the figures follow on their own line.
  static const std::regex summary(R"(^4 spp, 32x32, [0-9.]+ s, [0-9.]+ M samples/s, 2 threads, [0-9]+ samples dropped[^\n]*\nest\. relMSE [^\n]*\n$)");
  EXPECT_TRUE(std::regex_search(r.out, summary)) << "stdout: " << r.out;
  EXPECT_NE(r.out.find(", " + std::to_string(sum) + " samples dropped"), std::string::npos) << r.out;
}

TEST_F(RenderCommand, StatsJsonRecordsTheSobolSampler) {
  std::vector<std::string> a = small_render(in_work("image.pfm"), {"--stats-json", in_work("stats.json")});
  a[4] = "nee-mis+sobol+rr";  // the --strategy value
  const ChildResult r = run(a);
  ASSERT_TRUE(r.exited);
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json stats = nlohmann::json::parse(slurp(work() / "stats.json"));
  EXPECT_EQ(stats.at("strategy").get<std::string>(), "nee-mis+sobol+rr");
  EXPECT_EQ(stats.at("sampler").get<std::string>(), "sobol");
}

TEST_F(RenderCommand, RendersPng) {
  const ChildResult r = run(small_render(in_work("image.png")));
  ASSERT_TRUE(r.exited);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(work_entries(), std::vector<std::string>{"image.png"});
  const std::string png = slurp(work() / "image.png");
  ASSERT_GT(png.size(), 24u);
  EXPECT_EQ(png.substr(1, 3), "PNG");
  EXPECT_EQ(png.substr(12, 4), "IHDR");
  const auto u32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    for (std::size_t i = 0; i < 4; ++i) v = (v << 8) | static_cast<unsigned char>(png[at + i]);
    return v;
  };
  EXPECT_EQ(u32(16), 32u);
  EXPECT_EQ(u32(20), 32u);
  EXPECT_NE(r.out.find("4 spp"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("M samples/s"), std::string::npos) << r.out;
}

// A PFM's sidecar may replace an earlier sidecar, never the scene (box.json
// beside box.pfm) or another file; with --stats-json naming it, the stats
// JSON is the sidecar.
TEST_F(RenderCommand, APfmSidecarNeverReplacesAnotherFile) {
  const std::string scene = in_work("box.json");
  {
    std::ofstream(scene) << slurp(kBookScene);
  }
  const std::string before = slurp(scene);
  const auto render = [&](const std::string& out, std::initializer_list<std::string> extra = {}) {
    std::vector<std::string> a = small_render(out, extra);
    a[2] = scene;
    return run(a);
  };
  ChildResult r = render(in_work("box.pfm"));
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("would replace the scene file"), std::string::npos) << r.err;
  {
    std::ofstream(in_work("notes.json")) << "{\"mine\": true}";
  }
  r = render(in_work("notes.pfm"));
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("not a pdflab sidecar"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(scene), before);
  EXPECT_EQ(work_entries(), (std::vector<std::string>{"box.json", "notes.json"})) << "refused before rendering";
  r = render(in_work("image.pfm"), {"--stats-json", in_work("image.json")});
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(slurp(work() / "image.json"));
  EXPECT_EQ(j.at("seeds"), nlohmann::json::array({1}));
  EXPECT_TRUE(j.contains("samples_per_second")) << "the stats JSON is the sidecar";
  ASSERT_EQ(render(in_work("image.pfm")).status, 0) << "an earlier sidecar is replaced";
}

// Issue 33, item 7: whether "the estimate is unreliable" is printed depends
// on the samples, not on when the render's polls fell: the estimate is taken
// at each power of two and at the end, the same figures on one thread or two.
TEST_F(RenderCommand, TheEstimateVerdictDependsOnTheSamplesNotTheTiming) {
  const std::string small_light = std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes/small_light.json";
  nlohmann::json first;
  for (const char* threads : {"1", "2", "1", "2"}) {
    const ChildResult r = run({"render", "--scene", small_light, "--strategy", "cosine", "--width", "24", "--height",
                               "24", "--spp", "300", "--threads", threads, "--quiet", "--out", in_work("i.pfm"),
                               "--stats-json", in_work("s.json")});
    ASSERT_EQ(r.status, 0) << r.err;
    const nlohmann::json s = nlohmann::json::parse(slurp(work() / "s.json"));
    const nlohmann::json figures = {s.at("est_relmse_history"), s.at("est_relmse_unreliable"), s.at("est_relmse")};
    EXPECT_EQ(s.at("est_relmse_unreliable").get<bool>(), r.out.find("estimate is unreliable") != std::string::npos);
    if (first.is_null()) first = figures;
    EXPECT_EQ(figures, first) << "threads " << threads;
  }
  // Points at 2, 4, ..., 256 and 300.
  ASSERT_EQ(first[0].size(), 9u) << first[0];
  EXPECT_EQ(first[0].back()[0], 300);
  EXPECT_EQ(first[0][0][0], 2);
  std::printf("4 renders: the same history and verdict (unreliable: %s)\n", first[1].get<bool>() ? "yes" : "no");
}

// Issue 33, item 8: every --reference help names what load_reference reads.
TEST_F(RenderCommand, EveryReferenceHelpNamesPfmExrAndFilm) {
  for (const std::vector<std::string>& help : {std::vector<std::string>{"--help"}, {"render", "--help"},
                                               {"bench", "--help"}, {"sweep", "--help"}, {"veach", "--help"}}) {
    const ChildResult r = run(help);
    ASSERT_EQ(r.status, 0) << r.err;
    const std::size_t at = r.out.find("--reference ");
    ASSERT_NE(at, std::string::npos) << r.out;
    const std::string line = r.out.substr(at, r.out.find('\n', at) - at);
    EXPECT_NE(line.find(".pfm, .exr or .film"), std::string::npos) << help[0] << ": " << line;
  }
}

// Issue 33, item 8: docs/measuring.md says what the commands do: sweep's
// --seeds default, and a cached reference the viewer finds (the cache is
// keyed by size: a 300x300 reference is not found for the 600x600 view).
TEST_F(RenderCommand, MeasuringDocAgreesWithTheCommands) {
  const std::string doc = slurp(std::string(PDFLAB_SOURCE_DIR) + "/docs/measuring.md");
  const ChildResult sweep = run({"sweep", "--help"});
  const std::size_t seeds = sweep.out.find("--seeds");
  ASSERT_NE(seeds, std::string::npos);
  const std::size_t open = sweep.out.find("(default ", seeds);
  const std::string dflt = sweep.out.substr(open + 9, sweep.out.find(')', open) - open - 9);
  EXPECT_EQ(dflt, "3");
  const std::size_t bullet = doc.find("Each weight is rendered `--seeds K` times");
  ASSERT_NE(bullet, std::string::npos);
  EXPECT_NE(doc.substr(bullet, 200).find("default " + dflt + ";"), std::string::npos) << doc.substr(bullet, 200);
  const std::size_t example = doc.find("pdflab reference --scene assets/scenes/cornell_book.json");
  ASSERT_NE(example, std::string::npos);
  const std::string line = doc.substr(example, doc.find('\n', example) - example);
  EXPECT_EQ(line.find("--width"), std::string::npos) << "the viewer renders the scene's 600x600: " << line;
}

TEST_F(RenderCommand, RendersHdr) {
  const ChildResult r = run(small_render(in_work("image.hdr")));
  ASSERT_TRUE(r.exited);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(work_entries(), std::vector<std::string>{"image.hdr"});
  const std::string hdr = slurp(work() / "image.hdr");
  EXPECT_EQ(hdr.rfind("#?RADIANCE", 0), 0u);
  EXPECT_NE(hdr.find("-Y 32 +X 32"), std::string::npos);
}

}  // namespace
}  // namespace pdflab
