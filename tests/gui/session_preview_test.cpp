// The session's preview pass and target changes: the viewer depends on them,
// and the film must stay exactly what a plain session accumulates.
#include "renderer/scene/scene_loader.h"
#include "renderer/session/session.h"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

using namespace pdflab;
using namespace std::chrono_literals;

namespace {

std::shared_ptr<const Scene> small_scene(int size) {
  Scene s = load_scene_file(PDFLAB_SOURCE_DIR "/tests/gui/cornell_small.json");
  s.camera.width = size;
  s.camera.height = size;
  s.camera.prepare();
  return std::make_shared<const Scene>(std::move(s));
}

RenderSettings settings_for(std::shared_ptr<const Scene> scene, std::uint32_t spp) {
  RenderSettings rs;
  rs.scene = std::move(scene);
  rs.strategy = Strategy::parse("mix:cosine=0.5,light=0.5");
  rs.seed = 3;
  rs.target_spp = spp;
  return rs;
}

}  // namespace

TEST(SessionPreview, FirstImageIsAPreviewOfTheNewGeneration) {
  SessionOptions o;
  o.threads = 2;
  o.preview = true;
  o.preview_budget_ms = 0.01;  // forces the coarsest preview
  RenderSession session(o);
  session.set_settings(settings_for(small_scene(64), 4));
  const std::uint64_t generation = session.generation();
  std::vector<float> rgb;
  ImageInfo info;
  std::uint64_t version = 0;
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  bool saw_preview = false;
  while (std::chrono::steady_clock::now() < deadline) {
    if (session.copy_image(rgb, info, version)) {
      EXPECT_EQ(info.generation, generation);
      EXPECT_EQ(info.width, 64);
      EXPECT_EQ(rgb.size(), 3u * 64 * 64);
      if (info.preview) {
        saw_preview = true;
        EXPECT_EQ(info.spp, 0u);
      } else if (info.spp == 4) {
        break;
      }
    }
    std::this_thread::sleep_for(100us);
  }
  EXPECT_TRUE(saw_preview);
  ASSERT_TRUE(session.wait_until_done(30s));
  EXPECT_EQ(session.stats().samples, 4u * 64 * 64);  // preview samples are not counted
}

TEST(SessionPreview, FilmIsIdenticalWithAndWithoutPreview) {
  const auto scene = small_scene(48);
  SessionOptions with;
  with.threads = 2;
  with.preview = true;
  with.preview_budget_ms = 0.01;
  RenderSession a(with);
  RenderSession b(2);
  a.set_settings(settings_for(scene, 6));
  b.set_settings(settings_for(scene, 6));
  ASSERT_TRUE(a.wait_until_done(60s));
  ASSERT_TRUE(b.wait_until_done(60s));
  EXPECT_EQ(a.copy_film().mean_rgb(), b.copy_film().mean_rgb());
}

TEST(SessionTarget, RaisingTheTargetContinuesWithoutRestart) {
  RenderSession session(2);
  session.set_settings(settings_for(small_scene(32), 2));
  ASSERT_TRUE(session.wait_until_done(30s));
  const std::uint64_t generation = session.generation();
  session.set_target_spp(5);
  ASSERT_TRUE(session.wait_until_done(30s));
  EXPECT_EQ(session.generation(), generation);
  EXPECT_EQ(session.stats().spp, 5u);

  RenderSession reference(2);
  reference.set_settings(settings_for(small_scene(32), 5));
  ASSERT_TRUE(reference.wait_until_done(30s));
  EXPECT_EQ(session.copy_film().mean_rgb(), reference.copy_film().mean_rgb());
}
