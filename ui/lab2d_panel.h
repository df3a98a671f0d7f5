#pragma once
// The 2D lab: the environment map's sampling distribution in a window of its
// own, beside the 1D lab. The map with the latest samples as dots, the
// marginal CDF over rows, a picked row's conditional CDF, the samples'
// histogram against the pdf, and the resolution study. The state is plain
// data (renderer/lab/lab2d.h does the sums); drawing reads it, and tests
// drive the state without a window.
#include "renderer/lab/lab2d.h"

#include <array>
#include <cstdint>
#include <memory>
#include <string>

namespace pdflab {
class Environment;
}

namespace pdflab::ui {

class ViewTexture;

// The row of a map `height` rows high at `fraction` of the way down the
// image (a click on it), clamped to the map.
int lab2d_row_at(double fraction, int height);

struct Lab2dState {
  Lab2dState();
  ~Lab2dState();
  Lab2dState(const Lab2dState&) = delete;
  Lab2dState& operator=(const Lab2dState&) = delete;

  // Which map: the scene's (where it has one) or a built-in one.
  enum class Source : std::uint8_t { Scene, SunSky, SubTexelSun, BlackHalf, Constant, Count };
  Source source = Source::SunSky;
  std::string sun_sky_path;  // the shipped map's file
  std::shared_ptr<const Environment> scene_environment;  // the scene's map, or null
  std::unique_ptr<lab::Lab2d> lab;
  std::string error;  // why the chosen map could not be made (the lab keeps the last one)
  int row = -1;       // the picked row at the current level (-1: the sun's, or the brightest)
  bool running = true;
  int samples_per_frame = 500;
  bool log_bars = false;  // the CDF plots' bars on a log scale
  std::uint64_t max_samples = 1u << 20;
  std::array<float, 3> sized_for{};

  // Makes the lab for `source` (keeping the level's resolution where the new
  // map has it); false with `error` set when it cannot.
  bool choose(Source s);
  // The scene's map changed (or went): a lab on it follows.
  void set_scene_environment(std::shared_ptr<const Environment> environment);
  void set_level(int level);
  // The picked row, or the default one: where the sun is, else the row with most light.
  int picked_row() const;
  void step();  // one frame's samples while running (up to max_samples)

  // The map's picture on the GPU, made again when the level or map changes.
  std::unique_ptr<ViewTexture> texture;
  std::uint64_t generation = 0, texture_generation = ~std::uint64_t{0};  // a new lab: a new picture
  int texture_level = -1;
};

// Draws the lab's window; `open` false hides it (its close button).
void draw_lab2d_window(Lab2dState& state, bool* open);

std::string_view lab2d_source_name(Lab2dState::Source s);

}  // namespace pdflab::ui
