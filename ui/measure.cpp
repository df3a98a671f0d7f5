#include "ui/measure.h"

#include "renderer/metrics/metrics.h"

#include <algorithm>
#include <cmath>

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
    f.efficiency = efficiency(f.relmse, f.seconds);
  }
  return f;
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
  if (!published.info.preview && published.info.spp > 0) {
    if (published.info.generation != history_generation) {
      history.clear();
      history_generation = published.info.generation;
    }
    history.add(published.info.spp, published.info.estimated_relmse);
  }
  figures = compute_figures(published.info, published.rgb, &reference, unbiased);
  figures.estimate_unreliable = history.unreliable();
  if (figures.valid && published.info.generation == current_generation)
    curves.record(published.info.generation, label, !figures.against_reference, figures.spp, figures.seconds,
                  figures.plot_error());
  layer_ok = false;
  layer_why.clear();
}

void MeasureState::set_reference(ReferenceImage image) {
  reference = std::move(image);
  reference_error.clear();
  const bool unbiased = figures.unbiased;
  figures = compute_figures(published.info, published.rgb, &reference, unbiased);
  figures.estimate_unreliable = history.unreliable();
  layer_ok = false;
  layer_why.clear();
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
  layer_ok = build_view_layer(mode, published, &reference, layer, layer_why, &options, &weight_maps);
  return layer_ok;
}

}  // namespace pdflab::ui
