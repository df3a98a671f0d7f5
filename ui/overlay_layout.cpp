#include "ui/overlay_layout.h"

#include <algorithm>
#include <cmath>

namespace pdflab::ui {

bool Box::overlaps(const Box& o) const {
  if (empty() || o.empty()) return false;
  return x < o.right() && o.x < right() && y < o.bottom() && o.y < bottom();
}

bool Box::contains(const Box& o) const {
  return o.x >= x && o.y >= y && o.right() <= right() && o.bottom() <= bottom();
}

Box intersection(const Box& a, const Box& b) {
  const float x0 = std::max(a.x, b.x), y0 = std::max(a.y, b.y);
  const float x1 = std::min(a.right(), b.right()), y1 = std::min(a.bottom(), b.bottom());
  if (!(x1 > x0) || !(y1 > y0)) return {x0, y0, 0.0f, 0.0f};
  return {x0, y0, x1 - x0, y1 - y0};
}

Box centre_keep_out(const Box& image, const Box& area, float fraction) {
  // A zoomed image reaches past the area: the middle of what is seen.
  const Box seen = intersection(image, area);
  const Box& of = seen.empty() ? area : seen;
  const float w = of.w * fraction, h = of.h * fraction;
  return {of.x + (of.w - w) * 0.5f, of.y + (of.h - h) * 0.5f, w, h};
}

OverlayPlanner::OverlayPlanner(const Box& area, const Box& keep_out, float margin, float gap)
    : area_(area), keep_out_(keep_out), margin_(margin), gap_(gap) {}

float OverlayPlanner::column_width(Corner corner) const {
  const bool left = corner == Corner::TopLeft || corner == Corner::BottomLeft;
  const float w = left ? keep_out_.x - gap_ - (area_.x + margin_) : area_.right() - margin_ - (keep_out_.right() + gap_);
  return std::max(0.0f, w);
}

std::optional<Box> OverlayPlanner::try_size(Corner corner, float width, float height, float min_height) const {
  const bool left = corner == Corner::TopLeft || corner == Corner::BottomLeft;
  const bool top = corner == Corner::TopLeft || corner == Corner::TopRight;
  const float inner_w = area_.w - 2.0f * margin_;
  const float lo = area_.y + margin_, hi = area_.bottom() - margin_;
  if (!(inner_w > 0.0f) || !(hi > lo)) return std::nullopt;
  Box b;
  b.w = std::min(width, inner_w);
  if (!(b.w > 0.0f) || !(height > 0.0f)) return std::nullopt;
  b.x = left ? area_.x + margin_ : area_.right() - margin_ - b.w;
  // What it must keep clear of in its columns: the boxes placed before and
  // the image's middle, each with the gap around it.
  struct Span {
    float top, bottom;
    bool middle;  // the image's middle: a box never goes past it, away from its corner
  };
  std::vector<Span> blocked;
  const auto block = [&](const Box& o, bool middle) {
    const Box g{o.x - gap_, o.y - gap_, o.w + 2.0f * gap_, o.h + 2.0f * gap_};
    if (b.x < g.right() && g.x < b.right()) blocked.push_back({g.y, g.bottom(), middle});
  };
  for (const Box& p : placed_) block(p, false);
  block(keep_out_, true);
  // The free stretches of the column, nearest the corner first: the box goes
  // into the first one at least min_height long, as tall as it wants or as
  // that stretch allows.
  const auto take = [&](float start, float end) -> std::optional<Box> {
    const float room = end - start;
    if (room < min_height || !(room > 0.0f)) return std::nullopt;
    Box placed = b;
    placed.h = std::min(height, room);
    placed.y = top ? start : end - placed.h;
    return placed;
  };
  if (top) {
    std::sort(blocked.begin(), blocked.end(), [](const Span& a, const Span& c) { return a.top < c.top; });
    float cursor = lo;
    for (const Span& s : blocked) {
      if (s.top > cursor)
        if (const auto found = take(cursor, std::min(s.top, hi))) return found;
      if (s.middle) return std::nullopt;
      cursor = std::max(cursor, s.bottom);
      if (cursor >= hi) return std::nullopt;
    }
    return take(cursor, hi);
  }
  std::sort(blocked.begin(), blocked.end(), [](const Span& a, const Span& c) { return a.bottom > c.bottom; });
  float cursor = hi;
  for (const Span& s : blocked) {
    if (s.bottom < cursor)
      if (const auto found = take(std::max(s.bottom, lo), cursor)) return found;
    if (s.middle) return std::nullopt;
    cursor = std::min(cursor, s.top);
    if (cursor <= lo) return std::nullopt;
  }
  return take(lo, cursor);
}

std::optional<Box> OverlayPlanner::place(const BoxRequest& r) {
  const float width = std::max(r.width, r.min_width);
  const float height = std::max(r.height, r.min_height);
  const float column = std::max(r.min_width, std::min(width, column_width(r.corner)));
  struct Try {
    float w, min_h;
  };
  // Text would rather wrap in a narrower box than lose lines; a plot would
  // rather be shorter than narrower.
  const Try text[] = {{width, height}, {column, height}, {width, r.min_height}, {column, r.min_height}};
  const Try plot[] = {{width, height}, {width, r.min_height}, {column, height}, {column, r.min_height}};
  for (const Try& t : r.prefer_narrow ? text : plot) {
    if (t.w < r.min_width) continue;
    // Text made narrower wraps: each line may take as many lines as the width shrank.
    const float h = r.prefer_narrow && t.w < width ? height * std::ceil(width / t.w) : height;
    const float min_h = t.min_h >= height ? h : std::min(t.min_h, h);
    if (const auto b = try_size(r.corner, t.w, h, min_h)) {
      placed_.push_back(*b);
      return b;
    }
  }
  return std::nullopt;
}

}  // namespace pdflab::ui
