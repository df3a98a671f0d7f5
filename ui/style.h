#pragma once
// The text colours every panel uses for status: errors, success, warnings, secondary text.
#include <imgui.h>

#include <array>
#include <initializer_list>

namespace pdflab::ui {

inline const ImVec4 kRed{1.0f, 0.42f, 0.38f, 1.0f};
inline const ImVec4 kGreen{0.45f, 0.85f, 0.45f, 1.0f};
inline const ImVec4 kAmber{1.0f, 0.78f, 0.3f, 1.0f};
inline const ImVec4 kDim{0.65f, 0.65f, 0.68f, 1.0f};

// A display colour (colour_scale.h's Colour, RGB in 0..1) as ImGui's packed colour.
inline ImU32 to_u32(const std::array<float, 3>& c, float alpha = 1.0f) {
  return ImGui::ColorConvertFloat4ToU32(ImVec4(c[0], c[1], c[2], alpha));
}

// A table's columns as fixed shares of its width. Stretch columns left to
// size themselves (ImGuiTableFlags_SizingStretchProp alone) take their shares
// from what the cells held when the table last appeared: after a restart the
// figures read "0" for a frame, and the next frame's "0.43743" was clipped at
// the panel's right edge until the table refitted.
inline void share_columns(std::initializer_list<float> shares) {
  for (float share : shares) ImGui::TableSetupColumn(nullptr, ImGuiTableColumnFlags_WidthStretch, share);
}

}  // namespace pdflab::ui
