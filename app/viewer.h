#pragma once
// The interactive viewer: a GLFW window showing the render session's
// accumulation, with the ImGui panels of ui/.
#include "ui/settings.h"

#include <cstdint>
#include <memory>
#include <string>

namespace pdflab {

struct ViewerOptions {
  std::string scene;
  std::string strategy = "mix:cosine=0.5,light=0.5";
  std::uint32_t spp = 0;   // with `screenshot`: render this many samples per pixel, save, exit
  std::string screenshot;  // PNG path; the PFM and JSON go beside it
  // Window size in screen coordinates (0: as remembered, else fit the image and the panel).
  int window_width = 0, window_height = 0;
  // Remember the window's size, the panel's width and open sections between
  // runs (ui/preferences.h); off for benchmarks and tests that drive a Viewer.
  bool remember = false;
  // Write the layout (ui/layout_report.h) to this JSON file after each frame
  // whose layout changed (empty: not at all).
  std::string layout_json;
  std::string reference;  // PFM to measure the error against (empty: none)
  float ui_scale = 1.0f;  // panels and text, times the screen's own scale (0.5..4)
  bool presentation = false;  // start full screen without the panel
  bool auto_weight = false;   // start with auto weight on (a two-technique mixture)
  std::string view;           // start in this view mode (its label or short name; empty: the image)
  double make_reference_seconds = 0.0;  // the Make reference time's first value (0: 30 s)
  // A film file (film_file.h) to continue: its strategy, seed, size and depth
  // are applied and its accumulation goes on (scene and strategy must match it).
  std::string resume;
};

// Runs the viewer until the window closes. Returns the process exit status;
// throws InputError for bad options (checked before any window opens).
int run_viewer(const ViewerOptions& options);

// One frame at a time, for benchmarks and tests that drive the viewer directly.
class Viewer {
 public:
  explicit Viewer(const ViewerOptions& options);  // throws InputError, or std::runtime_error without a display
  ~Viewer();
  Viewer(const Viewer&) = delete;
  Viewer& operator=(const Viewer&) = delete;

  // Handles input, shows the newest image, draws the UI. False once the window
  // should close. Sleeps to pace itself unless `paced` is false. Draws only when
  // something visible changed unless `force_draw` (benchmarks: a user dragging a slider).
  bool frame(bool paced = true, bool force_draw = false);
  int run();

  struct FrameReport {
    double work_ms = 0.0;               // from the frame's start to the swap returning
    double cpu_ms = 0.0;                // the UI thread's CPU time in that span (not llvmpipe's threads)
    std::uint64_t shown_generation = 0; // settings generation of the image on screen
    bool shown_preview = false;
    std::uint32_t shown_spp = 0;
    bool new_image = false;             // a new image arrived this frame
    bool drawn = false;                 // false: nothing changed, nothing was drawn
  };
  const FrameReport& last_frame() const;

  // What a panel edit does: change the settings, then ask for them to apply.
  ui::ViewerSettings& settings();
  void request_restart();
  std::uint64_t session_generation() const;
  int exit_status() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pdflab
