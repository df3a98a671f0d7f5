// The viewer's plain-data parts: settings <-> strategies, presets, screenshot
// names and failures, image placement. No window needed.
#include "renderer/error.h"
#include "ui/camera_control.h"
#include "ui/display.h"
#include "ui/image_view.h"
#include "ui/screenshot.h"
#include "ui/settings.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;
using namespace pdflab;

namespace {

ui::ScreenshotData tiny_image() {
  ui::ScreenshotData d;
  d.width = 4;
  d.height = 2;
  d.rgb.assign(3 * 8, 0.25f);
  d.scene_name = "test";
  d.strategy = Strategy::parse("mix:cosine=1,light=3");
  d.spp = 7;
  d.seed = 9;
  d.version = "test";
  return d;
}

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("pdflab-ui-test-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir;
}

}  // namespace

TEST(SamplingSettings, MixtureRoundTripsAndNormalises) {
  const auto s = ui::SamplingSettings::from(Strategy::parse("mix:cosine=1,light=3"));
  EXPECT_TRUE(s.mixture);
  EXPECT_EQ(s.strategy().to_string(), Strategy::parse("mix:cosine=1,light=3").to_string());
  const auto n = s.normalised();
  EXPECT_FLOAT_EQ(n[static_cast<int>(Technique::Cosine)], 0.25f);
  EXPECT_FLOAT_EQ(n[static_cast<int>(Technique::Light)], 0.75f);
  EXPECT_FLOAT_EQ(n[static_cast<int>(Technique::UniformSphere)], 0.0f);
}

TEST(SamplingSettings, SingleTechniqueIsNotAMixture) {
  const auto s = ui::SamplingSettings::from(Strategy::parse("uniform-sphere"));
  EXPECT_FALSE(s.mixture);
  EXPECT_EQ(s.single, Technique::UniformSphere);
  EXPECT_EQ(s.strategy().to_string(), "uniform-sphere");
}

TEST(SamplingSettings, AllZeroWeightsNormaliseToZero) {
  ui::SamplingSettings s;
  s.mixture = true;
  for (float w : s.normalised()) EXPECT_EQ(w, 0.0f);
}

TEST(ImageView, ZoomKeepsThePointUnderTheCursorAndOneToOneIsWholePixels) {
  const ui::Viewport area{0, 0, 400, 300};
  ui::ImageView v;
  const ui::Viewport fitted = v.place(area, 100, 100);
  EXPECT_EQ(fitted.width, 300);
  // The image point under (150, 100) before and after zooming by 2.5.
  const auto image_point = [&](const ui::Viewport& p, double x, double y) {
    return std::pair{(x - p.x) * 100.0 / p.width, (y - p.y) * 100.0 / p.height};
  };
  const auto before = image_point(fitted, 150, 100);
  v.zoom_about(area, 100, 100, 2.5, 150, 100);
  EXPECT_FALSE(v.fit);
  const ui::Viewport zoomed = v.place(area, 100, 100);
  EXPECT_EQ(zoomed.width, 750);
  const auto after = image_point(zoomed, 150, 100);
  EXPECT_NEAR(before.first, after.first, 0.01);
  EXPECT_NEAR(before.second, after.second, 0.01);
  v.pan(area, 100, 100, 10, -4);
  EXPECT_EQ(v.place(area, 100, 100).x, zoomed.x + 10);
  EXPECT_EQ(v.place(area, 100, 100).y, zoomed.y - 4);
  v.zoom_about(area, 100, 100, 1e9, 0, 0);
  EXPECT_DOUBLE_EQ(v.zoom, ui::ImageView::kMaxZoom);
  v.actual_size(area, 101, 100);
  const ui::Viewport one = v.place(area, 101, 100);
  EXPECT_EQ(one.width, 101);
  EXPECT_EQ(one.height, 100);
  EXPECT_EQ(one.x, 149);
  EXPECT_EQ(one.y, 100);
  v.fit = true;
  EXPECT_EQ(v.place(area, 100, 100).width, fitted.width);
}

TEST(PixelInspector, ReadsThePublishedPixelItsNoiseAndTheReference) {
  PublishedImage img;
  img.info.width = img.info.data_width = 3;
  img.info.height = img.info.data_height = 2;
  img.info.spp = 16;
  img.rgb.resize(18);
  for (std::size_t i = 0; i < img.rgb.size(); ++i) img.rgb[i] = 0.1f * static_cast<float>(i);
  img.relative_standard_error = {0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f};
  const auto r = ui::read_pixel(img, nullptr, 2, 1);  // the last pixel
  ASSERT_TRUE(r);
  EXPECT_FLOAT_EQ(r->rgb[0], img.rgb[15]);
  EXPECT_FLOAT_EQ(r->rgb[2], img.rgb[17]);
  EXPECT_FLOAT_EQ(static_cast<float>(r->relative_standard_error), 0.6f);
  EXPECT_NEAR(r->luminance, 0.2126 * img.rgb[15] + 0.7152 * img.rgb[16] + 0.0722 * img.rgb[17], 1e-6);
  EXPECT_FALSE(r->has_reference);
  EXPECT_FALSE(ui::read_pixel(img, nullptr, 3, 0));
  EXPECT_FALSE(ui::read_pixel(img, nullptr, 0, -1));
  // The text shows what the PFM holds, %g with six digits.
  EXPECT_NE(r->text().find("RGB  1.5 1.6 1.7"), std::string::npos) << r->text();

  ui::ReferenceImage ref;
  ref.width = 3;
  ref.height = 2;
  ref.rgb.assign(18, 1.0f);
  const auto with_ref = ui::read_pixel(img, &ref, 2, 1);
  ASSERT_TRUE(with_ref && with_ref->has_reference);
  EXPECT_FLOAT_EQ(with_ref->reference[1], 1.0f);
  ref.width = 2;  // another size: not comparable
  EXPECT_FALSE(ui::read_pixel(img, &ref, 2, 1)->has_reference);

  // A preview: one value per 2x2 block, no noise figure.
  PublishedImage preview;
  preview.info.width = 4;
  preview.info.height = 4;
  preview.info.data_width = preview.info.data_height = 2;
  preview.info.preview_scale = 2;
  preview.info.preview = true;
  preview.rgb = {0, 0, 0, 1, 1, 1, 2, 2, 2, 3, 3, 3};
  const auto p = ui::read_pixel(preview, nullptr, 3, 2);
  ASSERT_TRUE(p);
  EXPECT_FLOAT_EQ(p->rgb[0], 3.0f);
  EXPECT_LT(p->relative_standard_error, 0.0);
}

TEST(SamplingSettings, TheWSliderPairIsTheTwoTechniquesInUseAndSurvivesZero) {
  const int cos = static_cast<int>(Technique::Cosine), light = static_cast<int>(Technique::Light);
  auto s = ui::SamplingSettings::from(Strategy::parse("mix:cosine=0.5,light=0.93"));
  EXPECT_EQ(ui::two_technique_pair(s, {-1, -1}), (std::array<int, 2>{cos, light}));
  // Dragged to w = 1: light's weight is 0, the pair stays while no other technique is used.
  s.weights[light] = 0.0f;
  EXPECT_EQ(ui::two_technique_pair(s, {cos, light}), (std::array<int, 2>{cos, light}));
  EXPECT_EQ(ui::two_technique_pair(s, {-1, -1}), (std::array<int, 2>{-1, -1}));
  // A third technique in use: no single w.
  s.weights[light] = 0.5f;
  s.weights[static_cast<int>(Technique::UniformSphere)] = 0.1f;
  EXPECT_EQ(ui::two_technique_pair(s, {cos, light}), (std::array<int, 2>{-1, -1}));
  EXPECT_EQ(ui::two_technique_pair(ui::SamplingSettings::from(Strategy::nee()), {cos, light}),
            (std::array<int, 2>{-1, -1}));
}

TEST(CameraControl, OrbitKeepsTheDistanceDollyAndPanMoveAsAsked) {
  const Camera c{};  // the default: 800 in front of the box, looking at its centre
  const float r = glm::length(c.lookfrom - c.lookat);
  const Camera o = ui::orbit(c, 0.3, 0.2);
  EXPECT_EQ(o.lookat, c.lookat);
  EXPECT_NEAR(glm::length(o.lookfrom - o.lookat), r, 1e-3f * r);
  EXPECT_FALSE(ui::same_placement(o, c));
  // Undone by the opposite turn (yaw, then pitch in reverse).
  const Camera back = ui::orbit(ui::orbit(o, 0.0, -0.2), -0.3, 0.0);
  EXPECT_NEAR(glm::length(back.lookfrom - c.lookfrom), 0.0f, 1e-2f);
  // Never over the top: pitching far stays short of vup.
  const Camera top = ui::orbit(c, 0.0, 10.0);
  const glm::vec3 dir = glm::normalize(top.lookfrom - top.lookat);
  EXPECT_LT(glm::dot(dir, c.vup), 1.0f);
  EXPECT_GT(glm::dot(dir, c.vup), 0.99f);
  // Dolly: the distance scales, the direction stays; never onto the point looked at.
  const Camera near = ui::dolly(c, 0.5);
  EXPECT_NEAR(glm::length(near.lookfrom - near.lookat), r * 0.5f, 1e-3f * r);
  EXPECT_GT(glm::length(ui::dolly(c, 0.0).lookfrom - c.lookat), 0.0f);
  EXPECT_GT(glm::length(ui::dolly(c, 1e-9).lookfrom - c.lookat), 0.0f);
  // Pan: both move together, across the view (not along it).
  const Camera p = ui::pan(c, 0.1, 0.0);
  EXPECT_EQ(p.lookfrom - c.lookfrom, p.lookat - c.lookat);
  const glm::vec3 shift = p.lookat - c.lookat;
  EXPECT_NEAR(glm::dot(shift, glm::normalize(c.lookat - c.lookfrom)), 0.0f, 1e-2f);
  // 0.1 of the view's height at the distance looked at.
  EXPECT_NEAR(glm::length(shift), 0.1f * 2.0f * r * std::tan(c.vfov_degrees * 3.14159265f / 360.0f), 0.05f);
}

TEST(QuitGuard, UnsavedSecondsCountFromTheLastSaveOfTheSameRender) {
  const ui::SaveMark none;
  EXPECT_DOUBLE_EQ(ui::unsaved_seconds(none, 3, 12.0), 12.0);
  const ui::SaveMark saved{3, 10.0};
  EXPECT_DOUBLE_EQ(ui::unsaved_seconds(saved, 3, 12.5), 2.5);
  EXPECT_DOUBLE_EQ(ui::unsaved_seconds(saved, 4, 1.0), 1.0);  // another render since: the save was not of it
  EXPECT_GT(ui::unsaved_seconds(none, 0, ui::kUnsavedAskSeconds + 1.0), ui::kUnsavedAskSeconds);
}

TEST(Presets, MatchTheBookAndFlagBias) {
  EXPECT_EQ(ui::preset_sampling(ui::Preset::Book5050).strategy().to_string(),
            Strategy::parse("mix:cosine=0.5,light=0.5").to_string());
  EXPECT_EQ(ui::preset_sampling(ui::Preset::CosineOnly).strategy().to_string(), "cosine");
  EXPECT_FALSE(ui::preset_sampling(ui::Preset::LightOnly).strategy().is_unbiased());
  EXPECT_TRUE(ui::preset_sampling(ui::Preset::Book5050).strategy().is_unbiased());
}

TEST(Screenshot, NamesNeverOverwriteAndFilesAreComplete) {
  const fs::path dir = fresh_dir("names");
  const std::time_t when = 1700000000;
  const auto first = ui::save_screenshot_in(dir.string(), tiny_image(), when);
  const auto second = ui::save_screenshot_in(dir.string(), tiny_image(), when);
  EXPECT_NE(first.png, second.png);
  EXPECT_NE(first.png.find("-1.png"), std::string::npos);
  EXPECT_NE(second.png.find("-2.png"), std::string::npos);
  for (const auto* s : {&first, &second})
    for (const std::string& p : {s->png, s->pfm, s->json}) EXPECT_GT(fs::file_size(p), 0u) << p;

  // A stray file of the user's with the next name is skipped, not replaced.
  const std::string stray = (dir / fs::path(first.png).filename()).string();
  const std::string taken = stray.substr(0, stray.size() - 6) + "-3.png";
  std::ofstream(taken) << "mine";
  const auto third = ui::save_screenshot_in(dir.string(), tiny_image(), when);
  EXPECT_NE(third.png.find("-4.png"), std::string::npos);
  EXPECT_EQ(fs::file_size(taken), 4u);

  int w = 0, h = 0;
  const auto rgb = read_pfm(first.pfm, w, h);
  EXPECT_EQ(w, 4);
  EXPECT_EQ(h, 2);
  EXPECT_FLOAT_EQ(rgb[0], 0.25f);
  std::ifstream json(first.json);
  const std::string text((std::istreambuf_iterator<char>(json)), {});
  EXPECT_NE(text.find("\"spp\": 7"), std::string::npos) << text;
  EXPECT_NE(text.find("\"seed\": 9"), std::string::npos) << text;
  EXPECT_NE(text.find("\"light\": 0.75"), std::string::npos) << text;
  fs::remove_all(dir);
}

TEST(Screenshot, UnwritableFolderThrowsAndLeavesNothing) {
  // /proc refuses new files even to root.
  EXPECT_THROW(ui::save_screenshot_in("/proc/pdflab-no-such-dir", tiny_image(), 1700000000), IoError);
  EXPECT_FALSE(fs::exists("/proc/pdflab-no-such-dir"));
}

TEST(Screenshot, SaveAsPutsPfmAndJsonBeside) {
  const fs::path dir = fresh_dir("as");
  fs::create_directories(dir);
  const auto saved = ui::save_screenshot_as((dir / "out.png").string(), tiny_image());
  EXPECT_EQ(saved.pfm, (dir / "out.pfm").string());
  EXPECT_EQ(saved.json, (dir / "out.json").string());
  EXPECT_TRUE(fs::exists(saved.png) && fs::exists(saved.pfm) && fs::exists(saved.json));
  fs::remove_all(dir);
}

TEST(FitImage, KeepsAspectAndCentres) {
  const ui::Viewport v = ui::fit_image({0, 0, 800, 600}, 600, 600);
  EXPECT_EQ(v.width, 600);
  EXPECT_EQ(v.height, 600);
  EXPECT_EQ(v.x, 100);
  EXPECT_EQ(v.y, 0);
  const ui::Viewport wide = ui::fit_image({0, 0, 400, 400}, 800, 200);
  EXPECT_EQ(wide.width, 400);
  EXPECT_EQ(wide.height, 100);
  EXPECT_EQ(wide.y, 150);
  EXPECT_EQ(ui::fit_image({0, 0, 0, 0}, 10, 10).width, 0);  // minimised
}
