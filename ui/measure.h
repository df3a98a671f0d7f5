#pragma once
// Measuring the speed-accuracy trade in the viewer, as plain data: the
// settings and requests of the measuring panels, the error figures of each
// published pass, and the state that ties them together. The colour scales
// (colour_scale.h), the convergence recorder (convergence.h) and the error
// layers (error_layers.h) each have their own file. No ImGui and no OpenGL
// here, so every number the panels show can be unit-tested.
#include "renderer/metrics/metrics.h"
#include "renderer/metrics/reference.h"
#include "renderer/session/session.h"
#include "ui/colour_scale.h"
#include "ui/convergence.h"
#include "ui/error_layers.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace pdflab::ui {

// "Make reference" aims at a reference whose own noise is at most this share
// of the figures shown when it starts (about 5% of the raw relMSE), or at a
// stated spp; a reference whose noise is more than kRoughShare of a figure
// makes that figure rough (never shown as a plain measurement).
inline constexpr double kTargetShare = 0.05;
inline constexpr double kRoughShare = 0.25;
enum class ReferenceTarget : std::uint8_t { Share, Spp };

// The measuring part of ViewerSettings.
struct MeasureSettings {
  ViewMode view_mode = ViewMode::Image;
  LayerOptions heat_map = default_heat_map_options();
  LayerOptions difference = default_difference_options();
  // The options of `mode` (the heat map's for a mode without any).
  const LayerOptions& layer_options(ViewMode mode) const { return mode == ViewMode::Difference ? difference : heat_map; }
  LayerOptions& layer_options(ViewMode mode) { return mode == ViewMode::Difference ? difference : heat_map; }
  // The current view's metric (E, Shift+E: step -1): the next one it offers,
  // on an automatic range (the old range belongs to another quantity).
  void set_metric(ErrorMetric metric);
  void step_metric(int step);
  bool show_plot = false;  // G shows it; off at first so the image is seen whole
  bool plot_against_spp = false;  // false: against rendering seconds
  std::string reference_field;    // the path as typed
  // "Make reference": its size as a divisor of the render's (1, 2 or 4), its
  // target (a share of the figures, or make_spp), the time it may take at
  // most, and the share of the hardware threads it takes (at 1 the main render
  // pauses until it is done).
  int make_divisor = 1;
  ReferenceTarget make_target = ReferenceTarget::Share;
  std::uint32_t make_spp = 1024;
  float make_seconds = 120.0f;
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

// Reads a reference (a PFM, with its variance and sidecar when they are
// there). Throws InputError naming the file when it cannot.
using pdflab::load_reference;

// What an image shows: the scene and its view, size and depth. A reference's
// comes from its sidecar; one loaded without a sidecar (a bare PFM) is taken
// to show the render as it was when it was loaded (`assumed`). Empty hashes
// and zero sizes are unknown and match anything.
struct ImageIdentity {
  // The scene file's content hash, or for a camera moved in the viewer a hash
  // of that and the camera (what the reference cache and film files key by).
  std::string view_hash;
  std::string scene_hash;  // the scene file's own content hash, when known
  int width = 0, height = 0, max_depth = 0;
  bool assumed = false;
};
// The identity a reference's sidecar gives (no hash: nothing but its size).
ImageIdentity identity_of(const ReferenceImage& reference);
// Empty when an image of `reference` can measure one of `render`; else one
// line naming what differs (size, camera, scene, depth) and that the figures
// are estimates.
std::string identity_mismatch(const ImageIdentity& reference, const ImageIdentity& render);

// The figures of one published full pass.
struct Figures {
  bool valid = false;              // false for previews and before the first pass
  bool against_reference = false;  // rmse, relmse, efficiency measured; else only estimates
  // With a reference loaded that does not match the image: why the figures are estimates.
  std::string estimate_why;
  // Measured against a reference whose own noise is more than kRoughShare of
  // the raw error: rough, not a measurement to trust.
  bool rough_reference = false;
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


// The goal of a reference made in the viewer: a relMSE that makes its noise
// kTargetShare of the raw error of the figures `now` shows, or the spp `s`
// states (also when there are no figures yet), within `s`'s time limit
// (ReferenceGoal::max_seconds). `note` says which, as a line for the panel.
ReferenceGoal reference_goal(const MeasureSettings& s, const Figures& now, std::string& note);

// A "Make reference" in progress, as the panel shows it.
struct ReferenceBuildStatus {
  bool running = false;
  bool finishing = false;  // rendered; being stored
  int width = 0, height = 0, threads = 0;
  double fraction = 0.0, seconds_left = 0.0;
  std::uint32_t spp = 0;
  std::string target;        // what it aims at, as a line
  double max_seconds = 0.0;  // its time limit
};

// Everything measured so far, owned by the viewer and read by the panels.
struct MeasureState {
  ReferenceImage reference;
  bool reference_from_cache = false;  // found in the cache (or made here), not loaded by hand
  std::string reference_error;  // the last failed load, empty when fine
  std::string reference_note;   // how the reference came (cache, made), or a seed changed for it
  bool reference_note_warns = false;  // the note is a warning (a reference short of its target)
  ImageIdentity render_identity;      // what the viewer renders now (set when its settings apply)
  ImageIdentity reference_identity;   // what `reference` shows
  ReferenceBuildStatus build;
  EstimateHistory history;      // of the generation on screen
  std::uint64_t history_generation = ~std::uint64_t{0};
  Figures figures;              // of the image on screen
  ConvergenceRecorder curves;
  PublishedImage published;     // the image on screen with its noise map and drop mask
  ViewMode layer_mode = ViewMode::Image;
  LayerOptions layer_options;   // what `layer` was built with
  bool layer_ok = false;        // `layer` shows `layer_mode` for `published`
  std::string layer_why;        // why not, when the mode is not Image
  ViewLayer layer;
  WeightMaps weight_maps;       // set by the viewer's weight prediction
  GuidingLeafMap guiding_leaves;  // set by the viewer from the session's path guiding

  // New weight maps: the layer follows.
  void set_weight_maps(WeightMaps maps) {
    weight_maps = std::move(maps);
    layer_ok = false;
    layer_why.clear();
  }
  // A new guiding-tree map: the layer follows.
  void set_guiding_leaves(GuidingLeafMap map) {
    guiding_leaves = std::move(map);
    layer_ok = false;
    layer_why.clear();
  }
  // A newly published image: figures, and a convergence point when it shows
  // the generation now rendering (`label` is that generation's strategy).
  void on_image(std::uint64_t current_generation, const std::string& label);
  // A new reference (or none): figures and layer follow at once.
  void set_reference(ReferenceImage image);
  // The render's identity after a settings change; a reference that came
  // without one takes the first it sees.
  void set_render_identity(const ImageIdentity& identity);
  // Empty when the reference (loaded) matches the image on screen; else why not.
  std::string reference_mismatch() const;
  // The reference when it can measure the image on screen, else null.
  const ReferenceImage* matching_reference() const {
    return reference.loaded() && reference_mismatch().empty() ? &reference : nullptr;
  }
  // Rebuilds the layer for the view mode and its options when either or the
  // image changed; true when it did (and must be uploaded).
  bool refresh_layer(const MeasureSettings& settings);
  bool refresh_layer(ViewMode mode) {
    MeasureSettings s;
    s.view_mode = mode;
    return refresh_layer(s);
  }
  // The loaded reference's identity, an assumed one filled from the render's.
  ImageIdentity reference_identity_of_loaded() const;
  // Size mismatch against the render, empty when none or no reference.
  std::string size_mismatch(int render_width, int render_height) const {
    return reference_size_mismatch(reference, render_width, render_height);
  }
};

}  // namespace pdflab::ui
