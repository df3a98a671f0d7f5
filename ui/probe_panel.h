#pragma once
// The pixel probe panel: what a strategy does at the first diffuse surface a
// clicked pixel sees. Directions drawn there on projected hemisphere discs, the
// pdf as a lat-long map, the light lobe and the material's own (bsdf) lobe
// alone on one colour scale, and a chi-square check run off the UI thread.
#include "renderer/metrics/probe.h"
#include "renderer/sampling/guiding.h"
#include "renderer/sampling/strategy.h"
#include "renderer/scene/scene.h"

#include <future>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace pdflab::ui {

// A point on a unit disc seen from above the normal (upper hemisphere) or from
// below it (lower). Lambert's equal-area projection: equal solid angles cover
// equal disc areas, so a uniform density of directions looks uniform.
struct DiscPoint {
  float x = 0.0f, y = 0.0f;  // |(x, y)| <= 1; +y up on screen means phi = 90 degrees
  bool lower = false;        // below the surface: belongs on the second disc
};
// From pdf_map / direction_to_map coordinates: u = phi / 2 pi, v = (1 - cos theta) / 2.
DiscPoint project_to_disc(float u, float v);

// The image pixel under a point given in the same units as the image's
// rectangle on screen (top-left origin); nullopt outside.
struct PixelHit {
  int x = 0, y = 0;
};
std::optional<PixelHit> pixel_at(float px, float py, float rect_x, float rect_y, float rect_w, float rect_h,
                                 int image_width, int image_height);

// Observed and expected counts per cos(theta) band (rows of the chi-square
// grid summed over phi), from the normal (band 0) to straight down.
struct BandHistogram {
  std::vector<double> observed, expected;
};
BandHistogram cos_theta_bands(const ProbeChiSquare& chi);

struct ProbeMap {
  std::string title;
  std::vector<float> values;  // pdf_map layout
  int width = 0, height = 0;
  float max_value = 0.0f;
  std::string error;  // why there is no map (a strategy the scene cannot use)
};

struct ProbeState {
  bool mode = false;  // clicks on the image probe a pixel
  bool open = false;  // the panel is shown
  bool log_scale = true;
  bool has_point = false;
  int pixel_x = 0, pixel_y = 0;
  std::string strategy_text;
  ProbePoint point;
  std::vector<ProbeSample> samples;
  std::vector<int> technique_counts = std::vector<int>(kTechniqueCount + 1, 0);  // last: no direction
  // Light samples by the importance target they aim at (quads, then spheres, as
  // the plan lists them): the target's index per sample (-1: not a light
  // sample) and a label per target, e.g. "light (quad)", "glass (sphere)".
  std::vector<int> sample_target;
  std::vector<std::string> target_labels;
  // The strategy's pdf; beside it, on one colour scale, the light lobe (the
  // `light` technique alone) and the material's own lobe (the `bsdf`
  // technique alone: cosine at a lambertian point, GGX's visible normals at a
  // microfacet one).
  ProbeMap strategy_map, light_map, bsdf_map;
  // `guided` alone as the render's distribution has learned it here (empty:
  // the strategy has no trained `guided`).
  ProbeMap guided_map;
  // Beside it, the light taken in here (L cos) traced by brute force
  // (incident_light_map), made in the background: what it should learn.
  ProbeMap incident_map;
  std::future<std::vector<float>> incident_job;
  int incident_serial = 0;  // the probe the running job belongs to
  // The quadtree `guided` draws from here: the S-tree leaf holding the point
  // (-1: no trained `guided`), its box and its D-tree's cells.
  int guide_leaf = -1;
  Vec3 guide_box_lo{0.0f}, guide_box_hi{0.0f};
  std::vector<GuidingDistribution::Cell> guide_cells;
  std::string bsdf_lobe;   // what the material's own lobe is here, in words
  std::string delta_note;  // the clicked surface is glass or metal: its delta lobe, in words
  ProbeLightChoice light_choice;  // each light's probability at the point

  // Kept alive for the chi-square job, which reads both.
  std::shared_ptr<const Scene> scene;
  std::shared_ptr<const SamplingPlan> plan;
  std::shared_ptr<const GuidingDistribution> guide;  // what plan->guiding points to
  std::future<ProbeChiSquare> chi_job;
  int serial = 0;      // bumped by every probe_pixel
  int chi_serial = 0;  // the probe the running check belongs to
  std::optional<ProbeChiSquare> chi;
  double chi_started = 0.0, chi_seconds = 0.0;

  bool chi_running() const { return chi_job.valid(); }
  bool incident_running() const { return incident_job.valid(); }
};

// Computes the hit point, directions and maps for a pixel (a few milliseconds);
// forgets any earlier chi-square result.
// `guide`: the render's path guiding distribution, which `guided` draws from
// (null: untrained, the uniform sphere).
void probe_pixel(ProbeState& state, std::shared_ptr<const Scene> scene, const Strategy& strategy, std::uint64_t seed,
                 int x, int y, std::shared_ptr<const GuidingDistribution> guide = nullptr);
// Starts the chi-square check in the background (no-op while one runs).
void start_probe_chi_square(ProbeState& state, double now);
// Collects a finished check; true when one arrived for the current probe (a
// check started before the last probe_pixel is dropped).
bool poll_probe_chi_square(ProbeState& state, double now);

// Which of the plan's importance targets a light direction aims at: its index
// (quads, then spheres), the one of highest density when several overlap; -1 none.
int light_target_of(const SamplingPlan& plan, const Vec3& origin, const Vec3& direction);
// One colour per importance target in the probe's legend.
std::uint32_t target_colour(int target);

void draw_probe_panel(ProbeState& state, double now, float area_width, float area_height);

}  // namespace pdflab::ui
