// Renders that outgrow one run, on the real binary: sample ranges rendered
// apart and merged equal one render; films that do not belong together, and
// damaged ones, are refused with exit status 2 naming both files; a render
// killed mid-way and resumed gives the uninterrupted image; the GNU parallel
// recipe with 4 jobs gives the single render; OpenEXR's exrheader reads the EXR.
#include "renderer/film/exr_io.h"
#include "renderer/film/image_io.h"
#include "tests/support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

namespace pdflab {
namespace {

namespace fs = std::filesystem;
using testing::ChildResult;
using testing::slurp;

const std::string kBookScene = std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes/cornell_book.json";
const std::string kSmallLight = std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes/small_light.json";
const std::string kMix = "mix:cosine=0.5,light=0.5";

double worst_relative_difference(const std::vector<float>& a, const std::vector<float>& b) {
  double worst = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double scale = std::max(std::abs(a[i]), std::abs(b[i]));
    if (scale > 0.0) worst = std::max(worst, std::abs(double{a[i]} - b[i]) / scale);
  }
  return worst;
}

// 'name', built so that GCC 12 sees no overlapping copy in "'" + name + "'" (-Wrestrict).
std::string quote(const std::string& name) {
  std::string q;
  q.reserve(name.size() + 2);
  q += '\'';
  q += name;
  q += '\'';
  return q;
}

// Runs a shell command line; returns its exit status.
int shell(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

class Distributed : public ::testing::Test {
 protected:
  std::string in_work(const std::string& name) const { return ws_.in_work(name); }
  ChildResult run(const std::vector<std::string>& args) const {
    const ChildResult r = ws_.run(args);
    if (!r.started) ADD_FAILURE() << "could not start " << PDFLAB_BINARY;
    return r;
  }
  void ok(const std::vector<std::string>& args) const {
    const ChildResult r = run(args);
    ASSERT_TRUE(r.exited && r.status == 0) << "status " << r.status << "\n" << r.err;
  }
  // A render of the book's box at 32x24; `extra` adds options or replaces the defaults' values.
  std::vector<std::string> render_args(const std::vector<std::string>& extra, const std::string& scene = kBookScene) const {
    std::vector<std::string> a = {"render", "--scene", scene, "--strategy", kMix, "--width", "32", "--height", "24",
                                  "--threads", "2", "--quiet"};
    for (std::size_t i = 0; i < extra.size(); ++i) {
      const auto it = std::find(a.begin(), a.end(), extra[i]);
      if (it != a.end() && it + 1 != a.end() && i + 1 < extra.size() && extra[i].rfind("--", 0) == 0 &&
          it != a.begin()) {
        *(it + 1) = extra[++i];
        continue;
      }
      a.push_back(extra[i]);
    }
    return a;
  }
  std::vector<float> pfm(const std::string& name) const {
    int w = 0, h = 0;
    return read_pfm(in_work(name), w, h);
  }
  std::vector<float> exr(const std::string& name) const {
    int w = 0, h = 0;
    return read_exr(in_work(name), w, h);
  }
  // Status 2, one "pdflab: error:" message containing every needle, and none of `unwritten` created.
  void expect_refusal(const std::vector<std::string>& args, const std::vector<std::string>& needles,
                      const std::vector<std::string>& unwritten) const {
    const ChildResult r = run(args);
    ASSERT_TRUE(r.exited) << r.err;
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_EQ(r.err.rfind("pdflab: error: ", 0), 0u) << r.err;
    for (const std::string& n : needles) EXPECT_NE(r.err.find(n), std::string::npos) << "lacks '" << n << "':\n" << r.err;
    for (const std::string& u : unwritten) EXPECT_FALSE(fs::exists(in_work(u))) << u << " was written";
    for (const auto& e : fs::directory_iterator(ws_.work()))
      EXPECT_EQ(e.path().filename().string().find(".tmp."), std::string::npos) << "left " << e.path();
  }

  testing::CommandWorkspace ws_{"pdflab-distributed"};
};

TEST_F(Distributed, MergeOfRangesEqualsOneRenderAndMergeOfSeedsHoldsBoth) {
  ok(render_args({"--spp", "32", "--out", in_work("single.pfm")}));
  ok(render_args({"--spp", "32", "--out", in_work("single.exr")}));
  ok(render_args({"--spp", "16", "--film-out", in_work("a.film")}));
  ok(render_args({"--spp", "16", "--first-sample", "16", "--film-out", in_work("b.film")}));
  ok({"merge", in_work("b.film"), in_work("a.film"), "--out", in_work("merged.pfm"), "--film-out", in_work("ab.film")});
  ok({"merge", in_work("a.film"), in_work("b.film"), "--out", in_work("merged.exr"), "--stats-json", in_work("m.json")});
  const double pfm_difference = worst_relative_difference(pfm("merged.pfm"), pfm("single.pfm"));
  const double exr_difference = worst_relative_difference(exr("merged.exr"), exr("single.exr"));
  EXPECT_LE(pfm_difference, 1e-6);
  EXPECT_LE(exr_difference, 1e-6);
  EXPECT_EQ(exr("merged.exr"), pfm("merged.pfm")) << "EXR and PFM hold the same floats";
  const auto stats = nlohmann::json::parse(slurp(in_work("m.json")));
  EXPECT_EQ(stats["spp"], 32);
  EXPECT_EQ(stats["samples"], "seed 1 samples [0, 32)");
  EXPECT_EQ(read_exr_attribute(in_work("merged.exr"), "pdflab.spp"), "32");
  std::printf("merge of [0,16) and [16,32) against one 32 spp render: PFM %.2e, EXR %.2e largest relative difference\n",
              pfm_difference, exr_difference);

  // The merged film continues like any other: [0, 32) resumed to 48 is one 48 spp render.
  ok(render_args({"--spp", "48", "--out", in_work("single48.pfm")}));
  ok({"render", "--resume", in_work("ab.film"), "--spp", "48", "--out", in_work("resumed48.pfm"), "--quiet"});
  EXPECT_EQ(pfm("resumed48.pfm"), pfm("single48.pfm"));

  // Two seeds over the same indices are independent: 2 x 16 samples, the average of the two images.
  ok(render_args({"--spp", "16", "--seed", "2", "--film-out", in_work("seed2.film"), "--out", in_work("seed2.pfm")}));
  ok(render_args({"--spp", "16", "--out", in_work("seed1.pfm")}));
  ok({"merge", in_work("a.film"), in_work("seed2.film"), "--out", in_work("seeds.pfm"), "--stats-json",
      in_work("s.json")});
  const auto seeds = nlohmann::json::parse(slurp(in_work("s.json")));
  EXPECT_EQ(seeds["spp"], 32);
  EXPECT_EQ(seeds["samples"], "seed 1 samples [0, 16), seed 2 samples [0, 16)");
  const auto one = pfm("seed1.pfm"), two = pfm("seed2.pfm"), both = pfm("seeds.pfm");
  for (std::size_t i = 0; i < both.size(); ++i)
    ASSERT_NEAR(both[i], 0.5f * (one[i] + two[i]), 1e-6f * (1.0f + std::abs(both[i]))) << "value " << i;
}

TEST_F(Distributed, FilmsThatDoNotBelongTogetherAreRefusedNamingBothFiles) {
  ok(render_args({"--spp", "8", "--film-out", in_work("a.film")}));
  ok(render_args({"--spp", "8", "--first-sample", "4", "--film-out", in_work("overlap.film")}));
  ok(render_args({"--spp", "8", "--first-sample", "8", "--strategy", "cosine", "--film-out", in_work("cosine.film")}));
  ok(render_args({"--spp", "8", "--first-sample", "8", "--width", "33", "--film-out", in_work("wide.film")}));
  ok(render_args({"--spp", "8", "--first-sample", "8", "--film-out", in_work("other.film")}, kSmallLight));
  ok(render_args({"--spp", "8", "--first-sample", "8", "--film-out", in_work("b.film")}));
  const std::string a = in_work("a.film");
  const auto refuse = [&](const std::string& second, const std::string& why) {
    expect_refusal({"merge", a, in_work("b.film"), in_work(second), "--out", in_work("m.exr"), "--film-out",
                    in_work("m.film")},
                   {"cannot merge", quote(in_work(second)), quote(a), why}, {"m.exr", "m.film"});
  };
  refuse("overlap.film", "counted twice");
  refuse("cosine.film", "different strategies");
  refuse("wide.film", "different image sizes");
  refuse("other.film", "different scenes");
  // An overlap with the second film, not the first, names the second.
  ok(render_args({"--spp", "4", "--first-sample", "12", "--film-out", in_work("late.film")}));
  expect_refusal({"merge", a, in_work("b.film"), in_work("late.film"), "--out", in_work("m.exr")},
                 {quote(in_work("b.film")), quote(in_work("late.film")), "overlap"}, {"m.exr"});

  // Damaged films: refused by name, nothing written.
  const std::string good = slurp(a);
  std::ofstream(in_work("truncated.film"), std::ios::binary).write(good.data(), static_cast<std::streamsize>(good.size() / 2));
  std::string flipped = good;
  flipped[flipped.size() / 2] = static_cast<char>(flipped[flipped.size() / 2] ^ 0x40);
  std::ofstream(in_work("corrupt.film"), std::ios::binary).write(flipped.data(), static_cast<std::streamsize>(flipped.size()));
  expect_refusal({"merge", a, in_work("truncated.film"), "--out", in_work("m.exr")}, {"truncated.film", "truncated"}, {"m.exr"});
  expect_refusal({"merge", a, in_work("corrupt.film"), "--out", in_work("m.exr")}, {"corrupt.film", "checksum"}, {"m.exr"});
  expect_refusal({"merge", kBookScene, "--out", in_work("m.exr")}, {"not a pdflab film"}, {"m.exr"});
  expect_refusal({"render", "--resume", in_work("corrupt.film"), "--spp", "16", "--out", in_work("m.pfm")},
                 {"corrupt.film", "checksum"}, {"m.pfm"});

  // Resuming against other settings, or a merge of several renders.
  expect_refusal({"render", "--resume", a, "--spp", "16", "--seed", "5", "--out", in_work("m.pfm")}, {"seed 1, not 5"}, {"m.pfm"});
  expect_refusal({"render", "--resume", a, "--spp", "16", "--strategy", "cosine", "--out", in_work("m.pfm")},
                 {"strategy"}, {"m.pfm"});
  expect_refusal({"render", "--resume", a, "--scene", kSmallLight, "--spp", "16", "--out", in_work("m.pfm")},
                 {"another scene"}, {"m.pfm"});
  ok(render_args({"--spp", "8", "--seed", "2", "--film-out", in_work("seed2.film")}));
  ok({"merge", a, in_work("seed2.film"), "--film-out", in_work("seeds.film")});
  expect_refusal({"render", "--resume", in_work("seeds.film"), "--spp", "32", "--out", in_work("m.pfm")},
                 {"merge of 2 renders"}, {"m.pfm"});
  expect_refusal(render_args({"--spp", "8"}), {"nothing to write"}, {});
  expect_refusal(render_args({"--spp", "8", "--first-sample", "4294967290", "--out", in_work("m.pfm")}),
                 {"last sample index"}, {"m.pfm"});
}

// A render with checkpoints is killed (SIGKILL, no chance to save) after its
// first checkpoint; resumed to the same spp it is the uninterrupted image, bit for bit.
TEST_F(Distributed, ResumeAfterAKillGivesTheUninterruptedImage) {
  constexpr const char* kSpp = "4096";  // about 0.6 s at 15 M samples/s: long after the first checkpoint
  const std::vector<std::string> args = {"--width", "48", "--height", "48", "--spp", kSpp};
  auto full = render_args(args);
  full.insert(full.end(), {"--out", in_work("full.pfm")});
  ok(full);

  auto killed = render_args(args);
  killed.insert(killed.end(), {"--film-out", in_work("run.film"), "--checkpoint-seconds", "0.05", "--out",
                               in_work("never.pfm")});
  std::vector<std::string> storage{PDFLAB_BINARY};
  storage.insert(storage.end(), killed.begin(), killed.end());
  std::vector<char*> argv;
  for (std::string& s : storage) argv.push_back(s.data());
  argv.push_back(nullptr);
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    const int null = ::open("/dev/null", O_RDWR);
    ::dup2(null, 1);
    ::dup2(null, 2);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  const auto start = std::chrono::steady_clock::now();
  while (!fs::exists(in_work("run.film")) && std::chrono::steady_clock::now() - start < std::chrono::seconds(60))
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  std::this_thread::sleep_for(std::chrono::milliseconds(60));
  ::kill(pid, SIGKILL);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the render ended before it was killed; make it longer";
  ASSERT_TRUE(fs::exists(in_work("run.film")));
  EXPECT_FALSE(fs::exists(in_work("never.pfm")));

  ok({"merge", in_work("run.film"), "--stats-json", in_work("partial.json"), "--out", in_work("partial.pfm")});
  const auto partial = nlohmann::json::parse(slurp(in_work("partial.json")));
  const int saved = partial["spp"];
  EXPECT_GT(saved, 0);
  EXPECT_LT(saved, 1024) << "killed mid-way";
  ok({"render", "--resume", in_work("run.film"), "--spp", kSpp, "--out", in_work("resumed.pfm"), "--quiet"});
  EXPECT_EQ(pfm("resumed.pfm"), pfm("full.pfm"));
  std::printf("killed after %d of 1024 spp; resumed image equals the uninterrupted one bit for bit\n", saved);
}

// SIGINT stops between passes and saves the film; status 130.
TEST_F(Distributed, InterruptSavesTheFilm) {
  auto args = render_args({"--width", "48", "--height", "48", "--spp", "100000", "--film-out", in_work("run.film")});
  std::vector<std::string> storage{PDFLAB_BINARY};
  storage.insert(storage.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& s : storage) argv.push_back(s.data());
  argv.push_back(nullptr);
  const std::string err_path = in_work("../stderr-int");
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    const int err = ::open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int null = ::open("/dev/null", O_RDWR);
    ::dup2(null, 1);
    ::dup2(err, 2);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(700));
  ::kill(pid, SIGINT);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 130);
  EXPECT_NE(slurp(err_path).find("--resume"), std::string::npos) << slurp(err_path);
  ok({"merge", in_work("run.film"), "--out", in_work("partial.pfm")});
}

TEST_F(Distributed, ParallelRecipeWithFourJobsEqualsOneRender) {
  ASSERT_EQ(shell("command -v parallel >/dev/null"), 0) << "GNU parallel is missing (scripts/install_deps.sh)";
  const std::string log = in_work("../parallel.log");
  const std::string command = "PDFLAB='" + std::string(PDFLAB_BINARY) + "' bash '" + PDFLAB_SOURCE_DIR +
                              "/scripts/render_parallel.sh' --jobs 4 --spp 64 --out '" + in_work("parallel.exr") +
                              "' --film-out '" + in_work("parallel.film") + "' --parts '" + in_work("parts") +
                              "' -- --scene '" + kBookScene + "' --strategy '" + kMix +
                              "' --width 32 --height 24 --seed 9 > '" + log + "' 2>&1";
  ASSERT_EQ(shell(command), 0) << slurp(log);
  int parts = 0;
  for (const auto& e : fs::directory_iterator(in_work("parts"))) parts += e.path().extension() == ".film";
  EXPECT_EQ(parts, 4);
  ok(render_args({"--spp", "64", "--seed", "9", "--out", in_work("single.exr")}));
  const double difference = worst_relative_difference(exr("parallel.exr"), exr("single.exr"));
  EXPECT_LE(difference, 1e-6);
  EXPECT_EQ(read_exr_attribute(in_work("parallel.exr"), "pdflab.samples"), "seed 9 samples [0, 64)");
  std::printf("GNU parallel, 4 jobs of 16 spp, merged, against one 64 spp render: largest relative difference %.2e\n",
              difference);
}

TEST_F(Distributed, ExrheaderReadsTheLayers) {
  ASSERT_EQ(shell("command -v exrheader >/dev/null"), 0) << "exrheader (Debian's openexr) is missing";
  ok(render_args({"--spp", "4", "--out", in_work("image.exr")}));
  const std::string out = in_work("../exrheader.txt");
  ASSERT_EQ(shell("exrheader '" + in_work("image.exr") + "' > '" + out + "' 2>&1"), 0) << slurp(out);
  const std::string header = slurp(out);
  for (const char* line : {"R, 32-bit floating-point", "G, 32-bit floating-point", "B, 32-bit floating-point",
                           "variance.R, 32-bit floating-point", "count, 32-bit unsigned integer",
                           "dataWindow (type box2i): (0 0) - (31 23)", "pdflab.strategy (type string): \"mix:cosine=0.5,light=0.5\"",
                           "pdflab.spp (type string): \"4\""})
    EXPECT_NE(header.find(line), std::string::npos) << "lacks '" << line << "':\n" << header;
}

}  // namespace
}  // namespace pdflab
