#pragma once
// The viewer's state as plain data. Panels edit it and raise requests; the
// viewer turns it into RenderSettings. Nothing here touches threads or OpenGL.
#include "renderer/sampling/strategy.h"
#include "renderer/session/session.h"
#include "ui/measure.h"

#include <array>
#include <optional>
#include <cstdint>
#include <string>
#include <vector>

namespace pdflab::ui {

struct SplitState;

// The strategy as the panel edits it: one technique, or a mixture with one
// slider per technique (raw weights; the renderer normalises them).
struct SamplingSettings {
  bool mixture = true;
  Technique single = Technique::Cosine;
  std::array<float, kTechniqueCount> weights{};
  std::array<float, kTechniqueCount> parameters = Strategy::default_parameters();  // `cosine-power:N`
  // Next-event estimation with MIS: its own mode, neither one technique nor a
  // mixture (two samples per vertex); overrides the two above while set.
  bool nee_mis = false;
  MisHeuristic heuristic = MisHeuristic::Power;
  // nee-mis's continuation (Strategy::weights; cosine alone unless a strategy
  // such as `fastest` set another).
  std::array<float, kTechniqueCount> continuation = Strategy::nee().weights;
  int roulette_depth = 0;  // Strategy::roulette_depth, for any of the above
  bool guided_roulette = false;  // Strategy::guided_roulette, kept only where the strategy has guided
  bool sobol = false;      // Strategy::sobol (the stratified sampler), for any of the above
  bool fastest = false;    // the `fastest` preset, as it expands
  // nee-mis's light choice (Strategy::light_choice; none: the scene's).
  std::optional<LightChoice> light_choice;

  Strategy strategy() const;
  Strategy strategy_without_name() const;  // as strategy(), never marked `fastest`
  static SamplingSettings from(const Strategy& strategy);
  // Weights as the renderer will use them (sum 1), or all zero when they sum to 0.
  std::array<float, kTechniqueCount> normalised() const;
  bool operator==(const SamplingSettings&) const = default;
};

enum class Preset { CosineOnly = 1, LightOnly = 2, Book5050 = 3 };
inline constexpr int kPresetCount = 3;
// Every preset the panel and the keys 1-5 offer, in their one place: 1-3 the
// presets above, 4 nee-mis, 5 fastest.
inline constexpr int kPresetKeyCount = 5;
SamplingSettings preset_by_key(int key);  // key 1..5
const char* preset_key_label(int key);   // "cosine only", ..., "nee-mis", "fastest"
// The key (1..5) whose preset `s` is, or 0.
int preset_key_of(const SamplingSettings& s);
// `fastest` (kFastestStrategy), as the panel edits it.
SamplingSettings fastest_sampling();
const char* preset_label(Preset p);
SamplingSettings preset_sampling(Preset p);

// The two techniques of a two-technique mixture (w * A + (1 - w) * B, the
// book's form): `remembered` when the others are all 0 (w may be 0 or 1 then),
// else the two with positive weights when exactly two have; {-1, -1} otherwise.
std::array<int, 2> two_technique_pair(const SamplingSettings& s, std::array<int, 2> remembered);

// Quitting asks first when a render has run longer than this since it was last saved.
inline constexpr double kUnsavedAskSeconds = 5.0;
struct SaveMark {
  std::uint64_t generation = ~std::uint64_t{0};  // none saved yet
  double seconds = 0.0;                          // the saved image's rendering time
};
// Rendering seconds a quit would lose: all of them for a render never saved,
// those since the save for the saved one.
double unsaved_seconds(const SaveMark& saved, std::uint64_t generation, double seconds);

inline constexpr float kDefaultPanelWidth = 400.0f, kMinPanelWidth = 240.0f, kMaxPanelShare = 0.45f;
// The panel's width in the window's units: `wish` (at scale 1) times `scale`,
// at least kMinPanelWidth * scale and at most kMaxPanelShare of the window
// (which wins when they disagree).
float panel_width_for(float wish, float scale, float window_width);

struct ViewerSettings {
  SamplingSettings sampling;
  int max_depth = 50;
  std::uint64_t seed = 1;
  float resolution_scale = 1.0f;
  bool paused = false;
  std::uint32_t stop_spp = 0;  // 0: render until stopped
  float stop_seconds = 0.0f;   // 0: no time limit; else stop at the first pass after it
  float exposure_ev = 0.0f;
  bool srgb = false;  // false: the book's gamma 2
  std::string screenshot_dir = "screenshots";
  MeasureSettings measure;
  // Presentation: full screen, no side panel, no badges or inspector over the image.
  bool presentation = false;
  bool caption = false;  // in presentation mode, a caption: strategy, spp, time
  // The side panel: its width at UI scale 1 (the window's scale multiplies
  // it; it never takes more than kMaxPanelShare of the window), and hidden (Tab).
  float panel_width = kDefaultPanelWidth;
  bool panel_hidden = false;
  float ui_scale = 1.0f;  // panels and text, times the screen's content scale
  // Non-zero: render at exactly this size instead of the scene's times
  // resolution_scale (set to match a reference image).
  int width_override = 0, height_override = 0;
  // Auto weight: between passes the viewer moves the w slider to the weight
  // the passes so far predict best, and the accumulation goes on.
  bool auto_weight = false;
};

inline constexpr std::array<float, 5> kResolutionScales = {0.25f, 0.5f, 1.0f, 1.5f, 2.0f};
inline constexpr std::array<float, 6> kUiScales = {0.75f, 1.0f, 1.25f, 1.5f, 2.0f, 2.5f};
inline constexpr float kMinUiScale = 0.5f, kMaxUiScale = 4.0f;

// What the panels ask for this frame, beyond edits to ViewerSettings.
struct UiRequests {
  bool restart_render = false;  // sampling, depth, seed or resolution changed, or "Restart"
  bool stop_changed = false;    // stop_spp or stop_seconds
  bool pause_changed = false;
  bool screenshot = false;
  bool retry_screenshot = false;
  bool toggle_presentation = false;
  bool toggle_camera_mode = false;
  bool reset_camera = false;
  bool save_film = false;
  bool export_view = false;         // the false-colour view as a PNG figure
  bool export_curve = false;        // the predicted curve as SVG and CSV
  bool export_convergence = false;  // the convergence plot as SVG and CSV
  bool toggle_panel = false;
  std::string load_scene;  // non-empty: try this file
  MeasureRequests measure;
};

struct Notice {
  std::string text;
  bool error = false;
  double shown_at = 0.0;  // seconds, on the viewer's clock
};

// The live prediction beside the w slider (app/viewer_weights.h).
struct WeightCurveStatus {
  bool active = false;     // a curve is shown (else `why`)
  std::string why;         // why there is no curve yet
  std::vector<float> weight, relative_efficiency;  // the grid; efficiency over its best
  std::vector<float> largest_share;  // per grid weight, the largest path's share of the predicted moment (NaN: none)
  float dominant_share = 0.1f;       // above this share the prediction is likely too high (kDominantShare)
  double best = -1.0;      // the predicted best weight (A's share)
  double sampling = -1.0;  // the weight the paths were drawn at
  std::uint64_t paths = 0;
  double fixed_cost_rays = -1.0;  // the cost model's fixed cost per sample, in rays (-1: not priced)
  bool cost_fitted = false;       // fitted to auto weight's passes (else the prior)
  std::vector<float> history;  // auto weight: each pass's weight, oldest first
};

// A line for the panel's message line: an error, a warning or a note.
struct PanelMessage {
  enum Kind { Note, Warning, Error } kind = Note;
  std::string text;
};

// Read-only facts the panels show.
struct UiStatus {
  SessionStats stats;
  int threads = 0;
  std::string scene_name;
  std::string scene_path;
  LightChoice scene_light_choice = LightChoice::Power;  // the scene file's `light_choice`
  int base_width = 0, base_height = 0;  // the scene's own resolution
  int width = 0, height = 0;            // rendered resolution
  std::vector<std::string> scene_files;  // assets/scenes/*.json
  std::string scene_error;               // last failed load, empty when fine
  std::string settings_error;            // strategy not usable on this scene, ...
  bool showing_preview = false;
  std::uint32_t shown_spp = 0;
  bool screenshot_pending = false;  // waiting for a full pass or for the writer
  bool can_retry_screenshot = false;
  bool camera_mode = false;
  bool camera_moved = false;  // not the scene's own camera
  Notice notice;
  double now = 0.0;
  double frame_ms = 0.0;
  const MeasureState* measure = nullptr;  // the viewer's; null in tests without one
  const SplitState* split = nullptr;      // while the split screen is on: its two sides
  WeightCurveStatus weights;
  float scale = 1.0f;           // the screen's content scale times the UI scale
  int max_depth = 0;            // of the render
  // The messages of the moment, most pressing first: the panel's message line
  // shows the first, its tooltip all of them.
  std::vector<PanelMessage> messages;
  bool can_export_view = false;         // a false-colour view is shown
  bool can_export_curve = false;        // a predicted curve is shown
  bool can_export_convergence = false;  // the convergence plot has points
};

// The side panel's sections, in order; the open ones are remembered between runs.
inline constexpr int kPanelSectionCount = 6;
inline constexpr std::array<const char*, kPanelSectionCount> kPanelSections = {
    "Sampling", "Scene and render", "Statistics", "Measure", "Display", "Screenshots and figures"};
inline constexpr std::array<bool, kPanelSectionCount> kPanelSectionsOpen = {true, true, false, true, false, false};

// Text-field buffers and other panel-local state that is not a setting.
struct PanelState {
  std::string scene_path_field;
  bool show_help = false;
  bool scene_field_initialised = false;
  // The two techniques of the "w" slider, kept while it is dragged to 0 or 1.
  std::array<int, 2> w_pair{-1, -1};
  std::array<bool, kPanelSectionCount> open = kPanelSectionsOpen;
  // The last predicted curve shown, and its pair: drawn greyed while the next
  // one is computed, so the box never empties.
  WeightCurveStatus last_curve;
  std::array<int, 2> last_curve_pair{-1, -1};
};

}  // namespace pdflab::ui
