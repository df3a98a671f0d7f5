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
#include <string>

namespace pdflab {

struct RunLimit {
  double seconds = 0.0;   // > 0: equal time (or)
  std::uint32_t spp = 0;  // > 0: equal samples
  int threads = 0;
  std::uint32_t first_sample = 0;  // each pixel's first sample index (a run continuing another)
};

struct MeasuredRun {
  Film film;           // the accumulation when the run stopped
  SessionStats stats;  // its spp, seconds, samples per second, drops
};

// `on_poll` (optional) sees the session after every wait, e.g. to copy the
// images published so far; `label` leads the progress line on stderr.
MeasuredRun render_measured(const std::shared_ptr<const Scene>& scene, const Strategy& strategy, std::uint64_t seed,
                            const RunLimit& limit, const std::string& label, bool show_progress,
                            const std::function<void(RenderSession&)>& on_poll = {});

}  // namespace pdflab
