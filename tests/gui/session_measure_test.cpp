// What the session publishes for the viewer's measurements: the per-pixel
// noise map and noise figures of each pass, and which pixels dropped samples
// and why. Checked against the film and against pixels rendered one by one.
#include "renderer/metrics/metrics.h"
#include "renderer/scene/scene_loader.h"
#include "renderer/session/session.h"

#include <gtest/gtest.h>

#include <chrono>

using namespace pdflab;
using namespace std::chrono_literals;

namespace {

std::shared_ptr<const Scene> load(const char* name) {
  return std::make_shared<const Scene>(load_scene_file(std::string(PDFLAB_SOURCE_DIR "/tests/gui/") + name));
}

PublishedImage render_and_publish(std::shared_ptr<const Scene> scene, const char* strategy, std::uint32_t spp,
                                  Film* film = nullptr) {
  RenderSession session(2);
  RenderSettings rs;
  rs.scene = std::move(scene);
  rs.strategy = Strategy::parse(strategy);
  rs.seed = 5;
  rs.target_spp = spp;
  session.set_settings(rs);
  EXPECT_TRUE(session.wait_until_done(60s));
  PublishedImage out;
  std::uint64_t version = 0;
  EXPECT_TRUE(session.copy_published(out, version));
  if (film) *film = session.copy_film();
  return out;
}

}  // namespace

TEST(SessionMeasure, DropMaskMarksExactlyThePixelsThatDroppedAndWhy) {
  // A tiny importance sphere whose cone pdf overflows: the light technique's
  // samples towards it are dropped as pdf_not_finite, from the floor only.
  const auto scene = load("tiny_target.json");
  const char* strategy = "mix:cosine=0.5,light=0.5";
  const std::uint32_t spp = 4;
  const PublishedImage img = render_and_publish(scene, strategy, spp);
  const std::size_t pixels = static_cast<std::size_t>(img.info.width) * img.info.height;
  ASSERT_EQ(img.drop_mask.size(), pixels);
  ASSERT_EQ(img.relative_standard_error.size(), pixels);

  // The same pixels rendered one at a time, outside the session.
  const SamplingPlan plan = SamplingPlan::make(Strategy::parse(strategy), *scene);
  std::size_t marked = 0, clean = 0;
  for (int y = 0; y < img.info.height; ++y)
    for (int x = 0; x < img.info.width; ++x) {
      DropCounts drops;
      for (std::uint32_t s = 0; s < spp; ++s) render_pixel_sample(*scene, plan, 5, x, y, s, drops);
      const std::uint8_t expected = drop_reason_bits(DropCounts{}, drops);
      const std::size_t p = static_cast<std::size_t>(y) * img.info.width + x;
      ASSERT_EQ(img.drop_mask[p], expected) << "pixel " << x << "," << y;
      if (expected) {
        EXPECT_EQ(expected, 1u << static_cast<int>(DropReason::PdfNotFinite));
        ++marked;
      } else {
        ++clean;
      }
    }
  // Both kinds occur: floor pixels drop, the background's never do.
  EXPECT_GT(marked, pixels / 10);
  EXPECT_GT(clean, pixels / 10);
}

TEST(SessionMeasure, NoDropsNoMarks) {
  const PublishedImage img = render_and_publish(load("tiny_target.json"), "cosine", 4);
  for (std::uint8_t bits : img.drop_mask) ASSERT_EQ(bits, 0);
}

TEST(SessionMeasure, NoiseMapAndFiguresAreTheFilmsOwn) {
  Film film;
  const PublishedImage img = render_and_publish(load("cornell_small.json"), "mix:cosine=0.5,light=0.5", 8, &film);
  EXPECT_FALSE(img.info.preview);
  EXPECT_EQ(img.info.spp, 8u);
  const std::vector<float> map = relative_standard_error_map(film);
  ASSERT_EQ(img.relative_standard_error.size(), map.size());
  for (std::size_t p = 0; p < map.size(); ++p) ASSERT_FLOAT_EQ(img.relative_standard_error[p], map[p]) << p;
  // The session sums the figures tile by tile (each tile as a pass renders
  // it), the film's own sweep row by row: the same terms in another order.
  EXPECT_NEAR(img.info.mean_relative_standard_error, mean_relative_standard_error(film),
              1e-12 * mean_relative_standard_error(film));
  EXPECT_NEAR(img.info.estimated_relmse, estimated_relmse(film), 1e-12 * estimated_relmse(film));
  EXPECT_GT(img.info.mean_relative_standard_error, 0.0);
}

TEST(SessionMeasure, DropMaskClearsOnRestart) {
  RenderSession session(2);
  RenderSettings rs;
  rs.scene = load("tiny_target.json");
  rs.strategy = Strategy::parse("mix:cosine=0.5,light=0.5");
  rs.target_spp = 2;
  session.set_settings(rs);
  ASSERT_TRUE(session.wait_until_done(60s));
  rs.strategy = Strategy::parse("cosine");
  session.set_settings(rs);
  ASSERT_TRUE(session.wait_until_done(60s));
  PublishedImage img;
  std::uint64_t version = 0;
  ASSERT_TRUE(session.copy_published(img, version));
  EXPECT_EQ(img.info.generation, session.generation());
  for (std::uint8_t bits : img.drop_mask) ASSERT_EQ(bits, 0);
}
