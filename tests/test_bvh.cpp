// The tree over a scene's objects (renderer/scene/bvh.h): the nearest hit it
// finds is the flat loop's, bit for bit, on every ray: random rays, rays
// aimed at points of quads and at spheres' outlines (the aimed reach rule),
// rays grazing quads, slivers, exact ties (duplicated objects: the first of
// equals by object number), through the one-path tracer, every packet width
// and intersect(); degenerate scenes; the threshold that decides whether a
// scene gets a tree.
#include "renderer/integrator/packet.h"
#include "renderer/sampling/leaf.h"
#include "renderer/sampling/techniques.h"
#include "renderer/sampling/rng.h"
#include "renderer/scene/bvh.h"
#include "renderer/scene/object_room.h"
#include "renderer/scene/scene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

namespace pdflab {
namespace {

// The nearest hit by the definition: every quad, then every sphere, the
// nearest below the limit winning, the first of equals; an aimed ray that
// finds nothing reaches what it was aimed at.
NearestHit brute_force(const Scene& scene, const TracedRay& r, bool* tie = nullptr) {
  const float limit = r.aimed >= 0 ? r.aimed_t * kAimedReach : kInf;
  float best = limit;
  std::int32_t id = -1;
  const auto nq = static_cast<std::int32_t>(scene.quads.size());
  std::vector<float> distances;
  for (std::int32_t i = 0; i < nq; ++i) {
    const float t = leaf::quad_hit_distance(scene.quads[static_cast<std::size_t>(i)], r.origin, r.direction);
    distances.push_back(t > 0.0f ? t : kInf);
    if (t > 0.0f && t < best) best = t, id = i;
  }
  for (std::size_t j = 0; j < scene.spheres.size(); ++j) {
    bool hit;
    const float t = leaf::sphere_hit_distance(scene.spheres[j], r.origin, r.direction, limit, hit);
    distances.push_back(hit ? t : kInf);
    if (hit && t < best) best = t, id = nq + static_cast<std::int32_t>(j);
  }
  if (tie && id >= 0) {
    int equal = 0;
    for (float t : distances) equal += t == best;
    *tie = equal > 1;
  }
  if (id < 0 && r.aimed >= 0) return {r.aimed_t, r.aimed};
  return {best, id};
}

bool same(const NearestHit& a, const NearestHit& b) {
  return std::memcmp(&a.t, &b.t, sizeof a.t) == 0 && a.object == b.object;
}

std::string show(const NearestHit& h) { return "t " + std::to_string(h.t) + ", object " + std::to_string(h.object); }

Vec3 random_direction(Rng& rng) {
  const float u1 = rng.uniform(), u2 = rng.uniform();
  return sample_uniform_sphere(u1, u2).direction;
}

Vec3 random_point(Rng& rng, float lo, float hi) {
  Vec3 p;
  for (int c = 0; c < 3; ++c) p[c] = lo + (hi - lo) * rng.uniform();
  return p;
}

// A scene made to trouble a tree: the room's walls, two of them twice (every
// ray that meets them meets two objects at the same distance), quads at
// random, slivers (edges 2e-6 radians from parallel), quads sharing edges,
// spheres from 1e-3 to 150 across, two of them twice.
Scene cluttered_scene(BvhUse tree) {
  Scene scene;
  scene.materials.push_back(Material{});
  scene.material_names.push_back("white");
  Rng rng(3, 17);
  const auto quad = [&](const Vec3& q, const Vec3& u, const Vec3& v) {
    ASSERT_EQ(quad_problem(u, v), "");
    scene.quads.push_back(make_quad(q, u, v, 0));
  };
  quad({555, 0, 0}, {0, 0, 555}, {0, 555, 0});
  quad({0, 0, 555}, {0, 0, -555}, {0, 555, 0});
  quad({0, 555, 0}, {555, 0, 0}, {0, 0, 555});
  quad({0, 0, 555}, {555, 0, 0}, {0, 0, -555});
  quad({555, 0, 555}, {-555, 0, 0}, {0, 555, 0});
  for (int i = 0; i < 120; ++i) {
    const Vec3 a = random_direction(rng);
    const Vec3 b = normalize(random_direction(rng) - a * dot(a, random_direction(rng)));
    quad(random_point(rng, 20, 500), a * (5.0f + 40.0f * rng.uniform()), normalize(b + a * 0.3f) * (5.0f + 40.0f * rng.uniform()));
  }
  for (int i = 0; i < 12; ++i) {  // slivers: v nearly along u
    const Vec3 a = random_direction(rng);
    const Vec3 b = normalize(cross(a, random_direction(rng)));
    const float sine = i % 2 ? 2e-6f : 1e-3f;
    quad(random_point(rng, 50, 450), a * 80.0f, (a + b * sine) * 60.0f);
  }
  for (int i = 0; i < 8; ++i) {  // a strip of quads sharing edges
    const Vec3 q(100.0f + 20.0f * static_cast<float>(i), 300.0f, 100.0f);
    quad(q, {20, 0, 0}, {0, 7, 13});
  }
  quad({0, 0, 555}, {555, 0, 0}, {0, 0, -555});  // the floor again
  quad({555, 0, 555}, {-555, 0, 0}, {0, 555, 0});  // the back wall again
  for (int i = 0; i < 90; ++i) {
    const float radius = i % 9 == 0 ? 1e-3f : i % 15 == 1 ? 150.0f : 2.0f + 30.0f * rng.uniform();
    scene.spheres.push_back(Sphere{random_point(rng, 20, 535), radius, 0});
  }
  scene.spheres.push_back(scene.spheres[4]);
  scene.spheres.push_back(scene.spheres[2]);
  scene.bvh_use = tree;
  scene.prepare();
  return scene;
}

// Rays of every kind the paths trace, from points inside the room.
std::vector<TracedRay> troubling_rays(const Scene& scene, int n, std::uint64_t seed) {
  Rng rng(seed, 5);
  std::vector<TracedRay> rays;
  const auto nq = static_cast<std::int32_t>(scene.quads.size());
  const auto ns = static_cast<std::int32_t>(scene.spheres.size());
  for (int i = 0; i < n; ++i) {
    TracedRay r;
    r.origin = random_point(rng, 1, 554);
    const int kind = i % 5;
    if (kind == 0) {
      r.direction = random_direction(rng);
    } else if (kind == 1 || kind == 2) {
      // Aimed at a point of a quad (at its edges a tenth of the time).
      const auto k = static_cast<std::int32_t>(rng.next_u32() % static_cast<std::uint32_t>(nq));
      const Quad& q = scene.quads[static_cast<std::size_t>(k)];
      float a = rng.uniform(), b = rng.uniform();
      if (rng.uniform() < 0.1f) a = rng.uniform() < 0.5f ? 0.0f : 1.0f;
      if (kind == 2) {
        // Grazing: from a point just off the quad's plane, beside it.
        const Vec3 beside = q.q + q.u * (2.0f * rng.uniform() - 0.5f) + q.v * (2.0f * rng.uniform() - 0.5f);
        r.origin = beside + q.normal * ((rng.uniform() - 0.5f) * 1e-2f);
      }
      const Vec3 to = q.q + q.u * a + q.v * b - r.origin;
      r.aimed_t = length(to);
      if (!(r.aimed_t > 0.0f)) continue;
      r.direction = to / r.aimed_t;
      r.aimed = rng.uniform() < 0.5f ? k : -1;
    } else if (kind == 3) {
      // Along a sphere's outline (the cone's edge), aimed at it or not.
      const auto k = static_cast<std::int32_t>(rng.next_u32() % static_cast<std::uint32_t>(ns));
      const Sphere& s = scene.spheres[static_cast<std::size_t>(k)];
      const Vec3 to = s.center - r.origin;
      const float distance = length(to);
      if (!(distance > s.radius)) continue;
      const float sine = s.radius / distance, cosine = std::sqrt(1.0f - sine * sine);
      const Vec3 axis = to / distance;
      const Vec3 side = normalize(cross(axis, random_direction(rng)));
      r.direction = normalize(axis * cosine + side * sine);
      r.aimed = rng.uniform() < 0.5f ? nq + k : -1;
      r.aimed_t = distance * cosine;
    } else {
      // From just off an object's surface, as a bounce leaves it.
      const Quad& q = scene.quads[rng.next_u32() % static_cast<std::uint32_t>(nq)];
      r.origin = q.q + q.u * rng.uniform() + q.v * rng.uniform() + q.normal * (rng.uniform() < 0.5f ? 1e-3f : -1e-3f);
      r.direction = random_direction(rng);
    }
    rays.push_back(r);
  }
  return rays;
}

struct Tally {
  int hits = 0, ties = 0, fallbacks = 0;
};

// Every ray's nearest hit through the tree, by every tracer, against the flat
// loop and the brute force search.
void expect_same_hits(const Scene& flat, const Scene& tree, const std::vector<TracedRay>& rays, Tally& tally) {
  const std::size_t n = rays.size();
  std::vector<NearestHit> one(n), flat_one(n);
  nearest_hits(tree, rays.data(), n, one.data());
  nearest_hits(flat, rays.data(), n, flat_one.data());
  std::vector<std::vector<NearestHit>> packets;
  for (PacketIsa isa : available_packet_isas()) {
    packets.emplace_back(n);
    nearest_hits(isa, tree, rays.data(), n, packets.back().data());
    packets.emplace_back(n);
    nearest_hits(isa, flat, rays.data(), n, packets.back().data());
  }
  for (std::size_t i = 0; i < n; ++i) {
    bool tie = false;
    const NearestHit expected = brute_force(flat, rays[i], &tie);
    tally.hits += expected.object >= 0;
    tally.ties += tie;
    tally.fallbacks += rays[i].aimed >= 0 && expected.object == rays[i].aimed && expected.t == rays[i].aimed_t;
    ASSERT_TRUE(same(one[i], expected)) << "ray " << i << ": one-path tracer with the tree " << show(one[i])
                                        << ", expected " << show(expected);
    ASSERT_TRUE(same(flat_one[i], expected)) << "ray " << i << ": without the tree " << show(flat_one[i]);
    for (std::size_t p = 0; p < packets.size(); ++p)
      ASSERT_TRUE(same(packets[p][i], expected)) << "ray " << i << ": packets " << p << " " << show(packets[p][i])
                                                 << ", expected " << show(expected);
    // intersect() (the probe's) agrees too, with the tree and without.
    const Ray ray{rays[i].origin, rays[i].direction};
    const int aimed_quad = rays[i].aimed < static_cast<std::int32_t>(flat.quads.size()) ? rays[i].aimed : -1;
    Hit a{}, b{};
    const bool ha = intersect_aimed(tree, ray, aimed_quad, rays[i].aimed_t, a);
    const bool hb = intersect_aimed(flat, ray, aimed_quad, rays[i].aimed_t, b);
    ASSERT_EQ(ha, hb) << "ray " << i;
    if (ha) {
      ASSERT_EQ(std::memcmp(&a.t, &b.t, sizeof a.t), 0) << "ray " << i << ": " << a.t << " against " << b.t;
      ASSERT_EQ(std::memcmp(&a.normal, &b.normal, sizeof a.normal), 0) << "ray " << i;
    }
  }
}

TEST(Bvh, FindsTheFlatLoopsNearestHitOnTroublingRays) {
  const Scene flat = cluttered_scene(BvhUse::Never), tree = cluttered_scene(BvhUse::Always);
  ASSERT_TRUE(flat.bvh.empty());
  ASSERT_TRUE(tree.bvh.covers(tree.quads.size(), tree.spheres.size()));
  ASSERT_GT(tree.bvh.wide.size(), 20u);
  const std::vector<TracedRay> rays = troubling_rays(flat, 20000, 11);
  Tally t;
    expect_same_hits(flat, tree, rays, t);
  // Not a comparison of misses: most rays hit, thousands of them tie, and
  // hundreds of aimed rays reach their object only by the aimed rule.
  EXPECT_GT(t.hits, 15000);
  EXPECT_GT(t.ties, 500);
  EXPECT_GT(t.fallbacks, 500);
  std::printf("%zu rays: %d hits, %d ties, %d aimed fallbacks\n", rays.size(), t.hits, t.ties, t.fallbacks);
}

// The room of many small objects that the tree is measured on, and rays from its camera.
TEST(Bvh, FindsTheFlatLoopsNearestHitInTheObjectRoom) {
  const Scene flat = object_room(400, 1, BvhUse::Never), tree = object_room(400, 1, BvhUse::Always);
  std::vector<TracedRay> rays = troubling_rays(flat, 5000, 12);
  Rng rng(4, 4);
  for (int i = 0; i < 5000; ++i)
    rays.push_back({flat.camera.lookfrom, flat.camera.generate_ray(600 * rng.uniform(), 600 * rng.uniform()).direction});
  Tally t;
    expect_same_hits(flat, tree, rays, t);
  EXPECT_GT(t.hits, 8000);
}

// The objects whose boxes are a large part of the scene's are set aside and
// tested first: the generated room's five walls and none of its small
// objects; in the cluttered scene, the six slivers 2e-6 radians from parallel,
// whose margins (growing with the skew) make their boxes far larger than the
// room. A scene of large objects only has no nodes and still finds the flat
// loop's hits.
TEST(Bvh, TheLargeObjectsAreTestedFirst) {
  const Scene room = object_room(400, 1, BvhUse::Always);
  EXPECT_EQ(room.bvh.large, (std::vector<std::int32_t>{0, 1, 2, 3, 4}));
  const Scene cluttered = cluttered_scene(BvhUse::Always);
  EXPECT_EQ(cluttered.bvh.large, (std::vector<std::int32_t>{126, 128, 130, 132, 134, 136}));

  Scene only[2];
  for (int k = 0; k < 2; ++k) {
    only[k].materials.push_back(Material{});
    only[k].material_names.push_back("white");
    only[k].quads.push_back(make_quad({555, 0, 0}, {0, 0, 555}, {0, 555, 0}, 0));
    only[k].quads.push_back(make_quad({0, 0, 555}, {555, 0, 0}, {0, 0, -555}, 0));
    only[k].quads.push_back(make_quad({0, 0, 555}, {555, 0, 0}, {0, 0, -555}, 0));  // the floor twice
    only[k].spheres.push_back(Sphere{{300, 200, 250}, 200.0f, 0});
    only[k].bvh_use = k == 0 ? BvhUse::Never : BvhUse::Always;
    only[k].prepare();
  }
  ASSERT_TRUE(only[1].bvh.wide.empty());
  ASSERT_EQ(only[1].bvh.large.size(), 4u);
  ASSERT_TRUE(only[1].bvh.covers(3, 1));
  Tally t;
  expect_same_hits(only[0], only[1], troubling_rays(only[0], 3000, 21), t);
  EXPECT_GT(t.hits, 2000);
  EXPECT_GT(t.ties, 100);
}

// The deepest leaf's depth (the root's is 1).
int tree_depth(const Bvh& bvh, std::int32_t at = 0) {
  const WideBvhNode& node = bvh.wide[static_cast<std::size_t>(at)];
  int deepest = 1;
  for (int k = 0; k < WideBvhNode::kWidth; ++k)
    if ((node.valid >> k & 1u) && node.child[k] >= 0) deepest = std::max(deepest, 1 + tree_depth(bvh, node.child[k]));
  return deepest;
}

// Every child's box holds its own children's boxes, the invalid children
// come last, and a node has at least two children (the root of a one-leaf
// tree excepted).
void expect_nested_boxes(const Bvh& bvh, std::int32_t at = 0) {
  const WideBvhNode& node = bvh.wide[static_cast<std::size_t>(at)];
  const int children = std::popcount(static_cast<unsigned>(node.valid));
  EXPECT_EQ(node.valid, (1u << children) - 1u);
  EXPECT_TRUE(children >= 2 || (at == 0 && children == 1));
  for (int k = 0; k < children; ++k) {
    if (node.child[k] < 0) continue;
    const WideBvhNode& inner = bvh.wide[static_cast<std::size_t>(node.child[k])];
    for (int j = 0; j < std::popcount(static_cast<unsigned>(inner.valid)); ++j)
      for (int a = 0; a < 3; ++a) {
        EXPECT_LE(node.lo[a][k], inner.lo[a][j]);
        EXPECT_GE(node.hi[a][k], inner.hi[a][j]);
      }
    expect_nested_boxes(bvh, node.child[k]);
  }
}

// Degenerate scenes: every object at one point (every hit a tie: the first
// object wins), objects from 1e-4 to 1e6 across side by side, and objects
// crowding towards one point, each a quarter-octave nearer to it than the
// last, the last ones at the same point in float.
TEST(Bvh, DegenerateScenes) {
  const char* const names[] = {"all at one point", "huge and tiny", "crowding towards a point",
                               "near float's largest coordinates"};
  for (int which = 0; which < 4; ++which) {
    SCOPED_TRACE(names[which]);
    Scene scenes[2];
    for (int k = 0; k < 2; ++k) {
      Scene& s = scenes[k];
      s.materials.push_back(Material{});
      s.material_names.push_back("white");
      Rng rng(9, 1);
      for (int i = 0; i < 300; ++i) {
        if (which == 0) {
          s.quads.push_back(make_quad({250, 250, 250}, {40, 0, 0}, {0, 40, 0}, 0));
          s.spheres.push_back(Sphere{{270, 270, 250}, 20.0f, 0});
        } else if (which == 3) {
          s.quads.push_back(make_quad(random_point(rng, -1.5e38f, 1.5e38f), {1e18f, 0, 0}, {0, 1e18f, 1e18f}, 0));
          s.spheres.push_back(Sphere{random_point(rng, -1.5e38f, 1.5e38f), 1e37f, 0});
        } else if (which == 2) {
          const float step = std::ldexp(1.0f, -i / 4);  // 1 down to 2^-74: the last ones coincide in float
          s.quads.push_back(make_quad(Vec3(100.0f + 300.0f * step, 250, 250), {step, 0, 0}, {0, step, 0}, 0));
          s.spheres.push_back(Sphere{Vec3(250, 100.0f + 300.0f * step, 250), 0.5f * step + 1e-3f, 0});
        } else {
          const float size = i % 3 == 0 ? 1e-4f : i % 3 == 1 ? 1.0f : 30.0f;
          s.quads.push_back(make_quad(random_point(rng, 100, 400), {size, 0, size}, {0, size, 0}, 0));
          s.spheres.push_back(Sphere{random_point(rng, 100, 400), size, 0});
        }
      }
      if (which == 1) s.spheres.push_back(Sphere{{250, -1e6f, 250}, 1e6f - 50.0f, 0});  // a ground a million across
      s.bvh_use = k == 0 ? BvhUse::Never : BvhUse::Always;
      s.prepare();
    }
    const Bvh& bvh = scenes[1].bvh;
    ASSERT_FALSE(bvh.empty());
    const std::size_t count = scenes[1].quads.size() + scenes[1].spheres.size();
    EXPECT_LE(bvh.large.size(), static_cast<std::size_t>(Bvh::kMaxLarge));
    // Every object is in one leaf or among the large ones, no walk deeper
    // than its stack.
    std::vector<int> seen(count, 0);
    for (const WideBvhNode& node : bvh.wide)
      for (int k = 0; k < WideBvhNode::kWidth; ++k)
        if ((node.valid >> k & 1u) && node.child[k] < 0) {
          const std::int32_t object = WideBvhNode::leaf_object(node.child[k]);
          ASSERT_TRUE(object >= 0 && static_cast<std::size_t>(object) < count) << object;
          ++seen[static_cast<std::size_t>(object)];
        }
    for (const std::int32_t object : bvh.large) ++seen[static_cast<std::size_t>(object)];
    EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), static_cast<std::ptrdiff_t>(seen.size()));
    EXPECT_LE(tree_depth(bvh), Bvh::kMaxDepth);
    expect_nested_boxes(bvh);
    std::printf("%s: %zu nodes, depth %d\n", names[which], bvh.wide.size(), tree_depth(bvh));
    std::vector<TracedRay> rays = which == 3 ? std::vector<TracedRay>{} : troubling_rays(scenes[0], 4000, 13);
    Rng rng(8, 8);
    for (int i = 0; i < 2000; ++i) {  // at the point, or at a tiny object
      const Vec3 o = which == 3 ? random_point(rng, -1e38f, 1e38f) : random_point(rng, 0, 555);
      const Vec3 at = which == 0   ? Vec3(265, 265, 250)
                      : which == 1 ? scenes[0].spheres[static_cast<std::size_t>(3 * (i % 100))].center
                      : i % 2      ? scenes[0].spheres[static_cast<std::size_t>(i % 120)].center
                      : which == 3 ? scenes[0].quads[static_cast<std::size_t>(i % 120)].q + Vec3(5e17f, 1e17f, 4e17f)
                                   : scenes[0].quads[static_cast<std::size_t>(i % 120)].q;
      rays.push_back({o, unit_direction(at - o)});
    }
    Tally t;
    expect_same_hits(scenes[0], scenes[1], rays, t);
    EXPECT_GT(t.hits, 1000);
    if (which == 0) {
      EXPECT_GT(t.ties, 1000);
    }
  }
}

// The tree is built from kBvhObjectThreshold objects on (the room's five
// walls count), always or never where asked, and a scene edited after
// prepare() is traced without it.
TEST(Bvh, BuiltFromTheThreshold) {
  const int walls = 5;
  EXPECT_TRUE(object_room(kBvhObjectThreshold - walls - 1).bvh.empty());
  EXPECT_FALSE(object_room(kBvhObjectThreshold - walls).bvh.empty());
  EXPECT_TRUE(object_room(500, 1, BvhUse::Never).bvh.empty());
  EXPECT_FALSE(object_room(3, 1, BvhUse::Always).bvh.empty());

  Scene edited = object_room(200);
  ASSERT_TRUE(edited.bvh.covers(edited.quads.size(), edited.spheres.size()));
  const Vec3 from = edited.camera.lookfrom;
  edited.spheres.push_back(Sphere{from + Vec3(0, 0, 50), 10.0f, 0});  // in front of the camera
  EXPECT_FALSE(edited.bvh.covers(edited.quads.size(), edited.spheres.size()));
  const TracedRay ray{from, {0, 0, 1}};
  NearestHit hit{};
  nearest_hits(edited, &ray, 1, &hit);
  EXPECT_EQ(hit.object, static_cast<std::int32_t>(edited.quads.size() + edited.spheres.size() - 1));
  for (PacketIsa isa : available_packet_isas()) {
    nearest_hits(isa, edited, &ray, 1, &hit);
    EXPECT_EQ(hit.object, static_cast<std::int32_t>(edited.quads.size() + edited.spheres.size() - 1));
  }
}

// A box holds every point where the float test reports a hit on its object:
// the margin is above float's error for origins and distances within a few
// times the scene's extent, and grows for a quad whose edges are nearly parallel.
TEST(Bvh, MarginsGrowWithTheSceneAndTheSkew) {
  const Quad square = make_quad({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 0);
  const Quad sliver = make_quad({0, 0, 0}, {1, 0, 0}, {1, 1e-5f, 0}, 0);
  EXPECT_GT(object_margin(square, 1000.0f), 1000.0f * 0x1.0p-24f * 100.0f);
  EXPECT_GT(object_margin(square, 1000.0f), 100.0f * object_margin(square, 1.0f) * 0.99f);
  EXPECT_GT(object_margin(sliver, 1000.0f), 1e4f * object_margin(square, 1000.0f));
}

}  // namespace
}  // namespace pdflab
