// `pdflab sweep` on the real binary: bad ranges and techniques exit 2 with a
// message naming the problem and write nothing; a tiny sweep writes one row per
// weight with the documented columns, the same errors `pdflab bench` measures
// for the same mixture and seed, one best weight inside its own interval, and
// a plot with the best weight marked.
#include "tests/command_test.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

const std::string kBookScene = std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes/cornell_book.json";

using pdflab::testing::ChildResult;
using pdflab::testing::slurp;
using pdflab::testing::png_size;

// One CSV line into fields; a field in double quotes may hold commas.
std::vector<std::string> csv_fields(const std::string& line) {
  std::vector<std::string> out(1);
  bool quoted = false;
  for (char c : line) {
    if (c == '"') quoted = !quoted;
    else if (c == ',' && !quoted) out.emplace_back();
    else out.back() += c;
  }
  return out;
}

std::vector<std::map<std::string, std::string>> read_csv(const std::string& text, std::vector<std::string>& header) {
  std::stringstream ss(text);
  std::string line;
  std::vector<std::map<std::string, std::string>> rows;
  if (!std::getline(ss, line)) return rows;
  header = csv_fields(line);
  while (std::getline(ss, line)) {
    const std::vector<std::string> fields = csv_fields(line);
    EXPECT_EQ(fields.size(), header.size()) << line;
    std::map<std::string, std::string> row;
    for (std::size_t i = 0; i < header.size() && i < fields.size(); ++i) row[header[i]] = fields[i];
    rows.push_back(row);
  }
  return rows;
}

double number(const std::map<std::string, std::string>& row, const std::string& column) {
  const auto it = row.find(column);
  if (it == row.end() || it->second.empty()) return std::nan("");
  return std::strtod(it->second.c_str(), nullptr);
}

class SweepCommand : public pdflab::testing::CommandTest {
 protected:
  SweepCommand() : CommandTest("pdflab-sweep") {}

  void make_reference() const { render_reference("nee-mis"); }
  std::vector<std::string> sweep_args(const std::vector<std::string>& extra) const {
    std::vector<std::string> a = {"sweep", "--scene", kBookScene, "--reference", in_work("ref.pfm"), "--csv",
                                  in_work("out.csv"), "--plot", in_work("out.svg"), "--threads", "2", "--quiet"};
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  }
};

TEST_F(SweepCommand, BadRangesAreBadInput) {
  make_reference();
  const std::vector<std::string> ok = {"--vary", "cosine,light", "--spp", "2"};
  auto with = [&](const std::string& weights) {
    std::vector<std::string> a = sweep_args(ok);
    a.insert(a.end(), {"--weights", weights});
    return a;
  };
  expect_bad_input(with("0.9:0.1:0.1"), "LO must be less than HI");
  expect_bad_input(with("0.5:0.5:0.1"), "LO must be less than HI");
  expect_bad_input(with("0:1:0"), "STEP must be positive");
  expect_bad_input(with("0:1:-0.1"), "STEP must be positive");
  expect_bad_input(with("-0.1:1:0.1"), "must lie in [0, 1]");
  expect_bad_input(with("0:1.5:0.1"), "must lie in [0, 1]");
  expect_bad_input(with("0:1"), "not LO:HI:STEP");
  expect_bad_input(with("0:1:0.1:"), "not LO:HI:STEP");
  expect_bad_input(with("a:1:0.1"), "LO 'a' is not a number");
  expect_bad_input(with("0:nan:0.1"), "HI 'nan' is not a number");
  expect_bad_input(with("0:1:0.0001"), "more than 201 weights");
  expect_bad_input(with("0.1:0.2:0.5"), "a sweep needs two weights");
}

TEST_F(SweepCommand, BadTechniquesAreBadInput) {
  make_reference();
  auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> a = sweep_args({"--weights", "0:1:0.5", "--spp", "2"});
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  };
  expect_bad_input(with({"--vary", "cosine"}), "not two techniques");
  expect_bad_input(with({"--vary", "cosine,light,light-sa"}), "not two techniques");
  expect_bad_input(with({"--vary", "cosine,cosine"}), "same technique twice");
  expect_bad_input(with({"--vary", "cosine,lamp"}), "--vary 'cosine,lamp': unknown strategy 'lamp'");
  expect_bad_input(with({"--vary", "cosine,nee-mis"}), "not a mixture technique");
  expect_bad_input(with({"--vary", "cosine,light", "--strategy", "nee-mis"}), "nee-mis is not a mixture");
  expect_bad_input(with({"--vary", "cosine,light", "--strategy", "uniform-sphere"}), "no weight");
  expect_bad_input(with({"--vary", "cosine,light", "--seeds", "0"}), "--seeds");
  expect_bad_input(with({"--vary", "cosine,light", "--seconds", "1"}), "exactly one");
  // At weight 0 the mixture is `light` alone, and this scene has no importance targets.
  const std::string no_targets = in_work("no_targets.json");
  {
    std::ofstream out(no_targets);
    out << R"({"camera": {"width": 12, "height": 8, "lookfrom": [0, 0, 3], "lookat": [0, 0, 0], "vup": [0, 1, 0],
                 "vfov": 40},
      "materials": {"white": {"type": "lambertian", "albedo": [0.7, 0.7, 0.7]}},
      "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "white"}]})";
  }
  std::vector<std::string> a = {"sweep", "--scene", no_targets, "--reference", in_work("ref.pfm"), "--csv",
                                in_work("out.csv"), "--vary", "cosine,light", "--weights", "0:1:0.5", "--spp", "2",
                                "--quiet"};
  expect_bad_input(a, "target");
}

TEST_F(SweepCommand, TinySweepWritesOneRowPerWeight) {
  make_reference();
  const ChildResult r =
      run(sweep_args({"--vary", "cosine,light", "--weights", "0:1:0.25", "--spp", "4", "--seeds", "2", "--map",
                      in_work("map.png")}));
  ASSERT_EQ(r.status, 0) << r.err;
  std::vector<std::string> header;
  const auto rows = read_csv(slurp(in_work("out.csv")), header);
  for (const char* column : {"weight", "relmse", "relmse_lo", "relmse_hi", "efficiency", "efficiency_lo",
                             "efficiency_hi", "samples_per_second", "predicted_efficiency", "best", "in_best_interval",
                             "rays_per_sample", "seconds_per_sample", "model_seconds_per_sample"})
    EXPECT_NE(std::find(header.begin(), header.end(), column), header.end()) << column;
  ASSERT_EQ(rows.size(), 5u);
  const double expected_weights[5] = {0.0, 0.25, 0.5, 0.75, 1.0};
  int best = -1, bests = 0;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_DOUBLE_EQ(number(rows[i], "weight"), expected_weights[i]);
    EXPECT_EQ(rows[i].at("seeds"), "2");
    EXPECT_EQ(rows[i].at("spp"), "4");
    EXPECT_GT(number(rows[i], "relmse"), 0.0);
    EXPECT_LE(number(rows[i], "relmse_lo"), number(rows[i], "relmse"));
    EXPECT_GE(number(rows[i], "relmse_hi"), number(rows[i], "relmse"));
    EXPECT_LE(number(rows[i], "efficiency_lo"), number(rows[i], "efficiency"));
    EXPECT_GE(number(rows[i], "efficiency_hi"), number(rows[i], "efficiency"));
    // Pooled over the seeds: 1 / (mean relMSE x spp * mean seconds per sample),
    // not the mean of each run's efficiency.
    EXPECT_NEAR(number(rows[i], "efficiency"),
                1.0 / (number(rows[i], "relmse_per_sample") * number(rows[i], "seconds_per_sample")),
                1e-4 * number(rows[i], "efficiency"));
    EXPECT_NEAR(number(rows[i], "relmse_per_sample"), number(rows[i], "relmse") * 4.0,
                1e-4 * number(rows[i], "relmse_per_sample"));  // 4 spp every run
    EXPECT_LE(number(rows[i], "relmse_per_sample_lo"), number(rows[i], "relmse_per_sample"));
    if (rows[i].at("best") == "1") best = static_cast<int>(i), ++bests;
    // Every path traces at least its camera ray; the cost model gives every row a time.
    EXPECT_GE(number(rows[i], "rays_per_sample"), 1.0) << i;
    EXPECT_GT(number(rows[i], "seconds_per_sample"), 0.0) << i;
    EXPECT_GT(number(rows[i], "model_seconds_per_sample"), 0.0) << i;
    // Predicted from the paths at 0.5: positive for every unbiased mixture.
    if (i > 0) {
      EXPECT_GT(number(rows[i], "predicted_efficiency"), 0.0) << i;
      EXPECT_LE(number(rows[i], "predicted_efficiency_lo"), number(rows[i], "predicted_efficiency"));
      EXPECT_LE(number(rows[i], "predicted_relative_efficiency"), 1.0);
    }
  }
  EXPECT_EQ(rows[0].at("strategy"), "light");
  EXPECT_EQ(rows[0].at("unbiased"), "0");  // light alone misses indirect light
  EXPECT_EQ(rows[2].at("strategy"), "mix:cosine=0.5,light=0.5");
  EXPECT_EQ(rows[4].at("strategy"), "cosine");
  ASSERT_EQ(bests, 1);
  EXPECT_NE(best, 0) << "a biased mixture is never the best weight";
  EXPECT_EQ(rows[static_cast<std::size_t>(best)].at("in_best_interval"), "1");
  EXPECT_DOUBLE_EQ(number(rows[static_cast<std::size_t>(best)], "relative_efficiency"), 1.0);

  // Equal samples and the same seed: the sweep's first seed renders the image
  // `pdflab bench` renders for the same mixture, and measures the same error.
  const ChildResult b = run({"bench", "--scene", kBookScene, "--reference", in_work("ref.pfm"), "--csv",
                             in_work("bench.csv"), "--strategies", "mix:cosine=0.5,light=0.5", "--spp", "4",
                             "--threads", "2", "--quiet"});
  ASSERT_EQ(b.status, 0) << b.err;
  const ChildResult one =
      run({"sweep", "--scene", kBookScene, "--reference", in_work("ref.pfm"), "--csv", in_work("one.csv"), "--vary",
           "cosine,light", "--weights", "0.5:1:0.5", "--spp", "4", "--seeds", "1", "--threads", "2", "--quiet"});
  ASSERT_EQ(one.status, 0) << one.err;
  std::vector<std::string> bench_header, one_header;
  const auto bench_rows = read_csv(slurp(in_work("bench.csv")), bench_header);
  const auto one_rows = read_csv(slurp(in_work("one.csv")), one_header);
  ASSERT_EQ(bench_rows.size(), 1u);
  ASSERT_EQ(one_rows.size(), 2u);
  EXPECT_NEAR(number(one_rows[0], "relmse"), number(bench_rows[0], "relmse"), 1e-5 * number(bench_rows[0], "relmse"));

  const std::string svg = slurp(in_work("out.svg"));
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  EXPECT_NE(svg.find("best " + std::string(best == 1 ? "0.25" : best == 2 ? "0.5" : best == 3 ? "0.75" : "1")),
            std::string::npos);
  EXPECT_NE(svg.find("weight of cosine"), std::string::npos);
  EXPECT_NE(svg.find("predicted from w = 0.5"), std::string::npos);
  // The map: a PNG of the reference's size times 6, plus its scale bar.
  EXPECT_EQ(png_size(slurp(in_work("map.png"))), std::make_pair(12u * 6u, 8u * 6u + 4u + 16u));
  EXPECT_NE(r.out.find("predicted best weight"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("best fixed weight's efficiency, fairly"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("cost model: seconds per sample"), std::string::npos) << r.out;
}

}  // namespace

namespace {

// --reference auto takes the cached reference of the scene at the given size;
// without one in the cache it is bad input before anything renders.
TEST_F(SweepCommand, AutoReferenceComesFromTheCache) {
  const std::string cache = in_work("cache");
  const std::vector<std::string> sweep = {"sweep", "--scene", kBookScene, "--reference", "auto", "--width", "12",
                                          "--height", "8", "--cache-dir", cache, "--csv", in_work("auto.csv"),
                                          "--vary", "cosine,light", "--weights", "0.25:0.75:0.5", "--spp", "2",
                                          "--seeds", "1", "--threads", "2", "--quiet"};
  expect_bad_input(sweep, "no cached reference");
  const ChildResult made = run({"reference", "--scene", kBookScene, "--width", "12", "--height", "8", "--spp", "64",
                                "--cache-dir", cache, "--threads", "2", "--quiet"});
  ASSERT_EQ(made.status, 0) << made.err;
  const ChildResult r = run(sweep);
  ASSERT_EQ(r.status, 0) << r.err;
  std::vector<std::string> header;
  const auto rows = read_csv(slurp(in_work("auto.csv")), header);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_GT(number(rows[0], "efficiency"), 0.0);
}

}  // namespace

namespace {

TEST_F(SweepCommand, AutoWeightAddsARow) {
  make_reference();
  const ChildResult r =
      run(sweep_args({"--vary", "cosine,light", "--weights", "0.25:0.75:0.25", "--spp", "16", "--seeds", "2", "--auto"}));
  ASSERT_EQ(r.status, 0) << r.err;
  std::vector<std::string> header;
  const auto rows = read_csv(slurp(in_work("out.csv")), header);
  ASSERT_EQ(rows.size(), 4u);
  const std::string history = rows[3].at("strategy");
  ASSERT_EQ(history.rfind("auto:0.5>", 0), 0u) << history;
  EXPECT_EQ(std::count(history.begin(), history.end(), '>'), 4) << "five passes";
  EXPECT_GT(number(rows[3], "efficiency"), 0.0);
  EXPECT_NE(r.out.find("auto weight: efficiency"), std::string::npos) << r.out;
}

// A cosine/guided pair: each weight's run trains its own tree; auto weight's
// first pass trains and its later passes draw from that tree; the prediction
// replays with the pilot's.
TEST_F(SweepCommand, GuidedPairIsSweptAndAutoWeighted) {
  make_reference();
  const ChildResult r = run(
      sweep_args({"--vary", "cosine,guided:2", "--weights", "0.25:0.75:0.5", "--spp", "16", "--seeds", "1", "--auto"}));
  ASSERT_EQ(r.status, 0) << r.err;
  std::vector<std::string> header;
  const auto rows = read_csv(slurp(in_work("out.csv")), header);
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0].at("strategy"), "mix:cosine=0.25,guided:2=0.75");
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_GT(number(rows[i], "efficiency"), 0.0) << i;
    EXPECT_GT(number(rows[i], "predicted_efficiency"), 0.0) << i;
  }
  const std::string history = rows[2].at("strategy");
  ASSERT_EQ(history.rfind("auto:0.5>", 0), 0u) << history;
  EXPECT_EQ(std::count(history.begin(), history.end(), '>'), 4) << "five passes";
  EXPECT_GT(number(rows[2], "efficiency"), 0.0);
}

}  // namespace

namespace {

// --cpu-time prices the runs by the process's CPU time: every row gets a time
// per sample and the pooled efficiency from it, and stdout says which clock
// priced the runs and what the load was.
TEST_F(SweepCommand, CpuTimePricesTheRuns) {
  make_reference();
  const ChildResult r = run(sweep_args({"--vary", "cosine,light", "--weights", "0.25:0.75:0.5", "--spp", "16",
                                        "--seeds", "2", "--cpu-time"}));
  ASSERT_EQ(r.status, 0) << r.err;
  std::vector<std::string> header;
  const auto rows = read_csv(slurp(in_work("out.csv")), header);
  ASSERT_EQ(rows.size(), 2u);
  for (const auto& row : rows) {
    EXPECT_GT(number(row, "seconds_per_sample"), 0.0);
    EXPECT_NEAR(number(row, "efficiency"), 1.0 / (number(row, "relmse_per_sample") * number(row, "seconds_per_sample")),
                1e-4 * number(row, "efficiency"));
  }
  EXPECT_NE(r.out.find("runs priced by their CPU time"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("load average (1 min)"), std::string::npos) << r.out;
}

}  // namespace
