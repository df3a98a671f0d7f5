// The tree over objects (renderer/scene/bvh.h) against Embree 3 on the same
// rays in the generated room (object_room): how often Embree's nearest hit is
// another object, or the same object at another distance (other bits), how
// often a ray aimed at a point of a quad (a light sample) misses that quad in
// Embree, and rays per second of each (the thread's CPU time). What
// docs/many_lights.md quotes for keeping a tree of pdflab's own. Built only
// where Embree 3 is installed (Debian's libembree-dev); pdflab itself does
// not use it.
//
//   bench_embree [--counts 100,1000,10000] [--rays 200000]
#include "renderer/integrator/packet.h"
#include "renderer/sampling/rng.h"
#include "renderer/sampling/techniques.h"
#include "renderer/scene/object_room.h"

#include <embree3/rtcore.h>

#include <ctime>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

using namespace pdflab;

namespace {

// The scene's quads (two triangles each, Embree's quad primitive) and spheres.
RTCScene embree_scene(RTCDevice device, const Scene& scene) {
  RTCScene out = rtcNewScene(device);
  RTCGeometry quads = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_QUAD);
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(quads, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                        3 * sizeof(float), 4 * scene.quads.size()));
  auto* index = static_cast<unsigned*>(rtcSetNewGeometryBuffer(quads, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT4,
                                                               4 * sizeof(unsigned), scene.quads.size()));
  for (std::size_t i = 0; i < scene.quads.size(); ++i) {
    const Quad& q = scene.quads[i];
    const Vec3 corners[4] = {q.q, q.q + q.u, q.q + q.u + q.v, q.q + q.v};
    for (int c = 0; c < 4; ++c)
      for (int k = 0; k < 3; ++k) v[(4 * i + static_cast<std::size_t>(c)) * 3 + static_cast<std::size_t>(k)] = corners[c][k];
    for (unsigned c = 0; c < 4; ++c) index[4 * i + c] = static_cast<unsigned>(4 * i) + c;
  }
  rtcCommitGeometry(quads);
  rtcAttachGeometryByID(out, quads, 0);
  rtcReleaseGeometry(quads);
  RTCGeometry spheres = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
  auto* p = static_cast<float*>(rtcSetNewGeometryBuffer(spheres, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4,
                                                        4 * sizeof(float), scene.spheres.size()));
  for (std::size_t i = 0; i < scene.spheres.size(); ++i) {
    const Sphere& s = scene.spheres[i];
    p[4 * i] = s.center.x, p[4 * i + 1] = s.center.y, p[4 * i + 2] = s.center.z, p[4 * i + 3] = s.radius;
  }
  rtcCommitGeometry(spheres);
  rtcAttachGeometryByID(out, spheres, 1);
  rtcReleaseGeometry(spheres);
  rtcCommitScene(out);
  return out;
}

NearestHit embree_nearest(RTCScene scene, const TracedRay& r, std::int32_t quads) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh{};
  rh.ray.org_x = r.origin.x, rh.ray.org_y = r.origin.y, rh.ray.org_z = r.origin.z;
  rh.ray.dir_x = r.direction.x, rh.ray.dir_y = r.direction.y, rh.ray.dir_z = r.direction.z;
  rh.ray.tnear = 0.0f;
  rh.ray.tfar = r.aimed >= 0 ? r.aimed_t * kAimedReach : kInf;
  rh.ray.mask = ~0u;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(scene, &context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return {kInf, -1};
  return {rh.ray.tfar, static_cast<std::int32_t>(rh.hit.primID) + (rh.hit.geomID == 1 ? quads : 0)};
}

// Rays as paths trace them: from the camera, from points in the room in any
// direction, and aimed at points of the objects' quads (light samples).
std::vector<TracedRay> rays_in(const Scene& scene, int n) {
  Rng rng(7, 7);
  std::vector<TracedRay> rays;
  const auto nq = static_cast<std::uint32_t>(scene.quads.size());
  for (int i = 0; i < n; ++i) {
    TracedRay r;
    Vec3 o;
    for (int c = 0; c < 3; ++c) o[c] = 1.0f + 553.0f * rng.uniform();
    const float u1 = rng.uniform(), u2 = rng.uniform();
    if (i % 3 == 0) {
      r = {scene.camera.lookfrom, scene.camera.generate_ray(600.0f * u1, 600.0f * u2).direction};
    } else if (i % 3 == 1) {
      r = {o, sample_uniform_sphere(u1, u2).direction};
    } else {
      const std::uint32_t k = rng.next_u32() % nq;
      const Quad& q = scene.quads[k];
      const Vec3 to = q.q + q.u * u1 + q.v * u2 - o;
      r = {o, normalize(to), static_cast<std::int32_t>(k), length(to)};
    }
    rays.push_back(r);
  }
  return rays;
}

// This thread's CPU time (the machine may be shared).
double thread_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

}  // namespace

int main(int argc, char** argv) {
  std::string counts = "100,1000,10000";
  int n = 200000;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i], value = argv[i + 1];
    if (key == "--counts") counts = value;
    else if (key == "--rays") n = std::stoi(value);
    else {
      std::fprintf(stderr, "unknown option %s\n", key.c_str());
      return 2;
    }
  }
  RTCDevice device = rtcNewDevice("threads=1");
  std::printf("| objects | rays | other object | same object, other distance | aimed rays missing their quad | "
              "pdflab tree, packets (M rays/s) | pdflab tree, one ray (M rays/s) | Embree, one ray (M rays/s) |\n");
  std::printf("|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  std::stringstream in(counts);
  for (std::string count; std::getline(in, count, ',');) {
    const Scene scene = object_room(std::stoi(count), 1, BvhUse::Always);
    const auto nq = static_cast<std::int32_t>(scene.quads.size());
    const std::vector<TracedRay> rays = rays_in(scene, n);
    std::vector<NearestHit> ours(rays.size()), one(rays.size()), theirs(rays.size());
    double start = thread_seconds();
    nearest_hits(best_packet_isa(), scene, rays.data(), rays.size(), ours.data());
    const double packet_s = thread_seconds() - start;
    start = thread_seconds();
    nearest_hits(scene, rays.data(), rays.size(), one.data());
    const double one_s = thread_seconds() - start;
    RTCScene es = embree_scene(device, scene);  // "threads=1": built on this thread
    start = thread_seconds();
    for (std::size_t i = 0; i < rays.size(); ++i) theirs[i] = embree_nearest(es, rays[i], nq);
    const double embree_s = thread_seconds() - start;
    rtcReleaseScene(es);
    int other_object = 0, other_t = 0, aimed = 0, aimed_missed = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      // An aimed ray that Embree finds nothing for reaches its quad by pdflab's rule;
      // Embree alone would have missed it.
      const bool fallback = rays[i].aimed >= 0 && theirs[i].object < 0;
      if (rays[i].aimed >= 0 && ours[i].object == rays[i].aimed) {
        ++aimed;
        aimed_missed += fallback;
      }
      if (fallback) continue;
      if (theirs[i].object != ours[i].object) ++other_object;
      else if (theirs[i].object >= 0 && std::memcmp(&theirs[i].t, &ours[i].t, sizeof(float)) != 0) ++other_t;
    }
    const double m = static_cast<double>(rays.size()) / 1e6;
    std::printf("| %zu | %zu | %.3f%% | %.1f%% | %d of %d | %.2f | %.2f | %.2f |\n", scene.quads.size() + scene.spheres.size(),
                rays.size(), 100.0 * other_object / static_cast<double>(rays.size()),
                100.0 * other_t / static_cast<double>(rays.size()), aimed_missed, aimed, m / packet_s, m / one_s,
                m / embree_s);
    std::fflush(stdout);
  }
  rtcReleaseDevice(device);
  return 0;
}
