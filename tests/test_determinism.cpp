// An image depends on (scene, strategy, seed, spp) only: never on the number
// of threads or on how passes and tiles happen to be scheduled. Checked on the
// binary (PFM bytes) and on RenderSession directly (the accumulated film).
#include "renderer/film/film.h"
#include "renderer/scene/scene_loader.h"
#include "renderer/session/session.h"
#include "tests/support.h"

#include "tests/render_support.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace pdflab {
namespace {

namespace fs = std::filesystem;

const std::string kBookScene = std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes/cornell_book.json";

using testing::TempDir;

// Renders the book scene at 24 x 20 (partial 16-pixel tiles on both axes) and
// returns the PFM's bytes; stderr goes to a file in `dir` for diagnostics.
std::string render_pfm(const TempDir& dir, const std::string& name, const std::string& threads,
                       const std::string& seed, const std::string& strategy = "mix:cosine=0.5,light=0.5") {
  const std::string out = dir.file(name);
  testing::ChildOptions o;
  o.cwd = dir.path();
  o.capture = dir.path();
  o.deadline_seconds = 120.0;
  const testing::ChildResult r =
      testing::run_pdflab({"render", "--scene", kBookScene, "--strategy", strategy, "--spp", "8",
                           "--width", "24", "--height", "20", "--seed", seed, "--threads", threads, "--out", out,
                           "--quiet"},
                          o);
  if (!r.exited || r.status != 0) {
    ADD_FAILURE() << "pdflab render failed (status " << r.status << "): " << r.err;
    return {};
  }
  std::string bytes = testing::slurp(out);
  EXPECT_GT(bytes.size(), 24u * 20u * 12u) << name;
  return bytes;
}

TEST(Determinism, ThreadCountDoesNotChangeTheImage) {
  TempDir dir;
  const std::string one = render_pfm(dir, "t1.pfm", "1", "11");
  const std::string two = render_pfm(dir, "t2.pfm", "2", "11");
  ASSERT_FALSE(one.empty());
  EXPECT_TRUE(one == two) << "--threads 1 and --threads 2 gave different PFM bytes";
}

TEST(Determinism, ThreadCountDoesNotChangeTheSobolSamplersImage) {
  TempDir dir;
  for (const char* strategy : {"mix:cosine=0.5,light=0.5+sobol", "nee-mis+mix:cosine=0.5,light=0.5+sobol"}) {
    const std::string one = render_pfm(dir, "s1.pfm", "1", "11", strategy);
    const std::string two = render_pfm(dir, "s2.pfm", "2", "11", strategy);
    const std::string without = std::string(strategy).substr(0, std::string(strategy).size() - 6);  // no +sobol
    const std::string independent = render_pfm(dir, "s3.pfm", "2", "11", without);
    ASSERT_FALSE(one.empty());
    EXPECT_TRUE(one == two) << strategy << ": --threads 1 and --threads 2 gave different PFM bytes";
    EXPECT_FALSE(one == independent) << strategy << ": the same image as without +sobol";
  }
}

TEST(Determinism, SeedChangesTheImage) {
  TempDir dir;
  const std::string a = render_pfm(dir, "a.pfm", "2", "11");
  const std::string b = render_pfm(dir, "b.pfm", "2", "12");
  ASSERT_FALSE(a.empty());
  ASSERT_EQ(a.size(), b.size());
  EXPECT_FALSE(a == b) << "--seed 11 and --seed 12 gave the same image";
  // Not just a few pixels: independent noise differs almost everywhere the
  // scene is lit. The header is identical, so compare the float data.
  std::size_t differing = 0;
  for (std::size_t i = a.size() - 24u * 20u * 12u; i + 4 <= a.size(); i += 4)
    differing += std::memcmp(a.data() + i, b.data() + i, 4) != 0;
  EXPECT_GT(differing, 24u * 20u * 3u / 2u) << "only " << differing << " floats differ";
}

// The same through the library: threads and pass sizes vary, sums must not.
Film render_film(const std::shared_ptr<const Scene>& scene, int threads, std::uint64_t seed) {
  testing::Rendered r =
      testing::render_to_completion(scene, "mix:cosine=0.5,light=0.5", 6, seed, threads, std::chrono::seconds(60));
  EXPECT_EQ(r.stats.spp, 6u);
  return std::move(r.film);
}

std::shared_ptr<const Scene> small_book_scene() {
  auto scene = std::make_shared<Scene>(load_scene_file(kBookScene));
  scene->camera.width = 20;
  scene->camera.height = 18;
  scene->camera.prepare();
  return scene;
}

TEST(Determinism, SessionFilmIsIdenticalForOneAndThreeThreads) {
  const auto scene = small_book_scene();
  const Film a = render_film(scene, 1, 3);
  const Film b = render_film(scene, 3, 3);
  ASSERT_EQ(a.pixel_count(), 20u * 18u);
  ASSERT_EQ(b.pixel_count(), a.pixel_count());
  std::size_t lit = 0;
  for (std::size_t p = 0; p < a.pixel_count(); ++p) {
    ASSERT_EQ(a.count(p), 6u);
    ASSERT_EQ(b.count(p), 6u);
    double ma[3], mb[3], va[3], vb[3];
    a.mean(p, ma);
    b.mean(p, mb);
    a.variance_of_mean(p, va);
    b.variance_of_mean(p, vb);
    // Bitwise: the same samples summed in the same order.
    EXPECT_EQ(std::memcmp(ma, mb, sizeof ma), 0) << "pixel " << p;
    EXPECT_EQ(std::memcmp(va, vb, sizeof va), 0) << "pixel " << p;
    lit += ma[0] > 0.0;
  }
  EXPECT_GT(lit, a.pixel_count() / 2) << "most of the box should receive light";

  const Film c = render_film(scene, 3, 4);
  std::size_t differing = 0;
  for (std::size_t p = 0; p < a.pixel_count(); ++p) {
    double ma[3], mc[3];
    a.mean(p, ma);
    c.mean(p, mc);
    differing += std::memcmp(ma, mc, sizeof ma) != 0;
  }
  EXPECT_GT(differing, a.pixel_count() / 2) << "seed 3 and seed 4 gave nearly the same film";
}

}  // namespace
}  // namespace pdflab
