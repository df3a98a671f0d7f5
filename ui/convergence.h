#pragma once
// The convergence plot's data: the running strategy's error per published
// pass, and pinned curves to compare against.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace pdflab::ui {

struct CurvePoint {
  double spp = 0.0, seconds = 0.0, error = 0.0;
};

struct Curve {
  std::string label;       // the strategy, as `pdflab render --strategy` takes it
  bool estimated = false;  // errors from the film's variance, not from a reference
  std::vector<CurvePoint> points;
  int width = 0, height = 0;  // the render's size (0: not known)
};
// "strategy, WxH (est.)": what a legend calls a curve.
std::string curve_label(const Curve& curve);

// Points of the running strategy as passes complete, and pinned curves to
// compare against. Points come from the published image's own spp and seconds,
// so the error and its abscissa always belong to the same pass.
class ConvergenceRecorder {
 public:
  static constexpr std::size_t kMaxPins = 6;
  // Points closer than this factor in spp are skipped: passes come ever more
  // often as spp grows, and a log axis needs only a few per decade.
  static constexpr double kMinSppStep = 1.02;

  // Adds a point of a render of width x height; a new generation, label or
  // error source starts a new live curve. Non-positive or non-finite errors (a
  // black image, 1 spp) are skipped. Returns whether the point was kept.
  bool record(std::uint64_t generation, const std::string& label, bool estimated, std::uint32_t spp, double seconds,
              double error, int width = 0, int height = 0);
  // Keeps the live curve (two points at least) under its label; the oldest pin
  // goes when there are kMaxPins. Returns false when there was nothing to keep.
  bool pin();
  void clear_pins() { pins_.clear(); }
  const Curve& live() const { return live_; }
  const std::vector<Curve>& pins() const { return pins_; }

 private:
  Curve live_;
  std::uint64_t generation_ = 0;
  bool started_ = false;
  std::vector<Curve> pins_;
};

}  // namespace pdflab::ui
