// References: relMSE corrected for the reference's own noise is unbiased (and
// its interval covers the truth), the files round-trip and a damaged one is
// refused with a message, the seed trap is closed, the cache key follows the
// scene's content; then `pdflab reference`, `render --reference auto` and
// `bench --reference auto` on the real binary.
#include "renderer/error.h"
#include "renderer/film/exr_io.h"
#include "renderer/film/film.h"
#include "renderer/metrics/metrics.h"
#include "renderer/metrics/reference.h"
#include "renderer/scene/scene_loader.h"
#include "tests/support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using pdflab::testing::ChildResult;
using pdflab::testing::slurp;

const std::string kBookScene = std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes/cornell_book.json";

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

// A smooth positive "true image", some pixels dark.
std::vector<float> truth_image(int w, int h) {
  std::vector<float> img(static_cast<std::size_t>(3 * w * h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c)
        img[static_cast<std::size_t>(3 * (y * w + x) + c)] =
            static_cast<float>(0.05 + 0.9 * (0.5 + 0.5 * std::sin(0.3 * x + 0.7 * c) * std::cos(0.2 * y)));
  return img;
}

// A render of `truth` with n samples per pixel: each sample is truth * (an
// exponential variate of mean 1), so the noise is skewed like a path tracer's.
// Returns the mean and writes the sample estimate of the variance of the mean.
std::vector<float> noisy_render(const std::vector<float>& truth, int n, std::mt19937_64& rng,
                                std::vector<float>& variance_of_mean) {
  std::exponential_distribution<double> e(1.0);
  std::vector<float> mean(truth.size());
  variance_of_mean.assign(truth.size(), 0.0f);
  for (std::size_t i = 0; i < truth.size(); ++i) {
    double s = 0.0, q = 0.0;
    for (int k = 0; k < n; ++k) {
      const double v = truth[i] * e(rng);
      s += v;
      q += v * v;
    }
    const double m = s / n;
    mean[i] = static_cast<float>(m);
    variance_of_mean[i] = static_cast<float>(std::max(0.0, q / n - m * m) / (n - 1.0));  // as Film's
  }
  return mean;
}

// The same for many samples, drawn at once: the mean of n exponential variates
// is Gamma(n, 1/n) distributed, and the variance estimate is the true variance
// of the mean times chi^2(n - 1) / (n - 1), as a sample variance would be.
std::vector<float> converged_render(const std::vector<float>& truth, int n, std::mt19937_64& rng,
                                    std::vector<float>& variance_of_mean) {
  std::gamma_distribution<double> mean_of_n(n, 1.0 / n);
  std::chi_squared_distribution<double> chi2(n - 1.0);
  std::vector<float> mean(truth.size());
  variance_of_mean.resize(truth.size());
  for (std::size_t i = 0; i < truth.size(); ++i) {
    mean[i] = static_cast<float>(truth[i] * mean_of_n(rng));
    variance_of_mean[i] = static_cast<float>(truth[i] * truth[i] / static_cast<double>(n) * chi2(rng) / (n - 1.0));
  }
  return mean;
}

// relMSE of `image` against the true image itself.
double true_relmse(const std::vector<float>& image, const std::vector<float>& truth) {
  return pdflab::relmse(image, truth);
}

// The default reference strategy: the book's mixture, and under an environment light
// nee-mis continued by cosine and the map's sampler (cosine alone would find a
// small sun only by chance).
TEST(ReferenceStrategy, FollowsWhatTheSceneHas) {
  const std::string dir = std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes";
  using pdflab::default_reference_strategy;
  EXPECT_EQ(default_reference_strategy(pdflab::load_scene_file(dir + "/cornell_book.json")).to_string(),
            "mix:cosine=0.5,light=0.5");
  pdflab::Scene sky = pdflab::load_scene_file(dir + "/sun_sky.json");
  EXPECT_EQ(default_reference_strategy(sky).to_string(), "nee-mis+mix:cosine=0.5,environment=0.5");
  sky.environment.reset();  // without its map: the book's mixture, whose light has no target there (cosine)
  EXPECT_EQ(default_reference_strategy(sky).to_string(), "mix:cosine=0.5,light=0.5");
}

TEST(CorrectedRelMse, TwoIndependentNoisyRendersShowNoErrorBeyondTheirNoise) {
  // x and r render the same image independently. Corrected for r's noise, the
  // error of x is its own noise, and minus that (the excess: squared bias) ~ 0;
  // the 95% interval covers 0 in about 95% of trials.
  const int w = 48, h = 48;
  const std::vector<float> truth = truth_image(w, h);
  std::mt19937_64 rng(12345);
  int covered = 0, raw_covered = 0;
  double sum_corrected = 0.0, sum_truth = 0.0, sum_raw = 0.0;
  constexpr int kTrials = 200;
  for (int t = 0; t < kTrials; ++t) {
    std::vector<float> vx, vr;
    const std::vector<float> x = noisy_render(truth, 16, rng, vx);
    const std::vector<float> r = converged_render(truth, 128, rng, vr);
    const pdflab::RelMseMeasure m = pdflab::measure_relmse(x, r, vr, vx);
    ASSERT_TRUE(m.reference_corrected);
    ASSERT_TRUE(m.has_excess);
    if (std::abs(m.excess) <= m.excess_interval) ++covered;
    // Uncorrected, the same test would see the reference's noise as error.
    if (std::abs(m.raw - m.image_noise) <= m.excess_interval) ++raw_covered;
    sum_corrected += m.corrected;
    sum_raw += m.raw;
    sum_truth += true_relmse(x, truth);
  }
  std::printf("the 95%% interval covered the true excess 0 in %d of %d trials\n", covered, kTrials);
  EXPECT_GE(covered, 0.90 * kTrials) << "the interval must cover the true excess 0 about 95% of the time";
  EXPECT_LE(covered, 0.99 * kTrials);
  EXPECT_LT(raw_covered, 0.5 * kTrials) << "without the correction the reference's noise shows as error";
  // On average the corrected figure is the relMSE against the true image
  // (within the few percent a noisy denominator r^2 + eps costs); raw is not.
  EXPECT_NEAR(sum_corrected / sum_truth, 1.0, 0.05);
  EXPECT_GT(sum_raw / sum_truth, 1.08);
}

TEST(CorrectedRelMse, KnownOffsetAndBlurGiveTheirKnownError) {
  const int w = 64, h = 64;
  const std::vector<float> truth = truth_image(w, h);
  std::mt19937_64 rng(99);
  std::vector<float> vr;
  const std::vector<float> r = converged_render(truth, 512, rng, vr);

  // 10% too bright everywhere.
  std::vector<float> offset = truth;
  for (float& v : offset) v *= 1.1f;
  const double known_offset = true_relmse(offset, truth);
  const pdflab::RelMseMeasure mo = pdflab::measure_relmse(offset, r, vr);
  // What remains besides chance is of second order: the noisy reference is
  // also in the denominator, which costs a fraction of its own relMSE.
  EXPECT_NEAR(mo.corrected, known_offset, mo.interval + 0.5 * mo.reference_noise)
      << "raw " << mo.raw << ", reference noise " << mo.reference_noise;
  EXPECT_GT(mo.raw - known_offset, 3.0 * std::abs(mo.corrected - known_offset))
      << "the raw figure carries the reference's noise on top";

  // A 3x3 box blur (edges clamped).
  std::vector<float> blur(truth.size());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) {
        double s = 0.0;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int xx = std::clamp(x + dx, 0, w - 1), yy = std::clamp(y + dy, 0, h - 1);
            s += truth[static_cast<std::size_t>(3 * (yy * w + xx) + c)];
          }
        blur[static_cast<std::size_t>(3 * (y * w + x) + c)] = static_cast<float>(s / 9.0);
      }
  const double known_blur = true_relmse(blur, truth);
  ASSERT_GT(known_blur, 1e-4);
  const pdflab::RelMseMeasure mb = pdflab::measure_relmse(blur, r, vr);
  EXPECT_NEAR(mb.corrected, known_blur, mb.interval + 0.5 * mb.reference_noise);
  EXPECT_GT(std::abs(mb.raw - known_blur), 2.0 * std::abs(mb.corrected - known_blur));
  EXPECT_NEAR(mb.reference_share(), mb.reference_noise / mb.raw, 1e-12);

  // Without a variance nothing is subtracted, and it says so.
  const pdflab::RelMseMeasure plain = pdflab::measure_relmse(blur, r, {});
  EXPECT_FALSE(plain.reference_corrected);
  EXPECT_DOUBLE_EQ(plain.corrected, plain.raw);
  EXPECT_NEAR(plain.raw, pdflab::relmse(blur, r), 1e-12 * plain.raw);
}

pdflab::Film small_film(int w, int h, int spp) {
  pdflab::Film film(w, h);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 2.0f);
  for (std::size_t p = 0; p < film.pixel_count(); ++p)
    for (int k = 0; k < spp; ++k) film.add(p, pdflab::Vec3(u(rng), u(rng) * 0.5f, u(rng) * 0.25f));
  return film;
}

pdflab::Reference saved_reference(const pdflab::testing::TempDir& dir, const std::string& name = "ref.pfm") {
  pdflab::ReferenceInfo info;
  info.scene_name = "test";
  info.scene_hash = "0123456789abcdef";
  info.max_depth = 7;
  info.strategy = "cosine";
  info.seed = pdflab::reference_seed(3);
  info.seed_stream = 3;
  info.spp = 16;
  info.seconds = 1.5;
  info.version = "test";
  const pdflab::Reference ref = pdflab::reference_from_film(small_film(6, 4, 16), info);
  pdflab::save_reference(dir.file(name), ref);
  return ref;
}

TEST(ReferenceFiles, RoundTripWithSidecar) {
  pdflab::testing::TempDir dir;
  const pdflab::Reference saved = saved_reference(dir);
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"ref.json", "ref.pfm", "ref.var.pfm"}));
  const pdflab::Reference loaded = pdflab::load_reference(dir.file("ref.pfm"));
  EXPECT_EQ(loaded.width, 6);
  EXPECT_EQ(loaded.height, 4);
  EXPECT_EQ(loaded.rgb, saved.rgb);
  EXPECT_EQ(loaded.variance, saved.variance);
  ASSERT_TRUE(loaded.has_variance());
  EXPECT_TRUE(loaded.info.is_reference);
  EXPECT_EQ(loaded.info.scene_hash, "0123456789abcdef");
  EXPECT_EQ(loaded.info.max_depth, 7);
  EXPECT_EQ(loaded.info.strategy, "cosine");
  EXPECT_TRUE(loaded.info.seed_known);
  EXPECT_EQ(loaded.info.seed, pdflab::reference_seed(3));
  EXPECT_EQ(loaded.info.seed_stream, 3u);
  EXPECT_EQ(loaded.info.spp, 16u);
  EXPECT_GT(loaded.info.estimated_relmse, 0.0);
  // The variance is the film's variance of the mean.
  const pdflab::Film film = small_film(6, 4, 16);
  double v[3];
  film.variance_of_mean(5, v);
  EXPECT_NEAR(loaded.variance[15], v[0], 1e-6 * v[0]);
}

TEST(ReferenceFiles, DamagedFilesAreRefusedWithAMessage) {
  const auto expect_refused = [](const std::string& path, const std::string& needle) {
    try {
      (void)pdflab::load_reference(path);
      ADD_FAILURE() << "loaded a damaged reference; expected '" << needle << "'";
    } catch (const pdflab::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  {
    pdflab::testing::TempDir dir;
    saved_reference(dir);
    fs::resize_file(dir.file("ref.pfm"), fs::file_size(dir.file("ref.pfm")) - 7);
    expect_refused(dir.file("ref.pfm"), "truncated");
  }
  {
    pdflab::testing::TempDir dir;
    saved_reference(dir);
    std::string bytes = slurp(dir.file("ref.var.pfm"));
    bytes[bytes.size() - 2] ^= 0x40;  // one flipped bit in the data, still a valid PFM
    write_text(dir.file("ref.var.pfm"), bytes);
    expect_refused(dir.file("ref.pfm"), "checksum");
  }
  {
    pdflab::testing::TempDir dir;
    saved_reference(dir);
    const std::string text = slurp(dir.file("ref.json"));
    write_text(dir.file("ref.json"), text.substr(0, text.size() / 2));
    expect_refused(dir.file("ref.pfm"), "not valid JSON");
  }
  {
    pdflab::testing::TempDir dir;
    saved_reference(dir);
    fs::remove(dir.file("ref.var.pfm"));
    expect_refused(dir.file("ref.pfm"), "variance file");
  }
}

TEST(ReferenceCache, DamagedEntryIsReportedNeverThrown) {
  pdflab::testing::TempDir dir;
  pdflab::ReferenceKey key{"0123456789abcdef", 6, 4, 7};
  EXPECT_EQ(pdflab::find_cached_reference(dir.path().string(), key).status, pdflab::CacheLookup::Missing);
  pdflab::ReferenceInfo info;
  info.scene_hash = key.scene_hash;
  info.max_depth = 7;
  info.strategy = "cosine";
  info.seed = pdflab::reference_seed(0);
  const pdflab::Reference ref = pdflab::reference_from_film(small_film(6, 4, 8), info);
  const std::string path = pdflab::store_cached_reference(dir.path().string(), key, ref);
  EXPECT_EQ(pdflab::find_cached_reference(dir.path().string(), key).status, pdflab::CacheLookup::Found);
  // Another depth or size is another key.
  EXPECT_EQ(pdflab::find_cached_reference(dir.path().string(), {key.scene_hash, 6, 4, 8}).status,
            pdflab::CacheLookup::Missing);
  fs::resize_file(path, 20);
  const pdflab::CacheLookup bad = pdflab::find_cached_reference(dir.path().string(), key);
  EXPECT_EQ(bad.status, pdflab::CacheLookup::Damaged);
  EXPECT_NE(bad.message.find("damaged"), std::string::npos) << bad.message;
  EXPECT_NE(bad.message.find(path), std::string::npos) << bad.message;
}

TEST(ReferenceCache, DirectoryFromOptionThenEnvironment) {
  EXPECT_EQ(pdflab::reference_cache_dir("/x/y"), "/x/y");
  ::setenv("PDFLAB_REFERENCE_CACHE", "/from/env", 1);
  EXPECT_EQ(pdflab::reference_cache_dir(), "/from/env");
  ::unsetenv("PDFLAB_REFERENCE_CACHE");
  ::setenv("XDG_CACHE_HOME", "/xdg", 1);
  EXPECT_EQ(pdflab::reference_cache_dir(), "/xdg/pdflab/references");
}

TEST(ReferenceCache, KeyFollowsTheSceneContentNotItsFormatting) {
  const std::string text = slurp(kBookScene);
  const pdflab::Scene a = pdflab::load_scene_text(text, "a");
  ASSERT_EQ(a.content_hash.size(), 16u);
  // Reformatted (no newlines), another size and depth: the same content.
  std::string flat = nlohmann::json::parse(text).dump();
  nlohmann::json j = nlohmann::json::parse(text);
  j["camera"]["width"] = 17;
  j["camera"]["max_depth"] = 3;
  j["description"] = "changed words";
  EXPECT_EQ(pdflab::load_scene_text(flat, "b").content_hash, a.content_hash);
  EXPECT_EQ(pdflab::load_scene_text(j.dump(), "c").content_hash, a.content_hash);
  // A changed albedo is another scene.
  j = nlohmann::json::parse(text);
  j["materials"]["white"]["albedo"][0] = 0.5;
  EXPECT_NE(pdflab::load_scene_text(j.dump(), "d").content_hash, a.content_hash);
}

TEST(SeedTrap, SameSeedIsNamedAndOthersPass) {
  pdflab::ReferenceInfo info;
  info.seed_known = true;
  info.seed = 1;
  info.strategy = "mix:cosine=0.5,light=0.5";
  const pdflab::Strategy book = pdflab::Strategy::parse("mix:cosine=0.5,light=0.5");
  const std::string same = pdflab::shared_random_numbers(info, 1, book);
  EXPECT_NE(same.find("seed 1 and strategy mix:cosine=0.5,light=0.5"), std::string::npos) << same;
  EXPECT_FALSE(pdflab::shared_random_numbers(info, 1, pdflab::Strategy::single(pdflab::Technique::Cosine)).empty());
  EXPECT_TRUE(pdflab::shared_random_numbers(info, 2, book).empty());
  info.seed_known = false;
  EXPECT_TRUE(pdflab::shared_random_numbers(info, 1, book).empty());
  EXPECT_TRUE(pdflab::is_reference_seed(pdflab::reference_seed(0)));
  EXPECT_FALSE(pdflab::is_reference_seed(1u << 30));
}

// Issue 33, item 5: every seed a reference's samples came from is known,
// also for a merge of several ranges of one seed or of several seeds, and
// for an EXR written before pdflab.seeds (its pdflab.samples is read).
TEST(SeedTrap, EverySeedOfAMergeIsKnown) {
  pdflab::ReferenceInfo info;
  pdflab::set_seeds(info, {9, 3, 9});
  EXPECT_TRUE(info.seed_known);
  EXPECT_EQ(info.seeds, (std::vector<std::uint64_t>{3, 9}));
  const pdflab::Strategy cosine = pdflab::Strategy::single(pdflab::Technique::Cosine);
  EXPECT_FALSE(pdflab::shared_random_numbers(info, 9, cosine).empty());
  EXPECT_FALSE(pdflab::shared_random_numbers(info, 3, cosine).empty());
  EXPECT_TRUE(pdflab::shared_random_numbers(info, 4, cosine).empty());

  pdflab::testing::TempDir dir("pdflab-seeds");
  const std::vector<float> rgb(4 * 3, 0.5f);
  pdflab::write_exr(dir.file("old.exr"), rgb, 2, 2,
                    {{"pdflab.strategy", "cosine"}, {"pdflab.samples", "seed 4 samples [0, 8), seed 4 samples [16, 24)"}});
  const pdflab::Reference old = pdflab::load_reference(dir.file("old.exr"));
  EXPECT_EQ(old.info.seeds, (std::vector<std::uint64_t>{4}));
  pdflab::write_exr(dir.file("new.exr"), rgb, 2, 2, {{"pdflab.strategy", "cosine"}, {"pdflab.seeds", "2,7"}});
  EXPECT_EQ(pdflab::load_reference(dir.file("new.exr")).info.seeds, (std::vector<std::uint64_t>{2, 7}));
}

TEST(EstimateHistory, FlagsAnEstimateThatStopsFalling) {
  pdflab::EstimateHistory steady;
  for (std::uint32_t n = 2; n <= 4096; n *= 2) steady.add(n, 0.5 / n * (n % 3 == 0 ? 1.2 : 1.0));
  EXPECT_FALSE(steady.unreliable());
  EXPECT_NEAR(steady.growth(), 1.0, 0.3);
  // The estimate of a strategy finding rare bright paths: flat, then up.
  pdflab::EstimateHistory rising;
  for (std::uint32_t n = 2; n <= 64; n *= 2) rising.add(n, 0.5 / n);
  EXPECT_FALSE(rising.unreliable());
  rising.add(128, 0.5 / 64 * 1.1);
  EXPECT_TRUE(rising.unreliable());
  EXPECT_GT(rising.growth(), 2.0);
}

TEST(ReferenceProgress, PredictsTheTimeToARelMseTarget) {
  // relMSE 4e-3 after 10 s: 1e-3 needs 40 s, 30 s more.
  const pdflab::ReferenceProgress p = pdflab::reference_progress({0, 0.0, 1e-3}, 100, 10.0, 4e-3);
  EXPECT_FALSE(p.reached);
  EXPECT_NEAR(p.fraction, 0.25, 1e-12);
  EXPECT_NEAR(p.seconds_left, 30.0, 1e-9);
  EXPECT_TRUE(pdflab::reference_progress({0, 0.0, 1e-3}, 400, 40.0, 0.9e-3).reached);
  EXPECT_NEAR(pdflab::reference_progress({256, 0.0, 0.0}, 64, 2.0, 0.0).seconds_left, 6.0, 1e-9);
  EXPECT_TRUE(pdflab::reference_progress({0, 5.0, 0.0}, 64, 5.0, 0.0).reached);
}

// The binary ----------------------------------------------------------------------

class ReferenceCommand : public ::testing::Test {
 protected:
  fs::path work() const { return ws_.work(); }
  std::string in_work(const std::string& name) const { return ws_.in_work(name); }
  std::string cache() const { return in_work("cache"); }
  ChildResult run(std::vector<std::string> args) const {
    const ChildResult r = ws_.run(args);
    if (!r.started) ADD_FAILURE() << "could not start " << PDFLAB_BINARY;
    return r;
  }
  ChildResult make_reference(const std::string& scene, std::vector<std::string> extra = {}) const {
    std::vector<std::string> a = {"reference", "--scene",     scene,  "--width",   "16",      "--height", "12",
                                  "--spp",     "128",         "--threads", "2", "--quiet", "--cache-dir", cache()};
    a.insert(a.end(), extra.begin(), extra.end());
    return run(a);
  }
  ChildResult render_auto(const std::string& scene, std::vector<std::string> extra = {}) const {
    std::vector<std::string> a = {"render",  "--scene", scene, "--strategy", "cosine", "--spp", "16", "--width", "16",
                                  "--height", "12", "--threads", "2", "--out", in_work("r.pfm"), "--reference", "auto",
                                  "--cache-dir", cache()};
    a.insert(a.end(), extra.begin(), extra.end());
    return run(a);
  }
  ChildResult bench_auto(const std::string& scene) const {
    return run({"bench", "--scene", scene, "--strategies", "cosine;nee-mis", "--spp", "8", "--width", "16", "--height",
                "12", "--threads", "2", "--quiet", "--reference", "auto", "--cache-dir", cache(), "--csv",
                in_work("b.csv")});
  }

 private:
  pdflab::testing::CommandWorkspace ws_{"pdflab-reference"};
};

TEST_F(ReferenceCommand, MadeOnceFoundByRenderAndBench) {
  const ChildResult made = make_reference(kBookScene, {"--out", in_work("copy.pfm")});
  ASSERT_EQ(made.status, 0) << made.err;
  int in_cache = 0;
  for (const auto& e : fs::directory_iterator(cache())) in_cache += e.path().extension() == ".pfm" ? 1 : 0;
  EXPECT_EQ(in_cache, 2) << "mean and variance";
  const nlohmann::json side = nlohmann::json::parse(slurp(in_work("copy.json")));
  EXPECT_EQ(side["format"], "pdflab-reference");
  EXPECT_EQ(side["strategy"], "mix:cosine=0.5,light=0.5") << "the default: the most efficient the report knows";
  EXPECT_EQ(side["spp"], 128);
  EXPECT_EQ(side["width"], 16);
  EXPECT_EQ(side["height"], 12);
  EXPECT_EQ(side["max_depth"], 50);
  EXPECT_EQ(side["seed_stream"], 0);
  EXPECT_TRUE(pdflab::is_reference_seed(side["seed"].get<std::uint64_t>()));
  EXPECT_EQ(side["scene_hash"].get<std::string>().size(), 16u);
  EXPECT_FALSE(side["version"].get<std::string>().empty());
  EXPECT_GT(side["seconds"].get<double>(), 0.0);

  const ChildResult r = render_auto(kBookScene, {"--stats-json", in_work("r.json")});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("using the cached reference"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("relMSE"), std::string::npos) << r.out;
  const nlohmann::json stats = nlohmann::json::parse(slurp(in_work("r.json")));
  EXPECT_TRUE(stats["reference_corrected"].get<bool>());
  EXPECT_LT(stats["relmse"].get<double>(), stats["relmse_raw"].get<double>());
  EXPECT_GT(stats["reference_share"].get<double>(), 0.0);
  EXPECT_LT(stats["reference_share"].get<double>(), 1.0);

  const ChildResult b = bench_auto(kBookScene);
  ASSERT_EQ(b.status, 0) << b.err;
  const std::string csv = slurp(in_work("b.csv"));
  EXPECT_NE(csv.find("relmse_raw,relmse_ci,ref_share"), std::string::npos) << csv;
}

TEST_F(ReferenceCommand, SceneEditInvalidatesTheCachedReference) {
  const std::string scene = in_work("scene.json");
  write_text(scene, slurp(kBookScene));
  ASSERT_EQ(make_reference(scene).status, 0);
  ASSERT_EQ(render_auto(scene).status, 0);
  nlohmann::json j = nlohmann::json::parse(slurp(scene));
  j["materials"]["white"]["albedo"][0] = 0.5;
  write_text(scene, j.dump(2));
  const ChildResult r = render_auto(scene);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("no cached reference"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("est. relMSE"), std::string::npos) << "falls back to the film's estimate: " << r.out;
  const ChildResult b = bench_auto(scene);
  EXPECT_EQ(b.status, 2) << b.err;
  EXPECT_NE(b.err.find("no cached reference"), std::string::npos) << b.err;
  EXPECT_NE(b.err.find("pdflab reference --scene"), std::string::npos) << "says how to make one: " << b.err;
}

TEST_F(ReferenceCommand, CorruptOrTruncatedCacheIsRefusedAndRebuilt) {
  ASSERT_EQ(make_reference(kBookScene).status, 0);
  fs::path mean;
  for (const auto& e : fs::directory_iterator(cache()))
    if (e.path().extension() == ".pfm" && e.path().stem().extension() != ".var") mean = e.path();
  ASSERT_FALSE(mean.empty());
  for (int damage = 0; damage < 3; ++damage) {
    if (damage == 0) fs::resize_file(mean, fs::file_size(mean) / 2);  // truncated
    if (damage == 1) write_text(mean, "PF\n16 12\n-1.0\n" + std::string(16 * 12 * 12, '\x7f'));  // garbage of the right size: the checksum fails
    if (damage == 2) write_text(fs::path(mean).replace_extension(".json"), "{\"format\": \"pdflab-ref");
    const ChildResult r = render_auto(kBookScene);
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("damaged and was ignored"), std::string::npos) << r.err;
    const ChildResult b = bench_auto(kBookScene);
    EXPECT_EQ(b.status, 2) << b.err;
    EXPECT_NE(b.err.find("damaged"), std::string::npos) << b.err;
    EXPECT_EQ(b.err.find("internal"), std::string::npos) << b.err;
    const ChildResult again = make_reference(kBookScene, {});
    ASSERT_EQ(again.status, 0) << again.err;
    const ChildResult fixed = render_auto(kBookScene);
    EXPECT_NE(fixed.err.find("using the cached reference"), std::string::npos) << fixed.err;
  }
}

TEST_F(ReferenceCommand, SameSeedAsTheReferenceIsRefused) {
  // The old recipe: a reference rendered like any image, with its sidecar.
  const ChildResult ref = run({"render", "--scene", kBookScene, "--strategy", "cosine", "--spp", "64", "--width", "16",
                               "--height", "12", "--seed", "7", "--threads", "2", "--quiet", "--out", in_work("old.pfm"),
                               "--stats-json", in_work("old.json")});
  ASSERT_EQ(ref.status, 0) << ref.err;
  const std::vector<std::string> render = {"render", "--scene", kBookScene, "--strategy", "cosine", "--spp", "16",
                                           "--width", "16", "--height", "12", "--threads", "2", "--quiet",
                                           "--reference", in_work("old.pfm"), "--out", in_work("r.pfm")};
  std::vector<std::string> same = render;
  same.insert(same.end(), {"--seed", "7"});
  const ChildResult r = run(same);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("seed 7 and strategy cosine"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(in_work("r.pfm"))) << "refused before rendering";
  const ChildResult b = run({"bench", "--scene", kBookScene, "--strategies", "cosine", "--spp", "4", "--seed", "7",
                             "--quiet", "--reference", in_work("old.pfm"), "--csv", in_work("b.csv")});
  EXPECT_EQ(b.status, 2) << b.err;
  EXPECT_NE(b.err.find("share random numbers"), std::string::npos) << b.err;
  std::vector<std::string> other = render;
  other.insert(other.end(), {"--seed", "8"});
  EXPECT_EQ(run(other).status, 0);

  // A reference of `pdflab reference` uses the reserved seeds: a render given one of them is refused too.
  ASSERT_EQ(make_reference(kBookScene, {"--strategy", "cosine", "--out", in_work("new.pfm")}).status, 0);
  const std::string reserved = std::to_string(pdflab::reference_seed(0));
  const ChildResult trap = run({"render", "--scene", kBookScene, "--strategy", "cosine", "--spp", "16", "--width", "16",
                                "--height", "12", "--seed", reserved, "--quiet", "--reference", in_work("new.pfm"),
                                "--out", in_work("t.pfm")});
  EXPECT_EQ(trap.status, 2) << trap.err;
  EXPECT_NE(trap.err.find("and strategy cosine"), std::string::npos) << trap.err;
}

// Issue 33, item 5: the recipe of docs/measuring.md (render --out ref.pfm
// with the default seed, then measure a render of the default seed against
// it) was not caught without a sidecar and gave relMSE 0 +- 0. Every render
// now writes what identifies it: a PFM's sidecar, an EXR's attributes, a
// film's ranges, also for merges of several ranges of one seed or of several
// seeds. A PFM that still lacks its sidecar gets a note.
TEST_F(ReferenceCommand, TheSeedTrapClosesForBareFilesAndMerges) {
  const std::vector<std::string> base = {"render", "--scene", kBookScene, "--strategy", "cosine", "--width", "16",
                                         "--height", "12", "--threads", "2", "--quiet"};
  const auto render = [&](std::vector<std::string> extra) {
    std::vector<std::string> a = base;
    a.insert(a.end(), extra.begin(), extra.end());
    return run(a);
  };
  ASSERT_EQ(render({"--spp", "64", "--out", in_work("ref.pfm")}).status, 0);
  ASSERT_TRUE(fs::exists(in_work("ref.json")));
  ChildResult r = render({"--spp", "8", "--reference", in_work("ref.pfm"), "--out", in_work("r.pfm")});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("seed 1 and strategy cosine"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(in_work("r.pfm")));

  // Several ranges of one seed, and several seeds, as a film, an EXR and a PFM.
  ASSERT_EQ(render({"--spp", "8", "--film-out", in_work("a.film")}).status, 0);
  ASSERT_EQ(render({"--spp", "8", "--first-sample", "32", "--film-out", in_work("b.film")}).status, 0);
  ASSERT_EQ(render({"--spp", "8", "--seed", "3", "--film-out", in_work("c.film")}).status, 0);
  ASSERT_EQ(run({"merge", in_work("a.film"), in_work("b.film"), "--film-out", in_work("ranges.film"), "--out",
                 in_work("ranges.exr")}).status, 0);
  ASSERT_EQ(run({"merge", in_work("a.film"), in_work("b.film"), in_work("c.film"), "--out", in_work("seeds.pfm")}).status, 0);
  for (const char* reference : {"ranges.film", "ranges.exr", "seeds.pfm"})
    for (const char* seed : {"1", "3"}) {
      if (std::string(reference) != "seeds.pfm" && std::string(seed) == "3") continue;
      r = render({"--spp", "8", "--seed", seed, "--reference", in_work(reference), "--out", in_work("r.pfm")});
      EXPECT_EQ(r.status, 2) << reference << " seed " << seed << ": " << r.err;
      EXPECT_NE(r.err.find("share random numbers"), std::string::npos) << r.err;
    }
  r = render({"--spp", "8", "--seed", "2", "--reference", in_work("seeds.pfm"), "--out", in_work("r.pfm")});
  EXPECT_EQ(r.status, 0) << r.err;

  // A PFM without its sidecar: a note (with the render's seed), not silence.
  fs::remove(in_work("ref.json"));
  std::vector<std::string> loud = base;
  loud.pop_back();  // not --quiet
  loud.insert(loud.end(), {"--spp", "8", "--reference", in_work("ref.pfm"), "--out", in_work("r.pfm")});
  r = run(loud);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("does not record its seed"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("seed 1"), std::string::npos) << r.err;
}

// Issue 33, item 6: --reference auto that finds nothing (or a damaged entry)
// says so with --quiet too, and the stats JSON records why.
TEST_F(ReferenceCommand, QuietAutoReferenceThatFindsNothingSaysSo) {
  const ChildResult r = render_auto(kBookScene, {"--quiet", "--stats-json", in_work("s.json")});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("warning: --reference auto: no cached reference"), std::string::npos) << r.err;
  const nlohmann::json stats = nlohmann::json::parse(slurp(in_work("s.json")));
  EXPECT_NE(stats.at("reference_missing").get<std::string>().find("no cached reference"), std::string::npos);
  ASSERT_EQ(make_reference(kBookScene).status, 0);
  for (const auto& e : fs::directory_iterator(cache()))
    if (e.path().extension() == ".json") write_text(e.path(), "{");
  const ChildResult damaged = render_auto(kBookScene, {"--quiet"});
  ASSERT_EQ(damaged.status, 0) << damaged.err;
  EXPECT_NE(damaged.err.find("warning: --reference auto: cached reference"), std::string::npos) << damaged.err;
  EXPECT_NE(damaged.err.find("damaged"), std::string::npos) << damaged.err;
}

// Issue 33, item 9: a cache folder that is a file, a symlink loop or under a
// file is refused before the render (it rendered the whole --seconds first),
// and nothing is written, not even --out.
TEST_F(ReferenceCommand, ACacheFolderThatCannotBeMadeIsRefusedBeforeRendering) {
  // Beside the working folder, whose listing cannot follow a loop.
  const std::string file = in_work("../file"), loop = in_work("../loop");
  write_text(file, "not a folder");
  fs::create_symlink(loop, loop);
  for (const std::string& dir : {file, file + "/sub", loop, loop + "/sub"}) {
    const std::vector<std::string> before = pdflab::testing::listing(work());
    const ChildResult r = run({"reference", "--scene", kBookScene, "--width", "8", "--height", "8", "--seconds", "30",
                               "--quiet", "--cache-dir", dir, "--out", in_work("ref.pfm")});
    EXPECT_EQ(r.status, 2) << dir << ": " << r.err;
    EXPECT_NE(r.err.find("reference cache folder"), std::string::npos) << r.err;
    EXPECT_LT(r.cpu_seconds, 10.0) << "rendered before refusing " << dir;
    EXPECT_EQ(pdflab::testing::listing(work()), before) << dir;
  }
}

TEST_F(ReferenceCommand, BiasedStrategyWithoutReferenceShowsNoEfficiency) {
  const auto plain = [&](const std::string& strategy) {
    return run({"render", "--scene", kBookScene, "--strategy", strategy, "--spp", "16", "--width", "16", "--height",
                "12", "--threads", "2", "--quiet", "--out", in_work("p.pfm"), "--stats-json", in_work("p.json")});
  };
  const ChildResult light = plain("light");
  ASSERT_EQ(light.status, 0) << light.err;
  EXPECT_NE(light.out.find("no efficiency: 'light' is biased"), std::string::npos) << light.out;
  EXPECT_NE(light.out.find("lower bound"), std::string::npos) << light.out;
  EXPECT_FALSE(nlohmann::json::parse(slurp(in_work("p.json"))).contains("est_efficiency"));
  const ChildResult cosine = plain("cosine");
  ASSERT_EQ(cosine.status, 0) << cosine.err;
  EXPECT_NE(cosine.out.find("efficiency estimate"), std::string::npos) << cosine.out;
  EXPECT_TRUE(nlohmann::json::parse(slurp(in_work("p.json"))).contains("est_efficiency"));
}

TEST_F(ReferenceCommand, BadInputIsRefusedBeforeRendering) {
  const auto expect_bad = [&](std::vector<std::string> args, const std::string& needle) {
    const ChildResult r = run(args);
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << "message lacks '" << needle << "': " << r.err;
    EXPECT_FALSE(fs::exists(cache())) << "nothing written";
  };
  const std::vector<std::string> base = {"reference", "--scene", kBookScene, "--width", "8", "--height", "8",
                                         "--cache-dir", cache()};
  const auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> a = base;
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  };
  expect_bad(with({}), "exactly one of --spp, --seconds and --target-relmse");
  expect_bad(with({"--spp", "4", "--seconds", "2"}), "exactly one");
  expect_bad(with({"--spp", "4", "--strategy", "light"}), "biased");
  expect_bad(with({"--spp", "4", "--out", in_work("x.png")}), "must name a .pfm");
  expect_bad(with({"--target-relmse", "nan"}), "positive number");
}

}  // namespace
