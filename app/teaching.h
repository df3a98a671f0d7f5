#pragma once
// The teaching views in the viewer: split screen A/B, the pixel probe and the
// 1D and 2D labs. The viewer calls these few hooks; everything else about the
// views lives here and in ui/split_view, ui/probe_panel, ui/lab1d_panel,
// ui/lab2d_panel.
#include "renderer/metrics/reference.h"
#include "renderer/session/session.h"
#include "ui/display.h"
#include "ui/lab1d_panel.h"
#include "ui/lab2d_panel.h"
#include "ui/probe_panel.h"
#include "ui/split_view.h"

#include <algorithm>
#include <functional>
#include <memory>
#include <vector>

namespace pdflab {

class TeachingViews {
 public:
  // on_image: wakes the viewer's event loop (called from render threads).
  explicit TeachingViews(std::function<void()> on_image);
  ~TeachingViews();
  TeachingViews(const TeachingViews&) = delete;
  TeachingViews& operator=(const TeachingViews&) = delete;

  // S split, P probe mode, L 1D lab, D 2D lab, C chi-square at the probed point.
  bool on_key(int glfw_key, RenderSession& main, bool paused);
  // Esc: leaves probe mode, else closes the 2D lab, else the 1D lab. False when none was on.
  bool on_escape();
  void leave_probe_mode() { probe_.mode = false; }
  // Before drawing: keeps the split sessions in step with the main session
  // (which rests while the split renders) and collects their images.
  void update(RenderSession& main, bool paused);
  // Inside the ImGui frame. `image` is where the viewer shows the image
  // (framebuffer pixels, origin bottom-left), `area_*` the image area in ImGui units.
  void draw_ui(RenderSession& main, const ui::Viewport& image, int framebuffer_height, float framebuffer_scale,
               float area_width, float area_height);
  bool split_active() const { return split_.on; }
  // The Measure section's reference (or null): both sides are measured against
  // it unless the split's own reference field names another.
  void set_shared_reference(const Reference* reference) { shared_reference_ = reference; }
  // A left click on the image means something here (a probe, the divider): it does not pan.
  bool takes_left_clicks() const { return probe_.mode || split_.on; }
  // The split's state for the side panel; null while it is off.
  const ui::SplitState* split_state() const { return split_.on ? &split_ : nullptr; }
  // Rendering time of the split's longer-running side (0 while it is off).
  double split_seconds() const { return split_.on ? std::max(split_.a.seconds, split_.b.seconds) : 0.0; }
  // The 2D lab's state while it is open, else null (the layout report shows it).
  const ui::Lab2dState* lab2d() const { return lab2d_open_ ? &lab2d_ : nullptr; }
  // The pixel probe's state (tests read its counts).
  const ui::ProbeState& probe() const { return probe_; }
  // OpenGL: both halves into `where`, A left of the divider.
  void draw_split_image(const ui::Viewport& where, float exposure_ev, bool srgb);
  // Something changes on screen without input: a split image, the lab, a running check.
  bool wants_frames() const;

 private:
  void enter_split(RenderSession& main);
  void leave_split(RenderSession& main, bool paused);
  void restart_split(const RenderSettings& main_settings);
  void load_reference();
  // Probes pixel (x, y) of the main render with its strategy, or with B's.
  void probe_at(const RenderSession& main, int x, int y, bool side_b);
  // The probe follows the render: a new strategy, weights, scene or seed (a new
  // generation), or a new B, probes the same pixel again.
  void follow_probe(const RenderSession& main);
  void pull(RenderSession& session, std::vector<float>& image, ImageInfo& info, std::uint64_t& version, bool& stale,
            ui::SideFigures& figures);

  std::function<void()> on_image_;
  ui::SplitState split_;
  ui::ProbeState probe_;
  ui::Lab1dState lab_;
  std::uint64_t probe_generation_ = 0;
  bool probe_side_b_ = false;
  std::string probe_b_;  // B's strategy when B was probed
  int probe_width_ = 0, probe_height_ = 0;  // the render's size when probed
  bool lab_open_ = false;
  ui::Lab2dState lab2d_;
  bool lab2d_open_ = false;

  std::unique_ptr<RenderSession> a_, b_;
  std::uint64_t seen_main_generation_ = ~std::uint64_t{0};
  std::string b_running_;  // B's strategy as rendering now
  std::vector<float> image_a_, image_b_;
  ImageInfo info_a_, info_b_;
  std::uint64_t version_a_ = 0, version_b_ = 0;
  bool stale_a_ = false, stale_b_ = false, new_image_ = false;
  std::unique_ptr<ui::ImageDisplay> display_a_, display_b_;
  Reference own_reference_;                      // the split's own field
  const Reference* shared_reference_ = nullptr;  // the Measure section's
  const Reference* reference() const { return own_reference_.loaded() ? &own_reference_ : shared_reference_; }
};

}  // namespace pdflab
