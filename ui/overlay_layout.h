#pragma once
// Where the boxes drawn over the image go (badges, the view's legend, the
// split's figures, the pixel inspector, the convergence plot, notices): each
// in a corner of the image area, in the first free stretch of its column from
// that corner (past the boxes already there), never over another box or the
// middle of the image, made narrower or shorter to fit, and left out when even
// its smallest size does not. Plain data, so the rules are tested without a window; ui/overlay_slots
// applies them to ImGui windows.
#include <optional>
#include <vector>

namespace pdflab::ui {

// A rectangle in ImGui coordinates (origin top left).
struct Box {
  float x = 0.0f, y = 0.0f, w = 0.0f, h = 0.0f;
  float right() const { return x + w; }
  float bottom() const { return y + h; }
  bool empty() const { return !(w > 0.0f) || !(h > 0.0f); }
  // Their insides meet (touching edges do not count).
  bool overlaps(const Box& o) const;
  bool contains(const Box& o) const;
};
Box intersection(const Box& a, const Box& b);

enum class Corner { TopLeft, TopRight, BottomLeft, BottomRight };

// The middle of the image that no box covers: the central `fraction` of the
// part of the image inside the area, each way.
inline constexpr float kKeepOutFraction = 0.25f;
Box centre_keep_out(const Box& image, const Box& area, float fraction = kKeepOutFraction);

// What a box asks for: its natural size, the smallest it may be made, and
// whether, to fit, it would rather be narrower (text that wraps, and so grows
// taller) than shorter (a plot).
struct BoxRequest {
  Corner corner = Corner::TopLeft;
  float width = 0.0f, height = 0.0f;
  float min_width = 0.0f, min_height = 0.0f;
  bool prefer_narrow = true;
};

class OverlayPlanner {
 public:
  // `margin` from the area's edges, `gap` between boxes and around the keep-out.
  OverlayPlanner(const Box& area, const Box& keep_out, float margin, float gap);
  // The box's place, or nothing when it does not fit at all.
  std::optional<Box> place(const BoxRequest& request);
  const std::vector<Box>& placed() const { return placed_; }
  const Box& keep_out() const { return keep_out_; }
  // The widest a box in `corner` may be beside the keep-out.
  float column_width(Corner corner) const;

 private:
  std::optional<Box> try_size(Corner corner, float width, float height, float min_height) const;
  Box area_, keep_out_;
  float margin_, gap_;
  std::vector<Box> placed_;
};

}  // namespace pdflab::ui
