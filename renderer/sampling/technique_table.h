// The table of sampling techniques. Everything that lists techniques — the
// strategy parser and its messages, the mixture in both tracers, the viewer's
// sliders and probe, `--help`, the chi-square suite — iterates this table; no
// code names a technique by its position. docs/adding_a_technique.md adds one.
//
// Read twice: plainly, for the list (PDFLAB_TECHNIQUES, below); with
// PDFLAB_TECHNIQUE_BODIES defined, inside a lane namespace, for each
// technique's sample and pdf (renderer/sampling/techniques/*.inc).
#if defined(PDFLAB_TECHNIQUE_BODIES)

#include "renderer/sampling/techniques/cosine.inc"
#include "renderer/sampling/techniques/uniform_hemisphere.inc"
#include "renderer/sampling/techniques/uniform_sphere.inc"
#include "renderer/sampling/techniques/light.inc"
#include "renderer/sampling/techniques/light_solid_angle.inc"
#include "renderer/sampling/techniques/cosine_power.inc"
#include "renderer/sampling/techniques/specular_objects.inc"
#include "renderer/sampling/techniques/uniform_cone.inc"
#include "renderer/sampling/techniques/bsdf.inc"
#include "renderer/sampling/techniques/environment.inc"
#include "renderer/sampling/techniques/guided.inc"

#elif !defined(PDFLAB_TECHNIQUE_TABLE_H)
#define PDFLAB_TECHNIQUE_TABLE_H

// X(Type): one row per technique, in the order the panel and the messages show them.
#define PDFLAB_TECHNIQUES(X) \
  X(Cosine)                  \
  X(UniformHemisphere)       \
  X(UniformSphere)           \
  X(Light)                   \
  X(LightSolidAngle)         \
  X(CosinePower)             \
  X(SpecularObjects)         \
  X(UniformCone)             \
  X(Bsdf)                    \
  X(EnvironmentMap)          \
  X(Guided)

#include <array>
#include <cstdint>
#include <string>
#include <string_view>

namespace pdflab {

enum class Technique : std::uint8_t {
#define PDFLAB_ENUM_ROW(T) T,
  PDFLAB_TECHNIQUES(PDFLAB_ENUM_ROW)
#undef PDFLAB_ENUM_ROW
  Count
};
inline constexpr int kTechniqueCount = static_cast<int>(Technique::Count);

// What the rest of the program knows of a technique besides its math, as a
// row with named fields (TechniqueInfo{.name = ..., .pdf = ...}).
struct TechniqueInfo {
  std::string_view name{};   // as typed in a strategy
  std::string_view draws{};  // what it draws, for --help and the README
  std::string_view pdf{};    // its density, as a formula
  // Why the technique alone is biased with its parameter at `p`: the part of
  // the hemisphere above a diffuse surface where its pdf is zero, said as what
  // it does ("sees only its targets"). Empty, or no function at all: its pdf
  // is positive over the whole hemisphere, and alone it is unbiased.
  std::string (*bias)(float p) = nullptr;
  // Why the technique alone, on a diffuse surface whose light reaches it from
  // every direction, has infinite variance with its parameter at `p` (f cos / p
  // unbounded and square-integrable nowhere near where it grows): an image
  // that converges, but slowly and unevenly, so no standard error describes
  // it. Empty, or no function: finite variance.
  std::string (*heavy_tail)(float p) = nullptr;
  bool draws_target = false;  // draws one more random number, for the target
  std::array<std::uint8_t, 3> colour{};  // its samples in the probe
  // A parameter written `name:P` (empty: none), its default and range.
  std::string_view parameter{};
  float parameter_default = 0.0f, parameter_min = 0.0f, parameter_max = 0.0f;

  // bias(p) and heavy_tail(p), or empty where there is no function.
  std::string bias_alone(float p) const { return bias ? bias(p) : std::string(); }
  std::string heavy_tail_alone(float p) const { return heavy_tail ? heavy_tail(p) : std::string(); }
};

// The light techniques' bias: they draw only directions towards their targets.
inline std::string sees_only_its_targets(float) { return "sees only its targets"; }

// What a technique derives from its parameter once per sampling plan (not per
// call), for its sample and pdf to read: a technique that needs any defines
// `static TechniqueConstants constants(float parameter)`.
struct TechniqueConstants {
  float value[4] = {};
};

}  // namespace pdflab

#endif
