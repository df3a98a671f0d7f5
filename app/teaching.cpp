#include "app/teaching.h"

#include "app/assets.h"

#include "renderer/error.h"
#include "renderer/film/image_io.h"
#include "renderer/metrics/metrics.h"
#include "ui/layout_report.h"

#include <glad/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <thread>

namespace pdflab {

TeachingViews::TeachingViews(std::function<void()> on_image) : on_image_(std::move(on_image)) {}

TeachingViews::~TeachingViews() {
  // Render threads stop before the displays (and their GL objects) go.
  a_.reset();
  b_.reset();
  if (probe_.chi_job.valid()) probe_.chi_job.wait();
  if (lab_.pi_job.valid()) lab_.pi_job.wait();
}

bool TeachingViews::on_key(int key, RenderSession& main, bool paused) {
  switch (key) {
    case GLFW_KEY_S:
      if (split_.on) leave_split(main, paused);
      else enter_split(main);
      return true;
    case GLFW_KEY_P:
      // The panel goes with the mode: leaving it clears the image for a clean look.
      probe_.mode = !probe_.mode;
      probe_.open = probe_.mode && probe_.has_point;
      return true;
    case GLFW_KEY_L: lab_open_ = !lab_open_; return true;
    case GLFW_KEY_D: lab2d_open_ = !lab2d_open_; return true;
    case GLFW_KEY_C:
      if (!probe_.has_point) return false;
      start_probe_chi_square(probe_, ImGui::GetTime());
      return true;
    default: return false;
  }
}

bool TeachingViews::on_escape() {
  if (probe_.mode || probe_.open) {
    probe_.mode = false;
    probe_.open = false;
    return true;
  }
  if (lab2d_open_) {
    lab2d_open_ = false;
    return true;
  }
  if (lab_open_) {
    lab_open_ = false;
    return true;
  }
  return false;
}

void TeachingViews::probe_at(const RenderSession& main, int x, int y, bool side_b) {
  const RenderSettings ms = main.settings();
  // In the split, a click probes the strategy of the side it lands on.
  Strategy strategy = ms.strategy;
  if (side_b && !b_running_.empty()) strategy = Strategy::parse(b_running_);
  // `guided` as the render drawing from it has learned it (the side's own session's in the split).
  const RenderSession* drawn = split_.on && a_ && b_ ? (side_b ? b_.get() : a_.get()) : &main;
  ui::probe_pixel(probe_, ms.scene, strategy, ms.seed, x, y, drawn->guiding());
  probe_generation_ = main.generation();
  probe_side_b_ = side_b;
  probe_b_ = b_running_;
  probe_width_ = ms.scene->camera.width;
  probe_height_ = ms.scene->camera.height;
}

void TeachingViews::follow_probe(const RenderSession& main) {
  if (!probe_.has_point) return;
  const bool side_b = probe_side_b_ && split_.on;
  if (main.generation() == probe_generation_ && side_b == probe_side_b_ && (!side_b || b_running_ == probe_b_)) return;
  const RenderSettings ms = main.settings();
  const int w = ms.scene->camera.width, h = ms.scene->camera.height;
  // The same place in the picture when the resolution changed.
  const auto rescale = [](int v, int from, int to) {
    return from > 0 ? std::clamp(static_cast<int>((static_cast<double>(v) + 0.5) * to / from), 0, to - 1) : 0;
  };
  const bool open = probe_.open;
  probe_at(main, rescale(probe_.pixel_x, probe_width_, w), rescale(probe_.pixel_y, probe_height_, h), side_b);
  probe_.open = open;
}

void TeachingViews::enter_split(RenderSession& main) {
  split_.on = true;
  const ui::SplitThreads threads =
      ui::split_threads(static_cast<int>(std::max(1u, std::thread::hardware_concurrency())));
  split_.threads_per_side = threads.a;
  SessionOptions options;
  options.background_priority = true;
  options.preview = true;
  options.on_image = on_image_;
  options.threads = threads.a;
  a_ = std::make_unique<RenderSession>(options);
  options.threads = threads.b;
  b_ = std::make_unique<RenderSession>(options);
  version_a_ = version_b_ = 0;
  seen_main_generation_ = ~std::uint64_t{0};
  // The main session rests: its threads would otherwise take a third of the machine.
  main.set_paused(true);
}

void TeachingViews::leave_split(RenderSession& main, bool paused) {
  split_.on = false;
  split_.divider.dragging = false;
  a_.reset();
  b_.reset();
  main.set_paused(paused);
}

void TeachingViews::restart_split(const RenderSettings& main_settings) {
  RenderSettings ra = main_settings;
  ra.target_spp = 0;  // an equal-time comparison runs until stopped
  RenderSettings rb = ra;
  split_.b_error.clear();
  try {
    rb.strategy = for_scene(Strategy::parse(split_.b_strategy), *rb.scene);
    (void)SamplingPlan::make(rb.strategy, *rb.scene);
  } catch (const InputError& e) {
    split_.b_error = e.what();
    // Keep comparing against the last B that worked (or A itself).
    rb.strategy = b_running_.empty() ? ra.strategy : Strategy::parse(b_running_);
    split_.b_strategy = b_running_.empty() ? rb.strategy.to_string() : b_running_;
  }
  // Back to back: both clocks start within microseconds of each other.
  a_->set_settings(ra);
  b_->set_settings(rb);
  b_running_ = rb.strategy.to_string();
  split_.a = {};
  split_.b = {};
  split_.a.strategy = ra.strategy.to_string();
  split_.b.strategy = b_running_;
  split_.a.unbiased = ra.strategy.is_unbiased();
  split_.b.unbiased = rb.strategy.is_unbiased();
}

void TeachingViews::load_reference() {
  own_reference_ = {};
  split_.reference_status.clear();
  if (split_.reference_path.empty()) return;
  try {
    own_reference_ = pdflab::load_reference(split_.reference_path);
    split_.reference_status =
        "loaded " + std::to_string(own_reference_.width) + "x" + std::to_string(own_reference_.height);
  } catch (const std::exception& e) {
    split_.reference_status = e.what();
  }
}

void TeachingViews::pull(RenderSession& session, std::vector<float>& image, ImageInfo& info, std::uint64_t& version,
                         bool& stale, ui::SideFigures& f) {
  if (session.copy_image(image, info, version)) {
    stale = true;
    new_image_ = true;
    if (!info.preview) {
      f.noise = info.mean_relative_standard_error;
      f.estimated_relmse = info.estimated_relmse;
      f.reference_relmse = -1.0;
      // Corrected for the reference's own noise, as the Measure section's figure.
      if (const Reference* ref = reference(); ref && ref->width == info.width && ref->height == info.height)
        f.reference_relmse = std::max(0.0, measure_relmse(image, ref->rgb, ref->variance).corrected);
    }
  }
  const SessionStats st = session.stats();
  f.spp = st.spp;
  f.seconds = st.seconds;
  f.samples_per_second = st.samples_per_second;
}

void TeachingViews::update(RenderSession& main, bool paused) {
  new_image_ = false;
  if (!split_.on) {
    follow_probe(main);
    return;
  }
  main.set_paused(true);  // Space toggles it; the split sessions take the pause instead
  const RenderSettings ms = main.settings();
  if (main.generation() != seen_main_generation_) {
    seen_main_generation_ = main.generation();
    restart_split(ms);
  }
  a_->set_paused(paused);
  b_->set_paused(paused);
  pull(*a_, image_a_, info_a_, version_a_, stale_a_, split_.a);
  pull(*b_, image_b_, info_b_, version_b_, stale_b_, split_.b);
  if (own_reference_.loaded() && split_.reference_status.rfind("loaded", 0) == 0 &&
      (own_reference_.width != ms.scene->camera.width || own_reference_.height != ms.scene->camera.height))
    split_.reference_status = "loaded, but " + std::to_string(own_reference_.width) + "x" +
                              std::to_string(own_reference_.height) + " is not the render's size";
  if (!own_reference_.loaded() && split_.reference_path.empty()) {
    const Reference* shared = shared_reference_;
    split_.reference_status =
        !shared || !shared->loaded() ? std::string()
        : shared->width == ms.scene->camera.width && shared->height == ms.scene->camera.height
            ? "using the Measure section's reference (" + std::to_string(shared->width) + "x" +
                  std::to_string(shared->height) + ")"
            : "the Measure section's reference is not the render's size";
  }
  follow_probe(main);
}

void TeachingViews::draw_ui(RenderSession& main, const ui::Viewport& image, int framebuffer_height,
                            float framebuffer_scale, float area_width, float area_height) {
  const double now = ImGui::GetTime();  // the clock the C key's check starts on, too
  const ImGuiIO& io = ImGui::GetIO();
  const float left = static_cast<float>(image.x) / framebuffer_scale;
  const float top = static_cast<float>(framebuffer_height - image.y - image.height) / framebuffer_scale;
  const float width = static_cast<float>(image.width) / framebuffer_scale;
  const float height = static_cast<float>(image.height) / framebuffer_scale;

  bool mouse_taken = false;
  if (split_.on) {
    ui::SplitRequests requests;
    ui::draw_split_controls(split_, requests);
    const bool free_mouse = !io.WantCaptureMouse || split_.divider.dragging;
    mouse_taken = free_mouse && split_.divider.update(io.MousePos.x, io.MousePos.y, ImGui::IsMouseClicked(0),
                                                      ImGui::IsMouseDown(0), left, top, width, height, 10.0f);
    ui::draw_split_overlay(split_, left, top, width, height);
    if (requests.load_reference) load_reference();
    if (requests.restart) restart_split(main.settings());
  }

  if (probe_.mode && !mouse_taken && !io.WantCaptureMouse && ImGui::IsMouseClicked(0)) {
    const RenderSettings ms = main.settings();
    const Camera& cam = ms.scene->camera;
    if (const auto hit = ui::pixel_at(io.MousePos.x, io.MousePos.y, left, top, width, height, cam.width, cam.height))
      probe_at(main, hit->x, hit->y, split_.on && io.MousePos.x > split_.divider.x(left, width));
  }
  if (probe_.has_point && probe_.open) {
    // A cross on the probed pixel.
    const RenderSettings ms = main.settings();
    const float sx = width / static_cast<float>(std::max(1, ms.scene->camera.width));
    const float sy = height / static_cast<float>(std::max(1, ms.scene->camera.height));
    const ImVec2 c(left + (static_cast<float>(probe_.pixel_x) + 0.5f) * sx,
                   top + (static_cast<float>(probe_.pixel_y) + 0.5f) * sy);
    ImDrawList* list = ImGui::GetBackgroundDrawList();
    for (const auto& [col, w] : {std::pair{IM_COL32(0, 0, 0, 200), 4.0f}, std::pair{IM_COL32(80, 255, 120, 255), 2.0f}}) {
      list->AddLine(ImVec2(c.x - 10, c.y), ImVec2(c.x - 3, c.y), col, w);
      list->AddLine(ImVec2(c.x + 3, c.y), ImVec2(c.x + 10, c.y), col, w);
      list->AddLine(ImVec2(c.x, c.y - 10), ImVec2(c.x, c.y - 3), col, w);
      list->AddLine(ImVec2(c.x, c.y + 3), ImVec2(c.x, c.y + 10), col, w);
    }
  }
  const bool was_open = probe_.open;
  ui::draw_probe_panel(probe_, now, area_width, area_height);
  if (was_open && !probe_.open) probe_.mode = false;  // its close button ends probing
  if (probe_.mode) {
    // Bottom left, placed with the other boxes over the image: the probe
    // panel opens at the top right.
    const char* text = "probe mode: click a pixel (P or Esc to leave)";
    ui::layout::Overlay o;
    o.corner = ui::Corner::BottomLeft;
    o.width = ImGui::CalcTextSize(text).x + 2.0f * ImGui::GetStyle().WindowPadding.x;
    float wrap = 0.0f;
    if (ui::layout::place_next_window("##probe_badge", o, &wrap)) {
      ImGui::SetNextWindowBgAlpha(0.6f);
      const ImGuiWindowFlags flags = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize |
                                     ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoInputs |
                                     ImGuiWindowFlags_NoFocusOnAppearing | ImGuiWindowFlags_NoNav;
      if (ImGui::Begin("##probe_badge", nullptr, flags)) {
        ImGui::PushTextWrapPos(ImGui::GetCursorPosX() + wrap);
        ImGui::TextColored(ImVec4(0.45f, 0.95f, 0.55f, 1.0f), "%s", text);
        ImGui::PopTextWrapPos();
      }
      ImGui::End();
    }
  }

  if (lab_open_) ui::draw_lab1d_window(lab_, &lab_open_, area_width, area_height);
  if (lab2d_open_) {
    if (lab2d_.sun_sky_path.empty()) lab2d_.sun_sky_path = asset_dir() + "/environments/sun_sky.hdr";
    lab2d_.set_scene_environment(main.settings().scene->environment);
    ui::draw_lab2d_window(lab2d_, &lab2d_open_);
  }
}

void TeachingViews::draw_split_image(const ui::Viewport& where, float exposure_ev, bool srgb) {
  if (!display_a_) {
    display_a_ = std::make_unique<ui::ImageDisplay>();
    display_b_ = std::make_unique<ui::ImageDisplay>();
    std::string error;
    if (!display_a_->init(error) || !display_b_->init(error)) {
      split_.b_error = "display: " + error;
      return;
    }
  }
  if (stale_a_ && !image_a_.empty()) display_a_->upload(image_a_.data(), info_a_.data_width, info_a_.data_height);
  if (stale_b_ && !image_b_.empty()) display_b_->upload(image_b_.data(), info_b_.data_width, info_b_.data_height);
  stale_a_ = stale_b_ = false;
  // The scissor also clips a display's tone-mapping pass into its own target,
  // so each is first drawn (and tone-mapped) into one pixel without it.
  const ui::Viewport dot{where.x, where.y, 1, 1};
  display_a_->draw(dot, exposure_ev, srgb);
  display_b_->draw(dot, exposure_ev, srgb);
  const int split_x = static_cast<int>(std::lround(split_.divider.fraction * static_cast<float>(where.width)));
  glEnable(GL_SCISSOR_TEST);
  glScissor(where.x, where.y, split_x, where.height);
  display_a_->draw(where, exposure_ev, srgb);
  glScissor(where.x + split_x, where.y, where.width - split_x, where.height);
  display_b_->draw(where, exposure_ev, srgb);
  glDisable(GL_SCISSOR_TEST);
}

bool TeachingViews::wants_frames() const {
  return new_image_ || split_.divider.dragging || (lab_open_ && lab_.running && lab_.count() < lab_.max_samples) ||
         (lab_open_ && lab_.pi_job.valid()) || probe_.chi_running() ||
         (lab2d_open_ && lab2d_.running && (!lab2d_.lab || lab2d_.lab->count() < lab2d_.max_samples));
}

}  // namespace pdflab
