#pragma once
// The pixel probe: what the strategy does at the first diffuse surface a
// pixel sees. Directions drawn there (with the technique that drew each), the
// strategy's pdf as a map over the sphere of directions, and a chi-square
// check of its sample/pdf pair at that very point.
#include "renderer/metrics/statistics.h"
#include "renderer/sampling/strategy.h"
#include "renderer/scene/scene.h"

#include <cstdint>
#include <string>
#include <vector>

namespace pdflab {

struct ProbePoint {
  bool found = false;  // false: the pixel's ray left the scene or hit a light first
  Vec3 point{0.0f}, normal{0.0f};  // normal faces the arriving ray
  std::uint32_t material = 0;
  // The surface there for the `bsdf` technique: lambertian, or a microfacet
  // conductor of roughness alpha seen from where the ray came (outgoing).
  SurfaceLobe surface;
  int specular_bounces = 0;  // mirror/glass bounces before the diffuse hit
  // The first surface the pixel's ray meets, when it is glass or metal (its
  // lobe is a delta: one direction, no density); valid if specular_bounces > 0.
  std::uint32_t first_material = 0;
};

// Follows the ray through pixel centre (x, y) past metal and glass (glass
// picks reflection or refraction with `seed`) to its first diffuse hit.
ProbePoint first_diffuse_hit(const Scene& scene, int x, int y, std::uint64_t seed = 1);

struct ProbeSample {
  Vec3 direction;
  float pdf;
  int technique;  // Technique index, or -1 for an empty light sample
};
std::vector<ProbeSample> probe_directions(const SamplingPlan& plan, const ProbePoint& at, int count,
                                          std::uint64_t seed);

// The pdf over the whole sphere of directions in a lat-long map around the
// normal: column = azimuth phi in [0, 2 pi), row = cos(theta) from +1 (top,
// the normal) to -1. `width` x `height` values, row-major. Rows are equal
// steps of cos(theta), so every cell spans the same solid angle,
// 4 pi / (width * height). `supersample` k: each value is the mean of the pdf
// at k x k points spread over its cell (the cell's mass over its solid angle,
// so a lobe narrower than a cell still shows); 1: the pdf at the cell's centre.
std::vector<float> pdf_map(const SamplingPlan& plan, const ProbePoint& at, int width, int height,
                           int supersample = 1);

// The material's own lobe at the probe point, as the `bsdf` technique draws
// it: the cosine lobe at a lambertian surface, GGX's visible normals
// reflected at a microfacet one. The same layout as pdf_map, so the two are
// compared cell by cell; each value is the technique's pdf (per steradian).
std::vector<float> bsdf_pdf_map(const Scene& scene, const ProbePoint& at, int width, int height,
                                int supersample = 1);

// The light arriving at the probe's point, traced by brute force, as a
// density in pdf_map's layout: in each cell above the surface, `per_cell`
// paths of nee-mis (the scene's plain estimator; cosine where it has no
// lights) leave the point along directions spread evenly over the cell, and
// their luminances times the cosine to the normal are averaged; the map is
// then divided by its integral over the sphere, so it is the distribution of
// the light the surface takes in, L(w) cos / (integral of L cos) — what path
// guiding learns to draw from. Cells below the surface: 0.
// All zeros where no light arrives. Deterministic for a seed.
std::vector<float> incident_light_map(const Scene& scene, const ProbePoint& at, int width, int height, int per_cell,
                                      std::uint64_t seed);
// Path guiding's spatial tree as the camera sees it: per pixel of the
// camera's image (row 0 at the top), the S-tree leaf that `guide` gives the
// first diffuse surface the pixel's ray meets (as first_diffuse_hit finds
// it, with the normal facing the ray), -1 where there is none.
std::vector<std::int32_t> guiding_leaf_map(const Scene& scene, const GuidingDistribution& guide);
// The bsdf technique's pdf at the probe point for one direction.
float bsdf_pdf(const Scene& scene, const ProbePoint& at, const Vec3& direction);
// In words, what that lobe is at the probe point ("cosine lobe (lambertian)",
// "GGX visible normals, alpha 0.07 (microfacet)").
std::string bsdf_lobe_name(const Scene& scene, const ProbePoint& at);
// In words, the delta lobe of the first surface when it is glass or metal
// ("glass (ior 1.5): a delta lobe ..."); empty when the first surface is the
// probe point itself.
std::string delta_lobe_note(const Scene& scene, const ProbePoint& at);

// The scene's name for material m (`fallback` where it has none).
std::string material_name(const Scene& scene, std::uint32_t m, const char* fallback = "");
// A light target's label: its material's name and its shape, e.g. "light (quad)".
std::string target_label(const Scene& scene, std::uint32_t material, const char* kind);
// Each target's label in the set's order (quads, then spheres); where several
// share one, each with its scene object number, e.g. "bulb03 #217 (sphere)".
std::vector<std::string> target_labels(const Scene& scene, const TargetSet& set);

// Map coordinates (0..1) of a direction in pdf_map's layout.
void direction_to_map(const ProbePoint& at, const Vec3& direction, float& u, float& v);

// How the strategy's light technique chooses a light at the probe point
// (TargetSet::by_point): one row per target of the set it draws from
// (nee-mis: its emitters; else light-sa's targets, else light's), quads first.
struct ProbeLightChoice {
  std::string set;  // "nee-mis emitters", "light-sa targets" or "light targets"
  // How the set chooses (nee-mis: LightChoice's name, "power", "uniform" or
  // "tree"; the others: "power" or "uniform").
  std::string choice;
  struct Row {
    std::string label;  // the material's name and the shape, e.g. "light (quad)"
    float share = 0.0f;        // its share of the choice by power (the set's own)
    float probability = 0.0f;  // the probability of choosing it at the point
    bool receives = true;      // false: the point is behind this one-sided light
  };
  std::vector<Row> rows;
};
// Empty rows where the strategy draws no light or the probe found no point.
ProbeLightChoice probe_light_choice(const Scene& scene, const SamplingPlan& plan, const ProbePoint& at);

// Chi-square test of the plan's samplers against plan.pdf at the probe point,
// by the test suite's harness (chi_square.h): samples binned in `phi_cells` x
// `z_cells` equal-solid-angle cells over the sphere, expected counts from the
// pdf integrated over each cell along the targets' outlines. It runs the packet
// kernel's sampler (what renders; its counts are the ones kept) and the
// one-path tracer's; it passes when both do.
struct ProbeChiSquare {
  stats::ChiSquareResult result;           // the packet sampler's
  stats::ChiSquareResult one_path_result;  // the one-path sampler's
  bool passed = false;
  double alpha = 0.01;
  int z_cells = 0, phi_cells = 0;
  std::vector<std::uint64_t> observed;  // per cell, row-major (z rows from +1 down)
  std::vector<double> expected;
  std::uint64_t empty_samples = 0;  // the technique had nothing to offer (a light seen edge-on)
};
ProbeChiSquare probe_chi_square(const SamplingPlan& plan, const ProbePoint& at, int samples, std::uint64_t seed,
                                int z_cells = 16, int phi_cells = 32, double alpha = 0.01);

}  // namespace pdflab
