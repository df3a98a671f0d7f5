// `pdflab bench` on the real binary: every class of bad input exits 2 with a
// message naming the problem and writes nothing; a tiny run writes a CSV with
// the documented columns, a curves CSV and a well-formed SVG plot.
#include "tests/command_test.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

const std::string kBookScene = std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes/cornell_book.json";

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

using pdflab::testing::ChildResult;
using pdflab::testing::slurp;
using pdflab::testing::png_size;

std::vector<std::string> split(const std::string& text, char sep) {
  std::vector<std::string> parts;
  std::stringstream ss(text);
  std::string part;
  while (std::getline(ss, part, sep)) parts.push_back(part);
  if (!text.empty() && text.back() == sep) parts.emplace_back();  // a last field left empty
  return parts;
}

// CSV rows as column name -> field; the first field may be quoted and hold commas.
std::vector<std::map<std::string, std::string>> parse_csv(const std::string& text, std::vector<std::string>& header) {
  std::vector<std::string> lines = split(text, '\n');
  std::vector<std::map<std::string, std::string>> rows;
  if (lines.empty()) return rows;
  header = split(lines[0], ',');
  for (std::size_t i = 1; i < lines.size(); ++i) {
    if (lines[i].empty()) continue;
    std::vector<std::string> fields;
    std::string rest = lines[i];
    if (!rest.empty() && rest[0] == '"') {
      const std::size_t close = rest.find('"', 1);
      fields.push_back(rest.substr(1, close - 1));
      rest = close + 1 < rest.size() ? rest.substr(close + 2) : "";
    }
    for (const std::string& f : split(rest, ',')) fields.push_back(f);
    std::map<std::string, std::string> row;
    for (std::size_t c = 0; c < header.size() && c < fields.size(); ++c) row[header[c]] = fields[c];
    row["#fields"] = std::to_string(fields.size());
    rows.push_back(row);
  }
  return rows;
}

// Minimal XML well-formedness: every element closed in order, one root, no
// stray '<' or unescaped '&' in text or attribute values.
::testing::AssertionResult well_formed_xml(const std::string& doc) {
  std::vector<std::string> open;
  int roots = 0;
  std::size_t i = 0;
  auto check_entities = [&](std::size_t from, std::size_t to) -> bool {
    for (std::size_t k = from; k < to; ++k) {
      if (doc[k] == '<') return false;
      if (doc[k] == '&') {
        const std::size_t semi = doc.find(';', k);
        if (semi == std::string::npos || semi > to || semi - k > 8) return false;
      }
    }
    return true;
  };
  while (i < doc.size()) {
    const std::size_t lt = doc.find('<', i);
    if (lt == std::string::npos) {
      if (!check_entities(i, doc.size())) return ::testing::AssertionFailure() << "bad text at the end";
      break;
    }
    if (!check_entities(i, lt)) return ::testing::AssertionFailure() << "bad character in text before offset " << lt;
    if (doc.compare(lt, 4, "<!--") == 0) {
      const std::size_t end = doc.find("-->", lt);
      if (end == std::string::npos) return ::testing::AssertionFailure() << "unterminated comment";
      i = end + 3;
      continue;
    }
    if (doc.compare(lt, 2, "<?") == 0) {
      const std::size_t end = doc.find("?>", lt);
      if (end == std::string::npos) return ::testing::AssertionFailure() << "unterminated declaration";
      i = end + 2;
      continue;
    }
    // Find the tag's end outside quoted attribute values.
    std::size_t gt = lt + 1;
    char quote = 0;
    for (; gt < doc.size(); ++gt) {
      if (quote) {
        if (doc[gt] == quote) quote = 0;
        else if (doc[gt] == '<') return ::testing::AssertionFailure() << "'<' in an attribute at " << gt;
      } else if (doc[gt] == '"' || doc[gt] == '\'') {
        quote = doc[gt];
      } else if (doc[gt] == '>') {
        break;
      }
    }
    if (gt >= doc.size()) return ::testing::AssertionFailure() << "unterminated tag at " << lt;
    std::string tag = doc.substr(lt + 1, gt - lt - 1);
    const bool closing = !tag.empty() && tag[0] == '/';
    const bool self_closing = !tag.empty() && tag.back() == '/';
    std::string name = tag.substr(closing ? 1 : 0);
    name = name.substr(0, name.find_first_of(" \t\n/"));
    if (name.empty()) return ::testing::AssertionFailure() << "tag without a name at " << lt;
    if (closing) {
      if (open.empty() || open.back() != name)
        return ::testing::AssertionFailure() << "</" << name << "> closes " << (open.empty() ? "nothing" : open.back());
      open.pop_back();
    } else {
      if (open.empty() && ++roots > 1) return ::testing::AssertionFailure() << "more than one root element";
      if (!self_closing) open.push_back(name);
    }
    i = gt + 1;
  }
  if (!open.empty()) return ::testing::AssertionFailure() << "<" << open.back() << "> never closed";
  if (roots != 1) return ::testing::AssertionFailure() << "no root element";
  return ::testing::AssertionSuccess();
}

class BenchCommand : public pdflab::testing::CommandTest {
 protected:
  BenchCommand() : CommandTest("pdflab-bench") {}

  void make_reference(const std::string& name = "ref.pfm") const { render_reference("mix:cosine=0.5,light=0.5", name); }

  std::vector<std::string> bench_args(const std::vector<std::string>& extra) const {
    std::vector<std::string> a = {"bench", "--scene", kBookScene, "--reference", in_work("ref.pfm"),
                                  "--csv", in_work("out.csv"), "--plot", in_work("out.svg"), "--curves",
                                  in_work("curves.csv"), "--threads", "2", "--quiet"};
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  }
};

TEST_F(BenchCommand, MissingReferenceIsBadInput) {
  expect_bad_input(bench_args({"--strategies", "cosine", "--spp", "2"}), "ref.pfm");
}

TEST_F(BenchCommand, ReferenceThatIsNotAPfmIsBadInput) {
  write_text(work() / "ref.pfm", "P6\n2 2\n255\n............");
  expect_bad_input(bench_args({"--strategies", "cosine", "--spp", "2"}), "not a colour PFM");
  write_text(work() / "ref.pfm", "PF\n4 4\n-1.0\n");  // header without pixels
  expect_bad_input(bench_args({"--strategies", "cosine", "--spp", "2"}), "truncated");
}

TEST_F(BenchCommand, ReferenceWithNonFiniteValuesIsBadInput) {
  // 2x1 little-endian PFM; the second pixel's green is NaN.
  std::string pfm = "PF\n2 1\n-1.0\n";
  const float values[6] = {0.5f, 0.5f, 0.5f, 0.5f, std::nanf(""), 0.5f};
  pfm.append(reinterpret_cast<const char*>(values), sizeof values);
  write_text(work() / "ref.pfm", pfm);
  expect_bad_input(bench_args({"--strategies", "cosine", "--spp", "2"}), "not finite (first at pixel 1,0)");
}

TEST_F(BenchCommand, ExactlyOneOfSecondsAndSpp) {
  make_reference();
  expect_bad_input(bench_args({"--strategies", "cosine", "--spp", "2", "--seconds", "1"}), "exactly one");
  expect_bad_input(bench_args({"--strategies", "cosine"}), "exactly one");
}

TEST_F(BenchCommand, SecondsMustBePositiveAndFinite) {
  make_reference();
  for (const char* bad : {"0", "-1", "nan", "inf", "soon"})
    expect_bad_input(bench_args({"--strategies", "cosine", "--seconds", bad}), "--seconds");
  expect_bad_input(bench_args({"--strategies", "cosine", "--spp", "0"}), "--spp");
}

TEST_F(BenchCommand, StrategiesAreChecked) {
  make_reference();
  expect_bad_input(bench_args({"--strategies", "cosine;bogus", "--spp", "2"}), "bogus");
  expect_bad_input(bench_args({"--strategies", " ; ", "--spp", "2"}), "no strategy");
}

TEST_F(BenchCommand, OutputsMustBeWritableAndDistinct) {
  make_reference();
  std::vector<std::string> args = {"bench", "--scene", kBookScene, "--reference", in_work("ref.pfm"),
                                   "--strategies", "cosine", "--spp", "2", "--quiet",
                                   "--csv", in_work("missing/out.csv")};
  expect_bad_input(args, "does not exist");
  args.back() = in_work("out.csv");
  args.insert(args.end(), {"--plot", in_work("out.csv")});
  expect_bad_input(args, "named twice");
}

TEST_F(BenchCommand, UnreadableSceneIsBadInput) {
  make_reference();
  std::vector<std::string> args = bench_args({"--strategies", "cosine", "--spp", "2"});
  args[2] = in_work("no_such_scene.json");
  expect_bad_input(args, "no_such_scene.json");
}

TEST_F(BenchCommand, TinyRunWritesTheTablesAndAPlot) {
  make_reference();
  // Without --quiet, so that the note about bias is printed (stderr is not a
  // terminal, so there is no progress line either way).
  std::vector<std::string> args = bench_args({"--strategies", "cosine;light;mix:cosine=0.5,light=0.5", "--spp", "16"});
  args.erase(std::find(args.begin(), args.end(), "--quiet"));
  const ChildResult r = run(args);
  ASSERT_EQ(r.status, 0) << r.err;

  std::vector<std::string> header;
  const auto rows = parse_csv(slurp(work() / "out.csv"), header);
  const std::vector<std::string> required = {"strategy", "spp", "seconds", "rmse", "relmse",
                                             "efficiency", "samples_per_second", "dropped"};
  ASSERT_GE(header.size(), required.size());
  EXPECT_TRUE(std::equal(required.begin(), required.end(), header.begin())) << slurp(work() / "out.csv");
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0].at("strategy"), "cosine");
  EXPECT_EQ(rows[1].at("strategy"), "light");
  EXPECT_EQ(rows[2].at("strategy"), "mix:cosine=0.5,light=0.5");
  for (const auto& row : rows) {
    EXPECT_EQ(row.at("#fields"), std::to_string(header.size()));
    EXPECT_EQ(row.at("spp"), "16");
    EXPECT_EQ(row.at("dropped"), "0");
    for (const char* column : {"seconds", "rmse", "relmse", "efficiency", "samples_per_second"}) {
      const double v = std::stod(row.at(column));
      EXPECT_TRUE(std::isfinite(v) && v > 0.0) << column << " = " << row.at(column);
    }
    // The reference sets the size: 12x8 pixels at 16 spp in the reported time.
    const double samples = std::stod(row.at("samples_per_second")) * std::stod(row.at("seconds"));
    EXPECT_NEAR(samples, 12.0 * 8.0 * 16.0, 1e-3 * 12.0 * 8.0 * 16.0) << row.at("strategy");
  }
  EXPECT_EQ(rows[0].at("unbiased"), "1");
  EXPECT_EQ(rows[1].at("unbiased"), "0");
  EXPECT_EQ(rows[2].at("unbiased"), "1");
  // Rendered 8 wide and 12 high, the image would be compared with pixels of
  // other parts of the scene: relMSE near 90. In the reference's layout the
  // mixture at 16 spp is near 0.1.
  EXPECT_LT(std::stod(rows[2].at("relmse")), 1.0);

  // The biased strategy is named as such on the table, in the plot and in a note.
  EXPECT_NE(r.out.find("(biased)"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("'light' is biased"), std::string::npos) << r.err;

  const std::string svg = slurp(work() / "out.svg");
  EXPECT_TRUE(well_formed_xml(svg));
  EXPECT_NE(svg.find("<svg"), std::string::npos);
  EXPECT_NE(svg.find("light (biased)"), std::string::npos);
  EXPECT_NE(svg.find("mix:cosine=0.5,light=0.5"), std::string::npos);

  std::vector<std::string> curve_header;
  const auto curve = parse_csv(slurp(work() / "curves.csv"), curve_header);
  EXPECT_EQ(curve_header, (std::vector<std::string>{"strategy", "spp", "seconds", "rmse", "relmse", "relmse_raw"}));
  ASSERT_FALSE(curve.empty());
  // Each strategy's curve ends at the final spp.
  for (const char* s : {"cosine", "light", "mix:cosine=0.5,light=0.5"}) {
    std::string last_spp;
    for (const auto& row : curve)
      if (row.at("strategy") == s) last_spp = row.at("spp");
    EXPECT_EQ(last_spp, "16") << s;
  }

  EXPECT_EQ(work_entries(), (std::vector<std::string>{"curves.csv", "out.csv", "out.svg", "ref.json", "ref.pfm"}));
}

// --predict: every mixture of the pair gets its weight and the efficiency
// predicted from the pilot's paths (the mixture nearest 0.5). At the pilot's
// own weight the prediction is the pilot's measured efficiency in expectation
// (the same samples and time per pass; the members' times give only the
// fixed cost's share); the others are positive.
TEST_F(BenchCommand, PredictsTheMixturesEfficiencyFromThePilotsPaths) {
  // A reference far less noisy than the runs: with one as noisy as a run, the
  // measured relMSE (corrected for the reference's noise) is itself mostly noise.
  const ChildResult ref = run({"render", "--scene", kBookScene, "--strategy", "mix:cosine=0.5,light=0.5", "--spp",
                               "16384", "--width", "12", "--height", "8", "--threads", "2", "--quiet", "--out",
                               in_work("ref.pfm")});
  ASSERT_EQ(ref.status, 0) << ref.err;
  const ChildResult r = run(bench_args({"--strategies",
                                        "cosine;mix:cosine=0.3,light=0.7;mix:cosine=0.5,light=0.5;"
                                        "mix:cosine=0.8,light=0.2;uniform-sphere",
                                        "--spp", "128", "--predict", "cosine,light"}));
  ASSERT_EQ(r.status, 0) << r.err;
  std::vector<std::string> header;
  const auto rows = parse_csv(slurp(work() / "out.csv"), header);
  ASSERT_EQ(rows.size(), 5u);
  ASSERT_EQ(header.back(), "predicted_largest_share");
  const double expected_weight[4] = {1.0, 0.3, 0.5, 0.8};
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(std::stod(rows[static_cast<std::size_t>(i)].at("weight")), expected_weight[i], 1e-9) << i;
    EXPECT_GT(std::stod(rows[static_cast<std::size_t>(i)].at("predicted_efficiency")), 0.0) << i;
    const double share = std::stod(rows[static_cast<std::size_t>(i)].at("predicted_largest_share"));
    EXPECT_GT(share, 0.0) << i;
    EXPECT_LE(share, 1.0) << i;
  }
  // uniform-sphere is no mixture of cosine and light: no weight, no prediction.
  EXPECT_EQ(rows[4].at("weight"), "");
  EXPECT_EQ(rows[4].at("predicted_efficiency"), "");
  EXPECT_EQ(rows[4].at("predicted_largest_share"), "");
  const double measured = std::stod(rows[2].at("efficiency")), predicted = std::stod(rows[2].at("predicted_efficiency"));
  EXPECT_NEAR(predicted / measured, 1.0, 0.4) << "measured " << measured << ", predicted " << predicted;
  EXPECT_NE(r.out.find("predicted best share of cosine"), std::string::npos) << r.out;

  expect_bad_input(bench_args({"--strategies", "cosine", "--spp", "2", "--predict", "cosine"}), "not two techniques");
  expect_bad_input(bench_args({"--strategies", "cosine;mix:cosine=0.5,light=0.5", "--spp", "2", "--predict",
                               "cosine,uniform-sphere"}),
                   "no strategy in --strategies mixes cosine and uniform-sphere");
  expect_bad_input(bench_args({"--strategies", "mix:cosine=0.99,light=0.01", "--spp", "2", "--predict", "cosine,light"}),
                   "to predict from");
}

TEST_F(BenchCommand, EqualTimeRunsForAboutTheGivenTime) {
  make_reference();
  const ChildResult r = run(bench_args({"--strategies", "cosine", "--seconds", "0.3"}));
  ASSERT_EQ(r.status, 0) << r.err;
  std::vector<std::string> header;
  const auto rows = parse_csv(slurp(work() / "out.csv"), header);
  ASSERT_EQ(rows.size(), 1u);
  // At least the time asked for; the pass in flight when time is up is kept,
  // and passes aim at 30-120 ms, so a loaded machine may add a little.
  EXPECT_GE(std::stod(rows[0].at("seconds")), 0.3);
  EXPECT_LT(std::stod(rows[0].at("seconds")), 3.0);
  EXPECT_GE(std::stoul(rows[0].at("spp")), 1u);
}

TEST_F(BenchCommand, ScenesWithMarkupInTheirNameStillGiveAWellFormedPlot) {
  make_reference();
  std::string scene = slurp(kBookScene);
  const std::size_t name = scene.find("\"Cornell box (book)\"");
  ASSERT_NE(name, std::string::npos);
  scene.replace(name, std::string("\"Cornell box (book)\"").size(), "\"A <box> & \\\"quotes\\\"\"");
  write_text(work() / "scene.json", scene);
  std::vector<std::string> args = bench_args({"--strategies", "cosine", "--spp", "2"});
  args[2] = in_work("scene.json");
  const ChildResult r = run(args);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(well_formed_xml(slurp(work() / "out.svg")));
}

// pdflab veach: the four estimators of Veach's figure as one 2x2 image, and
// the relMSE of every plate and plate-light pair as a Markdown table.
TEST_F(BenchCommand, VeachWritesTheFigureAndTheTable) {
  const std::string veach = std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes/veach_mis.json";
  const ChildResult ref = run({"render", "--scene", veach, "--strategy", "nee-mis+mix:bsdf=0.5,light-sa=0.5", "--spp",
                               "256", "--width", "48", "--height", "36", "--seed", "99", "--threads", "2", "--quiet",
                               "--out", in_work("ref.pfm")});
  ASSERT_EQ(ref.status, 0) << ref.err;
  const ChildResult r = run({"veach", "--scene", veach, "--reference", in_work("ref.pfm"), "--spp", "4", "--seeds",
                             "2", "--out", in_work("panel.png"), "--table", in_work("table.md"), "--threads", "2",
                             "--quiet"});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string table = slurp(work() / "table.md");
  EXPECT_EQ(table, r.out);
  for (const char* needle : {"| power (nee-mis+bsdf) | 4 |", "| alpha 0.005 |", "| alpha 0.2 |",
                             "| alpha 0.005, radius 0.9 |", "power / best single"})
    EXPECT_NE(table.find(needle), std::string::npos) << needle << " not in\n" << table;
  // The PNG's IHDR: 2 x 48 + 4 wide, 2 x 36 + 4 high.
  EXPECT_EQ(png_size(slurp(work() / "panel.png")), std::make_pair(100u, 76u));
  // A scene without a microfacet plate has nothing to measure.
  const ChildResult book = run({"render", "--scene", kBookScene, "--strategy", "cosine", "--spp", "2", "--width", "8", "--height", "8",
                                "--seed", "99", "--quiet", "--out", in_work("book.pfm")});
  ASSERT_EQ(book.status, 0) << book.err;
  expect_bad_input({"veach", "--scene", kBookScene, "--reference", in_work("book.pfm"), "--spp", "1", "--out",
                    in_work("book.png")},
                   "shows no microfacet plate");
}

}  // namespace
