#include "renderer/sampling/light_tree.h"

#include "renderer/sampling/leaf.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

namespace pdflab {

namespace {

// A cone of directions: its axis and the cosine of its half-angle (-1: every direction).
struct Cone {
  Vec3 axis;
  float cos_spread;
};

// The smallest cone (of the usual construction) that holds both.
Cone merge(const Cone& a, const Cone& b) {
  if (a.cos_spread <= -1.0f || b.cos_spread <= -1.0f) return {a.axis, -1.0f};
  const double ta = std::acos(std::clamp(static_cast<double>(a.cos_spread), -1.0, 1.0));
  const double tb = std::acos(std::clamp(static_cast<double>(b.cos_spread), -1.0, 1.0));
  const Cone& wide = ta >= tb ? a : b;
  const Cone& narrow = ta >= tb ? b : a;
  const double tw = std::max(ta, tb), tn = std::min(ta, tb);
  const double between = std::acos(std::clamp(static_cast<double>(glm::dot(wide.axis, narrow.axis)), -1.0, 1.0));
  if (between + tn <= tw) return wide;
  const double half = 0.5 * (tw + between + tn);
  if (half >= std::numbers::pi) return {wide.axis, -1.0f};
  // The axis turned from the wide cone's towards the narrow one's by half - tw.
  const double turn = half - tw;
  const Vec3 ortho = narrow.axis - wide.axis * glm::dot(wide.axis, narrow.axis);
  const float length = glm::length(ortho);
  if (!(length > 1e-7f)) return {wide.axis, static_cast<float>(std::cos(half))};
  const Vec3 axis = glm::normalize(wide.axis * static_cast<float>(std::cos(turn)) +
                                   ortho * (static_cast<float>(std::sin(turn)) / length));
  // A little wider than computed, for the float axis.
  return {axis, static_cast<float>(std::cos(std::min(half + 1e-5, std::numbers::pi)))};
}

}  // namespace

LightTree::LightTree(const std::vector<Emitter>& emitters, float floor_share) : count_(static_cast<int>(emitters.size())) {
  if (emitters.empty()) return;
  floor_count_ = static_cast<std::uint32_t>(static_cast<double>(floor_share) * kChoiceRange / count_);
  // Median splits from this depth on take at most ceil(log2 n) levels more.
  median_from_ = 64 - static_cast<int>(std::ceil(std::log2(static_cast<double>(count_))));
  path_.assign(emitters.size(), 0);
  path_length_.assign(emitters.size(), 0);
  std::vector<int> order(emitters.size());
  std::iota(order.begin(), order.end(), 0);
  nodes_.reserve(2 * emitters.size());
  nodes_.emplace_back();
  bounds_.emplace_back();
  build(0, order, 0, count_, emitters, 0, 0);
  bounds_ = {};
  make_pairs();
  nodes_ = {};
}

// The build's node at (2p + 1, 2p + 2), the children of a node, as pair p:
// the root's children are pair 0, and a node whose children are at c, c + 1
// leads to pair (c - 1) / 2.
void LightTree::make_pairs() {
  if (count_ <= 1) return;
  pairs_.resize((nodes_.size() - 1) / 2);
  const auto side = [&](const Node& n) {
    return Side{n.centre, n.radius2, n.radius, n.power, n.child >= 0 ? (n.child - 1) / 2 : -1 - n.light};
  };
  for (std::size_t p = 0; p < pairs_.size(); ++p) {
    const Node& l = nodes_[2 * p + 1];
    const Node& r = nodes_[2 * p + 2];
    Pair& pair = pairs_[p];
    pair.left = side(l);
    pair.right = side(r);
    if (l.cos_spread <= -1.0f && r.cos_spread <= -1.0f) continue;
    pair.cones = static_cast<std::int32_t>(cone_rows_.size());
    ConeRow c;
    c.left_axis = l.axis, c.left_cos_spread = l.cos_spread, c.left_sin_spread = l.sin_spread;
    c.right_axis = r.axis, c.right_cos_spread = r.cos_spread, c.right_sin_spread = r.sin_spread;
    cone_rows_.push_back(c);
  }
}

void LightTree::set_box(int at, const Vec3& lo, const Vec3& hi) {
  bounds_[static_cast<std::size_t>(at)] = {lo, hi};
  Node& n = nodes_[static_cast<std::size_t>(at)];
  n.centre = (lo + hi) * 0.5f;
  const Vec3 half = (hi - lo) * 0.5f;
  n.radius2 = glm::dot(half, half);
  n.radius = std::sqrt(n.radius2);
}

void LightTree::set_cone(Node& n, const Vec3& axis, float cos_spread) {
  n.axis = axis;
  n.cos_spread = cos_spread;
  n.sin_spread = cos_spread <= -1.0f ? 0.0f : std::sqrt(std::max(0.0f, 1.0f - cos_spread * cos_spread));
}

// Node `at` over order[begin, end): a leaf for one emitter, else split along
// the axis where the emitters' centres spread most.
void LightTree::build(int at, std::vector<int>& order, int begin, int end, const std::vector<Emitter>& emitters,
                      std::uint64_t path, int length) {
  if (end - begin == 1) {
    const Emitter& e = emitters[static_cast<std::size_t>(order[static_cast<std::size_t>(begin)])];
    Node& n = nodes_[static_cast<std::size_t>(at)];
    n.power = e.power;
    set_cone(n, e.axis, e.two_sided ? -1.0f : e.cos_spread);
    set_box(at, e.lo, e.hi);
    n.light = order[static_cast<std::size_t>(begin)];
    path_[static_cast<std::size_t>(n.light)] = path;
    path_length_[static_cast<std::size_t>(n.light)] = static_cast<std::uint8_t>(length);
    return;
  }
  Vec3 lo(kInf), hi(-kInf);
  const auto centre = [&](int i) {
    const Emitter& e = emitters[static_cast<std::size_t>(i)];
    return (e.lo + e.hi) * 0.5f;
  };
  for (int k = begin; k < end; ++k) {
    lo = glm::min(lo, centre(order[static_cast<std::size_t>(k)]));
    hi = glm::max(hi, centre(order[static_cast<std::size_t>(k)]));
  }
  const Vec3 extent = hi - lo;
  const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
  // At the middle of the centres' extent, so that nodes stay compact where the
  // emitters cluster (on the many-lights room 12% less relMSE than at their
  // median); at their median where that leaves a side empty, and from depth
  // median_from_ on, so that no path outgrows its 64 bits.
  const float cut = 0.5f * (lo[axis] + hi[axis]);
  int middle = static_cast<int>(std::partition(order.begin() + begin, order.begin() + end,
                                               [&](int i) { return centre(i)[axis] < cut; }) -
                                order.begin());
  if (middle == begin || middle == end || length >= median_from_) {
    middle = begin + (end - begin) / 2;
    std::nth_element(order.begin() + begin, order.begin() + middle, order.begin() + end, [&](int a, int b) {
      return centre(a)[axis] < centre(b)[axis] || (centre(a)[axis] == centre(b)[axis] && a < b);
    });
  }
  const int child = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  nodes_.emplace_back();
  bounds_.emplace_back();
  bounds_.emplace_back();
  build(child, order, begin, middle, emitters, path, length + 1);
  build(child + 1, order, middle, end, emitters, path | (std::uint64_t{1} << length), length + 1);
  const Node& l = nodes_[static_cast<std::size_t>(child)];
  const Node& r = nodes_[static_cast<std::size_t>(child + 1)];
  const Cone cone = merge({l.axis, l.cos_spread}, {r.axis, r.cos_spread});
  const Box& lb = bounds_[static_cast<std::size_t>(child)];
  const Box& rb = bounds_[static_cast<std::size_t>(child + 1)];
  set_box(at, glm::min(lb.lo, rb.lo), glm::max(lb.hi, rb.hi));
  Node& n = nodes_[static_cast<std::size_t>(at)];
  set_cone(n, cone.axis, cone.cos_spread);
  n.power = l.power + r.power;
  n.child = child;
}

// The choice and the probability are leaf::tree_choose and tree_probability,
// the packet tracer's own functions in one lane.
LightTree::Choice LightTree::sample(const Vec3& point, const Vec3& normal, std::uint32_t u) const {
  Choice c{0, 1.0f};
  leaf::tree_choose(*this, point, normal, leaf::has_direction(normal), static_cast<std::int32_t>(u), true, c.light,
                    c.probability);
  return c;
}

float LightTree::probability(const Vec3& point, const Vec3& normal, int light) const {
  return leaf::tree_probability(*this, point, normal, leaf::has_direction(normal), static_cast<std::int32_t>(light),
                                true);
}

std::vector<float> LightTree::probabilities(const Vec3& point, const Vec3& normal) const {
  std::vector<float> out(static_cast<std::size_t>(count_));
  for (int j = 0; j < count_; ++j) out[static_cast<std::size_t>(j)] = probability(point, normal, j);
  return out;
}

int LightTree::depth() const {
  int d = 0;
  for (const std::uint8_t k : path_length_) d = std::max(d, static_cast<int>(k));
  return d;
}

}  // namespace pdflab
