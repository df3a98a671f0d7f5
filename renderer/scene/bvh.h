#pragma once
// A bounding volume hierarchy over a scene's objects (its quads and spheres),
// for scenes with many of them: a binned surface-area-heuristic build into a
// flat array of nodes, walked nearest child first. The book's scenes have a
// dozen objects, which the flat arrays test faster than any tree:
// Scene::prepare builds one only from kBvhObjectThreshold objects on.
//
// The walk must find exactly the hit the flat loop finds, so that an image is
// the same bits with and without the tree. Two rules make it so:
//  - each object is tested by the same arithmetic as in the flat loop, and the
//    nearest hit wins, the first of equals by object number (quads first, then
//    spheres: the flat loop's order), whatever order the tree visits them in;
//  - an object's box holds every point where the float test can report a hit
//    on it, not only the object: it is widened by a margin (object_margin)
//    well above float's error in that test, so a ray the test says hits the
//    object always passes its box, grazing rays and slivers included.
#include "renderer/math.h"

#include <cstdint>
#include <vector>

namespace pdflab {

struct Quad;
struct Sphere;

// From this many objects (quads and spheres together) on, Scene::prepare
// builds the tree (BvhUse::Auto); below it the flat loop is faster
// (docs/many_lights.md, "The BVH over objects", measures the crossing).
inline constexpr int kBvhObjectThreshold = 50;

// Whether Scene::prepare builds the tree: above the threshold, always (the
// tests compare the two), or never.
enum class BvhUse : std::uint8_t { Auto, Always, Never };

struct BvhNode {
  float lo[3], hi[3];  // the box (of the objects' widened boxes)
  // A leaf: its objects are Bvh::objects[index .. index + count). Interior
  // (count 0): its children are the next node and node `index`, split along `axis`.
  std::int32_t index = 0;
  std::uint16_t count = 0;
  std::uint8_t axis = 0;
  std::uint8_t unused = 0;
};
static_assert(sizeof(BvhNode) == 32);

struct Bvh {
  // The deepest a tree is built (a longer walk falls back to halving by count),
  // so a walk's stack of nodes to visit holds at most this many.
  static constexpr int kMaxDepth = 64;
  // Objects per leaf at most (where the objects cannot be told apart by their
  // centres, a leaf still holds no more).
  static constexpr int kMaxLeaf = 4;

  std::vector<BvhNode> nodes;  // nodes[0] is the root; empty: no tree
  // Object numbers in leaf order: quad i is i, sphere j is quads + j (the
  // numbering of the tracer's hit rows).
  std::vector<std::int32_t> objects;
  int quads = 0, spheres = 0;  // the objects it was built over

  bool empty() const { return nodes.empty(); }
  // Whether it was built over these many quads and spheres (a scene edited
  // after prepare() falls back to the flat loop, as with the quad batch).
  bool covers(std::size_t quad_count, std::size_t sphere_count) const {
    return !empty() && static_cast<std::size_t>(quads) == quad_count && static_cast<std::size_t>(spheres) == sphere_count;
  }

  // The tree over the objects; `scale` is the scene's (Scene::scale), which
  // bounds the ray origins and distances that the margins must cover.
  static Bvh build(const std::vector<Quad>& quads, const std::vector<Sphere>& spheres, float scale);

  // The walk for one ray: calls test(object) for each object in a leaf whose
  // box the ray reaches at a distance in [0, best_t], nearer child first;
  // `test` lowers best_t when it finds a nearer hit.
  template <class Test>
  void walk(const Vec3& origin, const Vec3& direction, const float& best_t, Test test) const;

  // How far the walk reaches a node's box (a slab test): in [0, limit].
  static bool reaches(const BvhNode& node, const Vec3& origin, const Vec3& inverse, float limit);
};

// How much an object's box is widened on every side: float's error in the
// intersection tests, bounded for rays whose origin and distance are within
// a few `scale`, times a wide margin. A quad's error in its edge coordinates
// grows as its edges approach parallel (|u| |alpha_axis| + |v| |beta_axis|).
float object_margin(const Quad& quad, float scale);
float object_margin(const Sphere& sphere, float scale);

inline bool Bvh::reaches(const BvhNode& node, const Vec3& origin, const Vec3& inverse, float limit) {
  float near = 0.0f, far = limit;
  for (int a = 0; a < 3; ++a) {
    const float t0 = (node.lo[a] - origin[a]) * inverse[a];
    const float t1 = (node.hi[a] - origin[a]) * inverse[a];
    // A NaN (an origin on a box's face, parallel to it) constrains nothing:
    // the widened boxes hold every reported hit strictly inside.
    const float lo = t0 < t1 ? t0 : t1, hi = t0 < t1 ? t1 : t0;
    near = lo > near ? lo : near;
    far = hi < far ? hi : far;
  }
  return near <= far;
}

template <class Test>
void Bvh::walk(const Vec3& origin, const Vec3& direction, const float& best_t, Test test) const {
  if (empty()) return;
  const Vec3 inverse(1.0f / direction.x, 1.0f / direction.y, 1.0f / direction.z);
  std::int32_t stack[kMaxDepth];
  int top = 0;
  std::int32_t at = 0;
  for (;;) {
    const BvhNode& node = nodes[static_cast<std::size_t>(at)];
    if (reaches(node, origin, inverse, best_t)) {
      if (node.count) {
        for (int k = 0; k < node.count; ++k) test(objects[static_cast<std::size_t>(node.index + k)]);
      } else {
        const bool forward = direction[node.axis] >= 0.0f;
        stack[top++] = forward ? node.index : at + 1;
        at = forward ? at + 1 : node.index;
        continue;
      }
    }
    if (top == 0) return;
    at = stack[--top];
  }
}

}  // namespace pdflab
