#pragma once
// A light tree: nee-mis's choice of an emitter by what a shading point can
// receive from it, in time logarithmic in the number of emitters.
//
// A binary tree over the emitters (one emitter a leaf), each node carrying
// the power of the emitters below it, their bounding box and a cone that
// bounds the directions they emit into (an axis, the spread of the emitters'
// normals about it, and how far beyond those normals they emit: 90 degrees
// for a diffuse emitter). From a point, a node's importance is its power over
// its squared distance, times the cosine of the smallest angle its cone can
// make with the direction to the point, times the cosine of the smallest
// angle between the point's normal and a direction into its box: an upper
// bound in direction of what the point receives from it. Descending from the
// root, a child is chosen in proportion to its importance.
//
// The choice is exact. The top 24 bits of a 32-bit number are an integer u
// in [0, 2^24); the first kLightChoiceFloor of the range is split evenly
// among the emitters (a defensive floor: every emitter keeps at least
// floor(F 2^24 / n) / 2^24 of the choices wherever it is), and the rest is
// split at each node between its children, the left one taking
// round(S I_left / (I_left + I_right)) of the node's S numbers. An emitter's
// probability is the count of numbers that reach it over 2^24, a multiple of
// 2^-24 and so exact in float, and the same count is found again by following
// its path from the root (its bits), with the same float operations: sampler
// and pmf agree to the last bit, and the pmf of one emitter costs a descent,
// not a sum over every emitter. The descent is leaf::tree_descent
// (leaf_math.inc), which the packet tracer runs for all its lanes at once;
// sample and probability here are the same function in one lane.
#include "renderer/math.h"

#include <cstdint>
#include <vector>

namespace pdflab {

struct Scene;

class LightTree {
 public:
  // What the tree is built from, one per emitter, in the order their
  // probabilities are asked by (TargetSet's: quads, then spheres).
  struct Emitter {
    Vec3 lo, hi;       // its bounding box
    Vec3 axis;         // the direction it emits around (unit)
    float cos_spread;  // cos of the half-angle of its normals about axis: 1 for a flat quad, -1 for a sphere
    float power;       // emitter_power
    bool two_sided = false;  // a quad that emits on both sides: its cone is the whole sphere
  };
  struct Choice {
    int light;          // its index among the emitters
    float probability;  // of choosing it from the point, a multiple of 2^-24
  };

  LightTree() = default;
  // `floor_share`: the fraction of the choices split evenly among the emitters.
  LightTree(const std::vector<Emitter>& emitters, float floor_share);

  int size() const { return count_; }
  // The emitter the 32-bit number u chooses from `point` (normal: the
  // surface's, facing the side light arrives from; zero where the point
  // receives from both sides), with its probability.
  Choice sample(const Vec3& point, const Vec3& normal, std::uint32_t u) const;
  // The probability that sample chooses emitter `light` from `point`.
  float probability(const Vec3& point, const Vec3& normal, int light) const;
  // Every emitter's probability from `point` (sums to 1), for the probe and the tests.
  std::vector<float> probabilities(const Vec3& point, const Vec3& normal) const;
  // The smallest 32-bit number that chooses emitter `light` wherever the point is (one of its floor's).
  std::uint32_t first_choice_of(int light) const {
    return count_ <= 1 ? 0u : (static_cast<std::uint32_t>(light) * floor_count_) << 8;
  }
  // The tree's depth (the longest path from the root to an emitter).
  int depth() const;

  // What the descent reads (leaf::tree_descent): the two children of a node
  // side by side in one 64-byte row of 16 floats, so that a level of the
  // packet tracer's descent reads and transposes one row a lane, not two.
  // Each side: the sphere around the child's box and its power, and where it
  // leads. Cones are read apart (ConeRow), only where some lane needs one:
  // a subtree that holds a sphere emits every way and has none.
  struct Side {
    Vec3 centre;       // of the box
    float radius2;     // the squared half-diagonal of the box: the sphere through its corners
    float radius;      // sqrt(radius2)
    float power;
    std::int32_t link;  // the pair of the child's own children; -1 - emitter for a leaf
  };
  struct alignas(64) Pair {
    Side left;
    std::int32_t cones = -1;  // the children's ConeRow; -1: neither has a cone (both emit every way)
    Side right;
    float unused = 0.0f;
  };
  // The cones of a pair's children (cos_spread -1 and sin_spread 0: every direction).
  struct alignas(64) ConeRow {
    Vec3 left_axis;
    float left_cos_spread;  // of the emitters' normals about the axis; each emits up to 90 degrees beyond
    float left_sin_spread;
    Vec3 right_axis;
    float right_cos_spread;
    float right_sin_spread;
    float unused[6] = {};
  };
  static constexpr std::uint32_t kChoiceRange = 1u << 24;  // the top 24 bits of the 32-bit number choose

  // The root's children are pair 0.
  const Pair* pairs() const { return pairs_.data(); }
  const ConeRow* cone_rows() const { return cone_rows_.data(); }
  // Emitter `light`'s path from the root: bit k the side taken at depth k (1: right).
  std::uint64_t path(int light) const { return path_[static_cast<std::size_t>(light)]; }
  // The numbers of the 2^24 each emitter has in the uniform floor.
  std::uint32_t floor_count() const { return floor_count_; }
  // The numbers of the floor in all: below it, a number chooses an emitter evenly.
  std::uint32_t floor_total() const { return floor_count_ * static_cast<std::uint32_t>(count_); }

 private:
  struct Box {
    Vec3 lo, hi;
  };
  // A node as the build makes it (the root first, a node's children side by side).
  struct Node {
    Vec3 centre;
    float radius2;
    Vec3 axis;
    float cos_spread;  // -1: every direction
    float sin_spread;  // 0 where cos_spread is -1
    float radius;
    float power;
    std::int32_t child = -1;  // the left child (the right one is child + 1); -1: a leaf
    std::int32_t light = -1;  // a leaf's emitter
  };
  // The descent's rows from the build's nodes.
  void make_pairs();
  void build(int at, std::vector<int>& order, int begin, int end, const std::vector<Emitter>& emitters,
             std::uint64_t path, int length);

  void set_box(int at, const Vec3& lo, const Vec3& hi);
  // The node's cone, and the sine of its spread beside the cosine.
  static void set_cone(Node& n, const Vec3& axis, float cos_spread);

  std::vector<Node> nodes_;  // the build's; the root first
  std::vector<Pair> pairs_;
  std::vector<ConeRow> cone_rows_;
  std::vector<Box> bounds_;  // per node, for the build
  std::vector<std::uint64_t> path_;  // per emitter: bit k is the side taken at depth k (1: right)
  std::vector<std::uint8_t> path_length_;
  int count_ = 0;
  std::uint32_t floor_count_ = 0;  // numbers per emitter in the uniform floor
  int median_from_ = 0;  // the depth from which nodes split at the median (a path fits 64 bits)
};

}  // namespace pdflab
