#include "app/measured_run.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <utility>

namespace pdflab {

namespace {
thread_local std::function<bool()> interrupt_check;
}  // namespace

ScopedRunInterrupt::ScopedRunInterrupt(std::function<bool()> check) : previous_(std::move(interrupt_check)) {
  interrupt_check = std::move(check);
}

ScopedRunInterrupt::~ScopedRunInterrupt() { interrupt_check = std::move(previous_); }

MeasuredRun render_measured(const std::shared_ptr<const Scene>& scene, const Strategy& strategy, std::uint64_t seed,
                            const RunLimit& limit, const std::string& label, bool show_progress,
                            const std::function<void(RenderSession&)>& on_poll) {
  RenderSession session(limit.threads);
  RenderSettings settings;
  settings.scene = scene;
  settings.strategy = strategy;
  settings.seed = seed;
  settings.target_spp = limit.spp;  // 0 with a time limit: until paused
  settings.first_sample = limit.first_sample;
  settings.guiding = limit.guiding;
  session.set_settings(settings);
  for (;;) {
    const bool done = session.wait_until_done(std::chrono::milliseconds(25));
    const SessionStats st = session.stats();
    if (on_poll) on_poll(session);
    if (show_progress) {
      const double frac = limit.seconds > 0 ? st.seconds / limit.seconds : st.progress;
      std::fprintf(stderr, "\r%s %5.1f%%  %u spp  %.1f s   ", label.c_str(), 100.0 * std::min(1.0, frac), st.spp,
                   st.seconds);
      std::fflush(stderr);
    }
    if (done) break;
    if (interrupt_check && interrupt_check()) throw RunInterrupted();  // the session stops its workers
    if (limit.seconds > 0 && st.seconds >= limit.seconds) {
      session.set_paused(true);
      break;
    }
  }
  MeasuredRun run{session.copy_film(), {}};  // waits for the pass in flight
  run.stats = session.stats();
  run.guiding = session.guiding();
  return run;
}

}  // namespace pdflab
