#pragma once
// The chi-square check of a sampler against its pdf: the one harness the test
// suite and the viewer's probe both run. Directions are binned over the whole
// sphere in (cos theta, phi) about the shading normal, cells of equal solid
// angle; a cell's expected count is N times the pdf integrated over it by an
// adaptive quadrature that splits along every place the density may jump (the
// targets' outlines seen from the shading point). The pdf is integrated from
// the pdf function itself, so a sampler and its pdf are checked against each
// other, never against a shared formula.
#include "renderer/metrics/statistics.h"
#include "renderer/sampling/rng.h"
#include "renderer/sampling/strategy.h"
#include "renderer/scene/scene.h"

#include <glm/vec3.hpp>

#include <cstdint>
#include <functional>
#include <vector>

namespace pdflab::chi_square {

// Rows of equal cos(theta) width from +1 (row 0, the normal) down to -1, and
// columns of equal azimuth from 0 to 2 pi; or, where `z_edges` is given, rows
// between those cosines (z_cells + 1 of them, from 1 down to -1).
struct Grid {
  Grid() = default;
  Grid(int z, int phi) : z_cells(z), phi_cells(phi) {}
  int z_cells = 20, phi_cells = 40;
  std::vector<double> z_edges;
  // check_plan gives a narrow lobe rows of equal mass (follow_lobe; the
  // outcome's grid then says which rows, and may have more than z_cells).
  bool lobe_rows = false;
  int cells() const { return z_cells * phi_cells; }
};

// A direction's place on the sphere about the normal.
struct Point {
  double z, phi;  // cos(theta), azimuth in [0, 2 pi)
};

// The harness's own frame, in double and built independently of the
// renderer's Onb, so that a broken Onb cannot hide by distorting the cells the
// same way.
struct Frame {
  glm::dvec3 s, t, n;
  explicit Frame(const Vec3& normal);
  Vec3 direction(double z, double cos_phi, double sin_phi) const;
  Point coordinates(const Vec3& direction) const;
};

using Density = std::function<double(const Vec3&)>;
using Draw = std::function<DirectionSample(Rng&)>;

// Points along the outline of everything a technique aims at (the importance
// targets, and the glass and metal objects of specular-objects) as seen from
// `origin`: the curves where such a pdf jumps, spaced far closer than the
// quadrature's finest pieces.
std::vector<Point> target_outlines(const Scene& scene, const Vec3& origin, const Frame& frame);

// Points on the curves where the plan's techniques with weight say their own
// pdf jumps (a cone's edge: TechniqueT::pdf_edges), as seen about `normal`.
std::vector<Point> technique_edges(const SamplingPlan& plan, const Vec3& normal, const Frame& frame);

// Everything above for a plan: its scene's targets' outlines and its
// techniques' own edges.
std::vector<Point> plan_edges(const SamplingPlan& plan, const Vec3& origin, const Vec3& normal, const Frame& frame);

// Rows that follow a narrow lobe. Rows of equal cos(theta) width are blind to
// how a lobe narrower than one row is drawn inside it (a 10 degree cone lies
// in the first of 20 rows: only its azimuths were tested). Where one of
// `grid`'s rows holds more than a quarter of the density's mass, this gives
// the grid rows of equal mass instead (the quantiles of the density's
// marginal in theta, integrated on a grid that is finest at the normal), so a
// lobe of any width is cut into z_cells rows, and rows below it that double in
// width down to -1; else `grid` itself.
Grid follow_lobe(const Grid& grid, const Frame& frame, const Density& density);

// The pdf integrated over each cell (probability, not counts), row-major.
// Measured over the test suite's cases, the sphere's total is off by at most
// 4.3e-5 (a thin sliver of a light seen edge-on) and below 2e-5 elsewhere.
std::vector<double> cell_masses(const Grid& grid, const Frame& frame, const Density& density,
                                const std::vector<Point>& edges);

struct Outcome {
  stats::ChiSquareResult chi;
  Grid grid;
  std::vector<std::uint64_t> observed;  // per cell, row-major
  std::vector<double> expected;         // N times the cell's mass
  double integral = 0.0;                // of the pdf over the whole sphere
  std::uint64_t empty_samples = 0;      // the sampler had no direction (DirectionSample::none)
  std::uint64_t bad_pdf = 0;            // samples whose own pdf is not finite and > 0
  std::uint64_t pdf_mismatch = 0;       // samples whose own pdf differs from the density's by > 1e-3
  bool passed(double alpha) const { return chi.zero_cell_hits == 0 && bad_pdf == 0 && chi.p_value > alpha; }
};

// Draws `samples` directions with `draw` (an Rng seeded with `seed`) and tests
// their histogram against `density`. Empty samples count in N: they are the
// technique's missing mass, which the density does not integrate either.
Outcome run(const Grid& grid, const Frame& frame, const Draw& draw, const Density& density,
            const std::vector<Point>& edges, std::uint64_t seed, int samples);
// The same for several samplers against one integration of the density: the
// k-th draws from an Rng seeded with seed + k.
std::vector<Outcome> run_each(const Grid& grid, const Frame& frame, const std::vector<Draw>& draws,
                              const Density& density, const std::vector<Point>& edges, std::uint64_t seed,
                              int samples);

// The two samplers a plan has. OnePath: SamplingPlan::sample, what the one-path
// tracer calls. Packet: the packet kernel's sample_plan on the best ISA, what
// renders, in batches, with the same four random numbers per draw.
enum class Sampler { OnePath, Packet };
// `surface`: the surface drawn at (the `bsdf` technique's lobe; default lambertian).
Draw plan_sampler(const SamplingPlan& plan, const Vec3& origin, const Vec3& normal, Sampler which,
                  const SurfaceLobe& surface = {});

// The whole check of a plan's mixture at a shading point: the outlines of the
// plan's scene's targets and its techniques' own edges, the mixture's pdf, the
// chosen sampler, on `grid`'s rows or, where it asks for them (lobe_rows) and
// the lobe is narrow, rows of equal mass (follow_lobe).
// At `surface` (default lambertian), for the `bsdf` technique's lobe there.
Outcome check_plan(const SamplingPlan& plan, const Vec3& origin, const Vec3& normal, Sampler which, int samples,
                   std::uint64_t seed, const Grid& grid = {}, const SurfaceLobe& surface = {});
// ... for several samplers, in that order, against one integration.
std::vector<Outcome> check_plan(const SamplingPlan& plan, const Vec3& origin, const Vec3& normal,
                                const std::vector<Sampler>& samplers, int samples, std::uint64_t seed,
                                const Grid& grid = {}, const SurfaceLobe& surface = {});

}  // namespace pdflab::chi_square
