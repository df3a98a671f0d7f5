#include "app/viewer_references.h"

#include "renderer/error.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <thread>

#ifndef PDFLAB_VERSION
#define PDFLAB_VERSION "unknown"
#endif

namespace pdflab {

ViewerReferences::ViewerReferences(std::string cache_dir) : cache_dir_(reference_cache_dir(cache_dir)) {}

ViewerReferences::~ViewerReferences() {
  build_.reset();  // workers stop
  if (storing_.valid()) storing_.wait();
}

bool ViewerReferences::follow_scene(const Scene& render_scene, ui::MeasureState& m) {
  // The scene (its view), size and depth: the reference cache's key.
  const ReferenceKey key = reference_key(render_scene);
  if (key.stem() == looked_up_) return false;
  looked_up_ = key.stem();
  if (m.reference.loaded() && !m.reference_from_cache) return false;  // the user's own stays
  const CacheLookup found = find_cached_reference(cache_dir_, key);
  if (found.status == CacheLookup::Found) {
    m.set_reference(found.reference);
    m.reference_from_cache = true;
    m.reference_note = "Loaded the cached reference for this scene at " + std::to_string(key.width) + "x" +
                       std::to_string(key.height) + ", depth " + std::to_string(key.max_depth) + ": " +
                       std::to_string(found.reference.info.spp) + " spp of " + found.reference.info.strategy + ".";
    std::fprintf(stderr, "note: loaded the cached reference %s\n", found.path.c_str());  // for scripts
    return true;
  }
  if (found.status == CacheLookup::Damaged) {
    m.reference_error = found.message + "; Make reference rebuilds it.";
    std::fprintf(stderr, "note: %s\n", found.message.c_str());
  }
  // A reference from the cache of another view, size or depth stays loaded:
  // the figures say they are estimates and why (MeasureState::reference_mismatch),
  // and going back (Home, the old size) measures against it again.
  if (!m.reference.loaded()) m.reference_note.clear();
  return false;
}

void ViewerReferences::start(const Scene& render_scene, const std::string& scene_file, const ui::MeasureSettings& s,
                             ui::MeasureState& m) {
  if (running()) return;
  auto scene = std::make_shared<Scene>(render_scene);
  const int divisor = std::clamp(s.make_divisor, 1, 16);
  scene->camera.width = std::max(1, render_scene.camera.width / divisor);
  scene->camera.height = std::max(1, render_scene.camera.height / divisor);
  scene->camera.prepare();
  const int hardware = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  const int threads =
      std::clamp(static_cast<int>(std::lround(static_cast<double>(s.make_thread_share) * hardware)), 1, hardware);
  ReferenceJob job;
  job.scene = scene;
  job.scene_file = scene_file;
  job.strategy = default_reference_strategy(*scene);
  std::string target;
  job.goal = ui::reference_goal(s, m.figures, target);
  job.threads = threads;
  job.background_priority = true;
  job.version = PDFLAB_VERSION;
  try {
    build_ = std::make_unique<ReferenceBuild>(job);
  } catch (const std::exception& e) {
    m.reference_error = std::string("Cannot make a reference: ") + e.what();
    return;
  }
  build_key_ = reference_key(*scene);
  all_threads_ = threads >= hardware;
  m.reference_error.clear();
  m.reference_note.clear();
  m.build = {};
  m.build.running = true;
  m.build.width = scene->camera.width;
  m.build.height = scene->camera.height;
  m.build.threads = threads;
  m.build.target = target;
  m.build.max_seconds = job.goal.max_seconds;
}

void ViewerReferences::cancel(ui::MeasureState& m) {
  if (!build_) return;  // storing: let it finish, it is quick
  build_.reset();
  m.build = {};
  m.reference_note = "Reference cancelled; the cache is as it was.";
}

bool ViewerReferences::service(ui::MeasureState& m) {
  if (build_ && !storing_.valid()) {
    const ReferenceProgress p = build_->poll();
    const SessionStats st = build_->stats();
    m.build.fraction = p.fraction;
    m.build.seconds_left = p.seconds_left;
    m.build.spp = st.spp;
    if (p.reached) {
      m.build.finishing = true;
      // finish() waits for the pass in flight and the files take a moment: off
      // the UI thread. One stopped by the time limit short of its target stays
      // out of the cache, where later runs would take it for a finished one.
      storing_ = std::async(std::launch::async, [build = build_.get(), dir = cache_dir_, key = build_key_] {
        Stored out;
        try {
          out.reference = build->finish();
          out.capped = build->capped();
          if (!out.capped) {
            out.path = store_cached_reference(dir, key, out.reference);
            out.reference.path = out.path;
          }
        } catch (const std::exception& e) {
          out.error = e.what();
        }
        return out;
      });
    }
  }
  if (!storing_.valid() || storing_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return false;
  Stored done = storing_.get();
  build_.reset();
  m.build = {};
  if (!done.error.empty()) {
    m.reference_error = "Reference not stored: " + done.error;
    return false;
  }
  const ReferenceInfo info = done.reference.info;
  const int w = done.reference.width, h = done.reference.height;
  if (done.capped) done.reference.path = "made in the viewer (not cached)";
  m.set_reference(std::move(done.reference));
  m.reference_from_cache = !done.capped;
  looked_up_ = build_key_.stem();
  char note[320];
  if (done.capped) {
    std::snprintf(note, sizeof note,
                  "The reference stopped at its %.0f s limit short of its target: %dx%d, %u spp of %s. Kept for this "
                  "session, not cached.",
                  info.seconds, w, h, info.spp, info.strategy.c_str());
    std::fprintf(stderr, "note: made a reference short of its target (%u spp in %.0f s), not cached\n", info.spp,
                 info.seconds);
  } else {
    std::snprintf(note, sizeof note, "Made a reference: %dx%d, %u spp of %s in %.0f s, stored in the cache.", w, h,
                  info.spp, info.strategy.c_str(), info.seconds);
    std::fprintf(stderr, "note: made a reference, stored as %s\n", done.path.c_str());
  }
  m.reference_note = note;
  m.reference_note_warns = done.capped;
  return true;
}

std::optional<std::uint64_t> decorrelated_seed(const Reference& reference, std::uint64_t seed,
                                               const Strategy& strategy, std::string& note) {
  if (!reference.loaded()) return std::nullopt;
  const std::string shared = shared_random_numbers(reference.info, seed, strategy);
  if (shared.empty()) return std::nullopt;
  std::uint64_t other = seed + 1;
  if (is_reference_seed(other) || other == 0) other = 1;
  if (other == reference.info.seed) other = 2;
  note = "The render's seed is now " + std::to_string(other) + ": " + shared + ".";
  return other;
}

}  // namespace pdflab
