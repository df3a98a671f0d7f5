#pragma once
// The measuring UI: the Measure section of the side panel, the view-mode
// selector, the colour bar and drop legend over the image, the convergence
// plot, and the note on next-event estimation. ImGui only; the numbers come
// from ui/measure.h.
#include "ui/settings.h"

#include <cstdint>

#include <imgui.h>

namespace pdflab::ui {

// Where the image is drawn, in ImGui coordinates (top-left origin).
struct ImageRect {
  float x = 0.0f, y = 0.0f, width = 0.0f, height = 0.0f;
};

void draw_measure_section(ViewerSettings& settings, const UiStatus& status, UiRequests& requests);
void draw_view_mode_selector(ViewerSettings& settings);
// The heat map's and difference view's metric and range (nothing for the other views).
void draw_layer_controls(ViewerSettings& settings, const MeasureState* measure);
// "How is this different?": nee-mis against the book's one-sample mixture.
void draw_nee_explanation();
// The false-colour layer (texture: ViewTexture::id, 0 for none), its legend,
// and the convergence plot, over the image area. badges: the bottom-right
// corner of the image badges (draw_image_badges), which the legend moves below
// when the area is too narrow for both side by side.
void draw_image_overlays(const ImageRect& image, const ImageRect& area, ViewerSettings& settings,
                         const MeasureState& measure, std::uint32_t texture, UiRequests& requests,
                         ImVec2 badges = ImVec2(0.0f, 0.0f));

}  // namespace pdflab::ui
