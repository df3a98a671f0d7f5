// The viewer's layout and what it hands in, without a window: where overlays
// go (never over each other or the image's middle), the panel's width, the
// presets in one place, remembered settings, and the figures it exports.
#include "renderer/error.h"
#include "ui/figure_export.h"
#include "ui/overlay_layout.h"
#include "ui/preferences.h"
#include "ui/settings.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <unistd.h>

namespace fs = std::filesystem;
using namespace pdflab;
using namespace pdflab::ui;

namespace {

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("pdflab-layout-test-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir;
}

// A heat-map-like layer: a left-to-right ramp through the scale's colours.
ViewLayer ramp_layer(int w, int h) {
  ViewLayer l;
  l.width = w;
  l.height = h;
  l.scale = relative_error_scale();
  l.rgba.resize(4 * static_cast<std::size_t>(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const Colour c = sequential_colour(static_cast<double>(x) / (w - 1));
      std::uint8_t* p = &l.rgba[4 * (static_cast<std::size_t>(y) * w + x)];
      for (int i = 0; i < 3; ++i) p[i] = static_cast<std::uint8_t>(std::lround(c[static_cast<std::size_t>(i)] * 255.0f));
      p[3] = 255;
    }
  return l;
}

}  // namespace

TEST(OverlayPlanner, BoxesNeverOverlapEachOtherTheCentreOrLeaveTheArea) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  int placed = 0, left_out = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const Box area{0.0f, 0.0f, 300.0f + 1500.0f * u(rng), 300.0f + 900.0f * u(rng)};
    const float side = std::min(area.w, area.h) * (0.6f + 0.6f * u(rng));
    const Box image{(area.w - side) * u(rng), (area.h - side) * u(rng), side, side};
    const Box keep = centre_keep_out(image, area);
    OverlayPlanner planner(area, keep, 8.0f, 6.0f);
    std::vector<Box> boxes;
    for (int i = 0; i < 7; ++i) {
      BoxRequest r;
      r.corner = static_cast<Corner>(i % 4);
      r.width = 80.0f + 500.0f * u(rng);
      r.height = 30.0f + 300.0f * u(rng);
      r.min_width = 60.0f;
      r.min_height = 30.0f;
      r.prefer_narrow = u(rng) < 0.7f;
      if (const auto b = planner.place(r)) {
        ++placed;
        EXPECT_FALSE(b->overlaps(keep)) << "trial " << trial;
        EXPECT_TRUE((Box{area.x + 7.9f, area.y + 7.9f, area.w - 15.8f, area.h - 15.8f}).contains(*b)) << "trial " << trial;
        EXPECT_GE(b->w, 60.0f - 1e-3f);
        EXPECT_GE(b->h, 30.0f - 1e-3f);
        for (const Box& o : boxes) EXPECT_FALSE(b->overlaps(o)) << "trial " << trial;
        boxes.push_back(*b);
      } else {
        ++left_out;
      }
    }
  }
  EXPECT_GT(placed, 1000) << "the planner should fit most boxes";
  EXPECT_GT(left_out, 0) << "and leave some out where there is no room";
}

TEST(OverlayPlanner, TextWrapsInItsColumnAPlotGetsShorter) {
  const Box area{0.0f, 0.0f, 800.0f, 600.0f};
  const Box image{100.0f, 0.0f, 600.0f, 600.0f};
  const Box keep = centre_keep_out(image, area);
  EXPECT_FLOAT_EQ(keep.w, 150.0f);
  EXPECT_FLOAT_EQ(keep.x, 325.0f);
  OverlayPlanner planner(area, keep, 8.0f, 6.0f);
  // A text box too tall to fit above the keep-out at its width: it is made as
  // narrow as the column beside it, and as much taller as its lines may wrap,
  // not cut short.
  BoxRequest text{Corner::TopLeft, 400.0f, 250.0f, 100.0f, 40.0f, true};
  const auto t = planner.place(text);
  ASSERT_TRUE(t);
  EXPECT_FLOAT_EQ(t->w, planner.column_width(Corner::TopLeft));
  EXPECT_FLOAT_EQ(t->h, 500.0f);  // 400 wide into 311: two lines for each
  EXPECT_LE(t->right(), keep.x - 6.0f + 1e-3f);
  // One that fits above the keep-out keeps its natural size.
  OverlayPlanner roomy(area, keep, 8.0f, 6.0f);
  const auto n = roomy.place({Corner::TopLeft, 400.0f, 150.0f, 100.0f, 40.0f, true});
  ASSERT_TRUE(n);
  EXPECT_FLOAT_EQ(n->w, 400.0f);
  EXPECT_FLOAT_EQ(n->h, 150.0f);
  // A plot in the opposite corner finds room clear of both.
  BoxRequest plot{Corner::BottomRight, 500.0f, 300.0f, 100.0f, 40.0f, false};
  const auto p = planner.place(plot);
  ASSERT_TRUE(p);
  EXPECT_FALSE(p->overlaps(*t));
  EXPECT_FALSE(p->overlaps(keep));
  EXPECT_FLOAT_EQ(p->bottom(), area.bottom() - 8.0f);
  // Stacked in the same corner: the next one goes above the first.
  BoxRequest more{Corner::BottomLeft, 120.0f, 30.0f, 60.0f, 20.0f, true};
  const auto m1 = planner.place(more);
  const auto m2 = planner.place(more);
  ASSERT_TRUE(m1 && m2);
  EXPECT_FLOAT_EQ(m1->bottom(), area.bottom() - 8.0f);
  EXPECT_LE(m2->bottom(), m1->y - 6.0f + 1e-3f);
}

TEST(OverlayPlanner, NoRoomLeavesTheBoxOut) {
  const Box area{0.0f, 0.0f, 200.0f, 200.0f};
  OverlayPlanner planner(area, centre_keep_out(area, area), 8.0f, 6.0f);
  EXPECT_FALSE(planner.place({Corner::TopLeft, 180.0f, 180.0f, 180.0f, 180.0f, true}));
  EXPECT_TRUE(planner.placed().empty());
}

TEST(PanelWidth, FollowsTheScaleWithinItsShareOfTheWindow) {
  EXPECT_FLOAT_EQ(panel_width_for(400.0f, 1.0f, 1920.0f), 400.0f);
  EXPECT_FLOAT_EQ(panel_width_for(400.0f, 1.5f, 1920.0f), 600.0f);
  // 1280 wide at UI scale 2: never the 800 px it would be, 45% of the window at most.
  EXPECT_FLOAT_EQ(panel_width_for(400.0f, 2.0f, 1280.0f), kMaxPanelShare * 1280.0f);
  EXPECT_FLOAT_EQ(panel_width_for(10.0f, 1.0f, 1920.0f), kMinPanelWidth);
}

TEST(Presets, OnePlaceForAllFiveKeys) {
  for (int key = 1; key <= kPresetKeyCount; ++key) {
    const SamplingSettings s = preset_by_key(key);
    EXPECT_EQ(preset_key_of(s), key) << preset_key_label(key);
  }
  EXPECT_EQ(preset_by_key(4).strategy().to_string(), Strategy::nee().to_string());
  EXPECT_EQ(preset_by_key(5).strategy().to_string(), std::string(kFastestStrategy));
  SamplingSettings other = preset_by_key(3);
  other.weights[0] = 0.25f;
  EXPECT_EQ(preset_key_of(other), 0);
}

TEST(Preferences, RoundTripAndDefaultsForAMissingOrDamagedFile) {
  const fs::path dir = fresh_dir("prefs");
  const std::string path = (dir / "sub" / "viewer.json").string();
  std::string warning;
  EXPECT_EQ(load_preferences(path, warning), Preferences{});
  EXPECT_TRUE(warning.empty());
  Preferences p;
  p.window_width = 1280;
  p.window_height = 720;
  p.panel_width = 333.0f;
  p.panel_hidden = true;
  p.open = {false, true, true, false, true, true};
  p.caption = true;
  save_preferences(path, p);
  EXPECT_EQ(load_preferences(path, warning), p);
  EXPECT_TRUE(warning.empty());
  std::ofstream(path) << "{ \"window_width\": 12";
  EXPECT_EQ(load_preferences(path, warning), Preferences{});
  EXPECT_NE(warning.find("damaged"), std::string::npos) << warning;
  std::ofstream(path) << "{ \"panel_width\": \"wide\" }";
  EXPECT_EQ(load_preferences(path, warning), Preferences{});
  EXPECT_NE(warning.find("wrong type"), std::string::npos) << warning;
  // Out of range: brought in.
  std::ofstream(path) << "{ \"panel_width\": 5, \"window_width\": -3 }";
  const Preferences in = load_preferences(path, warning);
  EXPECT_FLOAT_EQ(in.panel_width, kMinPanelWidth);
  EXPECT_EQ(in.window_width, 0);
  ::setenv("PDFLAB_CONFIG_DIR", dir.c_str(), 1);
  EXPECT_EQ(preferences_path(), (dir / "viewer.json").string());
  ::unsetenv("PDFLAB_CONFIG_DIR");
  fs::remove_all(dir);
}

TEST(FigureExport, TheViewEnlargedPixelForPixelAboveItsColourBarAndCaption) {
  const ViewLayer layer = ramp_layer(40, 20);
  FigureCaption caption;
  caption.title = "noise heat map: relative standard error";
  caption.lines = {"Cornell box, 40x20", "mix:cosine=0.5,light=0.5", "64 spp, 1.2 s of rendering"};
  int w = 0, h = 0;
  const std::vector<std::uint8_t> rgb = view_figure_rgb(ViewMode::RelativeError, layer, caption, 480, w, h);
  const FigureGeometry g = view_figure_geometry(ViewMode::RelativeError, layer, caption, 480);
  EXPECT_EQ(g.scale, 12);  // 40 * 12 = 480
  EXPECT_EQ(w, g.width);
  EXPECT_EQ(h, g.height);
  ASSERT_EQ(rgb.size(), 3u * static_cast<std::size_t>(w) * h);
  // Each enlarged pixel is the layer's pixel.
  for (int y : {0, 7, 19})
    for (int x : {0, 13, 39}) {
      const int fx = g.image_x + x * g.scale + g.scale / 2, fy = g.image_y + y * g.scale + g.scale / 2;
      const std::uint8_t* f = &rgb[3 * (static_cast<std::size_t>(fy) * w + fx)];
      const std::uint8_t* l = &layer.rgba[4 * (static_cast<std::size_t>(y) * layer.width + x)];
      EXPECT_EQ(f[0], l[0]);
      EXPECT_EQ(f[1], l[1]);
      EXPECT_EQ(f[2], l[2]);
    }
  // Below the image: the colour bar (not white), and text (dark pixels) in the caption.
  const auto row_has = [&](int y0, int y1, auto pred) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < w; ++x)
        if (pred(&rgb[3 * (static_cast<std::size_t>(y) * w + x)])) return true;
    return false;
  };
  const int below = g.image_y + layer.height * g.scale;
  EXPECT_TRUE(row_has(below, h, [](const std::uint8_t* p) { return p[0] > 200 && p[2] < 150; })) << "the bar's yellow end";
  EXPECT_TRUE(row_has(h - 80, h, [](const std::uint8_t* p) { return p[0] < 140 && p[1] < 140 && p[2] < 140; }))
      << "caption text";
  // A longer caption makes a taller figure; the image does not move.
  caption.lines.push_back("one more line");
  const FigureGeometry g2 = view_figure_geometry(ViewMode::RelativeError, layer, caption, 480);
  EXPECT_GT(g2.height, g.height);
  EXPECT_EQ(g2.image_y, g.image_y);
  // The PNG decodes to the same size (its header's width and height).
  const std::vector<std::uint8_t> png = view_figure_png(ViewMode::RelativeError, layer, caption, 480);
  ASSERT_GT(png.size(), 24u);
  const auto be32 = [&](std::size_t at) {
    return (static_cast<unsigned>(png[at]) << 24) | (static_cast<unsigned>(png[at + 1]) << 16) |
           (static_cast<unsigned>(png[at + 2]) << 8) | png[at + 3];
  };
  EXPECT_EQ(be32(16), static_cast<unsigned>(g2.width));
  EXPECT_EQ(be32(20), static_cast<unsigned>(g2.height));
  EXPECT_THROW(view_figure_png(ViewMode::RelativeError, ViewLayer{}, caption), InputError);
}

TEST(FigureExport, CurvesAsCsvAndSvg) {
  ConvergenceRecorder rec;
  rec.record(1, "mix:cosine=0.5,light=0.5", false, 4, 0.5, 0.3, 96, 96);
  rec.record(1, "mix:cosine=0.5,light=0.5", false, 16, 2.0, 0.15, 96, 96);
  ASSERT_TRUE(rec.pin());
  rec.record(2, "cosine", true, 8, 1.0, 0.4, 48, 48);
  EXPECT_EQ(curve_label(rec.pins().front()), "mix:cosine=0.5,light=0.5, 96x96");
  EXPECT_EQ(curve_label(rec.live()), "cosine, 48x48 (est.)");
  const std::string csv = convergence_csv(rec);
  EXPECT_EQ(csv.substr(0, csv.find('\n')), "curve,label,estimated,width,height,spp,seconds,relative_rms_error");
  EXPECT_NE(csv.find("pin 1,\"mix:cosine=0.5,light=0.5\",no,96,96,16,2,0.15"), std::string::npos) << csv;
  EXPECT_NE(csv.find("now,\"cosine\",yes,48,48,8,1,0.4"), std::string::npos) << csv;
  const std::string svg = convergence_svg(rec, true, "Convergence");
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  EXPECT_NE(svg.find("pin: mix:cosine=0.5,light=0.5, 96x96"), std::string::npos);
  EXPECT_NE(svg.find("samples per pixel"), std::string::npos);

  WeightCurveStatus c;
  c.active = true;
  c.weight = {0.1f, 0.5f, 0.9f};
  c.relative_efficiency = {0.2f, 1.0f, 0.6f};
  c.largest_share = {0.5f, 0.01f, 0.02f};
  c.best = 0.5;
  const std::string curve = weight_curve_csv(c);
  EXPECT_EQ(curve, "w,relative_efficiency,largest_path_share\n0.1,0.2,0.5\n0.5,1,0.01\n0.9,0.6,0.02\n");
  const std::string curve_svg = weight_curve_svg(c, "cosine", "light", "Predicted");
  EXPECT_NE(curve_svg.find("predicted best w = 0.50"), std::string::npos);
}

TEST(FigureExport, FilesGetFreshNamesAndNothingIsOverwritten) {
  const fs::path dir = fresh_dir("figures");
  const std::vector<FigureFile> files = {{"svg", {'a'}}, {"csv", {'b'}}};
  const auto first = save_figure_files(dir.string(), "curve", files, 1700000000);
  const auto second = save_figure_files(dir.string(), "curve", files, 1700000000);
  ASSERT_EQ(first.size(), 2u);
  ASSERT_EQ(second.size(), 2u);
  EXPECT_NE(first[0], second[0]);
  EXPECT_NE(first[0].find("-1-curve.svg"), std::string::npos) << first[0];
  EXPECT_NE(second[1].find("-2-curve.csv"), std::string::npos) << second[1];
  for (const auto& p : first) EXPECT_EQ(fs::file_size(p), 1u);
  EXPECT_THROW(save_figure_files("", "curve", files, 0), InputError);
  fs::remove_all(dir);
}
