#pragma once
// Rendering a reference: an unbiased strategy, a seed from the stream reserved
// for references, until a goal (spp, seconds or an estimated relMSE). Used by
// `pdflab reference` and by the viewer's "Make reference", which polls it from
// its UI thread: nothing here blocks except finish().
#include "renderer/metrics/reference.h"
#include "renderer/session/session.h"

#include <memory>
#include <string>

namespace pdflab {

struct ReferenceJob {
  std::shared_ptr<const Scene> scene;  // at the reference's size and depth
  std::string scene_file;              // recorded in the sidecar
  Strategy strategy;
  std::uint32_t seed_stream = 0;
  ReferenceGoal goal;
  int threads = 0;                  // <= 0: every core
  bool background_priority = false;  // a viewer keeps its frame rate
  std::string version;
};

class ReferenceBuild {
 public:
  // Starts rendering. Throws InputError for a biased strategy (a reference
  // must converge to the true image), no goal, or a strategy the scene cannot use.
  explicit ReferenceBuild(ReferenceJob job);
  ~ReferenceBuild();  // stops the workers (a cancel)
  ReferenceBuild(const ReferenceBuild&) = delete;
  ReferenceBuild& operator=(const ReferenceBuild&) = delete;

  // Where it stands; pauses the render once the goal is reached. Cheap.
  ReferenceProgress poll();
  bool done() const { return reached_; }
  // Stopped by the goal's max_seconds short of the goal itself.
  bool capped() const { return capped_; }
  SessionStats stats() const { return session_.stats(); }
  const ReferenceJob& job() const { return job_; }
  // After done(): the reference with its sidecar filled (waits for the pass in flight).
  Reference finish() const;

 private:
  ReferenceJob job_;
  RenderSession session_;
  bool reached_ = false;
  bool capped_ = false;
  double estimated_relmse_ = 0.0;
  std::uint32_t estimate_spp_ = 0;
  std::vector<float> scratch_;
  std::uint64_t version_ = 0;
};

}  // namespace pdflab
