// Renders that outgrow one run, on the real binary: sample ranges rendered
// apart and merged equal one render; films that do not belong together, and
// damaged ones, are refused with exit status 2 naming both files; a render
// killed mid-way and resumed gives the uninterrupted image; the GNU parallel
// recipe with 4 jobs gives the single render, recovers from a part that
// failed, and runs over ssh (a real sshd on localhost) from any folder with
// relative paths; the Slurm script, run per task with the variables Slurm
// sets, recovers too; merge --expect-spp refuses gaps; OpenEXR's exrheader
// and OpenImageIO's oiiotool read the EXR's layers as the numbers they are.
#include "renderer/film/exr_io.h"
#include "renderer/film/film_file.h"
#include "renderer/film/image_io.h"
#include "renderer/metrics/metrics.h"
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

// 'text' for a shell, with any ' inside closed and reopened.
std::string sh_quote(const std::string& text) {
  std::string q = "'";
  for (char c : text) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// A command line run by bash with its stdout and stderr captured in `log`.
struct Shell {
  int status = -1;
  std::string output;
};
Shell run_shell(const std::string& command, const std::string& log) {
  Shell r;
  r.status = shell("bash -c " + sh_quote(command) + " > " + sh_quote(log) + " 2>&1 < /dev/null");
  r.output = slurp(log);
  return r;
}

void write_file(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
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
// Issue 33, item 14: sized by samples for the build: 4096 spp at 48x48 is
// about 0.6 s at 15 M samples/s in a release build and 100 s or more in an
// ASan build on a loaded machine (past the child's deadline once); 256 spp
// there takes about 6 s and still runs long past the first checkpoint.
TEST_F(Distributed, ResumeAfterAKillGivesTheUninterruptedImage) {
  const std::uint32_t spp = testing::spp_for_build(4096, 256);
  const std::string kSpp = std::to_string(spp);
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
  const auto patience = std::chrono::duration<double>(testing::deadline_for_build(60.0));
  while (!fs::exists(in_work("run.film")) && std::chrono::steady_clock::now() - start < patience)
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
  EXPECT_LT(saved, static_cast<int>(spp)) << "killed mid-way";
  ok({"render", "--resume", in_work("run.film"), "--spp", kSpp, "--out", in_work("resumed.pfm"), "--quiet"});
  EXPECT_EQ(pfm("resumed.pfm"), pfm("full.pfm"));
  std::printf("killed after %d of %u spp; resumed image equals the uninterrupted one bit for bit\n", saved, spp);
}

// SIGINT stops between passes and saves the film; status 130. The signal is
// sent once a first checkpoint shows the render under way (a fixed 0.7 s
// could fall before the first pass of a sanitizer build on a busy machine,
// with nothing to save).
TEST_F(Distributed, InterruptSavesTheFilm) {
  auto args = render_args({"--width", "48", "--height", "48", "--spp", "100000", "--film-out", in_work("run.film"),
                           "--checkpoint-seconds", "0.05"});
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
  const auto start = std::chrono::steady_clock::now();
  const auto patience = std::chrono::duration<double>(testing::deadline_for_build(60.0));
  while (!fs::exists(in_work("run.film")) && std::chrono::steady_clock::now() - start < patience)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
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
                           "variance.R, 32-bit floating-point", "count, 32-bit floating-point",
                           "dataWindow (type box2i): (0 0) - (31 23)", "pdflab.strategy (type string): \"mix:cosine=0.5,light=0.5\"",
                           "pdflab.spp (type string): \"4\""})
    EXPECT_NE(header.find(line), std::string::npos) << "lacks '" << line << "':\n" << header;
}

// Issue 33, item 4: the count layer is a FLOAT channel, so the field's tools
// read it as the number of samples (OpenImageIO normalised the old UINT one:
// oiiotool --stats showed a maximum of 0, --ch count stored 1.86e-9 for 8).
TEST_F(Distributed, OiiotoolReadsTheCountAsTheNumberOfSamples) {
  if (shell("command -v oiiotool >/dev/null") != 0)
    GTEST_SKIP() << "oiiotool (Debian's openimageio-tools) is not installed";
  ok(render_args({"--spp", "8", "--out", in_work("image.exr")}));
  const Shell stats = run_shell("oiiotool " + sh_quote(in_work("image.exr")) + " --ch count -o " +
                                    sh_quote(in_work("count.exr")) + " && oiiotool --stats " + sh_quote(in_work("count.exr")),
                                in_work("../oiiotool.txt"));
  ASSERT_EQ(stats.status, 0) << stats.output;
  EXPECT_NE(stats.output.find("Stats Min: 8.000000"), std::string::npos) << stats.output;
  EXPECT_NE(stats.output.find("Stats Max: 8.000000"), std::string::npos) << stats.output;
}

// merge --expect-spp N: the films must be the whole [0, N) of one seed. A gap
// is refused naming the missing range and the film that stopped before it;
// samples beyond N, or of a second seed, too; nothing is written.
TEST_F(Distributed, MergeExpectingTheWholeRefusesGapsAndNamesThem) {
  ok(render_args({"--spp", "16", "--film-out", in_work("a.film")}));
  ok(render_args({"--spp", "8", "--first-sample", "16", "--film-out", in_work("b.film")}));
  ok(render_args({"--spp", "8", "--first-sample", "32", "--film-out", in_work("c.film")}));
  ok(render_args({"--spp", "8", "--first-sample", "24", "--film-out", in_work("gap.film")}));
  ok(render_args({"--spp", "8", "--first-sample", "24", "--seed", "2", "--film-out", in_work("seed2.film")}));
  const std::vector<std::string> films = {in_work("a.film"), in_work("b.film"), in_work("c.film")};
  const auto merge = [&](std::vector<std::string> args) {
    args.insert(args.begin(), "merge");
    args.insert(args.end(), {"--out", in_work("m.exr"), "--film-out", in_work("m.film")});
    return args;
  };
  expect_refusal(merge({in_work("a.film"), in_work("b.film"), in_work("c.film"), "--expect-spp", "40"}),
                 {"hold 32 of the 40 samples per pixel", "missing seed 1 samples [24, 32) after " +
                  quote(in_work("b.film")) + ", which ends there"},
                 {"m.exr", "m.film"});
  expect_refusal(merge({in_work("a.film"), "--expect-spp", "40"}), {"missing seed 1 samples [16, 40)"}, {"m.exr"});
  expect_refusal(merge({in_work("a.film"), in_work("b.film"), in_work("c.film"), in_work("gap.film"), "--expect-spp",
                        "32"}),
                 {"beyond [0, 32): seed 1 samples [32, 40)"}, {"m.exr"});
  expect_refusal(merge({in_work("a.film"), in_work("b.film"), in_work("seed2.film"), "--expect-spp", "24"}),
                 {"samples of 2 seeds"}, {"m.exr"});
  ok(merge({in_work("a.film"), in_work("b.film"), in_work("c.film"), in_work("gap.film"), "--expect-spp", "40"}));
  // A film holding more than --spp asks for is not quietly continued at its size.
  expect_refusal({"render", "--resume", in_work("a.film"), "--spp", "8"}, {"holds 16 samples per pixel"}, {});
}

// Issue 33, item 1: a part that fails keeps what it rendered under its
// partial name, the others finish, the merge is not attempted and the
// continuation is printed; `merge --expect-spp` on what is there refuses the
// gap; the command again (with --parts) resumes the partial part and the
// merge equals one render. Another render's parts folder is refused.
TEST_F(Distributed, AFailedPartIsResumedAndNeverMergedAsWhole) {
  ASSERT_EQ(shell("command -v parallel >/dev/null"), 0) << "GNU parallel is missing (scripts/install_deps.sh)";
  // pdflab, except that while `fail` exists the part from sample 16 renders
  // half its samples and fails (a killed or crashed part that saved a checkpoint).
  const std::string wrapper = in_work("../pdflab-failing.sh"), marker = in_work("../fail"), calls = in_work("../calls");
  write_file(wrapper, "#!/bin/bash\n"
                      "echo \"$*\" >> " + sh_quote(calls) + "\n"
                      "if [ -e " + sh_quote(marker) + " ] && [[ \" $* \" == *\" --first-sample 16 \"* ]]; then\n"
                      "  args=(); prev=''; for a in \"$@\"; do [ \"$prev\" = --spp ] && a=$((a / 2)); args+=(\"$a\"); prev=$a; done\n"
                      "  " + sh_quote(PDFLAB_BINARY) + " \"${args[@]}\"; exit 1\n"
                      "fi\n"
                      "exec " + sh_quote(PDFLAB_BINARY) + " \"$@\"\n");
  fs::permissions(wrapper, fs::perms::owner_all);
  write_file(marker, "");
  const std::string command = "cd " + sh_quote(in_work("")) + " && PDFLAB=" + sh_quote(wrapper) + " bash " +
                              sh_quote(std::string(PDFLAB_SOURCE_DIR) + "/scripts/render_parallel.sh") +
                              " --jobs 4 --spp 64 --out parallel.exr --parts parts -- --scene " + sh_quote(kBookScene) +
                              " --strategy " + sh_quote(kMix) + " --width 32 --height 24 --seed 9";
  const Shell failed = run_shell(command, in_work("../first.log"));
  EXPECT_EQ(failed.status, 1) << failed.output;
  EXPECT_NE(failed.output.find("1 of 4 parts did not finish (first samples: 16"), std::string::npos) << failed.output;
  EXPECT_NE(failed.output.find("continue with:"), std::string::npos) << failed.output;
  EXPECT_FALSE(fs::exists(in_work("parallel.exr"))) << "merged with a part missing";
  EXPECT_FALSE(fs::exists(in_work("parts/part-16.film"))) << "a partial part under its final name";
  ASSERT_TRUE(fs::exists(in_work("parts/partial-16.film")));
  for (const char* whole : {"parts/part-0.film", "parts/part-32.film", "parts/part-48.film"})
    EXPECT_TRUE(fs::exists(in_work(whole))) << whole << ": the other parts went on";

  // Merged by hand, the gap is named; nothing written.
  expect_refusal({"merge", in_work("parts/part-0.film"), in_work("parts/partial-16.film"), in_work("parts/part-32.film"),
                  in_work("parts/part-48.film"), "--expect-spp", "64", "--out", in_work("m.exr")},
                 {"missing seed 9 samples [24, 32) after " + quote(in_work("parts/partial-16.film"))}, {"m.exr"});

  // Another render in the same parts folder is refused.
  std::string other = command;
  other.replace(other.find("--spp 64"), 8, "--spp 32");
  const Shell refused = run_shell(other, in_work("../other.log"));
  EXPECT_EQ(refused.status, 2) << refused.output;
  EXPECT_NE(refused.output.find("holds the parts of another render"), std::string::npos) << refused.output;

  // The documented recovery: the same command again.
  fs::remove(marker);
  fs::remove(calls);
  const Shell again = run_shell(command, in_work("../again.log"));
  ASSERT_EQ(again.status, 0) << again.output;
  const std::string call_log = slurp(calls);
  EXPECT_NE(call_log.find("render --resume parts/partial-16.film"), std::string::npos) << call_log;
  EXPECT_EQ(call_log.find("--first-sample 0 "), std::string::npos) << "a whole part was rendered again:\n" << call_log;
  ok(render_args({"--spp", "64", "--seed", "9", "--out", in_work("single.exr")}));
  const double difference = worst_relative_difference(exr("parallel.exr"), exr("single.exr"));
  EXPECT_LE(difference, 1e-6);
  EXPECT_EQ(read_exr_attribute(in_work("parallel.exr"), "pdflab.samples"), "seed 9 samples [0, 64)");
  std::printf("a part stopped at half and failed; the command again resumed it; merged against one render: %.2e\n",
              difference);
}

// A real sshd on localhost (its own keys, port and config, in the test's
// folder), for GNU parallel's --sshlogin; empty when it cannot start.
class LocalSshd {
 public:
  explicit LocalSshd(const fs::path& dir) : dir_(dir) {
    const std::string sshd = "/usr/sbin/sshd";
    if (!fs::exists(sshd)) {
      why_ = "no " + sshd + " (Debian's openssh-server)";
      return;
    }
    // sshd running as root separates privileges into /run/sshd, which an
    // ssh service makes at start-up; a machine without the service lacks it.
    if (::geteuid() == 0 && !fs::exists("/run/sshd")) {
      std::error_code ec;
      fs::create_directories("/run/sshd", ec);
    }
    fs::create_directories(dir_);
    const std::string d = dir_.string();
    if (shell("ssh-keygen -q -t ed25519 -N '' -f " + sh_quote(d + "/host_key") + " && ssh-keygen -q -t ed25519 -N '' -f " +
              sh_quote(d + "/id") + " && cp " + sh_quote(d + "/id.pub") + " " + sh_quote(d + "/authorized_keys")) != 0) {
      why_ = "ssh-keygen failed";
      return;
    }
    for (int attempt = 0; attempt < 5 && port_ == 0; ++attempt) {
      const int port = 20000 + static_cast<int>((static_cast<unsigned>(::getpid()) * 7919u + 131u * static_cast<unsigned>(attempt)) % 30000u);
      write_file(d + "/sshd_config", "Port " + std::to_string(port) + "\nListenAddress 127.0.0.1\nHostKey " + d +
                                         "/host_key\nAuthorizedKeysFile " + d + "/authorized_keys\nPidFile " + d +
                                         "/sshd.pid\nStrictModes no\nUsePAM no\nPasswordAuthentication no\n"
                                         "KbdInteractiveAuthentication no\nPubkeyAuthentication yes\n"
                                         "PermitRootLogin prohibit-password\n");
      if (shell(sshd + " -f " + sh_quote(d + "/sshd_config") + " -E " + sh_quote(d + "/sshd.log")) != 0) continue;
      ssh_ = "ssh -p " + std::to_string(port) + " -i " + d + "/id -o StrictHostKeyChecking=no -o UserKnownHostsFile=/dev/null "
             "-o BatchMode=yes -o LogLevel=ERROR -o ConnectTimeout=10";
      for (int wait = 0; wait < 100; ++wait) {
        if (shell(ssh_ + " 127.0.0.1 true > /dev/null 2>&1") == 0) {
          port_ = port;
          break;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
      }
      if (port_ == 0) stop();
    }
    if (port_ == 0) why_ = "sshd did not start or refused the login: " + slurp(dir_ / "sshd.log");
  }
  ~LocalSshd() { stop(); }
  bool running() const { return port_ != 0; }
  const std::string& why_not() const { return why_; }
  const std::string& ssh_command() const { return ssh_; }  // for $PARALLEL_SSH

 private:
  void stop() {
    const std::string pid = slurp(dir_ / "sshd.pid");
    if (!pid.empty()) ::kill(static_cast<pid_t>(std::stol(pid)), SIGTERM);
    std::error_code ec;
    fs::remove(dir_ / "sshd.pid", ec);
  }
  fs::path dir_;
  int port_ = 0;
  std::string why_, ssh_;
};

// Issue 33, item 2: the --sshlogin recipe run from a folder that is not the
// login's home, with relative paths (the scene, the parts, the image): each
// job starts in the submitting folder; slots asked for (4/) are dropped, so
// a machine runs one part at a time on all its cores (--threads 0).
TEST_F(Distributed, SshRecipeFromAnyFolderWithRelativePathsOneJobPerHost) {
  ASSERT_EQ(shell("command -v parallel >/dev/null"), 0) << "GNU parallel is missing (scripts/install_deps.sh)";
  LocalSshd sshd(fs::path(in_work("..")) / "sshd");
  if (!sshd.running()) GTEST_SKIP() << "no sshd on localhost for the test: " << sshd.why_not();
  fs::create_directories(in_work("scenes"));
  fs::copy_file(kBookScene, in_work("scenes/box.json"));
  // pdflab, noting where and with how many threads it ran, and whether another part was running.
  const std::string wrapper = in_work("../pdflab-logged.sh"), log = in_work("../parts.log"), lock = in_work("../running");
  write_file(wrapper, "#!/bin/bash\n"
                      "[ \"$1\" = render ] || exec " + sh_quote(PDFLAB_BINARY) + " \"$@\"\n"
                      "mkdir " + sh_quote(lock) + " 2>/dev/null || echo overlap >> " + sh_quote(log) + "\n"
                      "t=; prev=; for a in \"$@\"; do [ \"$prev\" = --threads ] && t=$a; prev=$a; done\n"
                      "echo \"part in $PWD with threads $t\" >> " + sh_quote(log) + "\n"
                      + sh_quote(PDFLAB_BINARY) + " \"$@\"; rc=$?\n"
                      "rmdir " + sh_quote(lock) + "\n"
                      "exit $rc\n");
  fs::permissions(wrapper, fs::perms::owner_all);
  const std::string command = "cd " + sh_quote(in_work("")) + " && PARALLEL_SSH=" + sh_quote(sshd.ssh_command()) +
                              " PDFLAB=" + sh_quote(wrapper) + " bash " +
                              sh_quote(std::string(PDFLAB_SOURCE_DIR) + "/scripts/render_parallel.sh") +
                              " --jobs 3 --spp 48 --out ssh.exr --parts parts --sshlogin 4/127.0.0.1"
                              " -- --scene scenes/box.json --strategy " + sh_quote(kMix) +
                              " --width 32 --height 24 --seed 4";
  const Shell r = run_shell(command, in_work("../ssh.log"));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("one part at a time per machine"), std::string::npos) << r.output;
  const std::string parts = slurp(log);
  EXPECT_EQ(parts.find("overlap"), std::string::npos) << "two parts at once on one machine:\n" << parts;
  const std::string expected = "part in " + fs::path(in_work("")).parent_path().string() + " with threads 0\n";
  std::size_t count = 0;
  for (std::size_t at = parts.find(expected); at != std::string::npos; at = parts.find(expected, at + 1)) ++count;
  EXPECT_EQ(count, 3u) << "each part in the submitting folder on all cores:\n" << parts;
  ok(render_args({"--spp", "48", "--seed", "4", "--out", in_work("single.exr")}));
  const double difference = worst_relative_difference(exr("ssh.exr"), exr("single.exr"));
  EXPECT_LE(difference, 1e-6);
  std::printf("3 parts over ssh to localhost from a folder with relative paths, merged against one render: %.2e\n",
              difference);
}

// Issue 33, item 3: the Slurm script's body, run per task with the variables
// Slurm sets. A task redone alone (sbatch --array=2: its count is 1 and its
// minimum 2) renders its own range; a 1-based array works; a preempted task
// resumes its partial film; a film of another render is refused; the merge
// with a task missing names the array index to run again and writes nothing.
TEST_F(Distributed, SlurmTasksRecoverAndTheMergeNamesWhatIsMissing) {
  const std::string script = std::string(PDFLAB_SOURCE_DIR) + "/scripts/slurm_render.sbatch";
  const std::string args = "--scene " + kBookScene + " --strategy cosine --width 16 --height 12 --seed 5";
  const auto task = [&](const std::string& parts, int id, int min, int count, const std::string& extra = "") {
    return run_shell("PDFLAB=" + sh_quote(PDFLAB_BINARY) + " SPP=40 TASKS=4 PARTS=" + sh_quote(parts) +
                         " RENDER_ARGS=" + sh_quote(args) + " SLURM_ARRAY_TASK_ID=" + std::to_string(id) +
                         " SLURM_ARRAY_TASK_MIN=" + std::to_string(min) + " SLURM_ARRAY_TASK_COUNT=" +
                         std::to_string(count) + " SLURM_CPUS_PER_TASK=2 " + extra + " bash " + sh_quote(script),
                     in_work("../task.log"));
  };
  const auto merge = [&](const std::string& parts, const std::string& out) {
    return run_shell("PDFLAB=" + sh_quote(PDFLAB_BINARY) + " SPP=40 TASKS=4 PARTS=" + sh_quote(parts) +
                         " MERGE=1 OUT=" + sh_quote(out) + " bash " + sh_quote(script),
                     in_work("../merge.log"));
  };
  ok({"render", "--scene", kBookScene, "--strategy", "cosine", "--width", "16", "--height", "12", "--seed", "5",
      "--spp", "40", "--quiet", "--out", in_work("single.exr")});

  // 0-63 style, one task lost; the merge names it; run alone, it renders part 2.
  const std::string parts = in_work("parts");
  for (int id : {0, 1, 3}) ASSERT_EQ(task(parts, id, 0, 4).status, 0) << id;
  const Shell missing = merge(parts, in_work("a.exr"));
  EXPECT_EQ(missing.status, 1) << missing.output;
  EXPECT_NE(missing.output.find("array indices 2"), std::string::npos) << missing.output;
  EXPECT_FALSE(fs::exists(in_work("a.exr")));
  const Shell redo = task(parts, 2, 2, 1);
  ASSERT_EQ(redo.status, 0) << redo.output;
  ASSERT_EQ(merge(parts, in_work("a.exr")).status, 0) << slurp(in_work("../merge.log"));
  EXPECT_LE(worst_relative_difference(exr("a.exr"), exr("single.exr")), 1e-6);
  EXPECT_EQ(read_exr_attribute(in_work("a.exr"), "pdflab.samples"), "seed 5 samples [0, 40)");

  // 1-64 style, and task 2 (part 1, [10, 20)) was preempted after [10, 15): it resumes.
  const std::string one_based = in_work("one-based");
  fs::create_directories(one_based);
  ok({"render", "--scene", kBookScene, "--strategy", "cosine", "--width", "16", "--height", "12", "--seed", "5",
      "--first-sample", "10", "--spp", "5", "--quiet", "--film-out", one_based + "/partial-1.film"});
  for (int id : {1, 2, 3, 4}) ASSERT_EQ(task(one_based, id, 1, 4).status, 0) << slurp(in_work("../task.log"));
  ASSERT_EQ(merge(one_based, in_work("b.exr")).status, 0) << slurp(in_work("../merge.log"));
  EXPECT_LE(worst_relative_difference(exr("b.exr"), exr("single.exr")), 1e-6);
  EXPECT_FALSE(fs::exists(one_based + "/partial-1.film"));

  // A partial film of another seed, or of another size, is not continued.
  const std::pair<std::string, std::string> stale[] = {
      {"--width 16 --height 12 --seed 6", "seed 6, not 5"}, {"--width 20 --height 12 --seed 5", "is 20x12"}};
  for (const auto& [settings, needle] : stale) {
    const std::string dir = in_work("stale-" + needle.substr(0, 4));
    fs::create_directories(dir);
    ASSERT_EQ(shell(sh_quote(PDFLAB_BINARY) + " render --scene " + sh_quote(kBookScene) + " --strategy cosine " +
                    settings + " --spp 3 --quiet --film-out " + sh_quote(dir + "/partial-0.film") + " > /dev/null"),
              0);
    const Shell refused = task(dir, 0, 0, 4);
    EXPECT_EQ(refused.status, 2) << settings << ": " << refused.output;
    EXPECT_NE(refused.output.find(needle), std::string::npos) << refused.output;
  }
  // Another render's parts folder, and a lone redo before any layout, are refused.
  const Shell other = task(parts, 0, 0, 4, "SPP=80");
  EXPECT_EQ(other.status, 2) << other.output;
  EXPECT_NE(other.output.find("holds the parts of another render"), std::string::npos) << other.output;
  const Shell lone = task(in_work("fresh"), 2, 2, 1);
  EXPECT_EQ(lone.status, 2) << lone.output;
  EXPECT_NE(lone.output.find("set FIRST_TASK"), std::string::npos) << lone.output;
}

// Issue 33, item 12: a film's strategy text is exact, so --resume without
// --strategy continues the very estimator (a parameter stored to six digits,
// or weights 1:2 as 0.333333:0.666667, continued another): the same image,
// bit for bit, as an uninterrupted render.
TEST_F(Distributed, ResumeWithoutTheStrategyContinuesTheSameEstimator) {
  for (const std::string strategy : {"cosine-power:3.1415926", "mix:cosine=1,light=2"}) {
    SCOPED_TRACE(strategy);
    ok(render_args({"--strategy", strategy, "--spp", "16", "--out", in_work("whole.pfm")}));
    ok(render_args({"--strategy", strategy, "--spp", "8", "--film-out", in_work("half.film")}));
    ok({"render", "--resume", in_work("half.film"), "--spp", "16", "--out", in_work("resumed.pfm"), "--quiet"});
    EXPECT_EQ(pfm("resumed.pfm"), pfm("whole.pfm"));
    // Named again, it is accepted as the film's own.
    ok({"render", "--resume", in_work("half.film"), "--strategy", strategy, "--spp", "16", "--quiet"});
  }
}

// A resumed render's summary describes the whole film: its time, samples and
// efficiency include what the film held (they were this run's alone, beside
// the whole film's spp and error, so the efficiency was overstated).
TEST_F(Distributed, AResumedRenderCountsTheWholeFilmsTime) {
  ok(render_args({"--spp", "8", "--film-out", in_work("half.film")}));
  const double before = read_film_file(in_work("half.film")).info.seconds;
  ASSERT_GT(before, 0.0);
  ok({"render", "--resume", in_work("half.film"), "--spp", "16", "--stats-json", in_work("stats.json"), "--quiet"});
  const nlohmann::json j = nlohmann::json::parse(slurp(in_work("stats.json")));
  EXPECT_EQ(j.at("samples").get<std::uint64_t>(), 16u * 32u * 24u);
  const double seconds = j.at("seconds").get<double>();
  EXPECT_GT(seconds, before);
  EXPECT_DOUBLE_EQ(read_film_file(in_work("half.film")).info.seconds, seconds);
  EXPECT_NEAR(j.at("samples_per_second").get<double>(), 16.0 * 32 * 24 / seconds, 1e-6 * 16 * 32 * 24 / seconds);
  EXPECT_DOUBLE_EQ(j.at("est_efficiency").get<double>(), efficiency(j.at("est_relmse").get<double>(), seconds));
}

}  // namespace
}  // namespace pdflab
