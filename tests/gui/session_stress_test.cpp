// What the viewer does to a RenderSession, a thousand times over while it
// renders: new strategies, weights, scenes, seeds, targets, pauses, with the
// "UI thread" copying images and statistics in between. Meant for the tsan
// preset (cmake --preset tsan), where any data race fails the test.
#include "renderer/error.h"
#include "renderer/scene/scene_loader.h"
#include "renderer/session/session.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <random>
#include <thread>

using namespace pdflab;
using namespace std::chrono_literals;

namespace {

std::shared_ptr<const Scene> scene_at(const std::string& file, int size, int depth) {
  Scene s = load_scene_file(file);
  s.camera.width = size;
  s.camera.height = size;
  s.max_depth = depth;
  s.camera.prepare();
  return std::make_shared<const Scene>(std::move(s));
}

// A scene without importance targets: light-only strategies are rejected on it.
constexpr const char* kNoTargets = R"({
  "name": "no targets",
  "camera": { "width": 24, "height": 16, "vfov": 40, "lookfrom": [0, 0, -5], "lookat": [0, 0, 0],
              "vup": [0, 1, 0], "max_depth": 8, "background": [0.5, 0.6, 0.7] },
  "materials": { "grey": { "type": "lambertian", "albedo": [0.5, 0.5, 0.5] } },
  "objects": [ { "type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "grey" } ]
})";

}  // namespace

TEST(SessionStress, ThousandChangesWhileRendering) {
  const std::string book = PDFLAB_SOURCE_DIR "/tests/gui/cornell_small.json";
  const std::vector<std::shared_ptr<const Scene>> scenes = {
      scene_at(book, 24, 6), scene_at(book, 40, 3), scene_at(book, 17, 50),
      std::make_shared<const Scene>(load_scene_text(kNoTargets, "<no targets>"))};

  SessionOptions options;
  options.threads = 4;  // more workers than cores: more interleavings
  options.background_priority = true;
  options.preview = true;
  options.preview_budget_ms = 0.05;  // previews on these small images too
  std::atomic<int> published{0};
  options.on_image = [&published] { published.fetch_add(1, std::memory_order_relaxed); };
  RenderSession session(options);

  std::mt19937 rng(12345);
  auto uniform = [&](float lo, float hi) { return std::uniform_real_distribution<float>(lo, hi)(rng); };
  RenderSettings rs;
  rs.scene = scenes[0];
  rs.strategy = Strategy::parse("mix:cosine=0.5,light=0.5");
  session.set_settings(rs);

  std::vector<float> rgb;
  ImageInfo info;
  std::uint64_t version = 0;
  int rejected = 0, images = 0;
  bool paused = false;
  for (int change = 0; change < 1000; ++change) {
    switch (rng() % 6) {
      case 0: {  // a new mixture, weights from the sliders
        float total = 0.0f;
        for (float& w : rs.strategy.weights) total += w = uniform(0.0f, 1.0f) < 0.3f ? 0.0f : uniform(0.0f, 1.0f);
        if (total == 0.0f) rs.strategy.weights[static_cast<int>(Technique::Cosine)] = 1.0f;
        break;
      }
      case 1:  // a single technique
        rs.strategy = Strategy::single(static_cast<Technique>(rng() % kTechniqueCount));
        break;
      case 2:
        rs.scene = scenes[rng() % scenes.size()];
        break;
      case 3:
        rs.seed = rng();
        break;
      case 4:
        session.set_target_spp(static_cast<std::uint32_t>(rng() % 4 == 0 ? 0 : rng() % 16));
        break;
      case 5:
        paused = !paused;
        session.set_paused(paused);
        break;
    }
    try {
      session.set_settings(rs);
    } catch (const InputError&) {
      ++rejected;  // light only on the scene without targets: the old settings go on
    }
    if (session.copy_image(rgb, info, version)) {
      ++images;
      ASSERT_EQ(rgb.size(), 3u * static_cast<std::size_t>(info.data_width) * static_cast<std::size_t>(info.data_height));
    }
    const SessionStats st = session.stats();
    ASSERT_LE(st.progress, 1.0);
    std::this_thread::sleep_for(std::chrono::microseconds(rng() % 1500));
  }

  // Still a working session afterwards: finishes a fixed target.
  session.set_paused(false);
  rs.scene = scenes[0];
  rs.strategy = Strategy::parse("cosine");
  rs.target_spp = 3;
  session.set_settings(rs);
  ASSERT_TRUE(session.wait_until_done(120s));
  const SessionStats st = session.stats();
  EXPECT_EQ(st.spp, 3u);
  EXPECT_EQ(session.copy_film().width(), 24);
  EXPECT_GE(published.load(), images);
  std::printf("changes: 1000, rejected: %d, images seen: %d of %d published\n", rejected, images, published.load());
}

// Path guiding's training passes (record from every worker at once, then the
// last one out builds the next distribution) with settings changed in the
// middle of training, many times: each generation trains anew from its own
// first pass and renders only once trained (ThreadSanitizer runs this too).
TEST(SessionStress, GuidingTrainsAnewAfterChangesMidTraining) {
  const auto door = scene_at(PDFLAB_SOURCE_DIR "/assets/scenes/door_ajar.json", 24, 8);
  SessionOptions options;
  options.threads = 4;
  options.preview = true;
  options.preview_budget_ms = 0.05;
  RenderSession session(options);
  RenderSettings rs;
  rs.scene = door;
  rs.target_spp = 2;
  const char* strategies[] = {"nee-mis+mix:cosine=0.5,guided:6=0.5", "mix:cosine=0.5,guided:3=0.5", "cosine"};
  for (int change = 0; change < 40; ++change) {
    rs.strategy = Strategy::parse(strategies[change % 3]);
    rs.seed = static_cast<std::uint64_t>(change);
    session.set_settings(rs);
    std::this_thread::sleep_for(std::chrono::microseconds(300 * (change % 7)));
  }
  rs.strategy = Strategy::parse("nee-mis+mix:cosine=0.5,guided:4=0.5");
  session.set_settings(rs);
  ASSERT_TRUE(session.wait_until_done(std::chrono::seconds(300)));
  const SessionStats st = session.stats();
  EXPECT_EQ(st.guiding_passes, 4);
  EXPECT_EQ(st.guiding_pass, 4);
  EXPECT_EQ(st.spp, 2u);
  EXPECT_GT(st.guiding.nodes, 6u);
  ASSERT_NE(session.guiding(), nullptr);
  rs.strategy = Strategy::parse("cosine");
  session.set_settings(rs);
  ASSERT_TRUE(session.wait_until_done(std::chrono::seconds(300)));
  EXPECT_EQ(session.stats().guiding_passes, 0);
  EXPECT_EQ(session.guiding(), nullptr);
}
