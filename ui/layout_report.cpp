#include "ui/layout_report.h"

#include <imgui.h>
#include <imgui_internal.h>  // the window list, for the report and last frame's sizes
#include <nlohmann/json.hpp>

#include <algorithm>
#include <string>
#include <utility>
#include <vector>

namespace pdflab::ui::layout {

namespace {

// One frame's state. The UI thread alone draws, so a file-level frame is all there is.
struct Frame {
  Box area, image, keep;
  float font = 13.0f;
  std::optional<OverlayPlanner> planner;
  std::vector<std::string> overlays, left_out;
  std::vector<std::pair<std::string, Box>> items;
};
Frame frame;

nlohmann::json box_json(const Box& b) { return {{"x", b.x}, {"y", b.y}, {"w", b.w}, {"h", b.h}}; }

}  // namespace

void begin_frame(const Box& area_box, const Box& image_box, float font_size) {
  frame.area = area_box;
  frame.image = image_box;
  frame.font = font_size;
  frame.keep = centre_keep_out(image_box, area_box);
  frame.planner.emplace(area_box, frame.keep, 0.6f * font_size, 0.4f * font_size);
  frame.overlays.clear();
  frame.left_out.clear();
  frame.items.clear();
}

const Box& area() { return frame.area; }
const Box& keep_out() { return frame.keep; }

bool place_next_window(const char* name, const Overlay& o, float* max_width) {
  if (!frame.planner) return false;
  const ImGuiStyle& style = ImGui::GetStyle();
  // Last frame's content at last frame's width: its height at about this one's.
  float height = o.height;
  if (!(height > 0.0f)) {
    const ImGuiWindow* w = ImGui::FindWindowByName(name);
    height = w && w->WasActive ? w->ContentSize.y + 2.0f * style.WindowPadding.y : frame.font * 2.0f;
  }
  BoxRequest r;
  r.corner = o.corner;
  r.width = o.max_width > 0.0f ? std::min(o.width, o.max_width) : o.width;
  r.height = height;
  r.min_width = o.min_width * frame.font;
  r.min_height = std::min(height, o.min_lines * ImGui::GetTextLineHeightWithSpacing() + 2.0f * style.WindowPadding.y);
  r.prefer_narrow = o.prefer_narrow;
  const std::optional<Box> b = frame.planner->place(r);
  if (!b) {
    frame.left_out.emplace_back(name);
    return false;
  }
  frame.overlays.emplace_back(name);
  const bool left = o.corner == Corner::TopLeft || o.corner == Corner::BottomLeft;
  const bool top = o.corner == Corner::TopLeft || o.corner == Corner::TopRight;
  // Anchored at its corner, so a box that settles smaller than planned stays in its place.
  ImGui::SetNextWindowPos(ImVec2(left ? b->x : b->right(), top ? b->y : b->bottom()), ImGuiCond_Always,
                          ImVec2(left ? 0.0f : 1.0f, top ? 0.0f : 1.0f));
  ImGui::SetNextWindowSizeConstraints(ImVec2(0.0f, 0.0f), ImVec2(b->w, b->h));
  if (max_width) *max_width = std::max(1.0f, b->w - 2.0f * style.WindowPadding.x);
  return true;
}

float text_height(int lines) {
  return static_cast<float>(lines) * ImGui::GetTextLineHeightWithSpacing() + 2.0f * ImGui::GetStyle().WindowPadding.y;
}

int placed_count() { return static_cast<int>(frame.overlays.size()); }

bool left_out(const char* name) {
  return std::find(frame.left_out.begin(), frame.left_out.end(), name) != frame.left_out.end();
}

void item(const char* name) {
  const ImVec2 a = ImGui::GetItemRectMin(), b = ImGui::GetItemRectMax();
  region(name, {a.x, a.y, b.x - a.x, b.y - a.y});
}

void region(const char* name, const Box& box) {
  for (auto& [n, b] : frame.items)
    if (n == name) {
      b = box;
      return;
    }
  frame.items.emplace_back(name, box);
}

std::string report_json(int window_width, int window_height, float ui_scale, const std::string& extra) {
  nlohmann::json j;
  j["window"] = {{"width", window_width}, {"height", window_height}};
  j["ui_scale"] = ui_scale;
  j["font_size"] = frame.font;
  j["image_area"] = box_json(frame.area);
  j["image"] = box_json(frame.image);
  j["keep_out"] = box_json(frame.keep);
  nlohmann::json windows = nlohmann::json::array();
  const ImGuiContext& g = *GImGui;
  for (const ImGuiWindow* w : g.Windows) {
    if (!w->Active || w->Hidden || (w->Flags & ImGuiWindowFlags_ChildWindow)) continue;
    const std::string name = w->Name;
    std::string role = "dialog";
    if (std::find(frame.overlays.begin(), frame.overlays.end(), name) != frame.overlays.end()) role = "overlay";
    else if (name.rfind("##panel", 0) == 0 || name == "pdflab") role = "panel";
    else if (w->Flags & ImGuiWindowFlags_Tooltip) role = "tooltip";
    else if (w->Flags & ImGuiWindowFlags_Popup) role = "popup";
    nlohmann::json entry = box_json({w->Pos.x, w->Pos.y, w->Size.x, w->Size.y});
    entry["name"] = name;
    entry["role"] = role;
    windows.push_back(entry);
  }
  j["windows"] = windows;
  j["left_out"] = frame.left_out;
  nlohmann::json items = nlohmann::json::object();
  for (const auto& [name, b] : frame.items) items[name] = box_json(b);
  j["items"] = items;
  if (!extra.empty()) {
    const nlohmann::json more = nlohmann::json::parse(extra, nullptr, false);
    if (more.is_object())
      for (auto it = more.begin(); it != more.end(); ++it) j[it.key()] = it.value();
  }
  return j.dump(1) + "\n";
}

}  // namespace pdflab::ui::layout
