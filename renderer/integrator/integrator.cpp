#include "renderer/integrator/integrator.h"

#include "renderer/sampling/mixture.h"
#include "renderer/sampling/sobol.h"

namespace pdflab {

std::string_view drop_reason_name(DropReason r) {
  switch (r) {
    case DropReason::PdfZero: return "pdf_zero";
    case DropReason::PdfNotFinite: return "pdf_not_finite";
    case DropReason::RadianceNotFinite: return "radiance_not_finite";
    default: return "unknown";
  }
}

namespace {

// A path's estimate as it leaves the tracer: a value that is not finite is
// dropped (counted, and zero in its place).
Vec3 checked_radiance(const Vec3& radiance, DropCounts& drops) {
  if (is_finite(radiance)) return radiance;
  drops.add(DropReason::RadianceNotFinite);
  return Vec3(0.0f);
}

// The `+sobol` sampler's point of a draw group at the vertex reached by
// segment `depth`, for this sample (where SamplingPlan::stratifies(depth); the
// pcg stream is stepped as without, its numbers replaced).
qmc::Point<std::uint32_t> stratified_point(const Rng& rng, int depth, qmc::Group group, int dims) {
  return qmc::group_point(rng.qmc_index, rng.qmc_seed, static_cast<std::uint32_t>(depth), group, dims);
}

// Follows a metal or dielectric bounce from `hit` (`normal` faces the incoming
// ray); returns false when the path ends (absorbed). The scatter rules are
// leaf math (metal_direction, dielectric_setup / dielectric_direction).
bool scatter_specular(const SamplingPlan& plan, int depth, const Material& m, const Hit& hit, const Vec3& normal,
                      bool front_face, Ray& ray, Vec3& throughput, Rng& rng) {
  Vec3 dir;
  if (m.type == MaterialType::Metal) {
    const bool fuzzy = m.fuzz > 0.0f;
    float u1 = 0.0f, u2 = 0.0f;
    if (fuzzy) {
      u1 = rng.uniform(), u2 = rng.uniform();
      if (plan.stratifies(depth)) {
        const qmc::Point<std::uint32_t> p = stratified_point(rng, depth, qmc::Group::Specular, 2);
        u1 = Rng::to_unit(p.dim[0]), u2 = Rng::to_unit(p.dim[1]);
      }
    }
    dir = leaf::metal_direction(ray.direction, normal, m.fuzz, fuzzy, u1, u2);
    if (dot(dir, normal) <= 0.0f) return false;  // fuzz pushed it under the surface: absorbed
    throughput *= m.albedo;
  } else {
    const leaf::Refraction r = leaf::dielectric_setup(ray.direction, normal, front_face, m.ior);
    bool reflects = r.total_internal;
    if (!reflects) {
      float u = rng.uniform();
      if (plan.stratifies(depth)) u = Rng::to_unit(stratified_point(rng, depth, qmc::Group::Specular, 1).dim[0]);
      reflects = r.reflectance > u;
    }
    dir = leaf::dielectric_direction(r, ray.direction, normal, reflects);
  }
  ray = spawn_ray(hit, dir);
  return true;
}

// Whether Russian roulette checks a diffuse vertex reached by segment
// `depth`, before its continuation (segment depth + 1) is drawn.
bool roulette_checks(const SamplingPlan& plan, int depth) {
  return plan.roulette_depth > 0 && depth + 1 >= plan.roulette_depth;
}

// Russian roulette at such a vertex (leaf::russian_roulette): whether the path
// goes on. Draws its random number only where it applies.
bool roulette_survives(const SamplingPlan& plan, int depth, Vec3& throughput, const Vec3& albedo, Rng& rng) {
  if (!roulette_checks(plan, depth)) return true;
  return leaf::russian_roulette(throughput, albedo, rng.uniform());
}

// Next-event estimation with MIS: at each diffuse vertex one light sample
// (shadow ray; the emitters chosen by power, in solid angle or by area where a
// light looks flat: emitter_set) and one
// sample of the plan's mixture (cosine alone for plain nee-mis) that continues
// the path. Emission reached by the continuation is weighted against the light
// technique's density for the same direction, and the light sample against the
// mixture's, so each light path is counted once in total. The light
// technique's density for the continuation is found at the vertex, from the
// spherical rectangle the light sample set up there (leaf::SolidAngleSetup).
Vec3 trace_path_nee(const Scene& scene, const SamplingPlan& plan, Ray ray, Rng& rng, DropCounts& drops) {
  Vec3 radiance(0.0f);
  Vec3 throughput(1.0f);
  bool unweighted_emission = true;  // camera rays and specular bounces: no light sample competes
  float previous_pdf = 0.0f;        // the continuation's pdf at the last diffuse vertex
  float previous_light_pdf = 0.0f;  // the emitters' density for the continuation's direction there
  int aimed_quad = -1;  // the quad the continuation was aimed at (DirectionSample::aimed_quad)
  float aimed_distance = 0.0f;
  for (int depth = 0; depth < scene.max_depth; ++depth) {
    Hit hit;
    const bool found = intersect_aimed(scene, ray, aimed_quad, aimed_distance, hit);
    aimed_quad = -1;
    if (!found) {
      radiance += throughput * scene.background;  // the background is not a light target
      break;
    }
    const Material& m = scene.materials[hit.material];
    const bool front_face = dot(ray.direction, hit.normal) < 0.0f;
    const Vec3 normal = front_face ? hit.normal : -hit.normal;

    if (m.type == MaterialType::DiffuseLight) {
      if (front_face || m.two_sided) {
        float w = 1.0f;
        if (!unweighted_emission)
          w = mis_weight(previous_pdf, previous_light_pdf, plan.heuristic);
        radiance += throughput * m.emit * w;
      }
      break;
    }
    if (m.type != MaterialType::Lambertian) {
      if (!scatter_specular(plan, depth, m, hit, normal, front_face, ray, throughput, rng)) break;
      unweighted_emission = true;
      continue;
    }

    // Every ray leaving this vertex starts at `origin`, off the surface on the
    // incoming ray's side: the light is sampled, and every pdf evaluated, from
    // there, so a light smaller than the offset is aimed at exactly.
    const Vec3 origin = diffuse_origin(hit, normal);

    // The light sample. Its shadow ray is a path segment too: at the last
    // vertex max_depth allows there is none (the path would have one too many).
    leaf::SolidAngleSetup setup{-1, {}};
    if (!plan.emitters.empty() && depth + 1 < scene.max_depth) {
      std::uint32_t uc = rng.next_u32();
      float u1 = rng.uniform(), u2 = rng.uniform();
      if (plan.stratifies(depth)) {
        const qmc::Point<std::uint32_t> p = stratified_point(rng, depth, qmc::Group::Light, 3);
        u1 = Rng::to_unit(p.dim[0]), u2 = Rng::to_unit(p.dim[1]), uc = p.dim[2];
      }
      const DirectionSample ls = to_direction_sample(
          leaf::sample_solid_angle_targets(plan.emitters, origin, static_cast<std::int32_t>(uc), u1, u2, true, setup));
      if (ls.none) {
        // Seen edge-on from here: no light sample, and the light pdf that the
        // material sample is weighed against is zero too.
      } else if (!(ls.pdf > 0.0f) || ls.pdf == kInf) {
        drops.add(ls.pdf == 0.0f || ls.pdf < 0.0f ? DropReason::PdfZero : DropReason::PdfNotFinite);
      } else {
        const float cosine = dot(ls.direction, normal);
        Hit shadow_hit;
        if (cosine > 0.0f &&
            intersect_aimed(scene, Ray{origin, ls.direction}, ls.aimed_quad, ls.aimed_distance, shadow_hit)) {
          const Material& lm = scene.materials[shadow_hit.material];
          if (lm.type == MaterialType::DiffuseLight && (dot(ls.direction, shadow_hit.normal) < 0.0f || lm.two_sided)) {
            const float lambert = leaf::cosine_hemisphere_density(cosine);
            const float continuation_pdf = plan.cosine_continuation
                                               ? lambert
                                               : plan.pdf(origin, normal, ls.direction, ls.aimed_quad, ls.aimed_distance);
            radiance += throughput * m.albedo * lm.emit *
                        leaf::light_sample_weight(lambert, continuation_pdf, ls.pdf, plan.heuristic);
          }
        }
      }
    }

    if (!roulette_survives(plan, depth, throughput, m.albedo, rng)) break;
    // The continuation, drawn by the plan's mixture. Cosine alone: f cos / p
    // is exactly the albedo (the lobe's own z, not a rounded dot product).
    const DirectionSample ds = plan.sample(origin, normal, rng, nullptr, depth);
    if (ds.none) break;  // a target seen edge-on: a valid zero estimate
    if (!(ds.pdf > 0.0f) || ds.pdf == kInf) {
      if (!plan.cosine_continuation) drops.add(ds.pdf == kInf || std::isnan(ds.pdf) ? DropReason::PdfNotFinite : DropReason::PdfZero);
      break;  // for the cosine lobe: exactly tangent, the estimate is zero
    }
    if (plan.cosine_continuation) {
      throughput *= m.albedo;
    } else {
      const float cosine = dot(ds.direction, normal);
      if (cosine <= 0.0f) break;  // below the surface: the BRDF is zero, a valid zero estimate
      throughput *= m.albedo * leaf::lambert_weight(cosine, ds.pdf);
    }
    previous_pdf = ds.pdf;
    if (depth + 1 < scene.max_depth)  // else the path ends before it could reach an emitter
      previous_light_pdf = leaf::solid_angle_targets_pdf(plan.emitters, origin, ds.direction, ds.aimed_quad,
                                                         ds.aimed_distance, true, &setup);
    unweighted_emission = false;
    ray = Ray{origin, ds.direction};
    aimed_quad = ds.aimed_quad;
    aimed_distance = ds.aimed_distance;
  }
  return checked_radiance(radiance, drops);
}

}  // namespace

Vec3 trace_path(const Scene& scene, const SamplingPlan& plan, Ray ray, Rng& rng, DropCounts& drops,
                PathRecord* record) {
  if (plan.nee_mis) return trace_path_nee(scene, plan, ray, rng, drops);
  Vec3 radiance(0.0f);
  Vec3 throughput(1.0f);
  int aimed_quad = -1;  // the quad the ray was aimed at (DirectionSample::aimed_quad)
  float aimed_distance = 0.0f;
  if (record) record->vertices.clear(), record->segments = 0;
  for (int depth = 0; depth < scene.max_depth; ++depth) {
    if (record) ++record->segments;
    Hit hit;
    const bool found = intersect_aimed(scene, ray, aimed_quad, aimed_distance, hit);
    aimed_quad = -1;
    if (!found) {
      radiance += throughput * scene.background;
      break;
    }
    const Material& m = scene.materials[hit.material];
    const float cos_in = dot(ray.direction, hit.normal);
    const bool front_face = cos_in < 0.0f;
    const Vec3 normal = front_face ? hit.normal : -hit.normal;  // faces the incoming ray

    if (m.type == MaterialType::DiffuseLight) {
      if (front_face || m.two_sided) radiance += throughput * m.emit;
      break;  // lights do not scatter
    }

    if (m.type == MaterialType::Lambertian) {
      // Sampled, and its pdf evaluated, from the point the ray leaves from.
      const Vec3 origin = diffuse_origin(hit, normal);
      float roulette = 0.0f;  // recorded: q before the cut, where a check is taken
      if (record && roulette_checks(plan, depth)) {
        roulette = leaf::roulette_largest(throughput, m.albedo);
        if (!std::isfinite(roulette)) roulette = 0.0f;  // survives at every weight (and is dropped)
      }
      if (!roulette_survives(plan, depth, throughput, m.albedo, rng)) break;
      const DirectionSample ds = plan.sample(origin, normal, rng, nullptr, depth);
      if (ds.none) break;  // a light seen edge-on: a valid zero estimate
      if (!(ds.pdf > 0.0f)) {
        drops.add(std::isnan(ds.pdf) ? DropReason::PdfNotFinite : DropReason::PdfZero);
        break;
      }
      if (ds.pdf == kInf) {
        drops.add(DropReason::PdfNotFinite);
        break;
      }
      // Drawn with the mixture's density, whatever becomes of it: a direction
      // below the surface ends the path, with a probability that depends on the weights.
      if (record) record->vertices.push_back({origin, normal, ds.direction, roulette, record->segments});  // where its pdfs were evaluated
      const float cosine = dot(ds.direction, normal);
      if (cosine <= 0.0f) break;  // below the surface: the BRDF is zero, a valid zero estimate
      throughput *= m.albedo * leaf::lambert_weight(cosine, ds.pdf);
      ray = Ray{origin, ds.direction};
      aimed_quad = ds.aimed_quad;
      aimed_distance = ds.aimed_distance;
    } else if (!scatter_specular(plan, depth, m, hit, normal, front_face, ray, throughput, rng)) {
      break;
    }
  }
  return checked_radiance(radiance, drops);
}

SampleSeed::SampleSeed(std::uint64_t seed_value)
    : rng_key(Rng::seed_key(seed_value)), scramble_key(mix64(seed_value ^ 0x5bd1e995u)) {}

#include "renderer/integrator/pixel_sample.inc"

namespace {
// pixel_sample_numbers for one sample.
struct OneSample {
  using U64 = std::uint64_t;
  using U32 = std::uint32_t;
  using F = float;
  static U32 low32(U64 x) { return static_cast<U32>(x); }
  static U64 wide(U32 x) { return x; }
  static F unit(U32 x) { return Rng::to_unit(x); }
};
}  // namespace

PixelSampleStart begin_pixel_sample(const Scene& scene, const SampleSeed& seed, int x, int y,
                                    std::uint32_t sample_index) {
  const std::uint64_t pixel = static_cast<std::uint64_t>(y) * static_cast<std::uint64_t>(scene.camera.width) +
                              static_cast<std::uint64_t>(x);
  const PixelSampleNumbers<OneSample> n =
      pixel_sample_numbers<OneSample>(seed, pixel, static_cast<float>(x), static_cast<float>(y), sample_index);
  PixelSampleStart start{scene.camera.generate_ray(n.px, n.py), Rng::from_parts(n.rng_state, n.rng_increment)};
  start.rng.qmc_index = sample_index;
  start.rng.qmc_seed = n.qmc_seed;
  return start;
}

Vec3 render_pixel_sample(const Scene& scene, const SamplingPlan& plan, std::uint64_t seed, int x, int y,
                         std::uint32_t sample_index, DropCounts& drops) {
  PixelSampleStart start = begin_pixel_sample(scene, SampleSeed(seed), x, y, sample_index);
  return trace_path(scene, plan, start.ray, start.rng, drops);
}

}  // namespace pdflab
