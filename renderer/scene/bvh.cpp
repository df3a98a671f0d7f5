#include "renderer/scene/bvh.h"

#include "renderer/scene/scene.h"

#include <algorithm>
#include <array>
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

// Makes the binary tree wide: which binary nodes become wide nodes, and which
// of their descendants become their children, chosen to minimise the
// surface-area cost of the walk, a ray's expected work (the collapse of
// Ylitie, Karras and Laine, 2017): a wide node costs kVisitCost times its
// area, a leaf kLeafCost times its own. For each binary node and each number
// of slots s (1 to 16), the least cost of its subtree as at most s children
// of the wide node above: as one child (a leaf, or a wide node whose sixteen
// slots go to its two subtrees), or, from two slots on, its two subtrees
// sharing the s slots. The greedy alternative, opening the child of largest
// area until there are sixteen, makes every interior child it stops at a node
// of its own, however few objects are below it: on the generated room of
// 10005 objects it made 3761 nodes (1.9 MB, beyond the second-level cache)
// where this makes 1363, and took 1.24x the time a sample under nee-mis
// (bench_objects); on the many-lights room the two walk as fast.
class Collapse {
 public:
  // The cost of visiting a wide node (its sixteen box tests, the stack) and
  // of testing a leaf's object (on every lane of the packet), per unit of
  // area: about the same; a third or three times as much changed nothing
  // measurable on the many-lights room.
  static constexpr double kVisitCost = 1.0;
  static constexpr double kLeafCost = 1.0;
  static constexpr int kSlots = WideBvhNode::kWidth;

  explicit Collapse(const std::vector<BvhNode>& nodes) : nodes_(nodes), cost_(nodes.size()), split_(nodes.size()) {
    // A node's children come after it: from the last, each node's children are done before it.
    for (std::size_t at = nodes.size(); at-- > 0;) {
      const BvhNode& node = nodes[at];
      const double area = node.box.half_area();
      std::array<double, kSlots + 1>& cost = cost_[at];
      std::array<std::int8_t, kSlots + 1>& split = split_[at];
      if (node.leaf) {
        cost.fill(kLeafCost * area);
        split.fill(0);
        continue;
      }
      const auto& left = cost_[at + 1];
      const auto& right = cost_[static_cast<std::size_t>(node.index)];
      // shared[s]: the least cost of the two subtrees in s slots, and its left share.
      std::array<double, kSlots + 1> shared{};
      std::array<std::int8_t, kSlots + 1> share{};
      // Each share starts at one slot to the left, so that a cost that is
      // not finite (a box of infinite area: a sliver whose margin is larger
      // than float) still leaves every slot count a valid share.
      for (int s = 2; s <= kSlots; ++s) {
        shared[s] = left[1] + right[s - 1];
        share[s] = 1;
        for (int k = 2; k < s; ++k) {
          const double c = left[k] + right[s - k];
          if (c < shared[s]) shared[s] = c, share[s] = static_cast<std::int8_t>(k);
        }
      }
      cost[1] = kVisitCost * area + shared[kSlots];
      split[1] = 0;
      for (int s = 2; s <= kSlots; ++s) {
        const bool open = shared[s] < cost[1];
        cost[s] = open ? shared[s] : cost[1];
        split[s] = open ? share[s] : 0;
      }
      split[0] = share[kSlots];  // the left share of a wide node's sixteen slots
    }
  }

  // The wide node for the binary node `at` (and below it, those for its
  // descendants). Returns its index in bvh.wide.
  std::int32_t make(Bvh& bvh, std::int32_t at) const {
    const auto index = static_cast<std::int32_t>(bvh.wide.size());
    bvh.wide.emplace_back();
    std::vector<std::int32_t> kids;
    const BvhNode& top = nodes_[static_cast<std::size_t>(at)];
    if (top.leaf) {
      kids.push_back(at);  // a tree of one leaf
    } else {
      const int k = split_[static_cast<std::size_t>(at)][0];
      gather(at + 1, k, kids);
      gather(top.index, kSlots - k, kids);
    }
    assert(kids.size() <= static_cast<std::size_t>(WideBvhNode::kWidth));
    WideBvhNode node;
    for (int a = 0; a < 3; ++a)
      for (int k = 0; k < WideBvhNode::kWidth; ++k) node.lo[a][k] = kInf, node.hi[a][k] = -kInf;
    for (int k = 0; k < WideBvhNode::kWidth; ++k) node.child[k] = WideBvhNode::leaf(0);
    for (std::size_t k = 0; k < kids.size(); ++k) {
      const BvhNode kid = nodes_[static_cast<std::size_t>(kids[k])];
      for (int a = 0; a < 3; ++a) node.lo[a][k] = kid.box.lo[a], node.hi[a][k] = kid.box.hi[a];
      node.valid = static_cast<std::uint16_t>(node.valid | (1u << k));
      node.child[k] = kid.leaf ? WideBvhNode::leaf(kid.index) : make(bvh, kids[k]);
      if (!kid.leaf) node.inner = static_cast<std::uint16_t>(node.inner | (1u << k));
    }
    bvh.wide[static_cast<std::size_t>(index)] = node;
    return index;
  }

 private:
  // The children that the subtree of `at` becomes in `slots` slots.
  void gather(std::int32_t at, int slots, std::vector<std::int32_t>& kids) const {
    const int k = slots > 1 ? split_[static_cast<std::size_t>(at)][slots] : 0;
    if (k == 0) {
      kids.push_back(at);
      return;
    }
    gather(at + 1, k, kids);
    gather(nodes_[static_cast<std::size_t>(at)].index, slots - k, kids);
  }

  const std::vector<BvhNode>& nodes_;
  std::vector<std::array<double, kSlots + 1>> cost_;   // [s]: the least cost in s slots
  std::vector<std::array<std::int8_t, kSlots + 1>> split_;  // [s]: the left share where opened, 0: one child
};

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
  // The number of wide nodes is known only once made (0.14 to 0.18 an object
  // on the generated rooms): the vector is sized to them after, not before.
  Collapse(nodes).make(bvh, 0);
  bvh.wide.shrink_to_fit();
  return bvh;
}

}  // namespace pdflab
