#pragma once
// The ImGui panels. They read UiStatus, edit ViewerSettings and PanelState, and
// say what else they want in UiRequests; the viewer does the rest.
#include "ui/overlay_layout.h"
#include "ui/settings.h"

#include <imgui.h>

namespace pdflab::ui {

// Background of the side panel as RGB: the panel draws none, the viewer
// clears the panel's rectangle to it.
inline constexpr float kPanelBackground[3] = {0.11f, 0.11f, 0.125f};

// The side panel in `box` (ImGui coordinates): a head that never scrolls
// (the render's state, its headline figure, the message line) over the
// sections, whose open ones PanelState keeps.
void draw_side_panel(const Box& box, ViewerSettings& settings, PanelState& state, const UiStatus& status,
                     UiRequests& requests);
// The strip over the panel's left edge that resizes it (settings.panel_width,
// at scale 1); returns the width to draw it at this frame.
float draw_panel_edge(const Box& panel, float scale, float window_width, ViewerSettings& settings);
// While the panel is hidden: the tab that brings it back.
void draw_panel_tab(UiRequests& requests);

// Keys and what they do, centred over the image area.
void draw_help_overlay(PanelState& state, float area_width, float area_height);

// The overlays below are placed by ui/layout_report (layout::begin_frame first).
// A short line over the image (preview, paused, done, biased), top left.
void draw_image_badges(const ViewerSettings& settings, const UiStatus& status);
// A short line at the top left (a mode just entered).
void draw_hint(const char* text);
// The last save or export notice over the image's bottom right, where it is
// seen (the panel's section may be closed).
void draw_notice_toast(const Notice& notice);
// Presentation mode's caption for the class: the strategy, spp and time.
void draw_caption(const ViewerSettings& settings, const UiStatus& status);

// The question before quitting with an unsaved render, a modal popup over
// everything (the rest of the window takes no input meanwhile), while
// `asking`; it closes itself when `asking` turns false.
enum class QuitChoice { None, SaveAndQuit, Quit, Cancel };
QuitChoice draw_quit_dialog(bool asking, double unsaved_seconds, bool saving, const Notice& notice);

}  // namespace pdflab::ui
