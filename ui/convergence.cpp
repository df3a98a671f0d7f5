#include "ui/convergence.h"

#include <cmath>

namespace pdflab::ui {

bool ConvergenceRecorder::record(std::uint64_t generation, const std::string& label, bool estimated,
                                 std::uint32_t spp, double seconds, double error) {
  if (!started_ || generation != generation_ || label != live_.label || estimated != live_.estimated) {
    live_ = Curve{label, estimated, {}};
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
