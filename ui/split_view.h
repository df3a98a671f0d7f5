#pragma once
// Split screen A/B: two strategies render the same scene with the same seed
// (so the same random numbers), side by side, with a draggable divider. The
// plain parts (thread split, divider dragging, per-side figures) are here and
// tested; the viewer owns the two sessions.
#include "renderer/sampling/strategy.h"

#include <cstdint>
#include <string>
#include <vector>

namespace pdflab::ui {

// Equal wall time per side: both sessions start in the same call and render at
// once on the same number of threads (at the same priority), so the scheduler
// gives each the same share of the machine. Odd counts leave one core idle
// rather than favour a side.
struct SplitThreads {
  int a = 1, b = 1;
};
SplitThreads split_threads(int hardware_threads);

// The divider's position over the image, as a fraction of its width. Input in
// screen units; grabbing within `grab` of the line starts a drag.
struct SplitDivider {
  float fraction = 0.5f;
  bool dragging = false;
  // Returns true while the divider owns the mouse (the click is not a probe).
  bool update(float mouse_x, float mouse_y, bool clicked, bool down, float left, float top, float width, float height,
              float grab);
  float x(float left, float width) const { return left + fraction * width; }
};

// One side's figures, from its last full pass.
struct SideFigures {
  std::string strategy;
  std::uint32_t spp = 0;
  double seconds = 0.0;
  double samples_per_second = 0.0;
  double noise = -1.0;             // mean relative standard error of the film; -1 unknown
  double estimated_relmse = -1.0;  // the film's own relMSE estimate; -1 unknown
  double reference_relmse = -1.0;  // against the loaded reference; -1 none
  bool unbiased = true;
  // 1 / (relMSE * seconds), from the reference when there is one, else from the
  // film's estimate; -1 unknown.
  double efficiency() const;
  bool efficiency_from_reference() const { return reference_relmse >= 0.0; }
};

// B's strategies offered in the split controls (A is the side panel's).
std::vector<std::string> split_strategy_choices();

struct SplitState {
  bool on = false;
  SplitDivider divider;
  std::string b_strategy = "cosine";
  std::string b_field = "cosine";  // the text field before Enter
  std::string b_error;
  std::string reference_path;
  std::string reference_status;  // "loaded 96x96", or why not
  SideFigures a, b;
  int threads_per_side = 0;
};

struct SplitRequests {
  bool restart = false;         // B's strategy changed
  bool load_reference = false;  // reference_path to be (re)loaded; empty clears
};

// The divider line over the image rectangle (ImGui coordinates) and the two
// sides' figures in the area's top corners; then the small controls window at
// its bottom left (both placed by ui/layout_report).
void draw_split_overlay(const SplitState& state, float left, float top, float width, float height);
void draw_split_controls(SplitState& state, SplitRequests& requests);

// "12.3%", "3.2e-04": compact figures for the side boxes.
std::string format_figure(double value, bool percent = false);

}  // namespace pdflab::ui
