#include "renderer/sampling/target_set.h"

#include "renderer/scene/environment.h"

#include "renderer/sampling/mixture.h"
#include "renderer/sampling/techniques.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace pdflab {

double emitter_power(const Material& m, double area) {
  if (m.type != MaterialType::DiffuseLight) return 0.0;
  return luminance(m.emit.x, m.emit.y, m.emit.z) * area * std::numbers::pi * (m.two_sided ? 2.0 : 1.0);
}

void TargetSet::set_probabilities(const std::vector<double>& weights) {
  if (weights.empty()) {
    choice = DiscreteDistribution();
    return;
  }
  choice = DiscreteDistribution(weights, DiscreteDistribution::Tiny::AtLeastOne);
  int i = 0;
  for (auto& q : quads) q.probability = choice.pmf(i++);
  for (auto& sp : spheres) sp.probability = choice.pmf(i++);
  by_point = solid_angle && size() >= 2;
  everywhere.clear();
  everywhere_threshold.clear();
  one_sided.clear();
  lit_everywhere = false;
  emitter_share = 0.0f;
  if (!by_point) return;
  // The lights, their total share (summed in the walk's order) and whether
  // one of them is seen from everywhere (a sphere or a two-sided quad).
  int lights = 0;
  for (int j = 0; j < size(); ++j) {
    if (!leaf::target_emits(*this, j)) continue;
    ++lights;
    emitter_share = emitter_share + leaf::target_share(*this, j);
    if (j >= static_cast<int>(quads.size()) || !quads[static_cast<std::size_t>(j)].axes.one_sided) lit_everywhere = true;
  }
  if (lights >= 2)
    for (int j = 0; j < static_cast<int>(quads.size()); ++j)
      if (quads[static_cast<std::size_t>(j)].axes.one_sided) one_sided.push_back(j);
  // leaf::begin_walk's choice for a point that receives from every light, in
  // the same float operations, so that its probabilities are the same numbers.
  leaf::TargetChoice c = leaf::begin_choice(*this, emitter_share);
  double below = 0.0;  // C_j: sums of multiples of 2^-24, exact
  for (int j = 0; j < size(); ++j) {
    everywhere.push_back(leaf::next_choice(*this, c, j, true));
    below += everywhere.back();
    if (j + 1 < size()) everywhere_threshold.push_back(static_cast<std::uint32_t>(std::min(below * 0x1.0p32, 4294967295.0)));
  }
}

bool TargetSet::receives(const Vec3& origin, int j) const { return leaf::receives_light(*this, j, origin); }

std::vector<float> TargetSet::probabilities_at(const Vec3& origin, const Vec3& normal) const {
  if (tree) return tree->probabilities(origin, normal);
  std::vector<float> out;
  out.reserve(static_cast<std::size_t>(size()));
  if (!by_point) {
    for (const QuadEntry& e : quads) out.push_back(e.probability);
    for (const SphereEntry& e : spheres) out.push_back(e.probability);
    return out;
  }
  leaf::ChoiceWalk walk = leaf::begin_walk(*this, origin, true);
  for (int j = 0; j < size(); ++j) out.push_back(walk.next());
  return out;
}

std::uint32_t TargetSet::first_choice_of(const Vec3& origin, int j) const {
  if (tree) return tree->first_choice_of(j);
  if (j <= 0) return 0u;
  if (!by_point) return choice.thresholds()[static_cast<std::size_t>(j - 1)];
  double below = 0.0;  // C_{j-1}: the probabilities are multiples of 2^-24, so the sum is exact
  const std::vector<float> p = probabilities_at(origin);
  for (int i = 0; i < j; ++i) below += p[static_cast<std::size_t>(i)];
  return static_cast<std::uint32_t>(below * 0x1.0p32);
}

float TargetSet::pdf_without(const Vec3& origin, const Vec3& direction, const void* skip, int aimed_quad,
                             float aimed_t) const {
  float sum = 0.0f;  // an area set (solid-angle sets: leaf::solid_angle_targets_pdf)
  for (const QuadEntry& e : quads)
    if (e.quad != skip)
      sum += e.probability * leaf::quad_area_pdf(*e.quad, origin, direction, e.index == aimed_quad, aimed_t);
  for (const SphereEntry& e : spheres)
    if (e.sphere != skip)
      sum += e.probability * leaf::sphere_cone_pdf(*e.sphere, origin, direction, e.index == aimed_quad);
  return sum;
}

float TargetSet::pdf(const Vec3& origin, const Vec3& direction, int aimed_quad, float aimed_t) const {
  if (tree) return leaf::tree_targets_pdf(*this, origin, direction, aimed_quad, aimed_t, true, nullptr, -1);
  if (solid_angle) return leaf::solid_angle_targets_pdf(*this, origin, direction, aimed_quad, aimed_t, true, nullptr);
  return pdf_without(origin, direction, nullptr, aimed_quad, aimed_t);
}

DirectionSample TargetSet::sample(const Vec3& origin, std::uint32_t u_choice, float u1, float u2) const {
  if (solid_angle) {
    leaf::SolidAngleSetup setup{-1, {}};
    const std::int32_t u = static_cast<std::int32_t>(u_choice);
    return to_direction_sample(tree ? leaf::sample_tree_targets(*this, origin, nullptr, u, u1, u2, true, setup, false,
                                                                nullptr, nullptr)
                                    : leaf::sample_solid_angle_targets(*this, origin, u, u1, u2, true, setup));
  }
  if (empty()) return {Vec3(0.0f, 0.0f, 1.0f), 0.0f, true};  // nothing to aim at
  const int chosen = choice.sample(u_choice);
  DirectionSample ds;
  const int nq = static_cast<int>(quads.size());
  if (chosen < nq) {
    const QuadEntry& e = quads[chosen];
    ds = sample_quad_area(*e.quad, origin, u1, u2);
    if (ds.none) return ds;
    ds.aimed_quad = e.index;
    ds.pdf = e.probability * ds.pdf + pdf_without(origin, ds.direction, e.quad);
  } else {
    const SphereEntry& e = spheres[chosen - nq];
    float sin_phi, cos_phi;
    sincos_2pi(u2, sin_phi, cos_phi);
    ds = to_direction_sample(leaf::sample_sphere_cone(*e.sphere, origin, u1, sin_phi, cos_phi, e.index));
    ds.pdf = e.probability * ds.pdf + pdf_without(origin, ds.direction, e.sphere);
  }
  return ds;
}

namespace {

// Fills a set with the scene's objects that `pick` accepts; returns their powers.
template <class Pick>
std::vector<double> collect_targets(const Scene& scene, TargetSet& set, Pick pick) {
  std::vector<double> quad_power, sphere_power;
  for (std::size_t i = 0; i < scene.quads.size(); ++i) {
    const Quad& q = scene.quads[i];
    if (!pick(Target{Target::Kind::Quad, static_cast<std::uint32_t>(i)})) continue;
    set.quads.push_back({&q, 0.0f, static_cast<std::int32_t>(i), rectangle_axes(q)});
    const Material& m = scene.materials[q.material];
    set.quads.back().axes.one_sided = m.type == MaterialType::DiffuseLight && !m.two_sided;
    quad_power.push_back(emitter_power(scene.materials[q.material], q.area));
  }
  for (std::size_t i = 0; i < scene.spheres.size(); ++i) {
    const Sphere& sp = scene.spheres[i];
    if (!pick(Target{Target::Kind::Sphere, static_cast<std::uint32_t>(i)})) continue;
    set.spheres.push_back({&sp, 0.0f, static_cast<std::int32_t>(scene.quads.size() + i)});
    const double area = 4.0 * std::numbers::pi * static_cast<double>(sp.radius) * sp.radius;
    sphere_power.push_back(emitter_power(scene.materials[sp.material], area));
  }
  quad_power.insert(quad_power.end(), sphere_power.begin(), sphere_power.end());
  set.emits.clear();
  for (const double p : quad_power) set.emits.push_back(p > 0.0 ? 1 : 0);
  return quad_power;
}

// Power-proportional choice; a target that emits nothing (the book's glass
// sphere) gets the mean emitter's share, so it is still aimed at as often as
// an average light. All-zero powers fall back to uniform.
std::vector<double> power_weights(std::vector<double> power) {
  double sum = 0.0;
  int emitting = 0;
  for (double p : power)
    if (p > 0.0) sum += p, ++emitting;
  const double stand_in = emitting ? sum / emitting : 1.0;
  for (double& p : power)
    if (!(p > 0.0)) p = stand_in;
  return power;
}

bool is_importance_target(const Scene& scene, const Target& t) {
  for (const Target& x : scene.targets)
    if (x.kind == t.kind && x.index == t.index) return true;
  return false;
}

MaterialType material_type(const Scene& scene, const Target& t) {
  const std::uint32_t m = t.kind == Target::Kind::Quad ? scene.quads[t.index].material : scene.spheres[t.index].material;
  return scene.materials[m].type;
}

bool is_emitter(const Scene& scene, const Target& t) { return material_type(scene, t) == MaterialType::DiffuseLight; }

bool is_specular(const Scene& scene, const Target& t) {
  const MaterialType type = material_type(scene, t);
  return type == MaterialType::Metal || type == MaterialType::Dielectric;
}

// Every object `pick` accepts, chosen uniformly, quads by area.
template <class Pick>
TargetSet uniform_area_set(const Scene& scene, Pick pick) {
  TargetSet set;
  const std::size_t n = collect_targets(scene, set, pick).size();
  set.set_probabilities(std::vector<double>(n, 1.0));
  return set;
}

}  // namespace

TargetSet book_target_set(const Scene& scene) {
  return uniform_area_set(scene, [&](const Target& t) { return is_importance_target(scene, t); });
}

TargetSet specular_object_set(const Scene& scene) {
  return uniform_area_set(scene, [&](const Target& t) { return is_specular(scene, t); });
}

TargetSet power_target_set(const Scene& scene) {
  TargetSet set;
  const std::vector<double> power =
      collect_targets(scene, set, [&](const Target& t) { return is_importance_target(scene, t); });
  set.solid_angle = true;
  set.set_probabilities(power_weights(power));
  return set;
}

namespace {

// The tree over a set's emitters (quads, then spheres), each with its power.
std::shared_ptr<const LightTree> light_tree(const TargetSet& set, const std::vector<double>& power) {
  std::vector<LightTree::Emitter> emitters;
  std::size_t k = 0;
  for (const TargetSet::QuadEntry& e : set.quads) {
    const Quad& q = *e.quad;
    LightTree::Emitter x;
    x.lo = glm::min(glm::min(q.q, q.q + q.u), glm::min(q.q + q.v, q.q + q.u + q.v));
    x.hi = glm::max(glm::max(q.q, q.q + q.u), glm::max(q.q + q.v, q.q + q.u + q.v));
    x.axis = q.normal;
    x.cos_spread = 1.0f;
    x.two_sided = !e.axes.one_sided;
    x.power = static_cast<float>(power[k++]);
    emitters.push_back(x);
  }
  for (const TargetSet::SphereEntry& e : set.spheres) {
    const Sphere& sp = *e.sphere;
    LightTree::Emitter x;
    x.lo = sp.center - Vec3(sp.radius);
    x.hi = sp.center + Vec3(sp.radius);
    x.axis = Vec3(0.0f, 0.0f, 1.0f);
    x.cos_spread = -1.0f;
    x.power = static_cast<float>(power[k++]);
    emitters.push_back(x);
  }
  return std::make_shared<const LightTree>(emitters, kLightChoiceFloor);
}

}  // namespace

TargetSet emitter_set(const Scene& scene, LightChoice light_choice) {
  TargetSet set;
  std::vector<double> power = collect_targets(scene, set, [&](const Target& t) { return is_emitter(scene, t); });
  for (TargetSet::QuadEntry& e : set.quads) e.axes.flat_distance_ratio = kEmitterFlatDistanceRatio;
  set.solid_angle = true;
  power = power_weights(power);
  if (light_choice == LightChoice::Uniform) std::fill(power.begin(), power.end(), 1.0);
  set.set_probabilities(power);
  if (light_choice == LightChoice::Tree && set.size() >= 2) {
    set.tree = light_tree(set, power);
    set.by_point = false;  // the tree reads the point
    set.target_of.assign(scene.quads.size() + scene.spheres.size(), -1);
    for (int j = 0; j < set.size(); ++j) {
      const int nq = static_cast<int>(set.quads.size());
      const std::int32_t id = j < nq ? set.quads[static_cast<std::size_t>(j)].index : set.spheres[static_cast<std::size_t>(j - nq)].index;
      set.target_of[static_cast<std::size_t>(id)] = j;
    }
  }
  return set;
}

float environment_light_share(const Scene& scene) {
  if (!scene.environment || !scene.environment->sampleable()) return 0.0f;
  double emitted = 0.0;  // the area lights' power
  double lo[3] = {kInf, kInf, kInf}, hi[3] = {-kInf, -kInf, -kInf};
  const auto extend = [&](const Vec3& p, double r) {
    for (int c = 0; c < 3; ++c) {
      lo[c] = std::min(lo[c], static_cast<double>(p[c]) - r);
      hi[c] = std::max(hi[c], static_cast<double>(p[c]) + r);
    }
  };
  for (const Quad& q : scene.quads) {
    emitted += emitter_power(scene.materials[q.material], q.area);
    for (const Vec3& p : {q.q, q.q + q.u, q.q + q.v, q.q + q.u + q.v}) extend(p, 0.0);
  }
  for (const Sphere& sp : scene.spheres) {
    const double r = sp.radius;
    emitted += emitter_power(scene.materials[sp.material], 4.0 * std::numbers::pi * r * r);
    extend(sp.center, r);
  }
  if (!(emitted > 0.0)) return 1.0f;
  double radius2 = 0.0;
  for (int c = 0; c < 3; ++c) radius2 += 0.25 * (hi[c] - lo[c]) * (hi[c] - lo[c]);
  // The power the map sends through the scene: through a disc of the scene's
  // bounding radius, from every direction, pi R^2 times the map's luminance
  // integrated over the sphere.
  const double environment = std::numbers::pi * radius2 * scene.environment->luminance_integral();
  double share = environment / (environment + emitted);
  share = std::clamp(share, static_cast<double>(kEnvironmentShareFloor), 1.0 - kEnvironmentShareFloor);
  return static_cast<float>(std::round(share * 0x1.0p24) * 0x1.0p-24);
}

}  // namespace pdflab
