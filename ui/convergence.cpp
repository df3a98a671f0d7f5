#include "ui/convergence.h"

#include <cmath>

namespace pdflab::ui {

std::string curve_label(const Curve& c) {
  std::string s = c.label.empty() ? std::string("-") : c.label;
  if (c.width > 0 && c.height > 0) s += ", " + std::to_string(c.width) + "x" + std::to_string(c.height);
  if (c.estimated) s += " (est.)";
  return s;
}

bool ConvergenceRecorder::record(std::uint64_t generation, const std::string& label, bool estimated,
                                 std::uint32_t spp, double seconds, double error, int width, int height) {
  if (!started_ || generation != generation_ || label != live_.label || estimated != live_.estimated) {
    live_ = Curve{label, estimated, {}, width, height};
    generation_ = generation;
    started_ = true;
  }
  if (spp == 0 || !(error > 0.0) || !std::isfinite(error) || !(seconds > 0.0)) return false;
  if (!live_.points.empty() && static_cast<double>(spp) < live_.points.back().spp * kMinSppStep) return false;
  live_.points.push_back({static_cast<double>(spp), seconds, error});
  return true;
}

bool ConvergenceRecorder::pin() {
  if (live_.points.size() < 2) return false;
  if (pins_.size() >= kMaxPins) pins_.erase(pins_.begin());
  pins_.push_back(live_);
  return true;
}

}  // namespace pdflab::ui
