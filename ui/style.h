#pragma once
// The text colours every panel uses for status: errors, success, warnings, secondary text.
#include <imgui.h>

namespace pdflab::ui {

inline const ImVec4 kRed{1.0f, 0.42f, 0.38f, 1.0f};
inline const ImVec4 kGreen{0.45f, 0.85f, 0.45f, 1.0f};
inline const ImVec4 kAmber{1.0f, 0.78f, 0.3f, 1.0f};
inline const ImVec4 kDim{0.65f, 0.65f, 0.68f, 1.0f};

}  // namespace pdflab::ui
