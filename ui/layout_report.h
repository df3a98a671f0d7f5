#pragma once
// This frame's layout: where the overlays over the image go (ui/overlay_layout's
// rules applied to ImGui windows), and the named rectangles of the panel's
// controls. `pdflab --layout-json FILE` writes it after each frame whose layout
// changed, for tests that click controls by name and check that nothing
// overlaps. ImGui must be in a frame for everything but report_json().
#include "ui/overlay_layout.h"

#include <string>

namespace pdflab::ui::layout {

// Starts a frame: the image area and the image on screen (ImGui coordinates),
// the font size the UI scale gives.
void begin_frame(const Box& area, const Box& image, float font_size);
const Box& area();
const Box& keep_out();

// An overlay's wishes, in font sizes for its smallest size.
struct Overlay {
  Corner corner = Corner::TopLeft;
  float width = 0.0f;                      // natural width (ImGui units)
  float min_width = 8.0f, min_lines = 1.0f;  // the smallest it may be made: font sizes, lines
  float height = 0.0f;                     // 0: last frame's content height
  float max_width = 0.0f;                  // never wider than this (0: no limit beyond the planner's)
  bool prefer_narrow = true;               // text; false: a plot (rather shorter than narrower)
};
// Places the next ImGui window, `name` (as given to Begin), by `o`: its
// position and size limit are set, and `max_width` gets the width its text
// should wrap at. False when it does not fit this frame (then skip Begin).
bool place_next_window(const char* name, const Overlay& o, float* max_width = nullptr);
// The height of a box of `lines` lines of text (a natural height to ask for:
// last frame's would be the height at last frame's width).
float text_height(int lines);
// Where overlays were placed this frame, and those left out for want of room.
int placed_count();
bool left_out(const char* name);

// The last ImGui item's rectangle, or any rectangle, under `name`.
void item(const char* name);
void region(const char* name, const Box& box);

// The report of the frame just drawn (call after ImGui::Render): the window,
// the UI scale, the image area, image and keep-out, every visible window with
// its role (panel, overlay, dialog, popup, tooltip), and the named rectangles.
// `extra` (a JSON object's members, or empty) is added as it is.
std::string report_json(int window_width, int window_height, float ui_scale, const std::string& extra);

}  // namespace pdflab::ui::layout
