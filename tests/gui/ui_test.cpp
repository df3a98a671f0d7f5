// The viewer's plain-data parts: settings <-> strategies, presets, screenshot
// names and failures, image placement. No window needed.
#include "renderer/error.h"
#include "ui/display.h"
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
