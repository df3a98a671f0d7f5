// The measuring parts of the viewer that need no window: convergence curves
// and pins, log axes, colour maps and legend values, reference handling, view
// layers, and nee-mis in the strategy settings.
#include "renderer/error.h"
#include "renderer/film/image_io.h"
#include "renderer/integrator/integrator.h"
#include "renderer/metrics/metrics.h"
#include "ui/measure.h"
#include "ui/settings.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

using namespace pdflab;
using namespace pdflab::ui;

namespace {

double lightness(const Colour& c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

PublishedImage flat_image(int w, int h, float value, std::uint32_t spp = 4) {
  PublishedImage img;
  img.info.width = img.info.data_width = w;
  img.info.height = img.info.data_height = h;
  img.info.spp = spp;
  img.info.seconds = 2.0;
  img.info.estimated_relmse = 0.01;
  img.info.mean_relative_standard_error = 0.1;
  img.rgb.assign(3 * static_cast<std::size_t>(w) * h, value);
  img.relative_standard_error.assign(static_cast<std::size_t>(w) * h, 0.1f);
  img.drop_mask.assign(static_cast<std::size_t>(w) * h, 0);
  return img;
}

ReferenceImage flat_reference(int w, int h, float value) {
  ReferenceImage ref;
  ref.width = w;
  ref.height = h;
  ref.rgb.assign(3 * static_cast<std::size_t>(w) * h, value);
  return ref;
}

}  // namespace

TEST(Convergence, RecordsPassesAndStartsANewCurvePerGeneration) {
  ConvergenceRecorder rec;
  EXPECT_TRUE(rec.record(1, "cosine", false, 1, 0.1, 0.5));
  EXPECT_TRUE(rec.record(1, "cosine", false, 2, 0.2, 0.35));
  EXPECT_FALSE(rec.record(1, "cosine", false, 2, 0.25, 0.3));  // same spp: no new information
  EXPECT_FALSE(rec.record(1, "cosine", false, 4, 0.4, 0.0));   // zero error cannot go on a log axis
  EXPECT_FALSE(rec.record(1, "cosine", false, 4, 0.4, NAN));
  EXPECT_TRUE(rec.record(1, "cosine", false, 4, 0.4, 0.25));
  ASSERT_EQ(rec.live().points.size(), 3u);
  EXPECT_EQ(rec.live().points[2].spp, 4.0);
  EXPECT_EQ(rec.live().points[2].seconds, 0.4);
  EXPECT_EQ(rec.live().label, "cosine");

  EXPECT_TRUE(rec.record(2, "nee-mis", false, 1, 0.2, 0.1));  // settings changed
  EXPECT_EQ(rec.live().points.size(), 1u);
  EXPECT_EQ(rec.live().label, "nee-mis");
  // A reference arriving mid-run changes what the errors mean: a new curve too.
  EXPECT_TRUE(rec.record(2, "nee-mis", true, 2, 0.4, 0.08));
  EXPECT_EQ(rec.live().points.size(), 1u);
  EXPECT_TRUE(rec.live().estimated);
}

TEST(Convergence, ThinsDensePassesToAFewPointsPerDecade) {
  ConvergenceRecorder rec;
  int kept = 0;
  for (std::uint32_t spp = 1; spp <= 10000; ++spp) kept += rec.record(1, "x", false, spp, spp * 0.01, 1.0 / std::sqrt(spp));
  EXPECT_EQ(static_cast<std::size_t>(kept), rec.live().points.size());
  EXPECT_LT(kept, 500);
  EXPECT_GT(kept, 100);
}

TEST(Convergence, PinKeepsTheCurveUnderItsLabel) {
  ConvergenceRecorder rec;
  rec.record(1, "cosine", false, 1, 0.1, 0.5);
  EXPECT_FALSE(rec.pin());  // one point is no curve
  rec.record(1, "cosine", false, 2, 0.2, 0.4);
  EXPECT_TRUE(rec.pin());
  rec.record(2, "mix:cosine=0.5,light=0.5", false, 1, 0.1, 0.2);
  ASSERT_EQ(rec.pins().size(), 1u);
  EXPECT_EQ(rec.pins()[0].label, "cosine");
  EXPECT_EQ(rec.pins()[0].points.size(), 2u);
  EXPECT_EQ(rec.live().label, "mix:cosine=0.5,light=0.5");  // the next strategy runs against it

  for (std::size_t i = 0; i < ConvergenceRecorder::kMaxPins + 2; ++i) {
    // Appended, not "s" + to_string: GCC 12 warns falsely (-Wrestrict) on that once inlined here.
    std::string label = "s";
    label += std::to_string(i);
    rec.record(10 + i, label, false, 1, 0.1, 0.5);
    rec.record(10 + i, label, false, 2, 0.2, 0.4);
    rec.pin();
  }
  EXPECT_EQ(rec.pins().size(), ConvergenceRecorder::kMaxPins);
  EXPECT_EQ(rec.pins().back().label, "s" + std::to_string(ConvergenceRecorder::kMaxPins + 1));
  rec.clear_pins();
  EXPECT_TRUE(rec.pins().empty());
  EXPECT_EQ(rec.live().points.size(), 2u);  // clearing pins leaves the running curve
}

TEST(LogAxis, SnapsToDecades) {
  const LogRange r = log_range({0.03, 0.5, 2.0, -1.0, 0.0, INFINITY});
  EXPECT_DOUBLE_EQ(r.lo, 0.01);
  EXPECT_DOUBLE_EQ(r.hi, 10.0);
  EXPECT_NEAR(r.position(0.1), 1.0 / 3.0, 1e-12);
  const auto ticks = decade_ticks(r.lo, r.hi);
  ASSERT_EQ(ticks.size(), 4u);
  EXPECT_DOUBLE_EQ(ticks[0], 0.01);
  EXPECT_DOUBLE_EQ(ticks[3], 10.0);
  const LogRange one = log_range({1.0});
  EXPECT_DOUBLE_EQ(one.lo, 1.0);
  EXPECT_DOUBLE_EQ(one.hi, 10.0);
  const LogRange none = log_range({});
  EXPECT_DOUBLE_EQ(none.lo, 1.0);
  EXPECT_DOUBLE_EQ(none.hi, 10.0);
}

TEST(ColourMaps, SequentialBrightensMonotonicallyAndDivergingIsPaleAtZero) {
  double last = -1.0;
  for (int i = 0; i <= 100; ++i) {
    const double l = lightness(sequential_colour(i / 100.0));
    EXPECT_GT(l, last) << i;
    last = l;
  }
  EXPECT_LT(lightness(sequential_colour(0.0)), 0.05);
  EXPECT_GT(lightness(sequential_colour(1.0)), 0.8);
  const Colour zero = diverging_colour(0.0);
  EXPECT_GT(lightness(zero), 0.85);
  const Colour neg = diverging_colour(-1.0), pos = diverging_colour(1.0);
  EXPECT_GT(neg[2], neg[0]);  // blue below
  EXPECT_GT(pos[0], pos[2]);  // red above
  // Out of range and NaN clamp rather than wrap.
  EXPECT_EQ(diverging_colour(-5.0), neg);
  EXPECT_EQ(sequential_colour(NAN), sequential_colour(0.0));
  // Every drop reason has its own colour, none the "several" white.
  for (int a = 0; a < kDropReasonCount; ++a) {
    EXPECT_NE(drop_reason_colour(a), kSeveralDropReasonsColour);
    for (int b = a + 1; b < kDropReasonCount; ++b) EXPECT_NE(drop_reason_colour(a), drop_reason_colour(b));
  }
}

TEST(ColourMaps, HeatMapLegendIsDecadesFromAThousandthToTen) {
  const ColourScale s = relative_error_scale();
  const auto ticks = legend_ticks(s);
  ASSERT_EQ(ticks.size(), 5u);
  const char* labels[] = {"0.001", "0.01", "0.1", "1", "10"};
  for (std::size_t i = 0; i < ticks.size(); ++i) {
    EXPECT_EQ(ticks[i].label, labels[i]);
    EXPECT_NEAR(ticks[i].position, static_cast<double>(i) / 4.0, 1e-12);
  }
  EXPECT_DOUBLE_EQ(s.position(0.1), 0.5);
  EXPECT_DOUBLE_EQ(s.position(0.0), 0.0);     // a noiseless pixel sits at the bottom
  EXPECT_DOUBLE_EQ(s.position(1e6), 1.0);
  EXPECT_EQ(s.colour(10.0), sequential_colour(1.0));
}

TEST(ColourMaps, NarrowBarsLeaveOutInnerLabelsThatWouldOverlap) {
  // Five labels 30 px wide at 0, 1/4, ... 1 of the bar, 4 px apart at least.
  const std::vector<float> w(5, 30.0f);
  const auto at = [](float bar) {
    std::vector<float> c;
    for (int i = 0; i < 5; ++i) c.push_back(bar * static_cast<float>(i) / 4.0f);
    return c;
  };
  // Wide: every label fits.
  EXPECT_EQ(labels_that_fit(at(400.0f), w, 400.0f, 4.0f), (std::vector<std::size_t>{0, 1, 2, 3, 4}));
  // 120 px: the ends sit at 0-30 and 90-120 (clamped); the middle label (45-75) clears both, the
  // quarter labels (15-45, 75-105) do not.
  EXPECT_EQ(labels_that_fit(at(120.0f), w, 120.0f, 4.0f), (std::vector<std::size_t>{0, 2, 4}));
  // Too narrow for any inner label: the ends still show, both.
  EXPECT_EQ(labels_that_fit(at(70.0f), w, 70.0f, 4.0f), (std::vector<std::size_t>{0, 4}));
  EXPECT_EQ(labels_that_fit({5.0f}, {30.0f}, 10.0f, 4.0f), (std::vector<std::size_t>{0}));
  EXPECT_TRUE(labels_that_fit({}, {}, 100.0f, 4.0f).empty());
}

TEST(ColourMaps, DifferenceLegendIsSymmetricAndNice) {
  EXPECT_DOUBLE_EQ(nice_ceiling(0.031), 0.05);
  EXPECT_DOUBLE_EQ(nice_ceiling(0.05), 0.05);
  EXPECT_DOUBLE_EQ(nice_ceiling(0.11), 0.2);
  EXPECT_DOUBLE_EQ(nice_ceiling(7.0), 10.0);
  const ColourScale s = difference_scale(0.2);
  const auto ticks = legend_ticks(s);
  ASSERT_EQ(ticks.size(), 5u);
  EXPECT_EQ(ticks[0].label, "-0.2");
  EXPECT_EQ(ticks[2].label, "0");
  EXPECT_EQ(ticks[4].label, "+0.2");
  EXPECT_DOUBLE_EQ(ticks[2].position, 0.5);
  EXPECT_EQ(s.colour(0.0), diverging_colour(0.0));
  EXPECT_EQ(s.colour(0.2), diverging_colour(1.0));

  // The 99th percentile sets the range: one firefly in 1000 pixels does not.
  std::vector<float> d(1000, 0.0f);
  for (int i = 0; i < 1000; ++i) d[i] = (i % 2 ? 1.0f : -1.0f) * 0.03f * (static_cast<float>(i) / 999.0f);
  d[17] = 1e6f;
  EXPECT_DOUBLE_EQ(difference_half_range(d), 0.05);
  const auto diff = luminance_difference({1, 1, 1, 0, 0, 0}, {0.5f, 0.5f, 0.5f, 0, 0, 1});
  ASSERT_EQ(diff.size(), 2u);
  EXPECT_NEAR(diff[0], 0.5f, 1e-6f);
  EXPECT_NEAR(diff[1], -0.0722f, 1e-6f);
}

TEST(ErrorMetrics, DifferenceValuesFollowTheirDefinitions) {
  // Grey image 0.6 against grey reference 0.4 (luminance = the grey), and 0.1 against 0.4.
  const std::vector<float> image = {0.6f, 0.6f, 0.6f, 0.1f, 0.1f, 0.1f}, reference(6, 0.4f);
  const auto at = [&](ErrorMetric m) { return difference_values(image, reference, m); };
  EXPECT_NEAR(at(ErrorMetric::Signed)[0], 0.2, 1e-6);
  EXPECT_NEAR(at(ErrorMetric::Signed)[1], -0.3, 1e-6);
  EXPECT_NEAR(at(ErrorMetric::Absolute)[1], 0.3, 1e-6);
  EXPECT_NEAR(at(ErrorMetric::Squared)[0], 0.04, 1e-6);
  EXPECT_NEAR(at(ErrorMetric::Squared)[1], 0.09, 1e-6);
  EXPECT_NEAR(at(ErrorMetric::Relative)[0], 0.2 / 0.41, 1e-6);
  EXPECT_NEAR(at(ErrorMetric::RelativeSquared)[1], 0.09 / (0.16 + 0.01), 1e-6);
  // Averaged over channels of a grey image, the relative squared error is relMSE's term.
  EXPECT_NEAR(at(ErrorMetric::RelativeSquared)[0], relmse({0.6f, 0.6f, 0.6f}, {0.4f, 0.4f, 0.4f}), 1e-6);
  for (int i = 0; i < kErrorMetricCount; ++i) {
    const auto m = static_cast<ErrorMetric>(i);
    EXPECT_TRUE(view_offers_metric(ViewMode::Difference, m));
    EXPECT_EQ(view_offers_metric(ViewMode::RelativeError, m), m != ErrorMetric::Signed);  // noise has no sign
    EXPECT_FALSE(view_offers_metric(ViewMode::Image, m));
  }
}

TEST(ErrorMetrics, EStepsThroughTheMetricsTheViewOffersOnAnAutomaticRange) {
  MeasureSettings s;
  s.view_mode = ViewMode::RelativeError;
  EXPECT_FALSE(s.heat_map.range.automatic);  // the heat map starts on its fixed 0.001..10
  std::vector<ErrorMetric> seen;
  for (int i = 0; i < 4; ++i) {
    s.step_metric(1);
    seen.push_back(s.heat_map.metric);
    EXPECT_TRUE(s.heat_map.range.automatic);
  }
  EXPECT_EQ(seen, (std::vector<ErrorMetric>{ErrorMetric::RelativeSquared, ErrorMetric::Absolute, ErrorMetric::Squared,
                                            ErrorMetric::Relative}));  // never Signed
  s.step_metric(-1);
  EXPECT_EQ(s.heat_map.metric, ErrorMetric::Squared);
  EXPECT_EQ(s.difference.metric, ErrorMetric::Signed);  // the other view's is its own
  s.view_mode = ViewMode::Difference;
  s.step_metric(-1);
  EXPECT_EQ(s.difference.metric, ErrorMetric::RelativeSquared);
  s.view_mode = ViewMode::Image;
  s.step_metric(1);
  EXPECT_EQ(s.difference.metric, ErrorMetric::RelativeSquared);
}

TEST(ErrorMetrics, HeatMapStandardErrorIsTheRelativeOneTimesMeanPlusEpsilon) {
  PublishedImage img = flat_image(2, 1, 0.5f);
  img.relative_standard_error = {0.1f, 0.0f};
  const double se = 0.1 * (0.5 + kRelMseEpsilon);
  EXPECT_NEAR(heat_map_values(img, ErrorMetric::Relative)[0], 0.1, 1e-7);
  EXPECT_NEAR(heat_map_values(img, ErrorMetric::Absolute)[0], se, 1e-7);
  EXPECT_NEAR(heat_map_values(img, ErrorMetric::Squared)[0], se * se, 1e-8);
  EXPECT_NEAR(heat_map_values(img, ErrorMetric::RelativeSquared)[0], 0.01, 1e-8);
  EXPECT_EQ(heat_map_values(img, ErrorMetric::Absolute)[1], 0.0f);
}

TEST(ViewRange, AutomaticRangeSpansThePercentilesRounded) {
  // 0.003 to 0.3, evenly in log, and one firefly.
  std::vector<float> v;
  for (int i = 0; i < 1000; ++i) v.push_back(static_cast<float>(0.003 * std::pow(100.0, i / 999.0)));
  v.push_back(1e6f);
  v.push_back(0.0f);  // a noiseless pixel: no part of a log range
  LayerOptions o;
  o.metric = ErrorMetric::Absolute;
  const ColourScale s = error_scale(ViewMode::Difference, o, v);
  EXPECT_TRUE(s.logarithmic);
  EXPECT_FALSE(s.diverging);
  EXPECT_DOUBLE_EQ(s.lo, 0.002);  // below the 1st percentile, 0.00314
  EXPECT_DOUBLE_EQ(s.hi, 0.5);    // above the 99th, 0.288; the firefly is not seen
  EXPECT_DOUBLE_EQ(nice_floor(0.00314), 0.002);
  EXPECT_DOUBLE_EQ(nice_floor(0.05), 0.05);
  EXPECT_DOUBLE_EQ(nice_floor(9.9), 5.0);
  // The signed error: symmetric, its half range from |d|'s 99th percentile.
  o.metric = ErrorMetric::Signed;
  const ColourScale d = error_scale(ViewMode::Difference, o, v);
  EXPECT_TRUE(d.diverging);
  EXPECT_DOUBLE_EQ(d.hi, 0.5);
  EXPECT_DOUBLE_EQ(d.lo, -0.5);
  // Nothing positive: a range still.
  const ColourScale none = error_scale(ViewMode::RelativeError, default_difference_options(), {0.0f, NAN});
  EXPECT_LT(none.lo, none.hi);
}

TEST(ViewRange, AFixedRangeIsKeptAndABadOneMadeUsable) {
  LayerOptions o;
  o.metric = ErrorMetric::Squared;
  o.range = {false, 0.02, 0.5};
  const ColourScale s = error_scale(ViewMode::Difference, o, {1e-9f, 100.0f});
  EXPECT_DOUBLE_EQ(s.lo, 0.02);
  EXPECT_DOUBLE_EQ(s.hi, 0.5);
  EXPECT_EQ(s.colour(0.5), sequential_colour(1.0));
  EXPECT_EQ(s.colour(0.02), sequential_colour(0.0));
  EXPECT_EQ(s.colour(100.0), sequential_colour(1.0));  // beyond the range: clamped
  EXPECT_NEAR(s.position(0.1), std::log10(5.0) / std::log10(25.0), 1e-12);
  const ViewRange swapped = sanitized({false, 0.5, 0.02}, false);
  EXPECT_DOUBLE_EQ(swapped.lo, 0.02);
  EXPECT_DOUBLE_EQ(swapped.hi, 0.5);
  for (const ViewRange& bad : {ViewRange{false, 0.0, 0.0}, ViewRange{false, -1.0, NAN}, ViewRange{false, 3.0, 3.0}}) {
    const ViewRange r = sanitized(bad, false);
    EXPECT_GT(r.lo, 0.0);
    EXPECT_GT(r.hi, r.lo);
    EXPECT_TRUE(std::isfinite(r.hi));
  }
  EXPECT_DOUBLE_EQ(sanitized({false, 0.0, -2.0}, true).hi, 1.0);
  o.metric = ErrorMetric::Signed;
  o.range = {false, -0.1, 0.1};
  EXPECT_DOUBLE_EQ(error_scale(ViewMode::Difference, o, {5.0f}).hi, 0.1);
}

TEST(ColourMaps, LegendOfASetRangeLabelsBothEndsAndRoundValuesBetween) {
  ColourScale s;
  s.logarithmic = true;
  s.lo = 0.02;
  s.hi = 0.5;
  const auto ticks = legend_ticks(s);
  const char* labels[] = {"0.02", "0.05", "0.1", "0.2", "0.5"};
  ASSERT_EQ(ticks.size(), 5u);
  for (std::size_t i = 0; i < ticks.size(); ++i) {
    EXPECT_EQ(ticks[i].label, labels[i]);
    EXPECT_NEAR(ticks[i].position, s.position(std::stod(labels[i])), 1e-12);  // each tick where its value is
  }
  // Fifteen decades: the ends and a few decades between, in order, none crowding an end.
  s.lo = 1e-9;
  s.hi = 1e6;
  const auto wide = legend_ticks(s);
  ASSERT_GE(wide.size(), 4u);
  EXPECT_LE(wide.size(), 7u);
  EXPECT_EQ(wide.front().label, "1e-09");
  EXPECT_EQ(wide.back().label, "1e+06");
  for (std::size_t i = 1; i < wide.size(); ++i) {
    EXPECT_GT(wide[i].position, wide[i - 1].position + 0.1) << wide[i].label;
    EXPECT_NEAR(wide[i].position, s.position(std::stod(wide[i].label)), 1e-9);
  }
}

TEST(ViewLayer, MetricAndRangeChangesRebuildTheLayerInTheirColours) {
  MeasureState m;
  m.set_reference(flat_reference(2, 1, 0.5f));
  m.published = flat_image(2, 1, 0.625f);  // an error of 1/8, exactly
  MeasureSettings s;
  s.view_mode = ViewMode::Difference;
  s.difference.metric = ErrorMetric::Squared;
  s.difference.range = {false, 1.0 / 256.0, 1.0 / 16.0};
  ASSERT_TRUE(m.refresh_layer(s));
  EXPECT_FALSE(m.refresh_layer(s));  // nothing changed: nothing to upload
  // (1/8)^2 sits half way between 1/256 and 1/16 on the log scale.
  const Colour mid = sequential_colour(0.5);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(m.layer.rgba[c], static_cast<std::uint8_t>(std::lround(mid[c] * 255.0f)));
  EXPECT_NE(m.layer.scale.title.find("^2"), std::string::npos);
  s.difference.range.hi = 1.0 / 64.0;  // now at the top
  ASSERT_TRUE(m.refresh_layer(s));
  const Colour top = sequential_colour(1.0);
  EXPECT_EQ(m.layer.rgba[0], static_cast<std::uint8_t>(std::lround(top[0] * 255.0f)));
  s.difference.metric = ErrorMetric::Signed;
  s.difference.range.automatic = true;
  ASSERT_TRUE(m.refresh_layer(s));
  EXPECT_TRUE(m.layer.scale.diverging);
  EXPECT_DOUBLE_EQ(m.layer.scale.hi, 0.2);
  // The heat map keeps its own options.
  s.view_mode = ViewMode::RelativeError;
  ASSERT_TRUE(m.refresh_layer(s));
  EXPECT_DOUBLE_EQ(m.layer.scale.lo, 1e-3);
  EXPECT_DOUBLE_EQ(m.layer.scale.hi, 10.0);
}

TEST(Reference, FiguresAreCorrectedForTheReferencesNoise) {
  ReferenceImage ref;
  ref.width = 4;
  ref.height = 2;
  ref.rgb.assign(24, 0.5f);
  PublishedImage img = flat_image(4, 2, 0.6f);
  const double raw = 0.01 / (0.25 + 0.01);
  ref.variance.assign(24, 0.002f);  // its own noise: 0.002 / 0.26 of relMSE
  const Figures f = compute_figures(img.info, img.rgb, &ref);
  ASSERT_TRUE(f.against_reference);
  EXPECT_TRUE(f.reference_corrected);
  EXPECT_NEAR(f.relmse_raw, raw, 1e-6);
  EXPECT_NEAR(f.relmse, (0.01 - 0.002) / 0.26, 1e-6);
  EXPECT_NEAR(f.reference_share, 0.2, 1e-5);
  EXPECT_NEAR(f.efficiency, 1.0 / (f.relmse * 2.0), 1e-9);
}

TEST(Reference, BiasedStrategyWithoutReferenceHasNoEfficiency) {
  const PublishedImage img = flat_image(4, 2, 0.6f);
  ASSERT_GT(img.info.estimated_relmse, 0.0);
  const Figures biased = compute_figures(img.info, img.rgb, nullptr, false);
  ASSERT_TRUE(biased.valid);
  EXPECT_FALSE(biased.unbiased);
  EXPECT_EQ(biased.estimated_efficiency, 0.0) << "no figure that would crown a strategy missing light";
  const Figures unbiased = compute_figures(img.info, img.rgb, nullptr, true);
  EXPECT_GT(unbiased.estimated_efficiency, 0.0);
  // The state takes it from the strategy's name.
  MeasureState m;
  m.published = img;
  m.on_image(img.info.generation, "light");
  EXPECT_FALSE(m.figures.unbiased);
  EXPECT_EQ(m.figures.estimated_efficiency, 0.0);
  m.on_image(img.info.generation, "mix:cosine=0.5,light=0.5");
  EXPECT_GT(m.figures.estimated_efficiency, 0.0);
}

TEST(Reference, SizeMismatchIsSaidAndFiguresFallBackToEstimates) {
  ReferenceImage ref;
  ref.path = "ref.pfm";
  ref.width = 4;
  ref.height = 2;
  ref.rgb.assign(24, 0.5f);
  EXPECT_EQ(reference_size_mismatch(ref, 4, 2), "");
  EXPECT_EQ(reference_size_mismatch(ReferenceImage{}, 4, 2), "");
  const std::string m = reference_size_mismatch(ref, 8, 8);
  EXPECT_NE(m.find("4x2"), std::string::npos) << m;
  EXPECT_NE(m.find("8x8"), std::string::npos) << m;

  PublishedImage img = flat_image(4, 2, 0.6f);
  Figures f = compute_figures(img.info, img.rgb, &ref);
  ASSERT_TRUE(f.valid);
  EXPECT_TRUE(f.against_reference);
  EXPECT_NEAR(f.rmse, 0.1, 1e-6);
  EXPECT_NEAR(f.relmse, relmse(img.rgb, ref.rgb, 1e-2), 1e-12);
  EXPECT_NEAR(f.relmse, 0.01 / (0.25 + 0.01), 1e-6);  // epsilon 1e-2
  EXPECT_NEAR(f.efficiency, 1.0 / (f.relmse * 2.0), 1e-9);
  EXPECT_NEAR(f.plot_error(), std::sqrt(f.relmse), 1e-12);

  const PublishedImage big = flat_image(8, 8, 0.6f);
  f = compute_figures(big.info, big.rgb, &ref);
  ASSERT_TRUE(f.valid);
  EXPECT_FALSE(f.against_reference);
  EXPECT_DOUBLE_EQ(f.estimated_relmse, 0.01);
  EXPECT_DOUBLE_EQ(f.estimated_efficiency, 1.0 / (0.01 * 2.0));
  EXPECT_DOUBLE_EQ(f.plot_error(), 0.1);

  PublishedImage preview = flat_image(4, 2, 0.6f, 0);
  preview.info.preview = true;
  EXPECT_FALSE(compute_figures(preview.info, preview.rgb, &ref).valid);
}

TEST(Reference, LoadsAPfmAndNamesABadOne) {
  const auto dir = std::filesystem::temp_directory_path();
  const std::string path = (dir / ("pdflab-measure-ref-" + std::to_string(::getpid()) + ".pfm")).string();
  const std::vector<float> rgb(3 * 6, 0.25f);
  const auto bytes = encode_pfm(rgb, 3, 2);
  write_file_atomic(path, bytes);
  const ReferenceImage ref = load_reference(path);
  EXPECT_EQ(ref.width, 3);
  EXPECT_EQ(ref.height, 2);
  EXPECT_EQ(ref.path, path);
  std::filesystem::remove(path);
  try {
    load_reference(path);
    FAIL() << "a missing file must throw";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

TEST(MeasureState, RenderAtReferenceSizeThenMeasures) {
  // The viewer's flow: a mismatched reference gives estimates only; at the
  // reference's size the next image is measured against it.
  MeasureState m;
  m.published = flat_image(8, 8, 0.5f);
  m.set_reference(flat_reference(4, 2, 0.5f));
  EXPECT_FALSE(m.size_mismatch(8, 8).empty());
  EXPECT_FALSE(m.figures.against_reference);
  m.published = flat_image(4, 2, 0.55f);
  m.published.info.generation = 3;
  m.on_image(3, "cosine");
  EXPECT_TRUE(m.size_mismatch(4, 2).empty());
  EXPECT_TRUE(m.figures.against_reference);
  ASSERT_EQ(m.curves.live().points.size(), 1u);
  EXPECT_FALSE(m.curves.live().estimated);
  // An image of an older generation (settings just changed) is not recorded.
  m.published.info.spp = 8;
  m.on_image(4, "cosine");
  EXPECT_EQ(m.curves.live().points.size(), 1u);
}

TEST(ViewLayer, EachModeSaysWhyWhenItCannotShow) {
  PublishedImage img = flat_image(4, 2, 0.5f);
  ViewLayer layer;
  std::string why;
  EXPECT_FALSE(build_view_layer(ViewMode::Image, img, nullptr, layer, why));
  EXPECT_TRUE(build_view_layer(ViewMode::RelativeError, img, nullptr, layer, why));
  EXPECT_EQ(layer.rgba.size(), 4u * 8u);
  EXPECT_EQ(layer.rgba[3], 255);
  why.clear();
  EXPECT_FALSE(build_view_layer(ViewMode::Difference, img, nullptr, layer, why));
  EXPECT_NE(why.find("reference"), std::string::npos);

  PublishedImage preview = img;
  preview.info.preview = true;
  preview.relative_standard_error.clear();
  preview.drop_mask.clear();
  why.clear();
  EXPECT_FALSE(build_view_layer(ViewMode::Drops, preview, nullptr, layer, why));
  EXPECT_NE(why.find("full pass"), std::string::npos);
}

TEST(ViewLayer, DropsAreColouredByReasonAndCounted) {
  PublishedImage img = flat_image(4, 1, 0.5f);
  img.drop_mask = {0, 1u << static_cast<int>(DropReason::PdfNotFinite), 1u << static_cast<int>(DropReason::PdfZero),
                   (1u << static_cast<int>(DropReason::PdfZero)) | (1u << static_cast<int>(DropReason::RadianceNotFinite))};
  ViewLayer layer;
  std::string why;
  ASSERT_TRUE(build_view_layer(ViewMode::Drops, img, nullptr, layer, why));
  EXPECT_EQ(layer.drop_pixels[static_cast<int>(DropReason::PdfZero)], 1u);
  EXPECT_EQ(layer.drop_pixels[static_cast<int>(DropReason::PdfNotFinite)], 1u);
  EXPECT_EQ(layer.drop_pixels[static_cast<int>(DropReason::RadianceNotFinite)], 0u);
  EXPECT_EQ(layer.drop_pixels[kDropReasonCount], 1u);  // several reasons
  EXPECT_LT(layer.rgba[3], 255);                       // clean pixel: a translucent dimmer
  const Colour cyan = drop_reason_colour(static_cast<int>(DropReason::PdfNotFinite));
  EXPECT_EQ(layer.rgba[4], static_cast<std::uint8_t>(std::lround(cyan[0] * 255.0f)));
  EXPECT_EQ(layer.rgba[7], 255);
  EXPECT_EQ(layer.rgba[12], 255);  // white for several
}

TEST(DropBits, OneBitPerReasonThatGrew) {
  DropCounts before, after;
  EXPECT_EQ(drop_reason_bits(before, after), 0);
  after.add(DropReason::RadianceNotFinite);
  after.add(DropReason::PdfZero);
  after.add(DropReason::PdfZero);
  EXPECT_EQ(drop_reason_bits(before, after),
            (1u << static_cast<int>(DropReason::PdfZero)) | (1u << static_cast<int>(DropReason::RadianceNotFinite)));
}

TEST(NeeMisSetting, IsItsOwnModeAndUnbiased) {
  for (const char* text : {"nee-mis", "nee-mis:balance"}) {
    const auto s = SamplingSettings::from(Strategy::parse(text));
    EXPECT_TRUE(s.nee_mis);
    EXPECT_EQ(s.strategy().to_string(), Strategy::parse(text).to_string());
    EXPECT_TRUE(s.strategy().is_unbiased()) << text;  // the "unbiased" badge, not "BIASED"
  }
  // Leaving nee-mis for a mixture restores a usable mixture, not all-zero weights.
  auto s = SamplingSettings::from(Strategy::nee(MisHeuristic::Balance));
  EXPECT_EQ(s.heuristic, MisHeuristic::Balance);
  s.nee_mis = false;
  EXPECT_TRUE(s.mixture);
  EXPECT_GT(s.normalised()[static_cast<int>(Technique::Cosine)], 0.0f);
  EXPECT_TRUE(s.strategy().is_unbiased());
  // Biased strategies still say so.
  EXPECT_FALSE(SamplingSettings::from(Strategy::parse("light-sa")).strategy().is_unbiased());
}

TEST(NoiseSummary, MatchesTheSeparateMetrics) {
  Film film(3, 2);
  for (std::size_t p = 0; p < film.pixel_count(); ++p)
    for (float s = 0.0f; s < 5.0f; s += 1.0f)
      film.add(p, Vec3(0.1f * static_cast<float>(p + 1) + 0.05f * s, 0.2f * s, 1.0f / (s + 1.0f)));
  std::vector<float> map;
  const NoiseSummary n = noise_summary(film, map);
  EXPECT_EQ(map, relative_standard_error_map(film));
  EXPECT_DOUBLE_EQ(n.mean_relative_standard_error, mean_relative_standard_error(film));
  EXPECT_NEAR(n.estimated_relmse, estimated_relmse(film), 1e-15);
}

namespace {

using namespace pdflab::ui;

// The weight views: the best-weight scale runs 0..1 about 0.5 (blue all b, red
// all a), a cell without a best weight is grey, a bad --view name is refused.
TEST(WeightViews, BestWeightLegendRunsFromZeroToOneAndGreyMeansNone) {
  WeightMaps maps;
  maps.a = "cosine";
  maps.b = "light";
  maps.width = 4;
  maps.height = 2;
  maps.block = 2;
  maps.best_weight = {0.0f, 1.0f};  // left block all light, right block all cosine
  maps.share_a = {0.0f, 0.0f, 1.0f, -1.0f, 0.0f, 0.0f, 1.0f, 1.0f};
  const ColourScale s = best_weight_scale(maps);
  std::vector<std::string> labels;
  for (const LegendTick& t : legend_ticks(s)) labels.push_back(t.label);
  EXPECT_EQ(labels, (std::vector<std::string>{"0", "0.25", "0.5", "0.75", "1"}));
  ViewLayer layer;
  std::string why;
  ASSERT_TRUE(build_view_layer(ViewMode::BestWeight, {}, nullptr, layer, why, nullptr, &maps)) << why;
  ASSERT_EQ(layer.rgba.size(), 4u * 8u);
  // Pixel (0,0) is in the all-light block: blue beats red; pixel (3,1) all cosine: red beats blue.
  EXPECT_GT(layer.rgba[2], layer.rgba[0]);
  EXPECT_GT(layer.rgba[(1 * 4 + 3) * 4 + 0], layer.rgba[(1 * 4 + 3) * 4 + 2]);
  ASSERT_TRUE(build_view_layer(ViewMode::TechniqueShare, {}, nullptr, layer, why, nullptr, &maps)) << why;
  // No light found (-1): the same grey in every channel.
  const std::uint8_t* grey = &layer.rgba[3 * 4];
  EXPECT_EQ(grey[0], grey[1]);
  EXPECT_EQ(grey[1], grey[2]);
  WeightMaps none;
  EXPECT_FALSE(build_view_layer(ViewMode::BestWeight, {}, nullptr, layer, why, nullptr, &none));
  EXPECT_NE(why.find("two techniques"), std::string::npos) << why;
  EXPECT_EQ(parse_view_mode("technique-share"), ViewMode::TechniqueShare);
  EXPECT_EQ(parse_view_mode("best-weight"), ViewMode::BestWeight);
  EXPECT_THROW(parse_view_mode("sideways"), pdflab::InputError);
}

// The guiding-tree view: each leaf a translucent colour of its own, solid
// borders where the leaf changes, the image left alone where no leaf is.
TEST(ViewLayers, GuidingTreeColoursLeavesAndDrawsTheirBorders) {
  GuidingLeafMap map;
  map.width = 4;
  map.height = 2;
  map.leaf = {3, 3, 8, -1,  //
              3, 3, 8, 8};
  ViewLayer layer;
  std::string why;
  ASSERT_TRUE(build_view_layer(ViewMode::GuidingTree, {}, nullptr, layer, why, nullptr, nullptr, &map)) << why;
  ASSERT_EQ(layer.rgba.size(), 4u * 8u);
  const auto alpha = [&](int x, int y) { return layer.rgba[static_cast<std::size_t>((y * 4 + x) * 4 + 3)]; };
  EXPECT_EQ(alpha(0, 0), 110);  // inside leaf 3
  EXPECT_EQ(alpha(1, 0), 230);  // leaf 3 meets leaf 8 to its right: a border
  EXPECT_EQ(alpha(2, 0), 230);  // leaf 8 meets nothing to its right
  EXPECT_EQ(alpha(3, 0), 0);    // no surface: the image shows
  EXPECT_EQ(alpha(3, 1), 110);
  // Two leaves' insides differ in colour.
  EXPECT_NE(std::vector<std::uint8_t>(layer.rgba.begin(), layer.rgba.begin() + 3),
            std::vector<std::uint8_t>(layer.rgba.begin() + 7 * 4, layer.rgba.begin() + 7 * 4 + 3));
  for (int a = 0; a < 6; ++a)
    for (int b = a + 1; b < 6; ++b) EXPECT_NE(guiding_leaf_colour(a), guiding_leaf_colour(b)) << a << ", " << b;
  // No map (a strategy without guided): the image, and why.
  const GuidingLeafMap none;
  EXPECT_FALSE(build_view_layer(ViewMode::GuidingTree, {}, nullptr, layer, why, nullptr, nullptr, &none));
  EXPECT_EQ(why.rfind("render a strategy with guided", 0), 0u) << why;
  EXPECT_EQ(parse_view_mode("guiding-tree"), ViewMode::GuidingTree);
}

}  // namespace

TEST(ReferenceIdentity, ACameraSceneDepthOrSizeChangeTurnsTheFiguresToEstimatesAndSaysWhy) {
  MeasureState m;
  ImageIdentity render{"aaaa", "aaaa", 4, 2, 8, false};
  m.set_render_identity(render);
  ReferenceImage ref = flat_reference(4, 2, 0.5f);
  ref.info.has_sidecar = true;
  ref.info.scene_hash = "aaaa";
  ref.info.max_depth = 8;
  m.published = flat_image(4, 2, 0.55f);
  m.set_reference(ref);
  m.on_image(0, "cosine");
  EXPECT_TRUE(m.figures.against_reference);
  EXPECT_TRUE(m.reference_mismatch().empty());
  EXPECT_NE(m.matching_reference(), nullptr);

  // The camera orbits: the view's hash is another, the scene's the same.
  render.view_hash = "bbbb";
  m.set_render_identity(render);
  m.on_image(0, "cosine");
  EXPECT_FALSE(m.figures.against_reference);
  EXPECT_NE(m.figures.estimate_why.find("camera moved"), std::string::npos) << m.figures.estimate_why;
  EXPECT_EQ(m.matching_reference(), nullptr);
  EXPECT_FALSE(m.refresh_layer(ViewMode::Difference));
  EXPECT_NE(m.layer_why.find("camera moved"), std::string::npos) << m.layer_why;

  // Another scene; another depth; another size.
  render = {"cccc", "cccc", 4, 2, 8, false};
  m.set_render_identity(render);
  EXPECT_NE(m.reference_mismatch().find("another scene"), std::string::npos) << m.reference_mismatch();
  render = {"aaaa", "aaaa", 4, 2, 3, false};
  m.set_render_identity(render);
  EXPECT_NE(m.reference_mismatch().find("max depth 8, the render 3"), std::string::npos) << m.reference_mismatch();
  render = {"aaaa", "aaaa", 4, 2, 8, false};
  m.set_render_identity(render);
  m.published = flat_image(8, 8, 0.55f);
  EXPECT_NE(m.reference_mismatch().find("4x2, the render 8x8"), std::string::npos) << m.reference_mismatch();
  // Back where it was: measured again.
  m.published = flat_image(4, 2, 0.55f);
  m.on_image(0, "cosine");
  EXPECT_TRUE(m.figures.against_reference);
}

TEST(ReferenceIdentity, ABarePfmIsTakenAsTheRenderItWasLoadedFor) {
  MeasureState m;
  m.set_render_identity({"aaaa", "aaaa", 4, 2, 8, false});
  m.published = flat_image(4, 2, 0.55f);
  m.set_reference(flat_reference(4, 2, 0.5f));  // no sidecar
  EXPECT_TRUE(m.reference_identity.assumed);
  EXPECT_EQ(m.reference_identity.view_hash, "aaaa");
  EXPECT_TRUE(m.reference_mismatch().empty());
  m.set_render_identity({"bbbb", "aaaa", 4, 2, 8, false});
  EXPECT_FALSE(m.reference_mismatch().empty());
  // Loaded before the render's identity is known (--reference at start-up): the first one it sees.
  MeasureState early;
  early.set_reference(flat_reference(4, 2, 0.5f));
  early.set_render_identity({"dddd", "dddd", 4, 2, 5, false});
  EXPECT_EQ(early.reference_identity.view_hash, "dddd");
  EXPECT_EQ(early.reference_identity.max_depth, 5);
}

TEST(Reference, AReferenceWhoseNoiseIsAboveAQuarterIsRough) {
  ReferenceImage ref = flat_reference(4, 2, 0.5f);
  const PublishedImage img = flat_image(4, 2, 0.6f);  // raw relMSE 0.01 / 0.26
  ref.variance.assign(24, 0.002f);                    // 20% of it: measured
  EXPECT_FALSE(compute_figures(img.info, img.rgb, &ref).rough_reference);
  ref.variance.assign(24, 0.004f);  // 40%: rough
  const Figures f = compute_figures(img.info, img.rgb, &ref);
  EXPECT_TRUE(f.against_reference);
  EXPECT_TRUE(f.rough_reference);
  EXPECT_NEAR(f.reference_share, 0.4, 1e-5);
  ref.variance.clear();  // unknown noise: not called rough (it cannot be told)
  EXPECT_FALSE(compute_figures(img.info, img.rgb, &ref).rough_reference);
}

TEST(MakeReference, AimsAtAShareOfTheFiguresOrAStatedSppWithinItsTimeLimit) {
  MeasureSettings s;
  s.make_seconds = 40.0f;
  Figures now;
  std::string note;
  // No figures yet: the stated spp.
  ReferenceGoal g = reference_goal(s, now, note);
  EXPECT_EQ(g.spp, s.make_spp);
  EXPECT_EQ(g.relmse, 0.0);
  EXPECT_DOUBLE_EQ(g.max_seconds, 40.0);
  EXPECT_NE(note.find("no figures yet"), std::string::npos) << note;
  now.valid = true;
  now.spp = 64;
  now.estimated_relmse = 0.019;
  g = reference_goal(s, now, note);
  EXPECT_EQ(g.spp, 0u);
  // Its noise 5% of the raw error: relMSE 0.05 / 0.95 of the render's.
  EXPECT_NEAR(g.relmse, 0.001, 1e-12);
  EXPECT_NEAR(g.relmse / (g.relmse + now.estimated_relmse), kTargetShare, 1e-12);
  s.make_target = ReferenceTarget::Spp;
  s.make_spp = 512;
  g = reference_goal(s, now, note);
  EXPECT_EQ(g.spp, 512u);
  EXPECT_EQ(note, "target: 512 spp");
  // Stopped by the time limit short of the goal: reached, and capped.
  ReferenceProgress p = reference_progress({0, 0.0, 1e-3, 10.0}, 100, 10.5, 4e-3);
  EXPECT_TRUE(p.reached);
  EXPECT_TRUE(p.capped);
  p = reference_progress({0, 0.0, 1e-3, 10.0}, 100, 5.0, 4e-3);
  EXPECT_FALSE(p.reached);
  EXPECT_NEAR(p.seconds_left, 5.0, 1e-9);  // the limit comes before the goal's 15 s
  p = reference_progress({0, 0.0, 1e-3, 10.0}, 100, 5.0, 0.9e-3);
  EXPECT_TRUE(p.reached);
  EXPECT_FALSE(p.capped);
}

TEST(EstimateHistory, TheUnreliableFlagClearsOnceTheEstimateFallsAgain) {
  EstimateHistory h;
  // Rare bright paths found between 4 and 8 spp: the estimate does not fall.
  h.add(2, 0.1);
  h.add(4, 0.05);
  h.add(8, 0.06);
  EXPECT_TRUE(h.unreliable_now());
  EXPECT_TRUE(h.unreliable());
  // Then relMSE x spp holds still: the warning clears (the render's record stays).
  for (std::uint32_t n = 16; n <= 256; n *= 2) h.add(n, 0.48 / n);
  EXPECT_FALSE(h.unreliable_now());
  EXPECT_TRUE(h.unreliable());
}
