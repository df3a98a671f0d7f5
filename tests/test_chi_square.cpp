// Chi-square tests of every sampling technique against its own pdf, and of the
// one-sample mixtures against sum_i w_i p_i, through the harness the viewer's
// probe runs too (renderer/metrics/chi_square.h), with both samplers: the
// one-path tracer's and the packet kernel's, which renders.
#include "renderer/integrator/packet.h"
#include "renderer/metrics/chi_square.h"
#include "renderer/metrics/statistics.h"
#include "renderer/sampling/leaf.h"
#include "renderer/sampling/rng.h"
#include "renderer/sampling/strategy.h"
#include "renderer/sampling/techniques.h"
#include "renderer/scene/environment.h"
#include "renderer/scene/scene.h"
#include "renderer/scene/scene_loader.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <memory>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

namespace pdflab {
namespace {

using chi_square::Frame;
using chi_square::Outcome;
using chi_square::Sampler;
using chi_square::target_outlines;

// 20 x 40 cells of equal solid angle (dz dphi = 0.1 * 2pi/40 = pi/200 sr each).
// Rows of equal mass where a lobe is narrow (chi_square::follow_lobe).
const chi_square::Grid kGrid = [] {
  chi_square::Grid g{20, 40};
  g.lobe_rows = true;
  return g;
}();
constexpr int kSamples = 1'000'000;
constexpr double kFamilyAlpha = 0.01;

template <class Draw>
Outcome run_chi_square(const Frame& frame, Draw&& draw, const chi_square::Density& density,
                       const std::vector<chi_square::Point>& edges, std::uint64_t seed, int samples = kSamples) {
  return chi_square::run(kGrid, frame, chi_square::Draw(std::forward<Draw>(draw)), density, edges, seed, samples);
}

// ---- Scenes with importance targets ----------------------------------------

enum class Targets {
  None,
  QuadOverhead,    // 1 x 1 quad one unit above the origin, facing down
  QuadUpright,     // vertical quad at x = 1: its plane contains the +y normal
  QuadEdgeOn,      // quad in the plane y = 0, seen from 0.2 above that plane
  Sphere,          // radius 0.6 two units above the origin
  SphereHorizon,   // sphere whose cone straddles the horizon of a +y normal
  TwoOverlapping,  // QuadOverhead plus a sphere in front of it (supports overlap)
  TwoDisjoint,     // QuadOverhead plus a sphere off to the side, low
  BookLight,       // the book's light quad alone (scene scale ~500)
  Book,            // the book's scene: its light and its glass sphere
  TwoPowers,       // two emitting quads overhead, one 40x the other's power
  ManyLamps,       // four small quads overhead (one facing up) and two spheres, of powers over a factor 50
  TwoLightsScene,  // assets/scenes/two_lights.json: a tiny bright light and a wide dim one
  GlossyScene,     // assets/scenes/glossy_metal.json: a metal box (six quads) and a metal sphere
  // No targets; environment maps other than the sky every other scene has:
  SubTexelSun,     // 64 x 32, a sky of 0.5 and a sun inside one texel holding 90% of the light
  BlackHalf,       // 32 x 16, black for phi < pi, lit beyond
  ConstantMap,     // 8 x 4 of radiance 1
};

// A lat-long map of w x h texels, radiance `at(x, y)`.
template <class At>
std::shared_ptr<const Environment> make_map(int w, int h, float rotation, At at) {
  std::vector<float> rgb;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const Vec3 c = at(x, y);
      rgb.insert(rgb.end(), {c.x, c.y, c.z});
    }
  return std::make_shared<Environment>(std::move(rgb), w, h, 1.0f, rotation);
}

// The map of each scene: a sky brighter towards the horizon with a sun of
// one texel (turned 30 degrees), or the scene's own.
std::shared_ptr<const Environment> scene_map(Targets which) {
  switch (which) {
    case Targets::SubTexelSun:
      // 64 x 32 texels of 0.5 sum to 0.5 * 4 pi; one texel 45 degrees from
      // the zenith, 0.0068 sr at 5000, holds 5.5 times that.
      return make_map(64, 32, 0.0f, [](int x, int y) { return x == 20 && y == 8 ? Vec3(5000.0f, 4800.0f, 4500.0f) : Vec3(0.5f); });
    case Targets::BlackHalf:
      return make_map(32, 16, 0.0f, [](int x, int y) { return x < 16 ? Vec3(0.0f) : Vec3(1.0f + 0.1f * static_cast<float>(y), 1.0f, 0.5f + 0.05f * static_cast<float>(x)); });
    case Targets::ConstantMap: return make_map(8, 4, 0.0f, [](int, int) { return Vec3(1.0f); });
    default:
      return make_map(32, 16, 30.0f, [](int x, int y) {
        if (x == 9 && y == 5) return Vec3(2000.0f);
        const float h = static_cast<float>(y);
        return Vec3(0.2f + 0.05f * h, 0.3f + 0.04f * h, 0.8f);
      });
  }
}

void add_quad_target(Scene& s, const Vec3& q, const Vec3& u, const Vec3& v) {
  s.targets.push_back({Target::Kind::Quad, static_cast<std::uint32_t>(s.quads.size())});
  s.quads.push_back(make_quad(q, u, v, 0));
}
void add_sphere_target(Scene& s, const Vec3& c, float r) {
  s.targets.push_back({Target::Kind::Sphere, static_cast<std::uint32_t>(s.spheres.size())});
  s.spheres.push_back(Sphere{c, r, 0});
}

std::unique_ptr<Scene> make_scene(Targets which) {
  if (which == Targets::Book)
    return std::make_unique<Scene>(load_scene_file(PDFLAB_SOURCE_DIR "/assets/scenes/cornell_book.json"));
  if (which == Targets::TwoLightsScene)
    return std::make_unique<Scene>(load_scene_file(PDFLAB_SOURCE_DIR "/assets/scenes/two_lights.json"));
  if (which == Targets::GlossyScene)
    return std::make_unique<Scene>(load_scene_file(PDFLAB_SOURCE_DIR "/assets/scenes/glossy_metal.json"));
  auto s = std::make_unique<Scene>();
  s->name = "chi-square targets";
  s->environment = scene_map(which);  // for the environment technique alone; no other technique sees it
  // Metal, so that specular-objects aims at the same objects as light (a
  // material changes no other technique's targets: they are marked).
  Material metal;
  metal.type = MaterialType::Metal;
  s->materials.push_back(metal);
  s->material_names.push_back("m");
  switch (which) {
    case Targets::None: break;
    case Targets::QuadOverhead: add_quad_target(*s, {-0.5f, 1, -0.5f}, {1, 0, 0}, {0, 0, 1}); break;
    case Targets::QuadUpright: add_quad_target(*s, {1, 0.05f, -0.5f}, {0, 0, 1}, {0, 0.95f, 0}); break;
    case Targets::QuadEdgeOn: add_quad_target(*s, {1, 0, -0.5f}, {0, 0, 1}, {1, 0, 0}); break;
    case Targets::Sphere: add_sphere_target(*s, {0, 2, 0}, 0.6f); break;
    case Targets::SphereHorizon: add_sphere_target(*s, {2, 0.3f, 0}, 0.5f); break;
    case Targets::TwoOverlapping:
      add_quad_target(*s, {-0.5f, 1, -0.5f}, {1, 0, 0}, {0, 0, 1});
      add_sphere_target(*s, {0.2f, 0.6f, 0}, 0.2f);
      break;
    case Targets::TwoDisjoint:
      add_quad_target(*s, {-0.5f, 1, -0.5f}, {1, 0, 0}, {0, 0, 1});
      add_sphere_target(*s, {1.5f, 0.4f, 0.5f}, 0.35f);
      break;
    case Targets::BookLight: add_quad_target(*s, {213, 554, 227}, {130, 0, 0}, {0, 0, 105}); break;
    case Targets::TwoPowers: {
      // Equal areas, emission 40 : 1, so power-proportional choice is 40 : 1.
      Material bright, dim;
      bright.type = dim.type = MaterialType::DiffuseLight;
      bright.emit = Vec3(40.0f);
      dim.emit = Vec3(1.0f);
      s->materials = {bright, dim};
      s->material_names = {"bright", "dim"};
      add_quad_target(*s, {-1.2f, 1, -0.3f}, {0.6f, 0, 0}, {0, 0, 0.6f});
      add_quad_target(*s, {0.6f, 1, -0.3f}, {0.6f, 0, 0}, {0, 0, 0.6f});
      s->quads[1].material = 1;
      break;
    }
    case Targets::ManyLamps: {
      Material lamp;
      lamp.type = MaterialType::DiffuseLight;
      s->materials.clear();
      s->material_names.clear();
      for (const float emit : {1.0f, 5.0f, 50.0f}) {
        lamp.emit = Vec3(emit);
        s->materials.push_back(lamp);
        s->material_names.push_back("lamp" + std::to_string(s->materials.size()));
      }
      for (int i = 0; i < 4; ++i) {
        const float x = -1.2f + 1.4f * static_cast<float>(i % 2), z = -1.2f + 1.4f * static_cast<float>(i / 2);
        if (i == 3) add_quad_target(*s, {x, 1.3f, z}, {0, 0, 0.4f}, {0.4f, 0, 0});  // faces up: lights nothing below
        else add_quad_target(*s, {x, 1.0f + 0.1f * static_cast<float>(i % 2), z}, {0.4f, 0, 0}, {0, 0, 0.4f});
        s->quads.back().material = static_cast<std::uint32_t>(i % 3);
      }
      for (int i = 0; i < 2; ++i) {
        add_sphere_target(*s, {-1.0f + 0.7f * static_cast<float>(i), 0.7f, 1.3f - 0.6f * static_cast<float>(i % 2)}, 0.12f);
        s->spheres.back().material = static_cast<std::uint32_t>((i + 1) % 3);
      }
      break;
    }
    case Targets::Book:
    case Targets::TwoLightsScene:
    case Targets::GlossyScene:
    case Targets::SubTexelSun:
    case Targets::BlackHalf:
    case Targets::ConstantMap: break;
  }
  return s;
}

struct ChiCase {
  const char* name;
  const char* strategy;
  Targets targets;
  Vec3 origin;
  Vec3 normal;  // normalised when the case runs
  // Sample the plan's emitter set instead (the light technique of nee-mis).
  bool emitter_set = false;
};

Vec3 unit(float x, float y, float z) { return normalize(Vec3(x, y, z)); }

const std::vector<ChiCase>& chi_cases() {
  static const std::vector<ChiCase> cases = {
      // Hemisphere and sphere techniques; -z and a normal with z = -0 are the
      // branch points of the branchless ONB.
      {"cosine_up", "cosine", Targets::None, {0, 0, 0}, {0, 0, 1}},
      {"cosine_minus_z", "cosine", Targets::None, {0, 0, 0}, {0, 0, -1}},
      {"cosine_oblique", "cosine", Targets::None, {0, 0, 0}, unit(1, 2, 3)},
      {"cosine_z_negative_zero", "cosine", Targets::None, {0, 0, 0}, {1, 0, -0.0f}},
      {"uniform_hemisphere_up", "uniform-hemisphere", Targets::None, {0, 0, 0}, {0, 1, 0}},
      {"uniform_hemisphere_minus_z", "uniform-hemisphere", Targets::None, {0, 0, 0}, {0, 0, -1}},
      {"uniform_hemisphere_oblique", "uniform-hemisphere", Targets::None, {0, 0, 0}, unit(-3, 1, 2)},
      {"uniform_sphere_up", "uniform-sphere", Targets::None, {0, 0, 0}, {0, 0, 1}},
      {"uniform_sphere_oblique", "uniform-sphere", Targets::None, {0, 0, 0}, unit(1, 2, 3)},
      // Light on one quad.
      {"light_quad_overhead", "light", Targets::QuadOverhead, {0, 0, 0}, {0, 1, 0}},
      {"light_quad_off_centre_tilted", "light", Targets::QuadOverhead, {0.8f, 0, 0.3f}, unit(1, 1, 0)},
      {"light_quad_close_wide", "light", Targets::QuadOverhead, {0.1f, 0.97f, -0.2f}, {0, 1, 0}},
      {"light_quad_behind_surface", "light", Targets::QuadOverhead, {0, 0, 0}, {0, -1, 0}},
      {"light_quad_grazing_near_horizon", "light", Targets::QuadUpright, {0, 0, 0}, {0, 1, 0}},
      {"light_quad_grazing_straddles_horizon", "light", Targets::QuadUpright, {0, 0.3f, 0}, {0, 1, 0}},
      {"light_quad_edge_on", "light", Targets::QuadEdgeOn, {0, 0.2f, 0}, {0, 1, 0}},
      {"light_quad_edge_on_tilted_normal", "light", Targets::QuadEdgeOn, {0, 0.2f, 0}, unit(1, 0.05f, 0)},
      {"light_book_light_from_floor", "light", Targets::BookLight, {278, 0, 279.5f}, {0, 1, 0}},
      {"light_book_light_from_ceiling_grazing", "light", Targets::BookLight, {278, 555, 150}, {0, -1, 0}},
      // Light on one sphere.
      {"light_sphere_overhead", "light", Targets::Sphere, {0, 0, 0}, {0, 1, 0}},
      {"light_sphere_close", "light", Targets::Sphere, {0.1f, 1.35f, 0}, {0, 1, 0}},
      {"light_sphere_near_horizon", "light", Targets::SphereHorizon, {0, 0, 0}, {0, 1, 0}},
      {"light_sphere_from_inside", "light", Targets::Sphere, {0.1f, 2.1f, 0}, {0, 1, 0}},
      // Light on two targets.
      {"light_two_overlapping", "light", Targets::TwoOverlapping, {0, 0, 0}, {0, 1, 0}},
      {"light_two_disjoint", "light", Targets::TwoDisjoint, {0, 0, 0}, {0, 1, 0}},
      {"light_book_from_red_wall", "light", Targets::Book, {0, 300, 300}, {1, 0, 0}},
      {"light_book_from_floor", "light", Targets::Book, {400, 0, 150}, {0, 1, 0}},
      // Mixtures cosine / light with light weight 0, 0.25, 0.5, 1.
      {"mix_light_0_two_disjoint", "mix:cosine=1,light=0", Targets::TwoDisjoint, {0, 0, 0}, {0, 1, 0}},
      {"mix_light_025_two_disjoint", "mix:cosine=0.75,light=0.25", Targets::TwoDisjoint, {0, 0, 0}, {0, 1, 0}},
      {"mix_light_05_two_disjoint", "mix:cosine=0.5,light=0.5", Targets::TwoDisjoint, {0, 0, 0}, {0, 1, 0}},
      {"mix_light_1_two_disjoint", "mix:cosine=0,light=1", Targets::TwoDisjoint, {0, 0, 0}, {0, 1, 0}},
      {"mix_light_0_grazing", "mix:cosine=1,light=0", Targets::QuadUpright, {0, 0.3f, 0}, {0, 1, 0}},
      {"mix_light_025_grazing", "mix:cosine=0.75,light=0.25", Targets::QuadUpright, {0, 0.3f, 0}, {0, 1, 0}},
      {"mix_light_05_grazing", "mix:cosine=0.5,light=0.5", Targets::QuadUpright, {0, 0.3f, 0}, {0, 1, 0}},
      {"mix_light_1_grazing", "mix:cosine=0,light=1", Targets::QuadUpright, {0, 0.3f, 0}, {0, 1, 0}},
      {"mix_light_0_book", "mix:cosine=1,light=0", Targets::Book, {0, 300, 300}, {1, 0, 0}},
      {"mix_light_025_book", "mix:cosine=0.75,light=0.25", Targets::Book, {0, 300, 300}, {1, 0, 0}},
      {"mix_light_05_book", "mix:cosine=0.5,light=0.5", Targets::Book, {0, 300, 300}, {1, 0, 0}},
      {"mix_light_1_book", "mix:cosine=0,light=1", Targets::Book, {0, 300, 300}, {1, 0, 0}},
      // Other mixtures: all three kinds of component, and unnormalised weights.
      {"mix_three_way_two_overlapping", "mix:cosine=0.4,uniform-sphere=0.2,light=0.4", Targets::TwoOverlapping,
       {0, 0, 0}, unit(0.3f, 1, 0)},
      {"mix_hemisphere_light_unnormalised", "mix:uniform-hemisphere=3,light=1", Targets::Sphere, {0, 0, 0},
       unit(1, 1, 0)},
      // light-sa: rectangles uniformly in solid angle, spheres by cone.
      {"light_sa_quad_overhead", "light-sa", Targets::QuadOverhead, {0, 0, 0}, {0, 1, 0}},
      {"light_sa_quad_off_centre_tilted", "light-sa", Targets::QuadOverhead, {0.8f, 0, 0.3f}, unit(1, 1, 0)},
      {"light_sa_quad_close_wide", "light-sa", Targets::QuadOverhead, {0.1f, 0.97f, -0.2f}, {0, 1, 0}},
      {"light_sa_quad_farther", "light-sa", Targets::QuadOverhead, {0, -2, 0}, {0, 1, 0}},
      {"light_sa_quad_behind_surface", "light-sa", Targets::QuadOverhead, {0, 0, 0}, {0, -1, 0}},
      {"light_sa_quad_grazing_near_horizon", "light-sa", Targets::QuadUpright, {0, 0, 0}, {0, 1, 0}},
      {"light_sa_quad_grazing_straddles_horizon", "light-sa", Targets::QuadUpright, {0, 0.3f, 0}, {0, 1, 0}},
      {"light_sa_quad_edge_on", "light-sa", Targets::QuadEdgeOn, {0, 0.2f, 0}, {0, 1, 0}},
      {"light_sa_book_light_from_floor", "light-sa", Targets::BookLight, {278, 0, 279.5f}, {0, 1, 0}},
      {"light_sa_book_light_from_ceiling_grazing", "light-sa", Targets::BookLight, {278, 555, 150}, {0, -1, 0}},
      {"light_sa_sphere_overhead", "light-sa", Targets::Sphere, {0, 0, 0}, {0, 1, 0}},
      {"light_sa_sphere_close", "light-sa", Targets::Sphere, {0.1f, 1.35f, 0}, {0, 1, 0}},
      {"light_sa_sphere_farther", "light-sa", Targets::Sphere, {0, -1.5f, 0}, {0, 1, 0}},
      {"light_sa_sphere_near_horizon", "light-sa", Targets::SphereHorizon, {0, 0, 0}, {0, 1, 0}},
      {"light_sa_sphere_from_inside", "light-sa", Targets::Sphere, {0.1f, 2.1f, 0}, {0, 1, 0}},
      {"light_sa_two_overlapping", "light-sa", Targets::TwoOverlapping, {0, 0, 0}, {0, 1, 0}},
      {"light_sa_book", "light-sa", Targets::Book, {400, 0, 150}, {0, 1, 0}},
      // Target choice by power: 40 : 1 between two equal quads, and the two-light scene.
      {"light_sa_two_powers", "light-sa", Targets::TwoPowers, {0, 0, 0}, {0, 1, 0}},
      {"light_sa_two_lights_scene", "light-sa", Targets::TwoLightsScene, {278, 0, 279.5f}, {0, 1, 0}},
      {"mix_light_sa_025", "mix:cosine=0.75,light-sa=0.25", Targets::TwoDisjoint, {0, 0, 0}, {0, 1, 0}},
      {"mix_light_sa_05_grazing", "mix:cosine=0.5,light-sa=0.5", Targets::QuadUpright, {0, 0.3f, 0}, {0, 1, 0}},
      {"mix_light_and_light_sa", "mix:cosine=0.4,light=0.3,light-sa=0.3", Targets::TwoPowers, {0, 0, 0}, unit(0.2f, 1, 0)},
      // specular-objects: the glass sphere of the book's scene; the metal box's
      // six faces and the metal sphere of the glossy one.
      {"specular_objects_book_from_floor", "specular-objects", Targets::Book, {400, 0, 150}, {0, 1, 0}},
      // (From the back wall: from the floor, the box's bottom face lies in the
      // shading point's plane, and its share of the samples along the horizon.)
      {"specular_objects_glossy_from_back_wall", "specular-objects", Targets::GlossyScene, {278, 300, 555},
       {0, 0, -1}},
      {"specular_objects_glossy_from_red_wall", "mix:cosine=0.8,specular-objects=0.2", Targets::GlossyScene,
       {0, 300, 300}, {1, 0, 0}},
      // The emitters that nee-mis samples (chosen by power; by area from where a
      // light looks flat, else in solid angle): both flat, both not, one of each.
      {"nee_emitters_two_powers", "nee-mis", Targets::TwoPowers, {0, 0, 0}, {0, 1, 0}, true},
      {"nee_emitters_book", "nee-mis", Targets::Book, {400, 0, 150}, {0, 1, 0}, true},
      {"nee_emitters_two_powers_close", "nee-mis", Targets::TwoPowers, {0, 0.9f, 0}, {0, 1, 0}, true},
      {"nee_emitters_two_powers_one_flat", "nee-mis", Targets::TwoPowers, {-0.9f, 0.8f, 0}, {0, 1, 0}, true},
      {"nee_emitters_book_close_to_the_light", "nee-mis", Targets::Book, {300, 500, 250}, {0, 1, 0}, true},
      // Chosen by the light tree (each emitter's probability from the point,
      // the set's density their sum), among lamps facing either way.
      {"nee_emitters_tree_many_lamps_among_them", "nee-mis+lights:tree", Targets::ManyLamps, {0.3f, 0.9f, 0.8f},
       {0, 1, 0}, true},
      // The environment map's 2D distribution: a sun inside one texel, a
      // black half (its pdf zero there), a constant map (uniform over the sphere).
      {"environment_sub_texel_sun", "environment", Targets::SubTexelSun, {0, 0, 0}, {0, 1, 0}},
      {"environment_sub_texel_sun_oblique", "environment", Targets::SubTexelSun, {0, 0, 0}, unit(1, 2, 3)},
      {"environment_sub_texel_sun_mix", "mix:cosine=0.5,environment=0.5", Targets::SubTexelSun, {0, 0, 0}, unit(0, 1, 1)},
      {"environment_black_half", "environment", Targets::BlackHalf, {0, 0, 0}, {0, 1, 0}},
      {"environment_black_half_mix", "mix:cosine=0.5,environment=0.5", Targets::BlackHalf, {0, 0, 0}, {0, 0, -1}},
      {"environment_constant", "environment", Targets::ConstantMap, {0, 0, 0}, unit(-1, 2, 1)},
  };
  return cases;
}

// Every technique in the table, alone and in a mixture, from the shading
// points where sampling code breaks: inside a sphere target, a quad seen
// edge-on, a quad straddling the horizon (grazing), and a normal along -z (the
// branch point of the frame). A new technique gets these with no edit here.
const std::vector<ChiCase>& table_cases() {
  static const std::vector<ChiCase> cases = [] {
    struct EdgePoint {
      const char* name;
      Targets targets;
      Vec3 origin, normal;
    };
    const EdgePoint points[] = {
        {"inside_sphere", Targets::Sphere, {0.1f, 2.1f, 0}, {0, 1, 0}},
        {"quad_edge_on", Targets::QuadEdgeOn, {0, 0.2f, 0}, {0, 1, 0}},
        {"grazing", Targets::QuadUpright, {0, 0.3f, 0}, {0, 1, 0}},
        {"minus_z", Targets::TwoOverlapping, {0, 0, 0}, {0, 0, -1}},
    };
    static std::deque<std::string> texts;  // the names and strategies the cases point into
    std::vector<ChiCase> out;
    for (int i = 0; i < kTechniqueCount; ++i) {
      const TechniqueInfo& t = technique_info(static_cast<Technique>(i));
      std::string id(t.name);
      std::replace(id.begin(), id.end(), '-', '_');
      const std::string partner = t.name == "cosine" ? "uniform-sphere" : "cosine";
      for (const EdgePoint& p : points) {
        for (const bool mixed : {false, true}) {
          texts.push_back("table_" + id + (mixed ? "_mix_" : "_") + p.name);
          const char* name = texts.back().c_str();
          texts.push_back(mixed ? "mix:" + partner + "=0.5," + std::string(t.name) + "=0.5" : std::string(t.name));
          out.push_back({name, texts.back().c_str(), p.targets, p.origin, p.normal});
        }
        // Alone at its parameter's ends too (the narrowest lobe, the widest).
        if (!t.parameter.empty())
          for (const auto& [end, value] : {std::pair{"min", t.parameter_min}, std::pair{"max", t.parameter_max}}) {
            texts.push_back("table_" + id + "_" + end + "_" + p.name);
            const char* name = texts.back().c_str();
            char text[64];
            std::snprintf(text, sizeof text, "%s:%g", std::string(t.name).c_str(), static_cast<double>(value));
            texts.push_back(text);
            out.push_back({name, texts.back().c_str(), p.targets, p.origin, p.normal});
          }
      }
    }
    return out;
  }();
  return cases;
}

std::vector<ChiCase> all_cases() {
  std::vector<ChiCase> v = chi_cases();
  v.insert(v.end(), table_cases().begin(), table_cases().end());
  return v;
}
const std::vector<ChiCase>& every_case() {
  static const std::vector<ChiCase> v = all_cases();
  return v;
}

// Every case is one test of the family; Sidak keeps the family's false-alarm
// rate at 1% for the whole list.
// Both samplers run every case but the emitter sets'.
double alpha_per_test() { return stats::sidak_alpha(kFamilyAlpha, 2 * static_cast<int>(every_case().size())); }

struct PlanUnderTest {
  std::unique_ptr<Scene> scene;
  SamplingPlan plan;
  Vec3 origin, normal;
};

PlanUnderTest bind(const ChiCase& c) {
  PlanUnderTest p;
  p.scene = make_scene(c.targets);
  p.plan = SamplingPlan::make(Strategy::parse(c.strategy), *p.scene);
  p.origin = c.origin;
  p.normal = normalize(c.normal);
  return p;
}

// The density under test: the plan's mixture, or its emitter set.
double case_density(const ChiCase& c, const PlanUnderTest& p, const Vec3& d) {
  return static_cast<double>(c.emitter_set ? p.plan.emitters.pdf(p.origin, d) : p.plan.pdf(p.origin, p.normal, d));
}

Outcome run_case(const ChiCase& c, std::uint64_t seed, Sampler which = Sampler::OnePath) {
  const PlanUnderTest p = bind(c);
  if (!c.emitter_set) return chi_square::check_plan(p.plan, p.origin, p.normal, which, kSamples, seed, kGrid);
  const Frame frame(p.normal);
  auto density = [&](const Vec3& d) { return case_density(c, p, d); };
  const auto edges = chi_square::plan_edges(p.plan, p.origin, p.normal, frame);
  if (which == Sampler::Packet) {
    // The packet kernel's light sample (packet.h's sample_emitters), a batch at
    // a time, with the same three numbers per draw as the one-path sampler.
    std::vector<DirectionSample> batch;
    std::size_t next = 0;
    auto packets = [&](Rng& rng) {
      if (next == batch.size()) {
        std::vector<PlanDraw> draws(256);
        for (PlanDraw& d : draws) {
          d.point = p.origin, d.normal = p.normal;
          d.u_choice = rng.next_u32(), d.u1 = rng.uniform(), d.u2 = rng.uniform();
        }
        batch.resize(draws.size());
        sample_emitters(best_packet_isa(), p.plan, draws.data(), draws.size(), batch.data());
        next = 0;
      }
      return batch[next++];
    };
    return run_chi_square(frame, packets, density, edges, seed);
  }
  auto sampler = [&](Rng& rng) {
    const std::uint32_t uc = rng.next_u32();
    const float u1 = rng.uniform(), u2 = rng.uniform();
    return p.plan.emitters.sample(p.origin, uc, u1, u2);
  };
  return run_chi_square(frame, sampler, density, edges, seed);
}

class ChiSquare : public ::testing::TestWithParam<int> {};

void expect_follows_pdf(const ChiCase& c, const Outcome& o) {
  const double alpha = alpha_per_test();
  std::printf("[chi2] %-40s chi2 %10.2f  dof %4d  p %.4g  (alpha %.3g, pooled %d, mismatches %llu)\n", c.name,
              o.chi.statistic, o.chi.dof, o.chi.p_value, alpha, o.chi.pooled_cells,
              static_cast<unsigned long long>(o.pdf_mismatch));
  EXPECT_EQ(o.bad_pdf, 0u) << "samples whose own pdf is zero, negative or not finite";
  EXPECT_EQ(o.empty_samples, 0u) << "samples with no direction where the pdf integrates to 1";
  EXPECT_EQ(o.chi.zero_cell_hits, 0u) << "samples in cells where the pdf integrates to zero";
  // A handful of samples within float rounding of a target's edge may be
  // judged off the target by the pdf's re-intersection; anything more is a
  // disagreement between sample_X and X_pdf.
  EXPECT_LE(o.pdf_mismatch, 10u) << "samples whose returned pdf disagrees with the pdf function";
  // The test has power only with several cells; every case is built to have them.
  EXPECT_GE(o.chi.dof, 3);
  EXPECT_GT(o.chi.p_value, alpha) << "chi2 = " << o.chi.statistic << ", dof = " << o.chi.dof;
}

TEST_P(ChiSquare, SamplesFollowPdf) {
  const ChiCase& c = every_case()[GetParam()];
  const Outcome o = run_case(c, 1000 + static_cast<std::uint64_t>(GetParam()));
  expect_follows_pdf(c, o);
}

// The same through the packet kernel's sampler, the code that renders.
TEST_P(ChiSquare, PacketSamplesFollowPdf) {
  const ChiCase& c = every_case()[GetParam()];
  if (c.emitter_set) {
    ASSERT_TRUE(bind(c).plan.emitters.solid_angle) << "sample_emitters draws a set drawn by solid angle";
  }
  expect_follows_pdf(c, run_case(c, 5000 + static_cast<std::uint64_t>(GetParam()), Sampler::Packet));
}

// The pdf integrates to 1 over the sphere; for `light`, whose pdf is zero off
// the targets, that is the integral over the directions that reach a target.
// Tolerance: the quadrature's own error, measured on these cases, is at most
// 4.3e-5 (the book light seen edge-on from the ceiling, a sliver 0.008 thick
// in cos theta where the pdf reaches ~400/sr) and below 2e-5 everywhere else;
// float pdf evaluation adds ~1e-7. 2e-4 keeps a 4x margin over the worst of
// that and still catches every real normalisation slip (a wrong solid-angle
// Jacobian, a target counted twice or with the wrong 1/targets, a mixture
// weight not normalised: all percent-level or worse).
TEST_P(ChiSquare, PdfIntegratesToOne) {
  const ChiCase& c = every_case()[GetParam()];
  const PlanUnderTest p = bind(c);
  const Frame frame(p.normal);
  auto density = [&](const Vec3& d) { return case_density(c, p, d); };
  double total = 0.0;
  const chi_square::Grid grid = chi_square::follow_lobe(kGrid, frame, density);  // as check_plan's
  for (double m : chi_square::cell_masses(grid, frame, density, chi_square::plan_edges(p.plan, p.origin, p.normal, frame)))
    total += m;
  std::printf("[integral] %-40s %.8f\n", c.name, total);
  EXPECT_NEAR(total, 1.0, 2e-4);
}

INSTANTIATE_TEST_SUITE_P(Techniques, ChiSquare, ::testing::Range(0, static_cast<int>(every_case().size())),
                         [](const ::testing::TestParamInfo<int>& param_info) {
                           return std::string(every_case()[param_info.param].name);
                         });

// ---- The test itself has power: wrong pdfs are rejected ------------------

// The nee_emitters cases reach both of nee-mis's light samplers: which of
// the emitters each origin samples by area (leaf::area_suffices), by name.
TEST(ChiSquareCases, NeeEmitterCasesReachBothSamplers) {
  const std::pair<const char*, std::vector<bool>> expected[] = {
      {"nee_emitters_two_powers", {true, true}},         {"nee_emitters_book", {true}},
      {"nee_emitters_two_powers_close", {false, false}}, {"nee_emitters_two_powers_one_flat", {false, true}},
      {"nee_emitters_book_close_to_the_light", {false}},
  };
  for (const auto& [name, by_area] : expected) {
    const auto c = std::find_if(every_case().begin(), every_case().end(),
                                [&](const ChiCase& x) { return std::string(x.name) == name; });
    ASSERT_NE(c, every_case().end()) << name;
    const PlanUnderTest p = bind(*c);
    ASSERT_EQ(p.plan.emitters.quads.size(), by_area.size()) << name;
    for (std::size_t i = 0; i < by_area.size(); ++i)
      EXPECT_EQ(leaf::area_suffices(p.plan.emitters.quads[i].axes, p.origin), by_area[i]) << name << " emitter " << i;
  }
}

TEST(ChiSquareHarness, RejectsCosineSamplesAgainstUniformPdf) {
  const Vec3 n(0, 0, 1);
  const Frame frame(n);
  auto sampler = [&](Rng& rng) {
    const float u1 = rng.uniform(), u2 = rng.uniform();
    return sample_cosine_hemisphere(Onb(n), u1, u2);
  };
  auto density = [&](const Vec3& d) { return static_cast<double>(uniform_hemisphere_pdf(n, d)); };
  const Outcome o = run_chi_square(frame, sampler, density, {}, 7, 100'000);
  EXPECT_LT(o.chi.p_value, 1e-12);
}

TEST(ChiSquareHarness, FlagsSamplesWherePdfIsZero) {
  const Vec3 n(0, 0, 1);
  const Frame frame(n);
  auto sampler = [&](Rng& rng) {
    const float u1 = rng.uniform(), u2 = rng.uniform();
    return sample_uniform_sphere(u1, u2);
  };
  auto density = [&](const Vec3& d) { return static_cast<double>(uniform_hemisphere_pdf(n, d)); };
  const Outcome o = run_chi_square(frame, sampler, density, {}, 8, 10'000);
  EXPECT_GT(o.chi.zero_cell_hits, 4000u);
}

// A wrong warp inside a narrow lobe: directions uniform in theta within a 10
// degree cone, judged against the cone's pdf (uniform in solid angle, so in
// cos theta). The whole cone lies in the first of 20 rows of equal cos width,
// where only azimuths are tested: the plain grid passes it. follow_lobe's
// rows of equal mass cut the cone into 20 and reject it; the right warp passes.
TEST(ChiSquareHarness, RejectsAWrongWarpInsideANarrowCone) {
  const Vec3 n(0, 0, 1);
  const Frame frame(n);
  Strategy strategy = Strategy::parse("uniform-cone:10");
  const std::unique_ptr<Scene> scene = make_scene(Targets::Sphere);
  const SamplingPlan plan = SamplingPlan::make(strategy, *scene);
  const double theta_max = 10.0 * std::numbers::pi / 180.0;
  auto wrong = [&](Rng& rng) {
    const double theta = theta_max * rng.uniform(), phi = 2.0 * std::numbers::pi * rng.uniform();
    const Vec3 d(static_cast<float>(std::sin(theta) * std::cos(phi)), static_cast<float>(std::sin(theta) * std::sin(phi)),
                 static_cast<float>(std::cos(theta)));
    return DirectionSample{d, plan.pdf(Vec3(0.0f), n, d)};
  };
  auto density = [&](const Vec3& d) { return static_cast<double>(plan.pdf(Vec3(0.0f), n, d)); };
  const std::vector<chi_square::Point> edges = chi_square::technique_edges(plan, n, frame);
  const chi_square::Grid plain{20, 40};
  const chi_square::Grid rows = chi_square::follow_lobe(plain, frame, density);
  ASSERT_GE(rows.z_cells, 20);
  EXPECT_GT(rows.z_edges[19], std::cos(theta_max) - 1e-3);  // 20 rows inside the cone
  const double alpha = 1e-3;
  const Outcome blind = chi_square::run(plain, frame, wrong, density, edges, 21, 100'000);
  const Outcome sharp = chi_square::run(rows, frame, wrong, density, edges, 21, 100'000);
  std::printf("uniform in theta in a 10 degree cone: plain rows p = %.3g, rows of equal mass p = %.3g\n",
              blind.chi.p_value, sharp.chi.p_value);
  EXPECT_TRUE(blind.passed(alpha));  // what the harness could not see
  EXPECT_FALSE(sharp.passed(alpha));
  EXPECT_LT(sharp.chi.p_value, 1e-12);
  // The right warp, the technique's own sampler, passes on the same rows.
  const Outcome right = chi_square::run(rows, frame, chi_square::plan_sampler(plan, Vec3(0.0f), n, Sampler::OnePath),
                                        density, edges, 22, 100'000);
  EXPECT_TRUE(right.passed(alpha)) << right.chi.p_value;
}

// A subtle error: light samples judged against the pdf of the same quad moved
// by 3% of its size. The statistic must see it.
TEST(ChiSquareHarness, RejectsSlightlyWrongLightPdf) {
  Scene scene = *make_scene(Targets::QuadOverhead);
  const Quad shifted = make_quad({-0.47f, 1, -0.5f}, {1, 0, 0}, {0, 0, 1}, 0);
  const Vec3 origin(0, 0, 0), n(0, 1, 0);
  const SamplingPlan plan = SamplingPlan::make(Strategy::parse("light"), scene);
  const Frame frame(n);
  auto sampler = [&](Rng& rng) {
    const std::uint32_t u0 = rng.next_u32();
    const float u1 = rng.uniform(), u2 = rng.uniform();
    return plan.book_targets.sample(origin, u0, u1, u2);
  };
  auto density = [&](const Vec3& d) { return static_cast<double>(quad_area_pdf(shifted, origin, d)); };
  Scene shifted_scene = scene;
  shifted_scene.quads[0] = shifted;
  const Outcome o =
      run_chi_square(frame, sampler, density, target_outlines(shifted_scene, origin, frame), 9, 200'000);
  EXPECT_TRUE(o.chi.p_value < 1e-6 || o.chi.zero_cell_hits > 0);
}

// ---- The p-value machinery against textbook values ------------------------

TEST(ChiSquareDistribution, MatchesKnownQuantiles) {
  // 95% quantiles of chi-square with 1, 10 and 100 degrees of freedom.
  EXPECT_NEAR(stats::chi_square_survival(3.841458820694124, 1), 0.05, 1e-9);
  EXPECT_NEAR(stats::chi_square_survival(18.307038053275146, 10), 0.05, 1e-9);
  EXPECT_NEAR(stats::chi_square_survival(124.34211340400407, 100), 0.05, 1e-8);
  // 2 dof is exponential: Q = exp(-x / 2), on both sides of the series/fraction switch.
  for (double x : {0.5, 1.9, 2.1, 7.0, 40.0, 300.0})
    EXPECT_NEAR(stats::chi_square_survival(x, 2) / std::exp(-0.5 * x), 1.0, 1e-12) << x;
  // P + Q = 1 and continuity across the switch at x = a + 1.
  for (double a : {0.5, 3.0, 399.5})
    for (double x : {a + 1.0 - 1e-9, a + 1.0, a + 1.0 + 1e-9, 0.3 * a, 3.0 * a})
      EXPECT_NEAR(stats::gamma_p(a, x) + stats::gamma_q(a, x), 1.0, 1e-12) << a << " " << x;
  EXPECT_NEAR(stats::gamma_q(399.5, 400.5 - 1e-9), stats::gamma_q(399.5, 400.5 + 1e-9), 1e-9);
  EXPECT_EQ(stats::chi_square_survival(0.0, 5), 1.0);
}

TEST(ChiSquareDistribution, SidakAndNormalQuantiles) {
  EXPECT_NEAR(stats::sidak_alpha(0.01, 1), 0.01, 1e-15);
  const double a = stats::sidak_alpha(0.01, 50);
  EXPECT_NEAR(std::pow(1.0 - a, 50), 0.99, 1e-12);
  EXPECT_NEAR(stats::normal_two_sided_quantile(0.05), 1.959963984540054, 1e-9);
  EXPECT_NEAR(stats::normal_two_sided_tail(3.0), 0.0026997960632601866, 1e-12);
}

TEST(ChiSquareDistribution, PoolsSmallCellsAndCountsImpossibleSamples) {
  const std::vector<std::uint64_t> observed = {10, 12, 1, 2, 3, 0};
  const std::vector<double> expected = {11.0, 11.0, 1.0, 2.0, 3.0, 0.0};
  auto r = stats::chi_square_test(observed, expected);
  EXPECT_EQ(r.pooled_cells, 3);
  EXPECT_EQ(r.cells, 3);
  EXPECT_EQ(r.dof, 2);
  EXPECT_NEAR(r.statistic, 1.0 / 11.0 + 1.0 / 11.0, 1e-12);
  EXPECT_EQ(r.zero_cell_hits, 0u);
  const std::vector<std::uint64_t> stray = {10, 12, 1, 2, 3, 4};
  EXPECT_EQ(stats::chi_square_test(stray, expected).zero_cell_hits, 4u);
}

}  // namespace
}  // namespace pdflab

namespace pdflab {
namespace {

// light-sa and nee-mis choose a target in proportion to its power, with 2%
// of the choices uniform (TargetSet::by_point; the point receives from
// both lamps); light (the book's) uniformly. Counted directly: which quad does
// each sample reach?
TEST(TargetChoice, ProportionalToPowerForLightSaUniformForLight) {
  const std::unique_ptr<Scene> scene = make_scene(Targets::TwoPowers);
  const SamplingPlan plan = SamplingPlan::make(Strategy::parse("light-sa"), *scene);
  ASSERT_EQ(plan.power_targets.quads.size(), 2u);
  EXPECT_NEAR(plan.power_targets.quads[0].probability, 40.0 / 41.0, 1e-6);
  EXPECT_NEAR(plan.book_targets.quads[0].probability, 0.5, 1e-6);
  EXPECT_NEAR(plan.emitters.quads[0].probability, 40.0 / 41.0, 1e-6);

  const Vec3 origin(0, 0, 0);
  const double by_power = kLightChoiceFloor / 2.0 + (1.0 - kLightChoiceFloor) * 40.0 / 41.0;
  EXPECT_NEAR(plan.power_targets.probabilities_at(origin)[0], by_power, 1e-6);
  EXPECT_NEAR(plan.emitters.probabilities_at(origin)[0], by_power, 1e-6);
  EXPECT_EQ(plan.book_targets.probabilities_at(origin)[0], 0.5f);
  for (const auto& [set, expected] : {std::pair{&plan.power_targets, by_power}, std::pair{&plan.book_targets, 0.5}}) {
    Rng rng(77, 1);
    const int n = 200000;
    int bright = 0, dim = 0;
    for (int i = 0; i < n; ++i) {
      const std::uint32_t uc = rng.next_u32();
      const float u1 = rng.uniform(), u2 = rng.uniform();
      const DirectionSample ds = set->sample(origin, uc, u1, u2);
      bright += quad_hit_distance(scene->quads[0], origin, ds.direction) > 0.0f;
      dim += quad_hit_distance(scene->quads[1], origin, ds.direction) > 0.0f;
    }
    EXPECT_GE(bright + dim, n - 5);  // every sample reaches one of them (edge rounding aside)
    const double se = std::sqrt(expected * (1.0 - expected) / n);
    EXPECT_NEAR(static_cast<double>(bright) / n, expected, 5.0 * se);
  }
}

// ---- The bsdf technique at a microfacet conductor ---------------------------------
// Directions are binned about the mirror direction after a stereographic
// zoom by 1/s (tan(theta'/2) = tan(theta/2) / s, theta from the mirror
// direction): a bijection of the sphere that spreads a lobe of width alpha
// over the grid for every alpha from 1e-3 to 1, with the density carried
// across by its Jacobian, s^2 (1 + r'^2)^2 / (1 + r^2)^2 (r = tan(theta/2)).

struct Zoom {
  glm::dvec3 axis;
  double s;
  Zoom(const Vec3& a, double scale) : axis(glm::normalize(glm::dvec3(a))), s(scale) {}
  // d to d' (and the density factor p'(d') / p(d)), or back with `inverse`.
  Vec3 map(const Vec3& d, bool inverse, double* factor = nullptr) const {
    const glm::dvec3 v(d);
    const double z = glm::dot(v, axis);
    const glm::dvec3 perp = v - axis * z;
    const double len = glm::length(perp);
    if (!(1.0 + z > 1e-300) || len == 0.0) {
      if (factor) *factor = len == 0.0 && z > 0.0 ? s * s : 1.0 / (s * s);
      return d;
    }
    const double r = len / (1.0 + z);
    const double r2 = inverse ? r * s : r / s;
    const double z2 = (1.0 - r2 * r2) / (1.0 + r2 * r2), len2 = 2.0 * r2 / (1.0 + r2 * r2);
    const double forward_r = inverse ? r2 : r, zoomed_r = inverse ? r : r2;
    if (factor) *factor = s * s * std::pow(1.0 + zoomed_r * zoomed_r, 2) / std::pow(1.0 + forward_r * forward_r, 2);
    const glm::dvec3 out = axis * z2 + perp * (len2 / len);
    return Vec3(glm::normalize(out));
  }
};

struct GlossyCase {
  float alpha;
  float view_degrees;
};

std::vector<GlossyCase> glossy_cases() {
  std::vector<GlossyCase> out;
  for (const float alpha : {1e-3f, 1e-2f, 0.1f, 0.5f, 1.0f})
    for (const float view : {0.0f, 60.0f, 85.0f}) out.push_back({alpha, view});
  return out;
}

// The reflection density's jump: directions reflected about the normals on
// the horizon (where D is alpha^2 / pi, and 0 beyond).
std::vector<chi_square::Point> horizon_reflections(const Vec3& wo, const Frame& frame, const Zoom& zoom,
                                                   const Vec3& n) {
  std::vector<chi_square::Point> out;
  const Onb onb(n);
  for (int i = 0; i < 16384; ++i) {
    const double phi = 2.0 * 3.14159265358979323846 * (i + 0.5) / 16384;
    const Vec3 m = onb.to_world(Vec3(static_cast<float>(std::cos(phi)), static_cast<float>(std::sin(phi)), 0.0f));
    if (dot(wo, m) <= 0.0f) continue;
    out.push_back(frame.coordinates(zoom.map(leaf::reflect(-wo, m), false)));
  }
  return out;
}

// A draw seen through the zoom: its direction mapped, its pdf times the map's Jacobian.
DirectionSample through_zoom(const Zoom& zoom, DirectionSample d) {
  double factor = 1.0;
  d.direction = zoom.map(d.direction, false, &factor);
  d.pdf = static_cast<float>(d.pdf * factor);
  return d;
}

// The density of `surface`'s plan at a zoomed direction: p(d) times the
// zoom's Jacobian p'(d') / p(d) at the pair.
double density_through_zoom(const SamplingPlan& plan, const SurfaceLobe& surface, const Vec3& origin, const Vec3& n,
                            const Zoom& zoom, const Vec3& zoomed) {
  double factor = 1.0;
  const Vec3 d = zoom.map(zoomed, true, &factor);
  return static_cast<double>(plan.pdf(surface, origin, n, d)) * factor;
}

// A plan's draw at a microfacet surface, zoomed, against its pdf, zoomed.
Outcome glossy_check(const SamplingPlan& plan, const Vec3& origin, const Vec3& n, const GlossyCase& c,
                     std::uint64_t seed, bool with_targets) {
  const Onb onb(n);
  const double t = c.view_degrees * 3.14159265358979323846 / 180.0;
  const Vec3 wo = onb.to_world(Vec3(static_cast<float>(std::sin(t)), 0.0f, static_cast<float>(std::cos(t))));
  const SurfaceLobe surface{true, c.alpha, wo};
  const Zoom zoom(leaf::reflect(-wo, n), std::min(1.0, 3.0 * c.alpha));
  const Frame frame(Vec3(zoom.axis));
  auto draw = [&](Rng& rng) {
    const std::uint32_t u0 = rng.next_u32();
    const float u1 = rng.uniform(), u2 = rng.uniform();
    const std::uint32_t u3 = rng.next_u32();
    return through_zoom(zoom, plan.sample_at(surface, origin, n, u1, u2, u0, u3));
  };
  auto density = [&](const Vec3& zoomed) { return density_through_zoom(plan, surface, origin, n, zoom, zoomed); };
  std::vector<chi_square::Point> edges = horizon_reflections(wo, frame, zoom, n);
  if (with_targets) {
    // The targets' outlines, traced about the unzoomed frame, then zoomed.
    const Frame plain(n);
    for (const chi_square::Point& q : target_outlines(*plan.scene, origin, plain))
      edges.push_back(frame.coordinates(zoom.map(plain.direction(q.z, std::cos(q.phi), std::sin(q.phi)), false)));
  }
  return run_chi_square(frame, draw, density, edges, seed, 400'000);
}

TEST(ChiSquareVndf, BsdfAloneFromNormalToGrazingAtEveryAlpha) {
  const Scene scene = *make_scene(Targets::None);
  const SamplingPlan plan = SamplingPlan::make(Strategy::parse("bsdf"), scene);
  const std::vector<GlossyCase> cases = glossy_cases();
  const double alpha = stats::sidak_alpha(kFamilyAlpha, static_cast<int>(cases.size()));
  std::uint64_t seed = 3600;
  for (const GlossyCase& c : cases) {
    const Outcome o = glossy_check(plan, Vec3(0.0f), Vec3(0, 0, 1), c, seed++, false);
    std::printf("[vndf] alpha %-6g view %2g: p = %.3g, integral %.6f, mismatched pdfs %llu\n", c.alpha,
                c.view_degrees, o.chi.p_value, o.integral, static_cast<unsigned long long>(o.pdf_mismatch));
    EXPECT_TRUE(o.passed(alpha)) << "alpha " << c.alpha << ", view " << c.view_degrees << ": p = " << o.chi.p_value
                                 << ", zero-cell hits " << o.chi.zero_cell_hits << ", bad pdfs " << o.bad_pdf;
    EXPECT_NEAR(o.integral, 1.0, 2e-3) << "alpha " << c.alpha << ", view " << c.view_degrees;
    EXPECT_LT(o.pdf_mismatch, 400u) << "alpha " << c.alpha << ", view " << c.view_degrees;
  }
}

// The zoomed harness has the power to see a small error: samples drawn at
// alpha judged against the density at 1.05 alpha must fail.
TEST(ChiSquareVndf, RejectsASlightlyWrongDensity) {
  const Scene scene = *make_scene(Targets::None);
  const SamplingPlan plan = SamplingPlan::make(Strategy::parse("bsdf"), scene);
  const Vec3 n(0, 0, 1);
  for (const float alpha : {1e-3f, 0.1f}) {
    const Vec3 wo(std::sin(1.0f), 0.0f, std::cos(1.0f));  // 57 degrees
    const SurfaceLobe drawn{true, alpha, wo}, judged{true, 1.05f * alpha, wo};
    const Zoom zoom(leaf::reflect(-wo, n), 3.0 * alpha);
    const Frame frame(Vec3(zoom.axis));
    auto draw = [&](Rng& rng) {
      const float u1 = rng.uniform(), u2 = rng.uniform();
      return through_zoom(zoom, plan.sample_at(drawn, Vec3(0.0f), n, u1, u2, 0, 0));
    };
    auto density = [&](const Vec3& zoomed) { return density_through_zoom(plan, judged, Vec3(0.0f), n, zoom, zoomed); };
    const Outcome o = run_chi_square(frame, draw, density, horizon_reflections(wo, frame, zoom, n), 3650, 400'000);
    std::printf("[vndf] drawn at alpha %g, judged at 1.05 alpha: p = %.3g\n", alpha, o.chi.p_value);
    EXPECT_LT(o.chi.p_value, 1e-6) << "alpha " << alpha;
  }
}

// Every mixture with bsdf, at a microfacet surface under a sphere target
// and a quad target (light and light-sa aim at them, bsdf at the lobe).
TEST(ChiSquareVndf, MixturesWithBsdf) {
  const Scene scene = *make_scene(Targets::TwoDisjoint);
  const char* strategies[] = {"mix:cosine=0.5,bsdf=0.5", "mix:bsdf=0.5,light=0.5", "mix:bsdf=0.7,light-sa=0.3",
                              "mix:bsdf=0.3,uniform-sphere=0.3,light-sa=0.4", "mix:bsdf=0.5,cosine-power:8=0.5"};
  const GlossyCase cases[] = {{0.05f, 30.0f}, {0.3f, 60.0f}, {1.0f, 85.0f}};
  const int tests = static_cast<int>(std::size(strategies) * std::size(cases));
  const double alpha = stats::sidak_alpha(kFamilyAlpha, tests);
  std::uint64_t seed = 3700;
  for (const char* text : strategies) {
    const SamplingPlan plan = SamplingPlan::make(Strategy::parse(text), scene);
    for (const GlossyCase& c : cases) {
      const Outcome o = glossy_check(plan, Vec3(0.0f), Vec3(0, 1, 0), c, seed++, true);
      std::printf("[vndf] %-44s alpha %-5g view %2g: p = %.3g, integral %.6f\n", text, c.alpha, c.view_degrees,
                  o.chi.p_value, o.integral);
      EXPECT_TRUE(o.passed(alpha)) << text << " alpha " << c.alpha << ", view " << c.view_degrees
                                   << ": p = " << o.chi.p_value << ", zero-cell hits " << o.chi.zero_cell_hits;
      EXPECT_NEAR(o.integral, 1.0, 3e-3) << text << " alpha " << c.alpha;
    }
  }
}

// ---- The environment map's 2D distribution ---------------------------------

// A constant map is uniform over the sphere: each texel's probability is its
// solid angle over 4 pi, and its density 1 / (4 pi) everywhere, to float.
TEST(EnvironmentMap, ConstantMapIsUniformOverTheSphere) {
  const std::shared_ptr<const Environment> map = scene_map(Targets::ConstantMap);
  Rng rng(3, 1);
  for (int i = 0; i < 1000; ++i) {
    const Environment::Sample s = map->sample(rng.uniform(), rng.uniform());
    ASSERT_FALSE(s.none);
    EXPECT_NEAR(length(s.direction), 1.0f, 1e-6f);
    EXPECT_NEAR(s.pdf, 1.0 / (4.0 * std::numbers::pi), 1e-7);
    EXPECT_EQ(s.pdf, map->pdf(s.direction)) << i;
  }
  EXPECT_NEAR(map->luminance_integral(), 4.0 * std::numbers::pi, 1e-9);
}

// The marginal and conditional CDFs: a texel is chosen with the share of
// luminance times solid angle that it holds; a black texel never.
TEST(EnvironmentMap, TexelsAreChosenInProportionToTheirLight) {
  const std::shared_ptr<const Environment> sun = scene_map(Targets::SubTexelSun);
  const double z0 = std::cos(std::numbers::pi * 8 / 32), z1 = std::cos(std::numbers::pi * 9 / 32);
  const double sun_sr = 2.0 * std::numbers::pi / 64 * (z0 - z1);
  const double sun_light = luminance(5000.0, 4800.0, 4500.0) * sun_sr;
  const double expected = sun_light / (sun_light + 0.5 * (4.0 * std::numbers::pi - sun_sr));
  EXPECT_NEAR(sun->texel_probability(20, 8), expected, 1e-9);
  EXPECT_GT(expected, 0.8);
  EXPECT_NEAR(sun->texel_density(20, 8), expected / sun_sr, 1e-3 * expected / sun_sr);
  const std::shared_ptr<const Environment> half = scene_map(Targets::BlackHalf);
  Rng rng(4, 1);
  for (int i = 0; i < 10000; ++i) {
    const Environment::Sample s = half->sample(rng.uniform(), rng.uniform());
    int x, y;
    half->texel_of(s.direction, x, y);
    ASSERT_GE(x, 16) << "a direction drawn where the map is black";
    EXPECT_EQ(half->pdf(s.direction), s.pdf);
  }
  EXPECT_EQ(half->pdf(Vec3(0.0f, 0.0f, 1.0f)), 0.0f) << "phi = pi / 2: the black half";
  EXPECT_GT(half->pdf(Vec3(0.0f, 0.0f, -1.0f)), 0.0f) << "phi = 3 pi / 2: lit";
}

// The environment map's sampler reaches its whole support: from u1 = 0 the
// zenith itself, from the largest u1 the nadir to within a float step of the
// last row's share, on a constant map whose every texel is lit.
TEST(EnvironmentMap, ReachesBothPoles) {
  const Environment map(std::vector<float>(8 * 4 * 3, 1.0f), 8, 4, 1.0f, 0.0f);
  for (const float u2 : {0.0f, 0.5f, kLargestUniform}) {
    const Environment::Sample top = map.sample(0.0f, u2), bottom = map.sample(kLargestUniform, u2);
    EXPECT_EQ(top.direction.y, 1.0f) << u2;
    EXPECT_LT(bottom.direction.y, -1.0f + 1e-6f) << u2;
    EXPECT_GT(top.pdf, 0.0f);
    EXPECT_GT(bottom.pdf, 0.0f);
  }
}

// The harness sees the Jacobian: the same samples judged against a density
// that forgets sin theta (every texel taken as 4 pi / (W H) sr) are rejected.
TEST(EnvironmentMap, HarnessRejectsADensityWithoutTheJacobian) {
  const std::unique_ptr<Scene> scene = make_scene(Targets::ConstantMap);
  const SamplingPlan plan = SamplingPlan::make(Strategy::parse("environment"), *scene);
  const Environment& map = *plan.environment;
  const Vec3 n(0, 1, 0);
  const Frame frame(n);
  auto wrong = [&](const Vec3& d) {
    int x, y;
    map.texel_of(d, x, y);
    return map.texel_probability(x, y) * map.width() * map.height() / (4.0 * std::numbers::pi);
  };
  auto sampler = chi_square::plan_sampler(plan, Vec3(0.0f), n, Sampler::OnePath);
  const std::vector<chi_square::Point> edges = chi_square::plan_edges(plan, Vec3(0.0f), n, frame);
  const Outcome o = run_chi_square(frame, sampler, wrong, edges, 31, 100'000);
  EXPECT_FALSE(o.passed(1e-3));
  EXPECT_LT(o.chi.p_value, 1e-12);
  auto right = [&](const Vec3& d) { return static_cast<double>(plan.pdf(Vec3(0.0f), n, d)); };
  EXPECT_TRUE(run_chi_square(frame, sampler, right, edges, 31, 100'000).passed(1e-3));
}

// ---- The rough dielectric ---------------------------------------------------

// Where the refraction density jumps: directions refracted through the
// normals on the horizon (D is alpha^2 / pi there, and 0 beyond).
std::vector<chi_square::Point> horizon_refractions(const Vec3& wo, float eta, const Frame& frame, const Zoom& zoom,
                                                   const Vec3& n) {
  std::vector<chi_square::Point> out;
  const Onb onb(n);
  for (int i = 0; i < 4096; ++i) {
    const double phi = 2.0 * 3.14159265358979323846 * (i + 0.5) / 4096;
    const Vec3 m = onb.to_world(Vec3(static_cast<float>(std::cos(phi)), static_cast<float>(std::sin(phi)), 0.0f));
    const float c = dot(wo, m);
    if (c <= 0.0f || (1.0f - c * c) > eta * eta) continue;  // faces away, or reflects all
    out.push_back(frame.coordinates(zoom.map(leaf::refract_at(wo, m, c, eta), false)));
  }
  return out;
}

// The bsdf technique at a rough dielectric, from outside (eta 1.5) and from
// inside (eta 1 / 1.5: total internal reflection past 41.8 degrees), normal to
// grazing views, alpha 1e-3 to 1, through both samplers (the packet kernel's
// and the one-path tracer's) against the pdf over the whole sphere. Where the
// lobes are narrow, the sphere is checked in two halves, each seen through a
// zoom on its own spike: the side of the surface the reflection leaves to
// (the draws below it count as missing mass, and the density is zero there),
// then the side the refraction enters; each half's mass is the density's
// integral over it, and the two add up to one.
TEST(ChiSquareRoughDielectric, BothSamplersBothSidesEveryAlpha) {
  const Scene scene = *make_scene(Targets::None);
  const SamplingPlan plan = SamplingPlan::make(Strategy::parse("bsdf"), scene);
  const Vec3 n(0, 0, 1);
  struct Case {
    float alpha, view;
  };
  const Case cases[] = {{1e-3f, 0.0f}, {1e-3f, 70.0f}, {0.05f, 30.0f}, {0.3f, 85.0f}, {1.0f, 60.0f}};
  const float etas[] = {1.5f, 1.0f / 1.5f};
  const double family = stats::sidak_alpha(kFamilyAlpha, 2 * 2 * 2 * static_cast<int>(std::size(cases) * std::size(etas)));
  std::uint64_t seed = 4100;
  for (const float eta : etas)
    for (const Case& c : cases) {
      const double t = c.view * 3.14159265358979323846 / 180.0;
      const Vec3 wo(static_cast<float>(std::sin(t)), 0.0f, static_cast<float>(std::cos(t)));
      const SurfaceLobe surface{true, c.alpha, wo, true, eta};
      const bool split = c.alpha < 0.2f;
      const bool refracts = std::sin(t) < eta;  // the smooth refraction exists (the zoom's axis)
      double total = 0.0;
      for (const int side : {1, -1}) {
        if (!split && side < 0) break;
        // Seen from inside past the critical angle a sharp lobe refracts nothing: no side to test.
        if (side < 0 && !refracts && c.alpha < 0.01f) break;
        const Vec3 axis = side < 0 && refracts ? leaf::refract_at(wo, n, wo.z, eta) : side < 0 ? Vec3(0, 0, -1)
                                                                                           : leaf::reflect(-wo, n);
        const Zoom zoom(axis, split ? std::min(1.0, 3.0 * c.alpha) : 1.0);
        const Frame frame(Vec3(zoom.axis));
        // The draws and the density on this side of the surface alone (or everywhere).
        const auto kept = [&](const Vec3& d) { return !split || (side > 0 ? d.z > 0.0f : d.z <= 0.0f); };
        std::vector<chi_square::Draw> draws;
        for (const Sampler which : {Sampler::Packet, Sampler::OnePath})
          draws.push_back([zoom, kept, d = chi_square::plan_sampler(plan, Vec3(0.0f), n, which, surface)](Rng& rng) mutable {
            DirectionSample s = d(rng);
            if (!kept(s.direction)) s.none = true;
            return through_zoom(zoom, s);
          });
        auto density = [&](const Vec3& zoomed) {
          double factor = 1.0;
          const Vec3 d = zoom.map(zoomed, true, &factor);
          return kept(d) ? static_cast<double>(plan.pdf(surface, Vec3(0.0f), n, d)) * factor : 0.0;
        };
        // Every fourth of the reflections' points: as close as the refractions' ones.
        std::vector<chi_square::Point> edges;
        const std::vector<chi_square::Point> reflections = horizon_reflections(wo, frame, zoom, n);
        for (std::size_t i = 0; i < reflections.size(); i += 4) edges.push_back(reflections[i]);
        for (const chi_square::Point& p : horizon_refractions(wo, eta, frame, zoom, n)) edges.push_back(p);
        for (int i = 0; split && i < 1024; ++i) {  // the surface's plane, where a split density stops
          const double phi = 2.0 * 3.14159265358979323846 * (i + 0.5) / 1024;
          edges.push_back(frame.coordinates(
              zoom.map(Vec3(static_cast<float>(std::cos(phi)), static_cast<float>(std::sin(phi)), 0.0f), false)));
        }
        const std::vector<Outcome> both = chi_square::run_each(kGrid, frame, draws, density, edges, seed++, 100'000);
        for (std::size_t k = 0; k < both.size(); ++k) {
          const Outcome& o = both[k];
          std::printf("[rough] %s eta %.3g alpha %-6g view %2g %s: p = %.3g, integral %.6f\n",
                      k == 0 ? "packet  " : "one-path", eta, c.alpha, c.view,
                      !split ? "whole sphere" : side > 0 ? "reflection side" : "refraction side", o.chi.p_value,
                      o.integral);
          EXPECT_TRUE(o.passed(family)) << (k == 0 ? "packet" : "one-path") << " eta " << eta << " alpha " << c.alpha
                                        << " view " << c.view << " side " << side << ": p = " << o.chi.p_value
                                        << ", zero-cell hits " << o.chi.zero_cell_hits << ", bad pdfs " << o.bad_pdf;
        }
        total += both[0].integral;
      }
      EXPECT_NEAR(total, 1.0, 3e-3) << "eta " << eta << " alpha " << c.alpha << " view " << c.view;
    }
}

// The harness sees a wrong refraction density: samples judged against a
// density whose refraction lobe lacks Walter's eta^2 in the Jacobian (the
// lobe's mass then 1 / eta^2 of what is drawn) must fail.
TEST(ChiSquareRoughDielectric, RejectsAWrongJacobian) {
  const Scene scene = *make_scene(Targets::None);
  const SamplingPlan plan = SamplingPlan::make(Strategy::parse("bsdf"), scene);
  const Vec3 n(0, 0, 1), wo(std::sin(0.5f), 0.0f, std::cos(0.5f));
  const float eta = 1.5f, alpha = 0.3f;
  const SurfaceLobe surface{true, alpha, wo, true, eta};
  const Frame frame(n);
  auto density = [&](const Vec3& d) {
    const double p = plan.pdf(surface, Vec3(0.0f), n, d);
    return d.z < 0.0f ? p / (eta * eta) : p;  // roughly the lobe without its eta^2
  };
  const Outcome o = run_chi_square(frame, chi_square::plan_sampler(plan, Vec3(0.0f), n, Sampler::OnePath, surface),
                                   density, {}, 4190, 100'000);
  std::printf("[rough] judged without eta^2: p = %.3g\n", o.chi.p_value);
  EXPECT_LT(o.chi.p_value, 1e-6);
}

}  // namespace
}  // namespace pdflab
