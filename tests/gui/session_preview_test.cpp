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
  // Every published image is recorded from the on_image hook: the publishing
  // worker still holds the session lock there, so none can be missed by polling.
  std::vector<ImageInfo> published;
  std::vector<std::size_t> sizes;
  RenderSession* self = nullptr;
  SessionOptions o;
  o.threads = 2;
  o.preview = true;
  o.preview_budget_ms = 0.01;  // forces the coarsest preview
  std::vector<float> rgb;
  std::uint64_t version = 0;
  o.on_image = [&] {
    ImageInfo info;
    if (self->copy_image(rgb, info, version)) {
      published.push_back(info);
      sizes.push_back(rgb.size());
    }
  };
  RenderSession session(o);
  self = &session;
  session.set_settings(settings_for(small_scene(64), 4));
  const std::uint64_t generation = session.generation();
  ASSERT_TRUE(session.wait_until_done(30s));
  ASSERT_GE(published.size(), 2u);
  EXPECT_TRUE(published.front().preview);
  EXPECT_EQ(published.front().spp, 0u);
  EXPECT_GT(published.front().preview_scale, 1);
  for (std::size_t i = 0; i < published.size(); ++i) {
    const ImageInfo& info = published[i];
    EXPECT_EQ(info.generation, generation);
    EXPECT_EQ(info.width, 64);
    EXPECT_EQ(info.data_width, (64 + info.preview_scale - 1) / info.preview_scale);
    EXPECT_EQ(sizes[i], 3u * static_cast<std::size_t>(info.data_width) * static_cast<std::size_t>(info.data_height));
    if (i > 0) {
      EXPECT_FALSE(info.preview);
    }
  }
  EXPECT_EQ(published.back().spp, 4u);
  EXPECT_EQ(session.stats().samples, 4u * 64 * 64);  // preview samples are not counted
}

TEST(SessionPreview, PlainCopyImageEnlargesThePreview) {
  SessionOptions o;
  o.threads = 1;
  o.preview = true;
  o.preview_budget_ms = 0.01;
  RenderSession session(o);
  session.set_paused(true);  // nothing after the preview: it stays the published image
  session.set_settings(settings_for(small_scene(37), 0));
  session.set_paused(false);
  session.set_paused(true);
  std::vector<float> raw, full;
  ImageInfo info;
  std::uint64_t v1 = 0, v2 = 0;
  int w = 0, h = 0;
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  while (!session.copy_image(raw, info, v1) && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(100us);
  ASSERT_TRUE(session.copy_image(full, w, h, v2));
  if (!info.preview || v1 != v2) {
    GTEST_SKIP() << "the first full pass was published before the copy";
  }
  ASSERT_EQ(full.size(), 3u * 37 * 37);
  const int s = info.preview_scale;
  for (int y = 0; y < 37; ++y)
    for (int x = 0; x < 37; ++x)
      ASSERT_EQ(full[3 * (y * 37 + x)], raw[3 * ((y / s) * info.data_width + x / s)]) << x << "," << y;
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

TEST(SessionTarget, ATimeLimitStopsAtAPassBoundaryAfterIt) {
  RenderSession session(2);
  RenderSettings rs = settings_for(small_scene(32), 0);
  rs.target_seconds = 0.25;
  session.set_settings(rs);
  ASSERT_TRUE(session.wait_until_done(120s));
  const SessionStats st = session.stats();
  EXPECT_TRUE(st.done);
  EXPECT_GE(st.seconds, 0.25);
  EXPECT_GT(st.spp, 0u);
  EXPECT_DOUBLE_EQ(st.progress, 1.0);
  // Stopped: the clock and the film hold still.
  std::this_thread::sleep_for(100ms);
  EXPECT_EQ(session.stats().spp, st.spp);
  EXPECT_DOUBLE_EQ(session.stats().seconds, st.seconds);
  // A later limit goes on with the same film.
  const std::uint64_t generation = session.generation();
  session.set_target_seconds(st.seconds + 0.2);
  ASSERT_TRUE(session.wait_until_done(120s));
  EXPECT_EQ(session.generation(), generation);
  EXPECT_GT(session.stats().spp, st.spp);
  // The spp target still counts beside it: whichever comes first.
  RenderSession both(2);
  rs.target_seconds = 3600.0;
  rs.target_spp = 3;
  both.set_settings(rs);
  ASSERT_TRUE(both.wait_until_done(120s));
  EXPECT_EQ(both.stats().spp, 3u);
}

TEST(SessionResume, AFilmsTimeAndSamplesGoOnFromTheFilm) {
  RenderSession first(2);
  first.set_settings(settings_for(small_scene(32), 4));
  ASSERT_TRUE(first.wait_until_done(60s));
  FilmStart start{first.copy_film(), 4, first.stats().dropped, 30.0};  // as a film saved after 30 s says
  const std::uint64_t film_samples = 4ull * 32 * 32;

  RenderSession resumed(2);
  RenderSettings rs = settings_for(small_scene(32), 8);
  rs.first_sample = 0;
  resumed.resume(rs, std::move(start));
  ASSERT_TRUE(resumed.wait_until_done(60s));
  const SessionStats st = resumed.stats();
  EXPECT_EQ(st.spp, 8u);
  // The film's 30 s and its samples are in the figures: per second and efficiency describe the whole film.
  EXPECT_GE(st.seconds, 30.0);
  EXPECT_LT(st.seconds, 30.0 + 60.0);
  EXPECT_EQ(st.samples, 2 * film_samples);
  EXPECT_NEAR(st.samples_per_second, static_cast<double>(st.samples) / st.seconds, 1e-6 * st.samples_per_second);
  // A published image says so too.
  std::vector<float> rgb;
  ImageInfo info;
  std::uint64_t version = 0;
  ASSERT_TRUE(resumed.copy_image(rgb, info, version));
  EXPECT_GE(info.seconds, 30.0);
  // A film whose time is not known: this run's clock and samples alone.
  RenderSession plain(2);
  plain.resume(settings_for(small_scene(32), 8), FilmStart{resumed.copy_film(), 8, {}, 0.0});
  plain.set_target_spp(12);
  ASSERT_TRUE(plain.wait_until_done(60s));
  EXPECT_EQ(plain.stats().samples, 4ull * 32 * 32);
  EXPECT_LT(plain.stats().seconds, 30.0);
}

TEST(SessionResume, AFilmAtItsTargetIsPublishedAtOnce) {
  // A film continued at (or past) its spp target renders no pass; it is still
  // this generation's image, or a viewer waiting for one (a screenshot at
  // --spp N, auto weight continuing a film that just reached its stop) waits forever.
  RenderSession first(2);
  first.set_settings(settings_for(small_scene(32), 4));
  ASSERT_TRUE(first.wait_until_done(60s));
  const Film film = first.copy_film();
  std::vector<float> first_rgb;
  ImageInfo first_info;
  std::uint64_t first_version = 0;
  ASSERT_TRUE(first.copy_image(first_rgb, first_info, first_version));

  for (const bool paused : {false, true}) {
    RenderSession resumed(2);
    resumed.set_paused(paused);
    resumed.resume(settings_for(small_scene(32), 4), FilmStart{film, 4, first.stats().dropped, 10.0});
    ASSERT_TRUE(resumed.wait_until_done(60s));
    std::vector<float> rgb;
    ImageInfo info;
    std::uint64_t version = 0;
    ASSERT_TRUE(resumed.copy_image(rgb, info, version)) << "paused " << paused;
    EXPECT_EQ(info.generation, resumed.generation());
    EXPECT_FALSE(info.preview);
    EXPECT_EQ(info.spp, 4u);
    EXPECT_GE(info.seconds, 10.0);
    EXPECT_EQ(rgb, first_rgb);  // the film's own mean, as the pass that made it published it
    EXPECT_EQ(resumed.stats().spp, 4u);
  }
}
