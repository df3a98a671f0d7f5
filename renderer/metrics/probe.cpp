#include "renderer/metrics/probe.h"

#include "renderer/sampling/onb.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace pdflab {

ProbePoint first_diffuse_hit(const Scene& scene, int x, int y, std::uint64_t seed) {
  ProbePoint at;
  Rng rng(seed, 99);
  Ray ray = scene.camera.generate_ray(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f);
  for (int depth = 0; depth < scene.max_depth; ++depth) {
    Hit hit;
    if (!intersect(scene, ray, kInf, hit)) return at;
    const Material& m = scene.materials[hit.material];
    const bool front = dot(ray.direction, hit.normal) < 0.0f;
    const Vec3 n = front ? hit.normal : -hit.normal;
    if (m.type == MaterialType::Lambertian) {
      at.found = true;
      at.point = diffuse_origin(hit, n);  // where its rays leave from
      at.normal = n;
      at.material = hit.material;
      return at;
    }
    if (m.type == MaterialType::DiffuseLight) return at;
    Vec3 dir;
    if (m.type == MaterialType::Metal) {
      dir = ray.direction - n * (2.0f * dot(ray.direction, n));
    } else {
      // Glass: refract when possible and a coin says so, else reflect.
      const float eta = front ? 1.0f / m.ior : m.ior;
      const float c = min_of(-dot(ray.direction, n), 1.0f);
      const float sin2_t = eta * eta * positive_part(1.0f - c * c);
      if (sin2_t > 1.0f || rng.uniform() < 0.1f) {
        dir = ray.direction - n * (2.0f * dot(ray.direction, n));
      } else {
        dir = normalize((ray.direction + n * c) * eta - n * std::sqrt(positive_part(1.0f - sin2_t)));
      }
    }
    ++at.specular_bounces;
    ray = spawn_ray(hit, dir);
  }
  return at;
}

std::vector<ProbeSample> probe_directions(const SamplingPlan& plan, const ProbePoint& at, int count,
                                          std::uint64_t seed) {
  std::vector<ProbeSample> out;
  if (!at.found) return out;
  Rng rng(seed, 7);
  out.reserve(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) {
    if (plan.nee_mis) {
      // nee-mis draws two directions at a vertex: one from the emitters...
      const std::uint32_t uc = rng.next_u32();
      const float u1 = rng.uniform(), u2 = rng.uniform();
      if (!plan.emitters.empty()) {
        const DirectionSample ls = plan.emitters.sample(at.point, uc, u1, u2);
        out.push_back({ls.direction, ls.pdf, ls.none ? -1 : static_cast<int>(Technique::LightSolidAngle)});
      }
      // ...and one from the cosine lobe.
      const DirectionSample cs = sample_cosine_hemisphere(Onb(at.normal), rng.uniform(), rng.uniform());
      out.push_back({cs.direction, cs.pdf, static_cast<int>(Technique::Cosine)});
      continue;
    }
    int technique = 0;
    const DirectionSample ds = plan.sample(at.point, at.normal, rng, &technique);
    out.push_back({ds.direction, ds.pdf, ds.none ? -1 : technique});
  }
  return out;
}

namespace {

// The frame of the maps and histograms: z along the normal.
struct MapFrame {
  Vec3 s, t, n;
  explicit MapFrame(const Vec3& normal) {
    const Onb onb(normal);
    s = onb.s, t = onb.t, n = onb.n;
  }
  Vec3 direction(float z, float phi) const {
    const float r = std::sqrt(positive_part(1.0f - z * z));
    return normalize(s * (r * std::cos(phi)) + t * (r * std::sin(phi)) + n * z);
  }
};

// The density a probe shows: for nee-mis, the two techniques it combines at
// the vertex, each taken once (the mean of the two densities).
float shown_pdf(const SamplingPlan& plan, const ProbePoint& at, const Vec3& d) {
  if (plan.nee_mis) {
    const float light = plan.emitters.empty() ? 0.0f : plan.emitters.pdf(at.point, d);
    const float cosine = cosine_hemisphere_pdf(at.normal, d);
    return plan.emitters.empty() ? cosine : 0.5f * (light + cosine);
  }
  return plan.pdf(at.point, at.normal, d);
}

}  // namespace

void direction_to_map(const ProbePoint& at, const Vec3& direction, float& u, float& v) {
  const MapFrame f(at.normal);
  const float z = std::clamp(dot(direction, f.n), -1.0f, 1.0f);
  float phi = std::atan2(dot(direction, f.t), dot(direction, f.s));
  if (phi < 0.0f) phi += 2.0f * kPi;
  u = phi / (2.0f * kPi);
  v = (1.0f - z) * 0.5f;
}

std::vector<float> pdf_map(const SamplingPlan& plan, const ProbePoint& at, int width, int height) {
  std::vector<float> out(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), 0.0f);
  if (!at.found) return out;
  const MapFrame f(at.normal);
  for (int row = 0; row < height; ++row) {
    const float z = 1.0f - 2.0f * (static_cast<float>(row) + 0.5f) / static_cast<float>(height);
    for (int col = 0; col < width; ++col) {
      const float phi = 2.0f * kPi * (static_cast<float>(col) + 0.5f) / static_cast<float>(width);
      out[static_cast<std::size_t>(row) * width + col] = shown_pdf(plan, at, f.direction(z, phi));
    }
  }
  return out;
}

ProbeChiSquare probe_chi_square(const SamplingPlan& plan, const ProbePoint& at, int samples, std::uint64_t seed,
                                int z_cells, int phi_cells, double alpha) {
  ProbeChiSquare out;
  out.alpha = alpha;
  out.z_cells = z_cells;
  out.phi_cells = phi_cells;
  const std::size_t cells = static_cast<std::size_t>(z_cells) * static_cast<std::size_t>(phi_cells);
  out.observed.assign(cells, 0);
  out.expected.assign(cells, 0.0);
  if (!at.found || plan.nee_mis) return out;  // nee-mis draws two directions; see probe_directions

  auto cell_of = [&](const Vec3& d) {
    float u, v;
    direction_to_map(at, d, u, v);
    const int col = std::min(phi_cells - 1, static_cast<int>(u * static_cast<float>(phi_cells)));
    const int row = std::min(z_cells - 1, static_cast<int>(v * static_cast<float>(z_cells)));
    return static_cast<std::size_t>(row) * phi_cells + col;
  };
  Rng rng(seed, 5);
  for (int i = 0; i < samples; ++i) {
    const DirectionSample ds = plan.sample(at.point, at.normal, rng);
    if (ds.none) {
      ++out.empty_samples;
      continue;
    }
    ++out.observed[cell_of(ds.direction)];
  }
  // Expected: N times the pdf integrated over each cell (cells have equal
  // solid angle 4 pi / cells). Midpoint rule on 8 x 8 points; a cell where the
  // pdf is not constant across them (a target's outline crosses it) is
  // integrated again on 64 x 64, so edges do not fake a failure. The empty
  // samples are the technique's missing mass, so N counts all samples.
  const MapFrame f(at.normal);
  const double cell_solid_angle = 4.0 * std::numbers::pi / static_cast<double>(cells);
  auto integrate = [&](int row, int col, int sub, float& lo, float& hi) {
    double sum = 0.0;
    lo = kInf, hi = -kInf;
    for (int a = 0; a < sub; ++a)
      for (int b = 0; b < sub; ++b) {
        const float v = (static_cast<float>(row) + (static_cast<float>(a) + 0.5f) / static_cast<float>(sub)) /
                        static_cast<float>(z_cells);
        const float u = (static_cast<float>(col) + (static_cast<float>(b) + 0.5f) / static_cast<float>(sub)) /
                        static_cast<float>(phi_cells);
        const float p = plan.pdf(at.point, at.normal, f.direction(1.0f - 2.0f * v, 2.0f * kPi * u));
        lo = min_of(lo, p), hi = max_of(hi, p);
        sum += p;
      }
    return sum / (static_cast<double>(sub) * sub);
  };
  // Cells an outline crosses, and their neighbours (a sliver of a target can
  // miss all 64 points of a cell next to one), get the fine grid.
  std::vector<char> edge(cells, 0);
  for (int row = 0; row < z_cells; ++row)
    for (int col = 0; col < phi_cells; ++col) {
      float lo, hi;
      const std::size_t i = static_cast<std::size_t>(row) * phi_cells + col;
      out.expected[i] = integrate(row, col, 8, lo, hi);
      edge[i] = hi > lo * 1.5f + 1e-6f;
    }
  for (int row = 0; row < z_cells; ++row)
    for (int col = 0; col < phi_cells; ++col) {
      bool near_edge = false;
      for (int dr = -1; dr <= 1; ++dr)
        for (int dc = -1; dc <= 1; ++dc) {
          const int r = row + dr, c = (col + dc + phi_cells) % phi_cells;  // azimuth wraps
          if (r >= 0 && r < z_cells && edge[static_cast<std::size_t>(r) * phi_cells + c]) near_edge = true;
        }
      const std::size_t i = static_cast<std::size_t>(row) * phi_cells + col;
      float lo, hi;
      // Still no density where samples landed: look much closer.
      const int sub = out.expected[i] == 0.0 && out.observed[i] > 0 ? 256 : (near_edge ? 64 : 0);
      if (sub) out.expected[i] = integrate(row, col, sub, lo, hi);
      out.expected[i] *= static_cast<double>(samples) * cell_solid_angle;
    }
  out.result = stats::chi_square_test(out.observed, out.expected);
  out.passed = out.result.zero_cell_hits == 0 && out.result.p_value > alpha;
  return out;
}

}  // namespace pdflab
