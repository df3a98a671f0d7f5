// The teaching views' plain parts: split-screen threads, divider and time
// accounting, probe projection and binning, the 1D and 2D labs' state, plot maths.
#include "renderer/scene/scene_loader.h"
#include "renderer/session/session.h"
#include "renderer/scene/environment.h"
#include "ui/lab1d_panel.h"
#include "ui/lab2d_panel.h"
#include "ui/probe_panel.h"
#include "ui/split_view.h"
#include "ui/teach_draw.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <thread>

namespace pdflab::ui {
namespace {

std::shared_ptr<const Scene> small_scene() {
  return std::make_shared<const Scene>(load_scene_file(PDFLAB_SOURCE_DIR "/tests/gui/cornell_small.json"));
}

TEST(SplitView, ThreadsAreSplitEquallyAndNeverZero) {
  EXPECT_EQ(split_threads(16).a, 8);
  EXPECT_EQ(split_threads(16).b, 8);
  EXPECT_EQ(split_threads(5).a, split_threads(5).b);  // the odd one idles rather than favour a side
  EXPECT_EQ(split_threads(1).a, 1);
  EXPECT_EQ(split_threads(0).b, 1);
}

TEST(SplitView, DividerDragsOnlyWhenGrabbedNearTheLine) {
  SplitDivider d;  // over an image at x 100..500, y 50..450: the line at x 300
  EXPECT_FALSE(d.update(150.0f, 200.0f, true, true, 100.0f, 50.0f, 400.0f, 400.0f, 8.0f));
  EXPECT_FLOAT_EQ(d.fraction, 0.5f);
  EXPECT_TRUE(d.update(305.0f, 200.0f, true, true, 100.0f, 50.0f, 400.0f, 400.0f, 8.0f));
  EXPECT_TRUE(d.update(200.0f, 600.0f, false, true, 100.0f, 50.0f, 400.0f, 400.0f, 8.0f));  // drag leaves the image
  EXPECT_FLOAT_EQ(d.fraction, 0.25f);
  EXPECT_TRUE(d.update(-50.0f, 200.0f, false, true, 100.0f, 50.0f, 400.0f, 400.0f, 8.0f));
  EXPECT_FLOAT_EQ(d.fraction, 0.0f);  // clamped at the edge
  EXPECT_FALSE(d.update(-50.0f, 200.0f, false, false, 100.0f, 50.0f, 400.0f, 400.0f, 8.0f));
  EXPECT_FALSE(d.dragging);
  // A click below the image is not a grab, even at the line's x.
  EXPECT_FALSE(d.update(100.0f, 460.0f, true, true, 100.0f, 50.0f, 400.0f, 400.0f, 8.0f));
}

TEST(SplitView, EfficiencyPrefersTheReference) {
  SideFigures f;
  EXPECT_LT(f.efficiency(), 0.0);  // nothing known yet
  f.seconds = 2.0;
  f.estimated_relmse = 0.01;
  EXPECT_DOUBLE_EQ(f.efficiency(), 50.0);
  EXPECT_FALSE(f.efficiency_from_reference());
  f.reference_relmse = 0.02;
  EXPECT_DOUBLE_EQ(f.efficiency(), 25.0);
  EXPECT_TRUE(f.efficiency_from_reference());
  EXPECT_EQ(format_figure(0.1234, true), "12.34%");
  EXPECT_EQ(format_figure(-1.0), "-");
}

TEST(SplitView, EveryOfferedStrategyParses) {
  for (const std::string& s : split_strategy_choices()) EXPECT_NO_THROW(Strategy::parse(s)) << s;
}

// The split's two sessions: started back to back on equal threads, they get
// equal rendering time, and with the same strategy and seed they draw the same
// random numbers (identical images).
TEST(SplitView, TwoSessionsGetEqualTimeAndTheSameRandomNumbers) {
  const auto scene = small_scene();
  const SplitThreads threads = split_threads(static_cast<int>(std::max(2u, std::thread::hardware_concurrency())));
  SessionOptions options;
  options.threads = threads.a;
  RenderSession a(options);
  options.threads = threads.b;
  RenderSession b(options);
  RenderSettings rs;
  rs.scene = scene;
  rs.strategy = Strategy::parse("mix:cosine=0.5,light=0.5");
  rs.seed = 7;
  a.set_settings(rs);
  rs.strategy = Strategy::parse("cosine");
  b.set_settings(rs);
  std::this_thread::sleep_for(std::chrono::milliseconds(600));
  a.set_paused(true);
  b.set_paused(true);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the passes in flight end
  const SessionStats sa = a.stats(), sb = b.stats();
  EXPECT_GT(sa.spp, 0u);
  EXPECT_GT(sb.spp, 0u);
  // Pausing waits for the pass in flight (30-120 ms each), so the clocks agree to about one pass.
  EXPECT_NEAR(sa.seconds, sb.seconds, 0.25) << sa.seconds << " vs " << sb.seconds;

  // Same strategy on both sides: identical images at equal spp.
  rs.strategy = Strategy::parse("mix:cosine=0.5,light=0.5");
  rs.target_spp = 8;
  a.set_paused(false);
  b.set_paused(false);
  a.set_settings(rs);
  b.set_settings(rs);
  ASSERT_TRUE(a.wait_until_done(std::chrono::seconds(60)));
  ASSERT_TRUE(b.wait_until_done(std::chrono::seconds(60)));
  std::vector<float> ia, ib;
  ImageInfo info_a, info_b;
  std::uint64_t va = 0, vb = 0;
  ASSERT_TRUE(a.copy_image(ia, info_a, va));
  ASSERT_TRUE(b.copy_image(ib, info_b, vb));
  EXPECT_EQ(info_a.spp, 8u);
  EXPECT_EQ(ia, ib);
  // The published noise figures come with full passes.
  EXPECT_GT(info_a.mean_relative_standard_error, 0.0);
  EXPECT_GT(info_a.estimated_relmse, 0.0);
  EXPECT_DOUBLE_EQ(info_a.mean_relative_standard_error, info_b.mean_relative_standard_error);
}

TEST(ProbeProjection, EqualAreaDiscs) {
  // The normal at the centre of the upper disc, straight down at the lower one's.
  DiscPoint d = project_to_disc(0.3f, 0.0f);
  EXPECT_NEAR(d.x, 0.0f, 1e-6f);
  EXPECT_NEAR(d.y, 0.0f, 1e-6f);
  EXPECT_FALSE(d.lower);
  d = project_to_disc(0.3f, 1.0f);
  EXPECT_TRUE(d.lower);
  EXPECT_NEAR(std::hypot(d.x, d.y), 0.0f, 1e-6f);
  // The horizon on the rim, at its azimuth.
  d = project_to_disc(0.25f, 0.5f);
  EXPECT_NEAR(d.x, 0.0f, 1e-6f);
  EXPECT_NEAR(d.y, 1.0f, 1e-6f);
  // Equal area: cos(theta) = 0.5 bounds half the hemisphere's solid angle, so half the disc's area.
  d = project_to_disc(0.0f, 0.25f);
  EXPECT_NEAR(d.x * d.x + d.y * d.y, 0.5f, 1e-6f);
}

TEST(ProbeProjection, PixelUnderTheMouse) {
  // A 100x50 image shown at 200x100 from (10, 20).
  auto hit = pixel_at(10.0f, 20.0f, 10.0f, 20.0f, 200.0f, 100.0f, 100, 50);
  ASSERT_TRUE(hit);
  EXPECT_EQ(hit->x, 0);
  EXPECT_EQ(hit->y, 0);
  hit = pixel_at(209.9f, 119.9f, 10.0f, 20.0f, 200.0f, 100.0f, 100, 50);
  ASSERT_TRUE(hit);
  EXPECT_EQ(hit->x, 99);
  EXPECT_EQ(hit->y, 49);
  hit = pixel_at(111.0f, 70.0f, 10.0f, 20.0f, 200.0f, 100.0f, 100, 50);
  ASSERT_TRUE(hit);
  EXPECT_EQ(hit->x, 50);
  EXPECT_EQ(hit->y, 25);
  EXPECT_FALSE(pixel_at(9.9f, 70.0f, 10.0f, 20.0f, 200.0f, 100.0f, 100, 50));
  EXPECT_FALSE(pixel_at(210.0f, 70.0f, 10.0f, 20.0f, 200.0f, 100.0f, 100, 50));
  EXPECT_FALSE(pixel_at(50.0f, 50.0f, 0.0f, 0.0f, 0.0f, 100.0f, 100, 50));
}

TEST(ProbeProjection, BandsSumTheRowsOfTheChiSquareGrid) {
  ProbeChiSquare chi;
  chi.z_cells = 2;
  chi.phi_cells = 3;
  chi.observed = {1, 2, 3, 10, 20, 30};
  chi.expected = {1.5, 1.5, 1.5, 20.0, 20.0, 20.0};
  const BandHistogram b = cos_theta_bands(chi);
  ASSERT_EQ(b.observed.size(), 2u);
  EXPECT_DOUBLE_EQ(b.observed[0], 6.0);
  EXPECT_DOUBLE_EQ(b.observed[1], 60.0);
  EXPECT_DOUBLE_EQ(b.expected[0], 4.5);
  EXPECT_DOUBLE_EQ(b.expected[1], 60.0);
}

TEST(ProbeProjection, ProbingAFloorPixelFillsThePanelState) {
  ProbeState s;
  const auto scene = small_scene();
  probe_pixel(s, scene, Strategy::parse("mix:cosine=0.5,light=0.5"), 1, 30, 88);
  ASSERT_TRUE(s.point.found);
  EXPECT_EQ(s.samples.size(), 400u);
  int total = 0;
  for (int c : s.technique_counts) total += c;
  EXPECT_EQ(total, 400);
  EXPECT_GT(s.technique_counts[0], 100);  // cosine, about half
  EXPECT_GT(s.technique_counts[3], 100);  // light
  EXPECT_EQ(s.strategy_map.values.size(), static_cast<std::size_t>(s.strategy_map.width * s.strategy_map.height));
  EXPECT_GT(s.light_map.max_value, s.bsdf_map.max_value);  // a small light: a sharp lobe
  // The floor is lambertian: its own lobe is the cosine lobe, cos / pi at most.
  EXPECT_NE(s.bsdf_lobe.find("cosine lobe"), std::string::npos) << s.bsdf_lobe;
  EXPECT_NEAR(s.bsdf_map.max_value, 1.0f / 3.14159265f, 0.01f);
  EXPECT_TRUE(s.delta_note.empty());
  // The check runs in the background and passes for a correct sample/pdf pair.
  start_probe_chi_square(s, 0.0);
  ASSERT_TRUE(s.chi_running());
  s.chi_job.wait();
  ASSERT_TRUE(poll_probe_chi_square(s, 1.0));
  ASSERT_TRUE(s.chi);
  EXPECT_TRUE(s.chi->passed) << s.chi->result.p_value;
}

TEST(ProbeProjection, LightSamplesAreSplitByTheTargetTheyAimAt) {
  ProbeState s;
  const auto scene = small_scene();
  probe_pixel(s, scene, Strategy::parse("light"), 1, 30, 88);
  ASSERT_TRUE(s.point.found);
  // The book's targets: the ceiling light (a quad) and the glass sphere.
  ASSERT_EQ(s.target_labels.size(), 2u);
  EXPECT_NE(s.target_labels[0].find("quad"), std::string::npos);
  EXPECT_NE(s.target_labels[1].find("sphere"), std::string::npos);
  ASSERT_EQ(s.sample_target.size(), s.samples.size());
  std::vector<int> per_target(2, 0);
  for (std::size_t i = 0; i < s.samples.size(); ++i) {
    if (s.samples[i].technique < 0) continue;
    ASSERT_GE(s.sample_target[i], 0) << "a light sample aiming at no target";
    ++per_target[static_cast<std::size_t>(s.sample_target[i])];
  }
  // Targets are chosen uniformly by `light`: about 200 each of 400.
  EXPECT_GT(per_target[0], 140);
  EXPECT_GT(per_target[1], 140);
  // Straight down into the floor aims at no target.
  EXPECT_EQ(light_target_of(*s.plan, s.point.point, -s.point.normal), -1);
}

TEST(ProbeProjection, ACheckStartedBeforeANewProbeIsDropped) {
  ProbeState s;
  const auto scene = small_scene();
  probe_pixel(s, scene, Strategy::parse("cosine"), 1, 30, 88);
  start_probe_chi_square(s, 0.0);
  ASSERT_TRUE(s.chi_running());
  // The strategy changes while it runs: the probe follows, the old check's result must not show.
  probe_pixel(s, scene, Strategy::parse("light"), 1, 30, 88);
  s.chi_job.wait();
  EXPECT_FALSE(poll_probe_chi_square(s, 1.0));
  EXPECT_FALSE(s.chi.has_value());
  EXPECT_FALSE(s.chi_running());
  EXPECT_EQ(s.technique_counts[0], 0);  // and the counts are the new strategy's
  EXPECT_GT(s.technique_counts[3], 0);
}

TEST(Lab1d, ATypedFReplacesTheFixedOneAndABadOneKeepsIt) {
  Lab1dState s;
  s.step(1000);
  ASSERT_TRUE(s.type_f("sin(pi*x)^2"));
  EXPECT_EQ(s.count(), 0u);  // started over
  EXPECT_NEAR(s.exact(), 1.0, 1e-9);
  EXPECT_EQ(s.f_name(), "sin(pi*x)^2");
  s.step(20000);
  EXPECT_NEAR(s.estimator.mean(), 1.0, 5.0 * s.estimator.standard_error());
  EXPECT_FALSE(s.type_f("sin(pi*"));
  EXPECT_NE(s.f_error.find("sin(pi*"), std::string::npos);
  EXPECT_EQ(s.f_name(), "sin(pi*x)^2");  // still the last good one
  EXPECT_GT(s.count(), 0u);              // and its samples
  s.select(lab::Integrand::Cosine, s.pdf);
  EXPECT_FALSE(s.typed);
  EXPECT_NEAR(s.exact(), std::sin(2.0), 1e-12);
}

TEST(Lab1d, BinsCoverTheIntervalHalfOpen) {
  EXPECT_EQ(lab_bin(0.0, 40), 0);
  EXPECT_EQ(lab_bin(0.0499, 40), 0);
  EXPECT_EQ(lab_bin(0.05, 40), 1);
  EXPECT_EQ(lab_bin(1.9999, 40), 39);
  EXPECT_EQ(lab_bin(2.0, 40), -1);
  EXPECT_EQ(lab_bin(-0.1, 40), -1);
  EXPECT_EQ(lab_bin(std::nan(""), 40), -1);
}

TEST(Lab1d, StepsFillHistogramAndHistoryAndSelectStartsOver) {
  Lab1dState s;
  s.select(lab::Integrand::Square, lab::Pdf::Linear);
  s.step(1000);
  s.step(1000);
  EXPECT_EQ(s.count(), 2000u);
  std::uint64_t total = 0;
  for (auto c : s.histogram) total += c;
  EXPECT_EQ(total, 2000u);
  // Samples follow p(x) = x / 2: the upper half holds about 3/4 of them.
  std::uint64_t upper = 0;
  for (int i = kLabBins / 2; i < kLabBins; ++i) upper += s.histogram[static_cast<std::size_t>(i)];
  EXPECT_NEAR(static_cast<double>(upper) / 2000.0, 0.75, 0.04);
  ASSERT_GE(s.history.size(), 20u);
  for (std::size_t i = 1; i < s.history.size(); ++i) EXPECT_GT(s.history[i].n, s.history[i - 1].n);
  EXPECT_NEAR(s.estimator.mean(), lab::exact_integral(lab::Integrand::Square), 5.0 * s.estimator.standard_error());

  s.select(lab::Integrand::Cosine, lab::Pdf::Uniform);
  EXPECT_EQ(s.count(), 0u);
  EXPECT_TRUE(s.history.empty());
  for (auto c : s.histogram) EXPECT_EQ(c, 0u);
}

TEST(Lab1d, ProportionalPdfGivesTheExactValueEverySample) {
  Lab1dState s;
  s.select(lab::Integrand::Square, lab::Pdf::Quadratic);
  s.step(500);
  EXPECT_NEAR(s.estimator.mean(), 8.0 / 3.0, 1e-9);
  // Zero up to the rounding of sum of squares minus squared sum.
  EXPECT_LT(s.estimator.standard_error(), 1e-6);
}

TEST(Lab1d, ReproducibleAndCapped) {
  Lab1dState a, b;
  a.step(300);
  b.step(300);
  EXPECT_EQ(a.estimator.mean(), b.estimator.mean());
  a.max_samples = 1000;
  a.step(5000);
  EXPECT_EQ(a.count(), 1000u);
}

TEST(Lab1d, StratifiedPiBeatsPlainAtLargeN) {
  const PiStudy p = run_pi_study(7, 4);
  ASSERT_EQ(p.n.size(), 7u);
  EXPECT_EQ(p.n.back(), 16384.0);
  EXPECT_LT(p.stratified_error.back(), p.plain_error.back());
  EXPECT_LT(p.plain_error.back(), p.plain_error.front());
}

TEST(Lab2d, AClickOnTheMapPicksTheRowUnderIt) {
  EXPECT_EQ(lab2d_row_at(0.0, 32), 0);
  EXPECT_EQ(lab2d_row_at(0.375, 32), 12);
  EXPECT_EQ(lab2d_row_at(0.999, 32), 31);
  EXPECT_EQ(lab2d_row_at(1.0, 32), 31);  // the bottom edge
  EXPECT_EQ(lab2d_row_at(-0.2, 32), 0);  // a drag above the map
  EXPECT_EQ(lab2d_row_at(std::nan(""), 32), 0);
}

TEST(Lab2d, StateFollowsTheMapTheLevelAndTheScene) {
  Lab2dState s;
  s.sun_sky_path = PDFLAB_SOURCE_DIR "/assets/environments/sun_sky.hdr";
  ASSERT_TRUE(s.choose(Lab2dState::Source::SunSky));
  ASSERT_TRUE(s.lab);
  // By default the row shown is the sun's.
  EXPECT_EQ(s.picked_row(), 39);
  s.set_level(2);  // 64 x 32
  EXPECT_EQ(s.picked_row(), 9);
  s.row = 20;
  s.set_level(1);  // 128 x 64: the picked row stays at the same place on the sphere
  EXPECT_EQ(s.picked_row(), 41);
  s.step();
  EXPECT_EQ(s.lab->count(), static_cast<std::uint64_t>(s.samples_per_frame));
  // Another map at the same resolution; its row is its own again.
  ASSERT_TRUE(s.choose(Lab2dState::Source::Constant));
  EXPECT_EQ(s.lab->map().width, 128);
  EXPECT_EQ(s.row, -1);
  // No scene map: refused with a reason, the lab kept.
  EXPECT_FALSE(s.choose(Lab2dState::Source::Scene));
  EXPECT_NE(s.error.find("no environment map"), std::string::npos) << s.error;
  EXPECT_EQ(s.source, Lab2dState::Source::Constant);
  // A scene map given: chosen, and followed when the scene's map changes.
  auto env = std::make_shared<const Environment>(std::vector<float>(16 * 8 * 3, 1.0f), 16, 8, 1.0f, 0.0f);
  s.set_scene_environment(env);
  ASSERT_TRUE(s.choose(Lab2dState::Source::Scene));
  EXPECT_TRUE(s.error.empty());
  EXPECT_EQ(s.lab->map().width, 16);
  auto other = std::make_shared<const Environment>(std::vector<float>(32 * 16 * 3, 2.0f), 32, 16, 1.0f, 0.0f);
  s.set_scene_environment(other);
  EXPECT_EQ(s.lab->levels(), 3);  // 32, 16, 8 across
  s.set_scene_environment(nullptr);  // a scene without a map: back to the shipped sky
  EXPECT_EQ(s.source, Lab2dState::Source::SunSky);
  // A sky file that is not there: the reason names it.
  s.sun_sky_path = "/nonexistent/sky.hdr";
  EXPECT_FALSE(s.choose(Lab2dState::Source::SunSky));
  EXPECT_NE(s.error.find("/nonexistent/sky.hdr"), std::string::npos) << s.error;
}

TEST(PlotMath, AxesTicksAndColours) {
  const draw::Axis lin{0.0, 2.0};
  EXPECT_DOUBLE_EQ(lin.to_unit(0.5), 0.25);
  const draw::Axis reversed{1.0, -1.0};
  EXPECT_DOUBLE_EQ(reversed.to_unit(1.0), 0.0);
  EXPECT_DOUBLE_EQ(reversed.to_unit(-1.0), 1.0);
  const draw::Axis log{1.0, 1000.0, true};
  EXPECT_NEAR(log.to_unit(10.0), 1.0 / 3.0, 1e-12);
  EXPECT_DOUBLE_EQ(log.to_unit(0.0), 0.0);  // clamped, not NaN

  const auto ticks = draw::nice_ticks(0.0, 2.0, 5);
  ASSERT_EQ(ticks.size(), 5u);
  EXPECT_DOUBLE_EQ(ticks[1], 0.5);
  EXPECT_EQ(draw::decade_ticks(1e-3, 10.0).size(), 5u);
  EXPECT_TRUE(draw::nice_ticks(1.0, 1.0).empty());

  const draw::Axis fit = draw::fit_axis({1.0, std::nan(""), 3.0}, false, 0.0);
  EXPECT_DOUBLE_EQ(fit.lo, 1.0);
  EXPECT_DOUBLE_EQ(fit.hi, 3.0);
  const draw::Axis fit_log = draw::fit_axis({0.0, 0.01, 100.0}, true, 0.0);
  EXPECT_NEAR(fit_log.lo, 0.01, 1e-12);

  EXPECT_EQ(draw::tick_label(0.0), "0");
  EXPECT_EQ(draw::tick_label(0.5), "0.5");
  EXPECT_EQ(draw::tick_label(1e-3), "0.001");
  EXPECT_EQ(draw::tick_label(1e-4), "1e-04");
  EXPECT_EQ(draw::tick_label(2.5e4), "2e+04");
  // A decade axis reads 10, 100, 1000, not 1e+03 after 100.
  EXPECT_EQ(draw::tick_label(100.0), "100");
  EXPECT_EQ(draw::tick_label(1000.0), "1000");
  EXPECT_EQ(draw::tick_label(2500.0), "2500");

  // The colour map brightens monotonically (reads in grey too).
  float last = -1.0f;
  for (int i = 0; i <= 20; ++i) {
    const ImVec4 c = ImGui::ColorConvertU32ToFloat4(draw::colormap(static_cast<float>(i) / 20.0f));
    const float luma = 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
    EXPECT_GT(luma, last - 1e-3f) << i;
    last = luma;
  }
}

}  // namespace
}  // namespace pdflab::ui
