#pragma once
// The ImGui panels. They read UiStatus, edit ViewerSettings and PanelState, and
// say what else they want in UiRequests; the viewer does the rest.
#include "ui/settings.h"

#include <imgui.h>

namespace pdflab::ui {

// Background of the side panel as RGB: the panel draws none, the viewer
// clears the panel's rectangle to it.
inline constexpr float kPanelBackground[3] = {0.11f, 0.11f, 0.125f};

// The side panel, `width` wide at the right edge of a display `display_height` high
// (ImGui coordinates).
void draw_side_panel(float width, float display_height, ViewerSettings& settings, PanelState& state,
                     const UiStatus& status, UiRequests& requests);

// Keys and what they do, centred over the image area.
void draw_help_overlay(PanelState& state, float area_width, float area_height);

// A short line over the image (preview, paused, biased), top-left of the image
// area. Returns the bottom-right corner of what it drew (0, 0 when nothing), so
// the view legend can keep clear of it.
ImVec2 draw_image_badges(const ViewerSettings& settings, const UiStatus& status);

// A short line at the top centre of the display (a mode just entered).
void draw_hint(const char* text);
// The last screenshot notice over the image area's bottom, where it is seen
// (the Screenshot section may be below the fold).
void draw_notice_toast(const Notice& notice, float area_width, float area_height);

// The question before quitting with an unsaved render, over everything (the
// rest of the window takes no input meanwhile).
enum class QuitChoice { None, SaveAndQuit, Quit, Cancel };
QuitChoice draw_quit_dialog(double unsaved_seconds, bool saving, const Notice& notice);

}  // namespace pdflab::ui
