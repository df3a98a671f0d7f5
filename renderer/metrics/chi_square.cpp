#include "renderer/metrics/chi_square.h"

#include "renderer/integrator/packet.h"
#include "renderer/sampling/mixture.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

namespace pdflab::chi_square {

namespace {

using glm::dvec3;

constexpr double kTwoPi = 2.0 * std::numbers::pi;

int row_index(const Grid& g, double z) {
  if (g.z_edges.empty()) return std::clamp(static_cast<int>((1.0 - z) * 0.5 * g.z_cells), 0, g.z_cells - 1);
  // The first row whose lower edge is at or below z (edges descend).
  const auto it = std::upper_bound(g.z_edges.begin() + 1, g.z_edges.end(), z, std::greater<double>());
  const auto row = static_cast<int>(it - (g.z_edges.begin() + 1));
  return std::clamp(row, 0, g.z_cells - 1);
}

int cell_index(const Grid& g, const Point& q) {
  const int row = row_index(g, q.z);
  const int col = std::clamp(static_cast<int>(q.phi / kTwoPi * g.phi_cells), 0, g.phi_cells - 1);
  return row * g.phi_cells + col;
}

struct Rect {
  double z0, z1, p0, p1;
  double area() const { return (z1 - z0) * (p1 - p0); }
  bool contains(const Point& q) const { return q.z >= z0 && q.z < z1 && q.phi >= p0 && q.phi < p1; }
};

Rect cell_rect(const Grid& g, int cell) {
  const int row = cell / g.phi_cells, col = cell % g.phi_cells;
  const auto r = static_cast<std::size_t>(row);
  if (!g.z_edges.empty())
    return {g.z_edges[r + 1], g.z_edges[r], kTwoPi * col / g.phi_cells, kTwoPi * (col + 1) / g.phi_cells};
  return {1.0 - 2.0 * (row + 1) / g.z_cells, 1.0 - 2.0 * row / g.z_cells, kTwoPi * col / g.phi_cells,
          kTwoPi * (col + 1) / g.phi_cells};
}

// Adaptive midpoint quadrature of a solid-angle pdf over a (z, phi) rectangle
// (d omega = dz dphi exactly, so no Jacobian). A smooth-integrand error
// estimate cannot find the jumps of a light pdf at target edges: a grid can
// step right over a thin piece of support. So the caller passes points on
// every place the density may jump (the targets' outlines, seen from the
// shading point); a rectangle holding one is always split, down to
// kMaxEdgeDepth, where each piece of outline gets a 377-point lattice over
// 1/16384 of the cell. Elsewhere a rectangle is split while its 8x8 and 16x16
// estimates disagree by more than 1e-4 relative, or while its points see both
// zero and non-zero density. A relative error d in a cell of expected count E
// adds about d^2 E to chi2, here < 0.01 even at E = 1e5.
class CellIntegrator {
 public:
  CellIntegrator(const Grid& grid, const Frame& frame, const Density& density, const std::vector<Point>& edges)
      : grid_(grid), frame_(frame), density_(density), edges_(static_cast<std::size_t>(grid.cells())) {
    for (const Point& q : edges) edges_[static_cast<std::size_t>(cell_index(grid_, q))].push_back(q);
  }

  // `extra`: more points to treat as edges in this cell (samples that landed
  // where a first pass saw no density: a closer look must confirm it).
  double integrate(int cell, const std::vector<Point>& extra = {}) const {
    const Rect r = cell_rect(grid_, cell);
    std::vector<Point> hints = edges_[static_cast<std::size_t>(cell)];
    hints.insert(hints.end(), extra.begin(), extra.end());
    return refine(r, midpoint(r), 0, r.area(), hints);
  }

 private:
  static constexpr int kGrid = 8;          // points per side of one rectangle's estimate
  static constexpr int kMaxDepth = 6;      // halvings of a cell's sides, smooth parts
  static constexpr int kMaxEdgeDepth = 7;  // ... and along outlines
  static constexpr double kAbsTol = 1e-9;  // probability per cell
  static constexpr double kRelTol = 1e-4;

  struct Estimate {
    double value = 0.0;
    bool any_zero = false, any_positive = false;
  };

  Estimate midpoint(const Rect& r) const {
    double cos_p[kGrid], sin_p[kGrid];
    const double dp = (r.p1 - r.p0) / kGrid, dz = (r.z1 - r.z0) / kGrid;
    for (int j = 0; j < kGrid; ++j) {
      const double p = r.p0 + (j + 0.5) * dp;
      cos_p[j] = std::cos(p);
      sin_p[j] = std::sin(p);
    }
    Estimate e;
    double sum = 0.0;
    for (int i = 0; i < kGrid; ++i) {
      const double z = r.z0 + (i + 0.5) * dz;
      for (int j = 0; j < kGrid; ++j) {
        const double f = density_(frame_.direction(z, cos_p[j], sin_p[j]));
        if (f > 0.0) e.any_positive = true;
        else e.any_zero = true;
        sum += f;
      }
    }
    e.value = sum * dz * dp;
    return e;
  }

  // A Fibonacci lattice: its n points have n distinct, evenly spaced z and
  // phi coordinates. An outline that runs along z or phi (a sphere's cone seen
  // along its axis is a line of constant z) would meet a product grid's rows
  // all at the same offset, an error of up to half a row that never averages
  // out; on the lattice it is at most 1/n of the rectangle.
  double lattice(const Rect& r) const {
    constexpr int kPoints = 377, kStep = 233;  // consecutive Fibonacci numbers
    double sum = 0.0;
    for (int i = 0; i < kPoints; ++i) {
      const double a = (i + 0.5) / kPoints;
      const double b = (static_cast<double>((i * kStep) % kPoints) + 0.5) / kPoints;
      const double p = r.p0 + b * (r.p1 - r.p0);
      sum += density_(frame_.direction(r.z0 + a * (r.z1 - r.z0), std::cos(p), std::sin(p)));
    }
    return sum * r.area() / kPoints;
  }

  double refine(const Rect& r, const Estimate& coarse, int depth, double cell_area,
                const std::vector<Point>& hints) const {
    const double zm = 0.5 * (r.z0 + r.z1), pm = 0.5 * (r.p0 + r.p1);
    const Rect kids[4] = {{r.z0, zm, r.p0, pm}, {r.z0, zm, pm, r.p1}, {zm, r.z1, r.p0, pm}, {zm, r.z1, pm, r.p1}};
    Estimate est[4];
    double fine = 0.0;
    bool mixed = coarse.any_zero && coarse.any_positive;
    for (int k = 0; k < 4; ++k) {
      est[k] = midpoint(kids[k]);
      fine += est[k].value;
      mixed = mixed || (est[k].any_zero && est[k].any_positive);
    }
    if (depth >= kMaxEdgeDepth || (depth >= kMaxDepth && hints.empty())) return hints.empty() ? fine : lattice(r);
    const double tol = kAbsTol * r.area() / cell_area + kRelTol * std::fabs(fine);
    if (!mixed && hints.empty() && std::fabs(fine - coarse.value) <= tol) return fine;
    double sum = 0.0;
    std::vector<Point> inside;
    for (int k = 0; k < 4; ++k) {
      inside.clear();
      for (const Point& q : hints)
        if (kids[k].contains(q)) inside.push_back(q);
      sum += refine(kids[k], est[k], depth + 1, cell_area, inside);
    }
    return sum;
  }

  Grid grid_;
  const Frame& frame_;
  const Density& density_;
  std::vector<std::vector<Point>> edges_;  // per cell
};

// The packet kernel's draws, a batch at a time, handed out one by one; each
// draw takes four numbers (technique, direction, target) from the stream.
struct PacketDraws {
  static constexpr std::size_t kBatch = 256;
  const SamplingPlan* plan;
  Vec3 origin, normal;
  SurfaceLobe surface;
  std::vector<DirectionSample> batch;
  std::size_t next = 0;

  DirectionSample operator()(Rng& rng) {
    if (next == batch.size()) {
      std::vector<PlanDraw> draws(kBatch);
      for (PlanDraw& d : draws) {
        d.point = origin, d.normal = normal;
        d.u0 = rng.next_u32(), d.u1 = rng.uniform(), d.u2 = rng.uniform(), d.u_choice = rng.next_u32();
        // u1's last cell drawn further (used by the techniques that draw the tail).
        if (d.u1 == kLargestUniform) d.top_log2 = uniform_tail_log2([&] { return rng.next_u32(); });
        d.surface = surface;
        if (surface.glossy && surface.transmits) d.u_lobe = rng.uniform();
      }
      batch.resize(kBatch);
      sample_plan(best_packet_isa(), *plan, draws.data(), draws.size(), batch.data());
      next = 0;
    }
    return batch[next++];
  }
};

}  // namespace

Frame::Frame(const Vec3& normal) {
  n = glm::normalize(dvec3(normal));
  const dvec3 helper = std::fabs(n.x) < 0.6 ? dvec3(1, 0, 0) : dvec3(0, 1, 0);
  s = glm::normalize(helper - n * glm::dot(helper, n));
  t = glm::cross(n, s);
}

Vec3 Frame::direction(double z, double cos_phi, double sin_phi) const {
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  return Vec3(s * (r * cos_phi) + t * (r * sin_phi) + n * z);
}

Point Frame::coordinates(const Vec3& direction) const {
  const dvec3 d = glm::normalize(dvec3(direction));
  Point q;
  q.z = std::clamp(glm::dot(d, n), -1.0, 1.0);
  q.phi = std::atan2(glm::dot(d, t), glm::dot(d, s));
  if (q.phi < 0.0) q.phi += kTwoPi;
  return q;
}

std::vector<Point> target_outlines(const Scene& scene, const Vec3& origin, const Frame& frame) {
  constexpr int kPerEdge = 4096;
  std::vector<Point> out;
  const dvec3 o(origin);
  auto add = [&](const dvec3& dir) { out.push_back(frame.coordinates(Vec3(glm::normalize(dir)))); };
  std::vector<Target> aimed_at = scene.targets;
  const auto specular = [&](std::uint32_t material) {
    const MaterialType type = scene.materials[material].type;
    return type == MaterialType::Metal || type == MaterialType::Dielectric;
  };
  for (std::uint32_t i = 0; i < scene.quads.size(); ++i)
    if (specular(scene.quads[i].material)) aimed_at.push_back({Target::Kind::Quad, i});
  for (std::uint32_t i = 0; i < scene.spheres.size(); ++i)
    if (specular(scene.spheres[i].material)) aimed_at.push_back({Target::Kind::Sphere, i});
  for (const Target& t : aimed_at) {
    if (t.kind == Target::Kind::Quad) {
      const Quad& quad = scene.quads[t.index];
      const dvec3 q(quad.q), u(quad.u), v(quad.v);
      for (int i = 0; i <= kPerEdge; ++i) {
        const double a = static_cast<double>(i) / kPerEdge;
        add(q + u * a - o);
        add(q + u * a + v - o);
        add(q + v * a - o);
        add(q + v * a + u - o);
      }
    } else {
      const Sphere& sphere = scene.spheres[t.index];
      const dvec3 to_centre = dvec3(sphere.center) - o;
      const double dist = glm::length(to_centre);
      if (dist <= sphere.radius) continue;  // from inside, the pdf is uniform: no outline
      const Frame cone(Vec3(to_centre / dist));
      const double sin_max = sphere.radius / dist;
      const double cos_max = std::sqrt(1.0 - sin_max * sin_max);
      for (int i = 0; i < 4 * kPerEdge; ++i) {
        const double a = kTwoPi * i / (4 * kPerEdge);
        add(cone.n * cos_max + (cone.s * std::cos(a) + cone.t * std::sin(a)) * sin_max);
      }
    }
  }
  return out;
}

namespace {
// Technique T's own edges, where it declares any and has weight.
template <class T>
void add_edges(const SamplingPlan& plan, const Vec3& normal, std::vector<Vec3>& directions) {
  if constexpr (requires { T::pdf_edges(plan, normal, directions); })
    if (plan.weight[static_cast<int>(T::id)] > 0.0f) T::pdf_edges(plan, normal, directions);
}
}  // namespace

std::vector<Point> technique_edges(const SamplingPlan& plan, const Vec3& normal, const Frame& frame) {
  std::vector<Vec3> directions;
#define PDFLAB_ROW(T) add_edges<leaf::T>(plan, normal, directions);
  PDFLAB_TECHNIQUES(PDFLAB_ROW)
#undef PDFLAB_ROW
  std::vector<Point> out;
  out.reserve(directions.size());
  for (const Vec3& d : directions) out.push_back(frame.coordinates(d));
  return out;
}

std::vector<Point> plan_edges(const SamplingPlan& plan, const Vec3& origin, const Vec3& normal, const Frame& frame) {
  std::vector<Point> edges = plan.scene ? target_outlines(*plan.scene, origin, frame) : std::vector<Point>{};
  const std::vector<Point> own = technique_edges(plan, normal, frame);
  edges.insert(edges.end(), own.begin(), own.end());
  return edges;
}

Grid follow_lobe(const Grid& grid, const Frame& frame, const Density& density) {
  // The marginal in theta on steps theta_i = pi (i / M)^2 (finest at the
  // normal: 4.7e-8 rad there, 7.7e-4 at the antipode), each step's mass by
  // the midpoint rule over K azimuths.
  constexpr int M = 8192, K = 32;
  std::vector<double> z(M + 1), mass(M);
  for (int i = 0; i <= M; ++i) {
    const double a = static_cast<double>(i) / M;
    z[static_cast<std::size_t>(i)] = std::cos(std::numbers::pi * a * a);
  }
  z[M] = -1.0;
  double cos_p[K], sin_p[K];
  for (int j = 0; j < K; ++j) {
    cos_p[j] = std::cos(kTwoPi * (j + 0.5) / K);
    sin_p[j] = std::sin(kTwoPi * (j + 0.5) / K);
  }
  double total = 0.0;
  for (int i = 0; i < M; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const double zm = 0.5 * (z[k] + z[k + 1]);
    double sum = 0.0;
    for (int j = 0; j < K; ++j) sum += density(frame.direction(zm, cos_p[j], sin_p[j]));
    mass[k] = sum / K * kTwoPi * (z[k] - z[k + 1]);
    total += mass[k];
  }
  if (!(total > 0.0)) return grid;
  // The uniform rows' largest share.
  std::vector<double> row_mass(static_cast<std::size_t>(grid.z_cells), 0.0);
  Grid uniform = grid;
  uniform.z_edges.clear();
  for (int i = 0; i < M; ++i) {
    const auto k = static_cast<std::size_t>(i);
    row_mass[static_cast<std::size_t>(row_index(uniform, 0.5 * (z[k] + z[k + 1])))] += mass[k];
  }
  if (*std::max_element(row_mass.begin(), row_mass.end()) <= 0.25 * total) return grid;
  // Rows of equal mass: an edge where the running mass passes each quantile.
  std::vector<double> edges{1.0};
  double running = 0.0;
  int next = 1;
  for (int i = 0; i < M && next < grid.z_cells; ++i) {
    const auto k = static_cast<std::size_t>(i);
    running += mass[k];
    while (next < grid.z_cells && running >= total * next / grid.z_cells) {
      if (z[k + 1] < edges.back()) edges.push_back(z[k + 1]);
      ++next;
    }
  }
  // Below the lobe, rows that double in width down to -1: a lobe's tail in
  // one row as wide as the rest of the sphere would be integrated from a few
  // points far from where its mass is.
  if (edges.size() >= 2) {
    const double width = edges[edges.size() - 2] - edges.back();
    for (double step = 2.0 * width; edges.back() - step > -1.0; step *= 2.0) edges.push_back(edges.back() - step);
  }
  if (edges.back() > -1.0) edges.push_back(-1.0);
  Grid out = grid;
  out.z_cells = static_cast<int>(edges.size()) - 1;
  out.z_edges = std::move(edges);
  return out;
}

std::vector<double> cell_masses(const Grid& grid, const Frame& frame, const Density& density,
                                const std::vector<Point>& edges) {
  const CellIntegrator integrator(grid, frame, density, edges);
  std::vector<double> mass(static_cast<std::size_t>(grid.cells()));
  for (int c = 0; c < grid.cells(); ++c) mass[static_cast<std::size_t>(c)] = integrator.integrate(c);
  return mass;
}

std::vector<Outcome> run_each(const Grid& grid, const Frame& frame, const std::vector<Draw>& draws,
                              const Density& density, const std::vector<Point>& edges, std::uint64_t seed,
                              int samples) {
  const auto cells = static_cast<std::size_t>(grid.cells());
  const CellIntegrator integrator(grid, frame, density, edges);
  std::vector<double> first_mass(cells);
  for (std::size_t c = 0; c < cells; ++c) first_mass[c] = integrator.integrate(static_cast<int>(c));

  std::vector<Outcome> outcomes;
  for (std::size_t k = 0; k < draws.size(); ++k) {
    std::vector<double> mass = first_mass;
    Outcome out;
    out.grid = grid;
    out.observed.assign(cells, 0);
    std::vector<std::vector<Point>> stray(cells);  // samples in cells of zero mass
    Rng rng(seed + k, 0x5eed);
    for (int i = 0; i < samples; ++i) {
      const DirectionSample ds = draws[k](rng);
      if (ds.none) {
        ++out.empty_samples;
        continue;
      }
      if (!(ds.pdf > 0.0f) || !std::isfinite(ds.pdf) || !is_finite(ds.direction)) {
        ++out.bad_pdf;
        continue;
      }
      // 1e-3 relative: float rounding in the two code paths is ~1e-6; only a
      // genuine disagreement (or a sample on a target's very edge) exceeds it.
      const double p = density(ds.direction);
      if (std::fabs(p - ds.pdf) > 1e-3 * std::max(p, static_cast<double>(ds.pdf))) ++out.pdf_mismatch;
      const Point q = frame.coordinates(ds.direction);
      const auto c = static_cast<std::size_t>(cell_index(grid, q));
      ++out.observed[c];
      if (mass[c] == 0.0 && stray[c].size() < 64) stray[c].push_back(q);
    }
    for (std::size_t c = 0; c < cells; ++c)
      if (!stray[c].empty()) mass[c] = integrator.integrate(static_cast<int>(c), stray[c]);

    out.expected.resize(cells);
    for (std::size_t c = 0; c < cells; ++c) {
      out.integral += mass[c];
      out.expected[c] = mass[c] * samples;
    }
    out.chi = stats::chi_square_test(out.observed, out.expected);
    outcomes.push_back(std::move(out));
  }
  return outcomes;
}

Outcome run(const Grid& grid, const Frame& frame, const Draw& draw, const Density& density,
            const std::vector<Point>& edges, std::uint64_t seed, int samples) {
  return std::move(run_each(grid, frame, {draw}, density, edges, seed, samples).front());
}

Draw plan_sampler(const SamplingPlan& plan, const Vec3& origin, const Vec3& normal, Sampler which,
                  const SurfaceLobe& surface) {
  if (which == Sampler::Packet) return PacketDraws{&plan, origin, normal, surface, {}, 0};
  return [&plan, origin, normal, surface](Rng& rng) {
    return plan.sample(origin, normal, rng, nullptr, -1, &surface);
  };
}

std::vector<Outcome> check_plan(const SamplingPlan& plan, const Vec3& origin, const Vec3& normal,
                                const std::vector<Sampler>& samplers, int samples, std::uint64_t seed,
                                const Grid& grid, const SurfaceLobe& surface) {
  const Frame frame(normal);
  const Density density = [&](const Vec3& d) { return static_cast<double>(plan.pdf(surface, origin, normal, d)); };
  const std::vector<Point> edges = plan_edges(plan, origin, normal, frame);
  std::vector<Draw> draws;
  for (Sampler which : samplers) draws.push_back(plan_sampler(plan, origin, normal, which, surface));
  const Grid rows = grid.lobe_rows && grid.z_edges.empty() ? follow_lobe(grid, frame, density) : grid;
  return run_each(rows, frame, draws, density, edges, seed, samples);
}

Outcome check_plan(const SamplingPlan& plan, const Vec3& origin, const Vec3& normal, Sampler which, int samples,
                   std::uint64_t seed, const Grid& grid, const SurfaceLobe& surface) {
  return std::move(check_plan(plan, origin, normal, std::vector<Sampler>{which}, samples, seed, grid, surface).front());
}

}  // namespace pdflab::chi_square
