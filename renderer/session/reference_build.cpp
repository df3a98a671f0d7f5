#include "renderer/session/reference_build.h"

#include "renderer/error.h"

namespace pdflab {

namespace {

SessionOptions options_for(const ReferenceJob& job) {
  SessionOptions o;
  o.threads = job.threads;
  o.background_priority = job.background_priority;
  return o;
}

}  // namespace

ReferenceBuild::ReferenceBuild(ReferenceJob job) : job_(std::move(job)), session_(options_for(job_)) {
  if (!job_.scene) throw std::invalid_argument("ReferenceBuild without a scene");
  if (!job_.strategy.is_unbiased())
    throw InputError("strategy '" + job_.strategy.to_string() + "' is biased (" + job_.strategy.bias_reason() +
                     "); a reference needs an unbiased one");
  const ReferenceGoal& g = job_.goal;
  if ((g.spp > 0) + (g.seconds > 0.0) + (g.relmse > 0.0) != 1)
    throw InputError("give exactly one goal: --spp, --seconds or --target-relmse");
  RenderSettings s;
  s.scene = job_.scene;
  s.strategy = job_.strategy;
  s.seed = reference_seed(job_.seed_stream);
  s.target_spp = g.spp;  // 0: until poll() pauses it
  session_.set_settings(s);  // InputError when the scene cannot take the strategy
}

ReferenceBuild::~ReferenceBuild() = default;

ReferenceProgress ReferenceBuild::poll() {
  ImageInfo info;
  if (session_.copy_image(scratch_, info, version_) && !info.preview && info.spp > 0) {
    estimated_relmse_ = info.estimated_relmse;
    estimate_spp_ = info.spp;
  }
  const SessionStats st = session_.stats();
  // The relMSE goal is judged on the last published pass, with that pass's time.
  ReferenceProgress p = reference_progress(job_.goal, job_.goal.relmse > 0.0 ? estimate_spp_ : st.spp,
                                           st.seconds, estimated_relmse_);
  if (job_.goal.spp > 0 && !p.capped) p.reached = st.done;
  if (p.reached && !reached_) {
    reached_ = true;
    capped_ = p.capped;
    if (!st.done) session_.set_paused(true);
  }
  if (reached_) {
    p.reached = true;
    p.fraction = 1.0;
    p.seconds_left = 0.0;
  }
  return p;
}

Reference ReferenceBuild::finish() const {
  if (!reached_) throw std::logic_error("ReferenceBuild::finish before the goal");
  const Film film = session_.copy_film();
  const SessionStats st = session_.stats();
  ReferenceInfo info;
  info.has_sidecar = info.is_reference = true;
  info.scene_name = job_.scene->name;
  info.scene_file = job_.scene_file;
  info.scene_hash = reference_key(*job_.scene).scene_hash;
  info.max_depth = job_.scene->max_depth;
  info.strategy = job_.strategy.to_string();
  info.seed_known = true;
  info.seed = reference_seed(job_.seed_stream);
  info.seed_stream = job_.seed_stream;
  info.spp = film.pixel_count() ? film.count(0) : 0;
  info.seconds = st.seconds;
  info.version = job_.version;
  return reference_from_film(film, std::move(info));
}

}  // namespace pdflab
