#pragma once
// One headless render of a strategy for a time or a number of samples per
// pixel, as bench and sweep measure it: a fresh session, polled every 25 ms,
// paused when the time is up, with a progress line on request.
#include "renderer/film/film.h"
#include "renderer/sampling/strategy.h"
#include "renderer/scene/scene.h"
#include "renderer/session/session.h"

#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>

namespace pdflab {

struct RunLimit {
  double seconds = 0.0;   // > 0: equal time (or)
  std::uint32_t spp = 0;  // > 0: equal samples
  int threads = 0;
  std::uint32_t first_sample = 0;  // each pixel's first sample index (a run continuing another)
  // Path guiding's distribution to draw from, untrained further (RenderSettings::guiding); null: its own.
  std::shared_ptr<const GuidingDistribution> guiding = nullptr;
};

struct MeasuredRun {
  Film film;           // the accumulation when the run stopped
  SessionStats stats;  // its spp, seconds, samples per second, drops
  // Path guiding's distribution the run rendered with (null: no `guided`).
  std::shared_ptr<const GuidingDistribution> guiding = nullptr;
};

// `on_poll` (optional) sees the session after every wait, e.g. to copy the
// images published so far; `label` leads the progress line on stderr.
MeasuredRun render_measured(const std::shared_ptr<const Scene>& scene, const Strategy& strategy, std::uint64_t seed,
                            const RunLimit& limit, const std::string& label, bool show_progress,
                            const std::function<void(RenderSession&)>& on_poll = {});

// Thrown out of a measured run when the check of a ScopedRunInterrupt says
// stop: its session's workers are stopped and what it rendered is dropped.
struct RunInterrupted : std::runtime_error {
  RunInterrupted() : std::runtime_error("interrupted") {}
};

// While one lives, every measured run on this thread calls `check` at each
// poll (every 25 ms) and throws RunInterrupted when it says true: how a
// notebook's Ctrl+C reaches a sweep of many runs, which the command line
// leaves to the signal's default.
class ScopedRunInterrupt {
 public:
  explicit ScopedRunInterrupt(std::function<bool()> check);
  ~ScopedRunInterrupt();
  ScopedRunInterrupt(const ScopedRunInterrupt&) = delete;
  ScopedRunInterrupt& operator=(const ScopedRunInterrupt&) = delete;

 private:
  std::function<bool()> previous_;
};

}  // namespace pdflab
