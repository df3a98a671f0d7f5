#include "ui/measure.h"

#include "renderer/metrics/metrics.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace pdflab::ui {

double Figures::plot_error() const {
  if (!valid) return 0.0;
  return std::sqrt(std::max(0.0, against_reference ? relmse : estimated_relmse));
}

Figures compute_figures(const ImageInfo& info, const std::vector<float>& rgb, const ReferenceImage* reference,
                        bool unbiased) {
  Figures f;
  if (info.preview || info.spp == 0) return f;
  f.valid = true;
  f.spp = info.spp;
  f.seconds = info.seconds;
  f.unbiased = unbiased;
  f.mean_relative_standard_error = info.mean_relative_standard_error;
  f.estimated_relmse = info.estimated_relmse;
  f.estimated_efficiency = unbiased ? efficiency(f.estimated_relmse, f.seconds) : 0.0;
  if (reference && reference->loaded() && reference->width == info.width && reference->height == info.height &&
      reference->rgb.size() == rgb.size()) {
    f.against_reference = true;
    f.rmse = rmse(rgb, reference->rgb);
    const RelMseMeasure m = measure_relmse(rgb, reference->rgb, reference->has_variance() ? reference->variance
                                                                                          : std::vector<float>{});
    f.relmse = m.corrected;
    f.relmse_interval = m.interval;
    f.relmse_raw = m.raw;
    f.reference_share = m.reference_share();
    f.reference_corrected = m.reference_corrected;
    f.rough_reference = m.reference_corrected && f.reference_share > kRoughShare;
    f.efficiency = efficiency(f.relmse, f.seconds);
  }
  return f;
}

ImageIdentity identity_of(const ReferenceImage& reference) {
  ImageIdentity id;
  id.width = reference.width;
  id.height = reference.height;
  const ReferenceInfo& info = reference.info;
  // A film of a scene without a content hash records zeros: unknown.
  if (info.has_sidecar && !info.scene_hash.empty() && info.scene_hash.find_first_not_of('0') != std::string::npos)
    id.view_hash = info.scene_hash;
  if (info.has_sidecar) id.max_depth = info.max_depth;
  id.assumed = id.view_hash.empty();
  return id;
}

std::string identity_mismatch(const ImageIdentity& ref, const ImageIdentity& render) {
  char text[200];
  if (ref.width > 0 && render.width > 0 && (ref.width != render.width || ref.height != render.height)) {
    std::snprintf(text, sizeof text, "The reference is %dx%d, the render %dx%d: the figures are estimates.", ref.width,
                  ref.height, render.width, render.height);
    return text;
  }
  if (!ref.view_hash.empty() && !render.view_hash.empty() && ref.view_hash != render.view_hash) {
    const bool same_scene = ref.view_hash == render.scene_hash ||
                            (!ref.scene_hash.empty() && ref.scene_hash == render.scene_hash);
    if (same_scene)
      return render.view_hash != render.scene_hash
                 ? "The camera moved away from the reference's view (Home goes back): the figures are estimates."
                 : "The reference shows another view of this scene: the figures are estimates.";
    return "The reference is of another scene: the figures are estimates.";
  }
  if (ref.max_depth > 0 && render.max_depth > 0 && ref.max_depth != render.max_depth) {
    std::snprintf(text, sizeof text, "The reference has max depth %d, the render %d: the figures are estimates.",
                  ref.max_depth, render.max_depth);
    return text;
  }
  return {};
}

ReferenceGoal reference_goal(const MeasureSettings& s, const Figures& now, std::string& note) {
  ReferenceGoal goal;
  goal.max_seconds = std::clamp(static_cast<double>(s.make_seconds), 1.0, 3600.0);
  if (s.make_target == ReferenceTarget::Share && now.valid && now.estimated_relmse > 0.0) {
    // The reference's noise is about its own relMSE over the raw error's sum of
    // both: at most kTargetShare of it when its relMSE is share / (1 - share)
    // of the render's.
    goal.relmse = now.estimated_relmse * kTargetShare / (1.0 - kTargetShare);
    char text[160];
    std::snprintf(text, sizeof text, "target: relMSE %.3g, %.0f%% of the render's %.3g at %u spp", goal.relmse,
                  100.0 * kTargetShare, now.estimated_relmse, now.spp);
    note = text;
    return goal;
  }
  goal.spp = std::max<std::uint32_t>(1, s.make_spp);
  note = "target: " + std::to_string(goal.spp) + " spp";
  if (s.make_target == ReferenceTarget::Share) note += " (no figures yet to aim the share at)";
  return goal;
}

namespace {

bool label_unbiased(const std::string& label) {
  try {
    return Strategy::parse(label).is_unbiased();
  } catch (const std::exception&) {
    return true;  // not a strategy (a test's label): nothing is withheld
  }
}

}  // namespace

void MeasureState::on_image(std::uint64_t current_generation, const std::string& label) {
  const bool unbiased = label_unbiased(label);
  // A path guiding training pass is shown but discarded: it is no point of the film's history or curve.
  const bool kept = !published.info.preview && published.info.training_pass == 0;
  if (kept && published.info.spp > 0) {
    if (published.info.generation != history_generation) {
      history.clear();
      history_generation = published.info.generation;
    }
    history.add(published.info.spp, published.info.estimated_relmse);
  }
  figures = compute_figures(published.info, published.rgb, matching_reference(), unbiased);
  figures.estimate_why = reference.loaded() ? reference_mismatch() : std::string();
  figures.estimate_unreliable = history.unreliable_now();
  if (kept && figures.valid && published.info.generation == current_generation)
    curves.record(published.info.generation, label, !figures.against_reference, figures.spp, figures.seconds,
                  figures.plot_error(), published.info.width, published.info.height);
  layer_ok = false;
  layer_why.clear();
}

void MeasureState::set_reference(ReferenceImage image) {
  reference = std::move(image);
  reference_error.clear();
  reference_note_warns = false;
  reference_identity = reference_identity_of_loaded();
  const bool unbiased = figures.unbiased;
  figures = compute_figures(published.info, published.rgb, matching_reference(), unbiased);
  figures.estimate_why = reference.loaded() ? reference_mismatch() : std::string();
  figures.estimate_unreliable = history.unreliable_now();
  layer_ok = false;
  layer_why.clear();
}

ImageIdentity MeasureState::reference_identity_of_loaded() const {
  ImageIdentity id = identity_of(reference);
  if (id.assumed && !render_identity.view_hash.empty()) {
    // Without a sidecar: the render as it is now, at the reference's own size.
    id.view_hash = render_identity.view_hash;
    id.scene_hash = render_identity.scene_hash;
    id.max_depth = render_identity.max_depth;
  }
  return id;
}

void MeasureState::set_render_identity(const ImageIdentity& identity) {
  render_identity = identity;
  if (reference.loaded() && reference_identity.assumed && reference_identity.view_hash.empty())
    reference_identity = reference_identity_of_loaded();
  layer_ok = false;
  layer_why.clear();
}

std::string MeasureState::reference_mismatch() const {
  if (!reference.loaded()) return {};
  ImageIdentity shown = render_identity;
  if (published.info.width > 0) {
    shown.width = published.info.width;
    shown.height = published.info.height;
  }
  return identity_mismatch(reference_identity, shown);
}

void MeasureSettings::set_metric(ErrorMetric metric) {
  LayerOptions& o = layer_options(view_mode);
  if (!view_offers_metric(view_mode, metric) || o.metric == metric) return;
  o.metric = metric;
  o.range.automatic = true;
}

void MeasureSettings::step_metric(int step) {
  if (view_mode != ViewMode::RelativeError && view_mode != ViewMode::Difference) return;
  int m = static_cast<int>(layer_options(view_mode).metric);
  for (int i = 0; i < kErrorMetricCount; ++i) {
    m = ((m + step) % kErrorMetricCount + kErrorMetricCount) % kErrorMetricCount;
    if (view_offers_metric(view_mode, static_cast<ErrorMetric>(m))) break;
  }
  set_metric(static_cast<ErrorMetric>(m));
}

bool MeasureState::refresh_layer(const MeasureSettings& settings) {
  const ViewMode mode = settings.view_mode;
  const LayerOptions& options = settings.layer_options(mode);
  if (mode == layer_mode && (mode == ViewMode::Image || (options == layer_options && (layer_ok || !layer_why.empty()))))
    return false;
  layer_mode = mode;
  layer_options = options;
  layer_why.clear();
  layer_ok = build_view_layer(mode, published, matching_reference(), layer, layer_why, &options, &weight_maps,
                              &guiding_leaves);
  if (!layer_ok && mode == ViewMode::Difference && reference.loaded() && !matching_reference())
    layer_why = reference_mismatch();
  return layer_ok;
}

}  // namespace pdflab::ui
