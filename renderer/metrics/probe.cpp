#include "renderer/metrics/probe.h"

#include "renderer/error.h"
#include "renderer/integrator/integrator.h"
#include "renderer/metrics/chi_square.h"
#include "renderer/sampling/guiding.h"

#include "renderer/sampling/onb.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
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
    // A microfacet conductor is a diffuse vertex too: the strategy draws there
    // (the probe shows its techniques as at a lambertian point).
    if (m.type == MaterialType::Lambertian || m.type == MaterialType::Microfacet) {
      at.found = true;
      at.point = diffuse_origin(hit, n);  // where its rays leave from
      at.normal = n;
      at.material = hit.material;
      at.surface.glossy = m.type == MaterialType::Microfacet;
      at.surface.alpha = m.alpha;
      at.surface.outgoing = normalize(-ray.direction);
      at.surface.transmits = m.type == MaterialType::Microfacet && m.transmits;
      at.surface.eta = front ? m.ior : 1.0f / m.ior;  // n beyond the surface over n on the ray's side
      return at;
    }
    if (m.type == MaterialType::DiffuseLight) return at;
    if (depth == 0) at.first_material = hit.material;
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
      // ...and one from its continuation's mixture (the cosine lobe for plain nee-mis).
      int technique = 0;
      const DirectionSample cs = plan.sample(at.point, at.normal, rng, &technique, -1, &at.surface);
      out.push_back({cs.direction, cs.pdf, cs.none ? -1 : technique});
      continue;
    }
    int technique = 0;
    const DirectionSample ds = plan.sample(at.point, at.normal, rng, &technique, -1, &at.surface);
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
    const float continuation = plan.pdf(at.surface, at.point, at.normal, d);
    return plan.emitters.empty() ? continuation : 0.5f * (light + continuation);
  }
  return plan.pdf(at.surface, at.point, at.normal, d);
}

// The lat-long map of any density of a direction, in pdf_map's layout: each
// cell the mean of the density at k x k points spread evenly over it in
// (cos theta, phi), where equal areas are equal solid angles (k = 1: the
// cell's centre).
template <typename Density>
std::vector<float> map_of(const ProbePoint& at, int width, int height, int k, const Density& density) {
  std::vector<float> out(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), 0.0f);
  if (!at.found) return out;
  k = std::max(1, k);
  const MapFrame f(at.normal);
  for (int row = 0; row < height; ++row) {
    for (int col = 0; col < width; ++col) {
      double sum = 0.0;
      for (int a = 0; a < k; ++a) {
        const float fa = (static_cast<float>(a) + 0.5f) / static_cast<float>(k);
        const float z = 1.0f - 2.0f * (static_cast<float>(row) + fa) / static_cast<float>(height);
        for (int b = 0; b < k; ++b) {
          const float fb = (static_cast<float>(b) + 0.5f) / static_cast<float>(k);
          const float phi = 2.0f * kPi * (static_cast<float>(col) + fb) / static_cast<float>(width);
          sum += static_cast<double>(density(f.direction(z, phi)));
        }
      }
      out[static_cast<std::size_t>(row) * width + col] = static_cast<float>(sum / (k * k));
    }
  }
  return out;
}

std::string short_number(float x) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", static_cast<double>(x));
  return text;
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

std::vector<float> pdf_map(const SamplingPlan& plan, const ProbePoint& at, int width, int height, int supersample) {
  return map_of(at, width, height, supersample, [&](const Vec3& d) { return shown_pdf(plan, at, d); });
}

std::vector<float> bsdf_pdf_map(const Scene& scene, const ProbePoint& at, int width, int height, int supersample) {
  const SamplingPlan plan = SamplingPlan::make(Strategy::single(Technique::Bsdf), scene);
  return map_of(at, width, height, supersample, [&](const Vec3& d) { return plan.pdf(at.surface, at.point, at.normal, d); });
}

std::vector<std::int32_t> guiding_leaf_map(const Scene& scene, const GuidingDistribution& guide) {
  const int width = scene.camera.width, height = scene.camera.height;
  std::vector<std::int32_t> leaves(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), -1);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const ProbePoint at = first_diffuse_hit(scene, x, y);
      if (at.found)
        leaves[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)] =
            guide.leaf_at(at.point, at.normal);
    }
  return leaves;
}

std::vector<float> incident_light_map(const Scene& scene, const ProbePoint& at, int width, int height, int per_cell,
                                      std::uint64_t seed) {
  std::vector<float> out(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), 0.0f);
  if (!at.found) return out;
  SamplingPlan plan;
  try {
    plan = SamplingPlan::make(Strategy::nee(), scene);
  } catch (const InputError&) {
    plan = SamplingPlan::make(Strategy::single(Technique::Cosine), scene);
  }
  const MapFrame f(at.normal);
  const int k = std::max(1, static_cast<int>(std::lround(std::sqrt(static_cast<double>(std::max(1, per_cell))))));
  double integral = 0.0;
  DropCounts drops;
  for (int row = 0; row < height / 2; ++row) {  // the rows above the surface (cos theta from 1 to 0)
    for (int col = 0; col < width; ++col) {
      Rng rng(seed, static_cast<std::uint64_t>(row) * static_cast<std::uint64_t>(width) + static_cast<std::uint64_t>(col));
      double sum = 0.0;
      const auto fk = static_cast<float>(k);
      for (int a = 0; a < k; ++a)
        for (int b = 0; b < k; ++b) {
          const float z = 1.0f - 2.0f * (static_cast<float>(row) + (static_cast<float>(a) + rng.uniform()) / fk) /
                                     static_cast<float>(height);
          const float phi = 2.0f * kPi * (static_cast<float>(col) + (static_cast<float>(b) + rng.uniform()) / fk) /
                            static_cast<float>(width);
          const Vec3 light = trace_path(scene, plan, Ray{at.point, f.direction(z, phi)}, rng, drops);
          sum += luminance(light.x, light.y, light.z) * z;  // times the cosine: what guiding learns
        }
      const double mean = sum / (k * k);
      out[static_cast<std::size_t>(row) * width + col] = static_cast<float>(mean);
      integral += mean;
    }
  }
  // Each cell is 4 pi / (width height) of the sphere.
  integral *= 4.0 * std::numbers::pi / (static_cast<double>(width) * height);
  if (!(integral > 0.0)) return std::vector<float>(out.size(), 0.0f);
  for (float& v : out) v = static_cast<float>(v / integral);
  return out;
}

float bsdf_pdf(const Scene& scene, const ProbePoint& at, const Vec3& direction) {
  const SamplingPlan plan = SamplingPlan::make(Strategy::single(Technique::Bsdf), scene);
  return plan.pdf(at.surface, at.point, at.normal, direction);
}

std::string material_name(const Scene& scene, std::uint32_t m, const char* fallback) {
  return m < scene.material_names.size() ? scene.material_names[m] : fallback;
}

std::string target_label(const Scene& scene, std::uint32_t material, const char* kind) {
  return material_name(scene, material, "target") + " (" + kind + ")";
}

std::vector<std::string> target_labels(const Scene& scene, const TargetSet& set) {
  std::vector<std::string> labels;
  std::vector<std::int32_t> ids;
  for (const TargetSet::QuadEntry& e : set.quads) labels.push_back(target_label(scene, e.quad->material, "quad")), ids.push_back(e.index);
  for (const TargetSet::SphereEntry& e : set.spheres)
    labels.push_back(target_label(scene, e.sphere->material, "sphere")), ids.push_back(e.index);
  // Targets of one material (a string of bulbs) told apart by their object number.
  std::map<std::string, int> uses;
  for (const std::string& l : labels) ++uses[l];
  for (std::size_t k = 0; k < labels.size(); ++k)
    if (uses[labels[k]] > 1) {
      const std::size_t open = labels[k].rfind(" (");
      labels[k].insert(open, " #" + std::to_string(ids[k]));
    }
  return labels;
}

std::string bsdf_lobe_name(const Scene& scene, const ProbePoint& at) {
  if (!at.found) return "no surface";
  const std::string name = material_name(scene, at.material);
  if (at.surface.glossy && at.surface.transmits)
    return "GGX visible normals, alpha " + short_number(at.surface.alpha) + ", reflected or refracted (" + name +
           ": rough dielectric, eta " + short_number(at.surface.eta) + ")";
  if (at.surface.glossy)
    return "GGX visible normals, alpha " + short_number(at.surface.alpha) + " (" + name + ": microfacet)";
  return "cosine lobe (" + name + ": lambertian)";
}

std::string delta_lobe_note(const Scene& scene, const ProbePoint& at) {
  if (at.specular_bounces == 0 || at.first_material >= scene.materials.size()) return {};
  const Material& m = scene.materials[at.first_material];
  const std::string name = material_name(scene, at.first_material);
  if (m.type == MaterialType::Dielectric)
    return "The clicked surface is " + name + " (glass, ior " + short_number(m.ior) +
           "): a delta lobe, the mirror direction or the refracted one, chosen by the Fresnel reflectance (" +
           (m.exact_fresnel ? "exact" : "Schlick's") + "); "
           "no density a strategy could draw or mix. The probe follows it to the first non-specular surface.";
  if (m.fuzz > 0.0f)
    return "The clicked surface is " + name + " (metal, fuzz " + short_number(m.fuzz) +
           "): the mirror direction perturbed by fuzz, followed outside any pdf. The probe follows the mirror "
           "direction to the first non-specular surface.";
  return "The clicked surface is " + name +
         " (metal): a delta lobe, the mirror direction alone; no density a strategy could draw or mix. "
         "The probe follows it to the first non-specular surface.";
}

ProbeLightChoice probe_light_choice(const Scene& scene, const SamplingPlan& plan, const ProbePoint& at) {
  ProbeLightChoice out;
  const TargetSet* set = nullptr;
  if (plan.nee_mis) {
    set = &plan.emitters, out.set = "nee-mis emitters", out.choice = light_choice_name(plan.light_choice);
  } else if (plan.weight[static_cast<int>(Technique::LightSolidAngle)] > 0.0f) {
    set = &plan.power_targets, out.set = "light-sa targets", out.choice = "power";
  } else if (plan.weight[static_cast<int>(Technique::Light)] > 0.0f) {
    set = &plan.book_targets, out.set = "light targets", out.choice = "uniform";
  }
  if (!set || !at.found || set->empty()) return out;
  // A light tree reads the point's normal too, as the light sample there does.
  const std::vector<float> p = set->probabilities_at(at.point, set->tree ? at.normal : Vec3(0.0f));
  const std::vector<std::string> labels = target_labels(scene, *set);
  int j = 0;
  for (const TargetSet::QuadEntry& e : set->quads) {
    out.rows.push_back({labels[static_cast<std::size_t>(j)], e.probability, p[static_cast<std::size_t>(j)],
                        set->receives(at.point, j)});
    ++j;
  }
  for (const TargetSet::SphereEntry& e : set->spheres) {
    out.rows.push_back({labels[static_cast<std::size_t>(j)], e.probability, p[static_cast<std::size_t>(j)], true});
    ++j;
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
  const chi_square::Grid grid{z_cells, phi_cells};
  std::vector<chi_square::Outcome> both = chi_square::check_plan(
      plan, at.point, at.normal, {chi_square::Sampler::Packet, chi_square::Sampler::OnePath}, samples, seed, grid,
      at.surface);
  chi_square::Outcome& packet = both[0];
  const chi_square::Outcome& one_path = both[1];
  out.result = packet.chi;
  out.one_path_result = one_path.chi;
  out.observed = std::move(packet.observed);
  out.expected = std::move(packet.expected);
  out.empty_samples = packet.empty_samples;
  out.passed = packet.passed(alpha) && one_path.passed(alpha);
  return out;
}

}  // namespace pdflab
