#include "renderer/scene/bvh.h"

#include "renderer/scene/scene.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <utility>

namespace pdflab {

namespace {

// The widening of an object's box against the scene's extent: 2^-14 is 2^10
// float steps. The float tests' error in where they find a hit is a few steps
// of the coordinates involved (origin, distance, the object's corner, at most
// about 12 `scale` together), times the quad's skew: a margin of 2^10 steps
// leaves a factor above ten to spare.
constexpr float kMarginPerScale = 0x1.0p-14f;

struct Box {
  Vec3 lo{kInf}, hi{-kInf};
  void grow(const Vec3& p) {
    lo = Vec3(min_of(lo.x, p.x), min_of(lo.y, p.y), min_of(lo.z, p.z));
    hi = Vec3(max_of(hi.x, p.x), max_of(hi.y, p.y), max_of(hi.z, p.z));
  }
  void grow(const Box& b) {
    grow(b.lo);
    grow(b.hi);
  }
  // Half the surface area (the heuristic needs only ratios); 0 when empty.
  double half_area() const {
    if (!(lo.x <= hi.x)) return 0.0;
    const double x = static_cast<double>(hi.x) - lo.x, y = static_cast<double>(hi.y) - lo.y,
                 z = static_cast<double>(hi.z) - lo.z;
    return x * y + y * z + z * x;
  }
};

// A node of the binary tree the build makes first (then made wide).
struct BvhNode {
  Box box;  // of the objects' widened boxes
  // A leaf: its one object is `index`. Interior: its children are the next
  // node and node `index`.
  std::int32_t index = 0;
  bool leaf = false;
};

struct Item {
  Box box;      // widened
  Vec3 centre;  // of the object's own box
  std::int32_t object;
};

constexpr int kBins = 16;
// Below this depth the heuristic chooses the splits; from it on the objects
// are halved by count, so no tree is deeper than Bvh::kMaxDepth for up to
// 2^(kMaxDepth - kHeuristicDepth - 1) objects (a leaf is one): 2^31, more
// than a scene can number.
constexpr int kHeuristicDepth = 32;
static_assert((std::int64_t{1} << (Bvh::kMaxDepth - kHeuristicDepth - 1)) >= INT32_MAX);

class Builder {
 public:
  Builder(std::vector<Item>& items, std::vector<BvhNode>& nodes) : items_(items), nodes_(nodes) {}

  std::int32_t build(int begin, int end, int depth) {
    const auto at = static_cast<std::int32_t>(nodes_.size());
    nodes_.emplace_back();
    Box box, centres;
    for (int i = begin; i < end; ++i) {
      box.grow(items_[static_cast<std::size_t>(i)].box);
      centres.grow(items_[static_cast<std::size_t>(i)].centre);
    }
    const int n = end - begin;
    int middle = -1;
    if (n > 1) choose_split(begin, end, depth, centres, middle);
    if (middle < 0) {
      BvhNode& leaf = nodes_[static_cast<std::size_t>(at)];
      leaf.box = box;
      leaf.index = items_[static_cast<std::size_t>(begin)].object;
      leaf.leaf = true;
      return at;
    }
    build(begin, middle, depth + 1);  // the next node
    const std::int32_t second = build(middle, end, depth + 1);
    BvhNode& node = nodes_[static_cast<std::size_t>(at)];
    node.box = box;
    node.index = second;
    return at;
  }

 private:
  // In double, and clamped before it becomes an int: centres near float's
  // largest values would overflow float's differences (and a NaN or an
  // infinity turned into an int is undefined).
  static int bin_of(float centre, float lo, double extent) {
    const double x = kBins * ((static_cast<double>(centre) - lo) / extent);
    return x >= kBins - 1 ? kBins - 1 : x > 0.0 ? static_cast<int>(x) : 0;
  }
  static double spread(const Box& centres, int axis) {
    return static_cast<double>(centres.hi[axis]) - centres.lo[axis];
  }

  // Where to split [begin, end), two objects or more (`middle`, the items reordered).
  void choose_split(int begin, int end, int depth, const Box& centres, int& middle) {
    const int n = end - begin;
    double best_cost = kInf;
    int best_axis = -1, best_split = 0;
    if (depth < kHeuristicDepth) {
      for (int a = 0; a < 3; ++a) {
        const double extent = spread(centres, a);
        if (!(extent > 0.0)) continue;
        Box bins[kBins];
        int counts[kBins] = {};
        for (int i = begin; i < end; ++i) {
          const Item& item = items_[static_cast<std::size_t>(i)];
          const int b = bin_of(item.centre[a], centres.lo[a], extent);
          bins[b].grow(item.box);
          ++counts[b];
        }
        // Sweeps from the right, then the left: the cost of each of the kBins - 1 planes.
        double right_area[kBins];
        int right_count[kBins];
        Box right;
        int count = 0;
        for (int b = kBins - 1; b > 0; --b) {
          right.grow(bins[b]);
          count += counts[b];
          right_area[b] = right.half_area();
          right_count[b] = count;
        }
        Box left;
        count = 0;
        for (int b = 0; b + 1 < kBins; ++b) {
          left.grow(bins[b]);
          count += counts[b];
          if (count == 0 || right_count[b + 1] == 0) continue;
          const double cost = left.half_area() * count + right_area[b + 1] * right_count[b + 1];
          if (cost < best_cost) best_cost = cost, best_axis = a, best_split = b + 1;
        }
      }
    }
    if (best_axis < 0) {
      // The centres coincide, or the tree is deep: halves by count, along the widest spread of centres.
      int axis = 0;
      for (int a = 1; a < 3; ++a)
        if (spread(centres, a) > spread(centres, axis)) axis = a;
      middle = begin + n / 2;
      const auto first = items_.begin() + begin;
      std::nth_element(first, items_.begin() + middle, items_.begin() + end, [&](const Item& x, const Item& y) {
        return x.centre[axis] < y.centre[axis] || (x.centre[axis] == y.centre[axis] && x.object < y.object);
      });
      return;
    }
    const int axis = best_axis;
    const float lo = centres.lo[axis];
    const double extent = spread(centres, axis);
    const auto split = std::partition(items_.begin() + begin, items_.begin() + end,
                                      [&](const Item& item) { return bin_of(item.centre[axis], lo, extent) < best_split; });
    middle = static_cast<int>(split - items_.begin());
  }

  std::vector<Item>& items_;
  std::vector<BvhNode>& nodes_;
};

// Moves the objects whose boxes are at least Bvh::kLargeShare of the scene's
// area (at most Bvh::kMaxLarge of them, the largest, the lower number first
// among equals) from `items` to `large`, by increasing number.
void set_aside_large(std::vector<Item>& items, std::vector<std::int32_t>& large) {
  Box scene;
  for (const Item& item : items) scene.grow(item.box);
  const double least = Bvh::kLargeShare * scene.half_area();
  std::vector<std::pair<double, std::int32_t>> candidates;
  for (const Item& item : items) {
    const double area = item.box.half_area();
    if (area >= least && area > 0.0) candidates.emplace_back(-area, item.object);
  }
  if (candidates.size() > static_cast<std::size_t>(Bvh::kMaxLarge)) {
    std::nth_element(candidates.begin(), candidates.begin() + Bvh::kMaxLarge, candidates.end());
    candidates.resize(Bvh::kMaxLarge);
  }
  for (const auto& c : candidates) large.push_back(c.second);
  std::sort(large.begin(), large.end());
  items.erase(std::remove_if(items.begin(), items.end(),
                             [&](const Item& item) { return std::binary_search(large.begin(), large.end(), item.object); }),
              items.end());
}

// The wide node for the binary node `at` (and, below it, those for its
// descendants): its children are the binary node's, each interior one of
// largest area opened into its own two while there are fewer than sixteen.
// Returns its index in bvh.wide.
std::int32_t widen(Bvh& bvh, const std::vector<BvhNode>& nodes, std::int32_t at) {
  const auto index = static_cast<std::int32_t>(bvh.wide.size());
  bvh.wide.emplace_back();
  std::int32_t kids[WideBvhNode::kWidth];
  int n = 0;
  const BvhNode& top = nodes[static_cast<std::size_t>(at)];
  if (top.leaf) {
    kids[n++] = at;  // a tree of one leaf
  } else {
    kids[n++] = at + 1;
    kids[n++] = top.index;
  }
  while (n < WideBvhNode::kWidth) {
    int open = -1;
    for (int k = 0; k < n; ++k) {
      const BvhNode& kid = nodes[static_cast<std::size_t>(kids[k])];
      if (!kid.leaf && (open < 0 || kid.box.half_area() > nodes[static_cast<std::size_t>(kids[open])].box.half_area()))
        open = k;
    }
    if (open < 0) break;
    const BvhNode& opened = nodes[static_cast<std::size_t>(kids[open])];
    kids[n++] = opened.index;
    kids[open] = kids[open] + 1;
  }
  WideBvhNode node;
  for (int a = 0; a < 3; ++a)
    for (int k = 0; k < WideBvhNode::kWidth; ++k) node.lo[a][k] = kInf, node.hi[a][k] = -kInf;
  for (int k = 0; k < WideBvhNode::kWidth; ++k) node.child[k] = WideBvhNode::leaf(0);
  for (int k = 0; k < n; ++k) {
    const BvhNode kid = nodes[static_cast<std::size_t>(kids[k])];
    for (int a = 0; a < 3; ++a) node.lo[a][k] = kid.box.lo[a], node.hi[a][k] = kid.box.hi[a];
    node.valid = static_cast<std::uint16_t>(node.valid | (1u << k));
    if (!kid.leaf) node.inner = static_cast<std::uint16_t>(node.inner | (1u << k));
    node.child[k] = kid.leaf ? WideBvhNode::leaf(kid.index) : widen(bvh, nodes, kids[k]);
  }
  bvh.wide[static_cast<std::size_t>(index)] = node;
  return index;
}

}  // namespace

float object_margin(const Quad& quad, float scale) {
  const float skew = length(quad.u) * length(quad.alpha_axis) + length(quad.v) * length(quad.beta_axis);
  const float size = max_abs_component(quad.q) + max_abs_component(quad.u) + max_abs_component(quad.v);
  return kMarginPerScale * max_of(scale, size) * (1.0f + skew);
}

float object_margin(const Sphere& sphere, float scale) {
  return kMarginPerScale * max_of(scale, max_abs_component(sphere.center) + sphere.radius);
}

Bvh Bvh::build(const std::vector<Quad>& quads, const std::vector<Sphere>& spheres, float scale) {
  Bvh bvh;
  bvh.quads = static_cast<int>(quads.size());
  bvh.spheres = static_cast<int>(spheres.size());
  std::vector<Item> items;
  items.reserve(quads.size() + spheres.size());
  for (const Quad& q : quads) {
    Box own;
    for (const Vec3& corner : {q.q, q.q + q.u, q.q + q.v, q.q + q.u + q.v}) own.grow(corner);
    const Vec3 m(object_margin(q, scale));
    items.push_back({{own.lo - m, own.hi + m}, own.lo * 0.5f + own.hi * 0.5f, static_cast<std::int32_t>(items.size())});
  }
  for (const Sphere& s : spheres) {
    const Vec3 reach(s.radius + object_margin(s, scale));
    items.push_back({{s.center - reach, s.center + reach}, s.center, static_cast<std::int32_t>(items.size())});
  }
  set_aside_large(items, bvh.large);
  if (items.empty()) return bvh;
  std::vector<BvhNode> nodes;
  nodes.reserve(2 * items.size());
  Builder(items, nodes).build(0, static_cast<int>(items.size()), 0);
  bvh.wide.reserve(nodes.size() / 4 + 1);
  widen(bvh, nodes, 0);
  return bvh;
}

}  // namespace pdflab
