#pragma once
// A bounding volume hierarchy over a scene's objects (its quads and spheres),
// for scenes with many of them: its large objects set aside, the rest a
// binned surface-area-heuristic tree of sixteen children a node, walked one
// ray at a time (bvh_walk.inc). The book's scenes have a
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
#include <cstring>
#include <vector>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

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

// A node of the tree: up to sixteen children, whose sixteen boxes the walk
// tests against a ray at once (bvh_walk.inc's reach_children), one AVX-512
// register an axis. Built as a binary tree by the surface-area heuristic, then
// made wide by the collapse of least surface-area cost (bvh.cpp's Collapse):
// the same leaves, the same boxes. On the
// many-lights room (483 objects in the tree) a ray visits 1.6 of these nodes
// below the root, against 2.5 with eight children a node
// (docs/many_lights.md).
struct alignas(64) WideBvhNode {
  static constexpr int kWidth = 16;
  float lo[3][kWidth], hi[3][kWidth];  // child k's box: lo[axis][k] .. hi[axis][k]
  // An interior child: the node's index in Bvh::wide; a leaf (negative): its
  // one object, leaf_object(child[k]). A leaf is one object, even where the
  // objects cannot be told apart by their centres: on the many-lights room,
  // leaves of two or four objects took 9% and 21% more time.
  std::int32_t child[kWidth];
  std::uint16_t valid = 0;  // bit k: child k exists (the others' boxes are empty)
  std::uint16_t inner = 0;  // bit k: child k is a node (the others that exist are leaves)

  static constexpr std::int32_t leaf(std::int32_t object) { return -1 - object; }
  static constexpr std::int32_t leaf_object(std::int32_t child) { return -1 - child; }
};

struct Bvh {
  // The deepest a tree is built (a longer walk falls back to halving by count),
  // so a walk's stack of nodes to visit holds at most this many.
  static constexpr int kMaxDepth = 64;

  // Objects whose boxes are a large part of the scene's (a room's walls and
  // floor: from kLargeShare of its area on, the kMaxLarge largest): every
  // walk tests them first, before any node. In a leaf, such an object's box
  // would widen every node above it to most of the scene, and most rays would
  // walk down to it through nodes they need for nothing else; tested first,
  // it gives most rays a near hit that cuts the walk short. On the many-lights
  // room: 20 of 526 objects, 12% less time (docs/many_lights.md).
  static constexpr double kLargeShare = 1.0 / 128;
  static constexpr int kMaxLarge = 32;

  // Object numbers: quad i is i, sphere j is quads + j (the numbering of the
  // tracer's hit rows).
  std::vector<std::int32_t> large;  // tested first, by increasing number
  std::vector<WideBvhNode> wide;    // wide[0] is the root; empty: every object is `large`
  int quads = 0, spheres = 0;  // the objects it was built over

  bool empty() const { return wide.empty() && large.empty(); }
  // Whether it was built over these many quads and spheres (a scene edited
  // after prepare() falls back to the flat loop, as with the quad batch).
  bool covers(std::size_t quad_count, std::size_t sphere_count) const {
    return !empty() && static_cast<std::size_t>(quads) == quad_count && static_cast<std::size_t>(spheres) == sphere_count;
  }

  // The tree over the objects; `scale` is the scene's (Scene::scale), which
  // bounds the ray origins and distances that the margins must cover.
  static Bvh build(const std::vector<Quad>& quads, const std::vector<Sphere>& spheres, float scale);

  // The walk for one ray: calls test(object) for each of the large objects,
  // then for each object in a leaf whose box the ray reaches at a distance in
  // [0, best_t], nearer child first; `test` lowers best_t when it finds a
  // nearer hit.
  template <class Test>
  void walk(const Vec3& origin, const Vec3& direction, const float& best_t, Test test) const;

};

// How much an object's box is widened on every side: float's error in the
// intersection tests, bounded for rays whose origin and distance are within
// a few `scale`, times a wide margin. A quad's error in its edge coordinates
// grows as its edges approach parallel (|u| |alpha_axis| + |v| |beta_axis|).
float object_margin(const Quad& quad, float scale);
float object_margin(const Sphere& sphere, float scale);

namespace bvh_walk {
#include "renderer/scene/bvh_walk.inc"
}  // namespace bvh_walk

template <class Test>
void Bvh::walk(const Vec3& origin, const Vec3& direction, const float& best_t, Test test) const {
  for (const std::int32_t object : large) test(object);
  const float from[3] = {origin.x, origin.y, origin.z};
  const float inverse[3] = {1.0f / direction.x, 1.0f / direction.y, 1.0f / direction.z};
  bvh_walk::walk_tree(*this, from, inverse, [&] { return best_t; }, test);
}

}  // namespace pdflab
