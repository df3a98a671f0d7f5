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
// "How is this different?": nee-mis (with the continuation `s` has: cosine
// alone, or fastest's mixture) against the book's one-sample mixture.
// `choice`: how the light sample's emitter is chosen (the strategy's, else the scene's).
void draw_nee_explanation(const SamplingSettings& s, LightChoice choice);
// The false-colour layer (texture: ViewTexture::id, 0 for none) over the
// image, its legend and the convergence plot, placed by ui/layout_report.
void draw_image_overlays(const ImageRect& image, ViewerSettings& settings, const MeasureState& measure,
                         std::uint32_t texture, UiRequests& requests);

}  // namespace pdflab::ui
