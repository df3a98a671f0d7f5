#pragma once
// Measuring the speed-accuracy trade in the viewer, as plain data: view modes,
// the reference image, error figures of each published pass, convergence
// curves, colour maps and their legends. No ImGui and no OpenGL here, so every
// number the panels show can be unit-tested.
#include "renderer/metrics/metrics.h"
#include "renderer/metrics/reference.h"
#include "renderer/session/session.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace pdflab::ui {

enum class ViewMode : std::uint8_t { Image, RelativeError, Difference, Drops, Count };
inline constexpr int kViewModeCount = static_cast<int>(ViewMode::Count);
const char* view_mode_label(ViewMode mode);
ViewMode next_view_mode(ViewMode mode);

// The measuring part of ViewerSettings.
struct MeasureSettings {
  ViewMode view_mode = ViewMode::Image;
  bool show_plot = false;  // G shows it; off at first so the image is seen whole
  bool plot_against_spp = false;  // false: against rendering seconds
  std::string reference_field;    // the path as typed
  // "Make reference": its size as a divisor of the render's (1, 2 or 4), its
  // rendering time, and the share of the hardware threads it takes (at 1 the
  // main render pauses until it is done).
  int make_divisor = 1;
  float make_seconds = 30.0f;
  float make_thread_share = 0.5f;
};

// What the measuring panels ask for this frame.
struct MeasureRequests {
  std::string load_reference;  // non-empty: try this PFM
  bool clear_reference = false;
  bool render_at_reference_size = false;
  bool make_reference = false;
  bool cancel_reference = false;
  bool pin_curve = false;
  bool clear_pins = false;
};

// The reference (renderer/metrics/reference.h): mean, variance, sidecar.
using ReferenceImage = pdflab::Reference;

// Reads a reference (a PFM, with its variance and sidecar when they are
// there). Throws InputError naming the file when it cannot.
using pdflab::load_reference;
// Empty when the sizes agree; otherwise a sentence saying which is which.
std::string reference_size_mismatch(const ReferenceImage& reference, int render_width, int render_height);

// The figures of one published full pass.
struct Figures {
  bool valid = false;              // false for previews and before the first pass
  bool against_reference = false;  // rmse, relmse, efficiency measured; else only estimates
  std::uint32_t spp = 0;
  double seconds = 0.0;
  // relmse is corrected for the reference's noise (metrics.h, measure_relmse):
  // relmse_interval its 95% half width, relmse_raw the uncorrected figure.
  double rmse = 0.0, relmse = 0.0, efficiency = 0.0;
  double relmse_interval = 0.0, relmse_raw = 0.0, reference_share = 0.0;
  bool reference_corrected = false;  // false: the reference has no variance
  // The film's own account (metrics.h), available without a reference: a
  // lower bound on the error (blind to what the samples never found).
  double mean_relative_standard_error = 0.0;
  double estimated_relmse = 0.0, estimated_efficiency = 0.0;
  // A biased strategy gets no efficiency from the estimate (0 then): it would
  // rank a strategy that misses light as the best.
  bool unbiased = true;
  // The estimate stopped falling as samples doubled (EstimateHistory).
  bool estimate_unreliable = false;
  // What the convergence plot draws: the relative RMS error sqrt(relMSE),
  // measured when there is a reference of the right size, estimated otherwise.
  // It falls as 1/sqrt(N) for an unbiased strategy, like the noise.
  double plot_error() const;
};

// `reference` may be null or of another size: then only the estimates are set.
// `unbiased`: of the strategy that rendered the image.
Figures compute_figures(const ImageInfo& info, const std::vector<float>& rgb, const ReferenceImage* reference,
                        bool unbiased = true);

struct CurvePoint {
  double spp = 0.0, seconds = 0.0, error = 0.0;
};

struct Curve {
  std::string label;       // the strategy, as `pdflab render --strategy` takes it
  bool estimated = false;  // errors from the film's variance, not from a reference
  std::vector<CurvePoint> points;
};

// Points of the running strategy as passes complete, and pinned curves to
// compare against. Points come from the published image's own spp and seconds,
// so the error and its abscissa always belong to the same pass.
class ConvergenceRecorder {
 public:
  static constexpr std::size_t kMaxPins = 6;
  // Points closer than this factor in spp are skipped: passes come ever more
  // often as spp grows, and a log axis needs only a few per decade.
  static constexpr double kMinSppStep = 1.02;

  // Adds a point; a new generation, label or error source starts a new live
  // curve. Non-positive or non-finite errors (a black image, 1 spp) are skipped.
  // Returns whether the point was kept.
  bool record(std::uint64_t generation, const std::string& label, bool estimated, std::uint32_t spp, double seconds,
              double error);
  // Keeps the live curve (two points at least) under its label; the oldest pin
  // goes when there are kMaxPins. Returns false when there was nothing to keep.
  bool pin();
  void clear_pins() { pins_.clear(); }
  const Curve& live() const { return live_; }
  const std::vector<Curve>& pins() const { return pins_; }

 private:
  Curve live_;
  std::uint64_t generation_ = 0;
  bool started_ = false;
  std::vector<Curve> pins_;
};

// A logarithmic axis snapped to whole decades.
struct LogRange {
  double lo = 1.0, hi = 10.0;
  double position(double v) const;  // 0 at lo, 1 at hi
};
// Covers every positive finite value; one decade at least; [1, 10] when there is none.
LogRange log_range(const std::vector<double>& values);
std::vector<double> decade_ticks(const LogRange& range);

using Colour = std::array<float, 3>;  // display RGB in 0..1
// Dark purple to pale yellow, monotonic in lightness so a grey print still orders it.
Colour sequential_colour(double t);  // t in 0..1
// Blue below zero, near-white at zero, red above.
Colour diverging_colour(double t);  // t in -1..1
// One colour per DropReason, and one for a pixel with several reasons.
Colour drop_reason_colour(int reason);
inline constexpr Colour kSeveralDropReasonsColour = {1.0f, 1.0f, 1.0f};

// The value scale of a false-colour view and its legend.
struct ColourScale {
  bool logarithmic = false;
  bool diverging = false;  // symmetric: -hi..hi
  double lo = 0.0, hi = 1.0;
  std::string title;
  double position(double v) const;  // 0..1 along the colour bar
  Colour colour(double v) const;
};
struct LegendTick {
  double position = 0.0;  // 0..1 along the bar
  std::string label;
};
std::vector<LegendTick> legend_ticks(const ColourScale& scale);

// The heat map's scale: relative standard error, logarithmic, 0.001 to 10.
ColourScale relative_error_scale();
// The difference view's: symmetric about 0, up to `half_range`.
ColourScale difference_scale(double half_range);
// 1, 2 or 5 times a power of ten, at least v.
double nice_ceiling(double v);
// Luminance of (image - reference) per pixel.
std::vector<float> luminance_difference(const std::vector<float>& rgb, const std::vector<float>& reference);
// A half range for the difference view: the 99th percentile of |d|, made nice,
// so a few fireflies do not wash the rest out.
double difference_half_range(const std::vector<float>& difference);

// A false-colour layer as RGBA8, row 0 at the top, drawn over (Drops) or
// instead of (the others) the image. Returns false with the reason in `why`
// when the mode cannot be shown for this image (a preview, no reference, ...).
struct ViewLayer {
  std::vector<std::uint8_t> rgba;
  int width = 0, height = 0;
  ColourScale scale;  // for the colour bar (unused for Drops)
  std::array<std::uint64_t, 4> drop_pixels{};  // Drops: pixels per reason (+ several, last)
};
bool build_view_layer(ViewMode mode, const PublishedImage& image, const ReferenceImage* reference, ViewLayer& out,
                      std::string& why);

// A "Make reference" in progress, as the panel shows it.
struct ReferenceBuildStatus {
  bool running = false;
  bool finishing = false;  // rendered; being stored
  int width = 0, height = 0, threads = 0;
  double fraction = 0.0, seconds_left = 0.0;
  std::uint32_t spp = 0;
};

// Everything measured so far, owned by the viewer and read by the panels.
struct MeasureState {
  ReferenceImage reference;
  bool reference_from_cache = false;  // found in the cache (or made here), not loaded by hand
  std::string reference_error;  // the last failed load, empty when fine
  std::string reference_note;   // how the reference came (cache, made), or a seed changed for it
  ReferenceBuildStatus build;
  EstimateHistory history;      // of the generation on screen
  std::uint64_t history_generation = ~std::uint64_t{0};
  Figures figures;              // of the image on screen
  ConvergenceRecorder curves;
  PublishedImage published;     // the image on screen with its noise map and drop mask
  ViewMode layer_mode = ViewMode::Image;
  bool layer_ok = false;        // `layer` shows `layer_mode` for `published`
  std::string layer_why;        // why not, when the mode is not Image
  ViewLayer layer;

  // A newly published image: figures, and a convergence point when it shows
  // the generation now rendering (`label` is that generation's strategy).
  void on_image(std::uint64_t current_generation, const std::string& label);
  // A new reference (or none): figures and layer follow at once.
  void set_reference(ReferenceImage image);
  // Rebuilds the layer for `mode`; true when it changed (and must be uploaded).
  bool refresh_layer(ViewMode mode);
  // Size mismatch against the render, empty when none or no reference.
  std::string size_mismatch(int render_width, int render_height) const {
    return reference_size_mismatch(reference, render_width, render_height);
  }
};

}  // namespace pdflab::ui
