#pragma once
// The 1D lab: the book's chapters before the path tracer, in a window of its
// own. The state is plain data that advances by a number of samples per
// frame; drawing reads it. Tests drive the state without a window.
#include "renderer/lab/expression.h"
#include "renderer/lab/lab1d.h"

#include <array>
#include <cstdint>
#include <future>
#include <optional>
#include <string>
#include <vector>

namespace pdflab::ui {

inline constexpr int kLabBins = 40;

// Histogram bin of x in [kLow, kHigh) among `bins`; -1 outside.
int lab_bin(double x, int bins = kLabBins);

// The running estimate recorded at geometrically spaced N (a log axis).
struct LabHistoryPoint {
  std::uint64_t n = 0;
  double mean = 0.0, standard_error = 0.0;
};

// |estimate - pi| against N, root mean square over several seeds, for plain
// and stratified points; N are powers of four (squares, for stratification).
struct PiStudy {
  std::vector<double> n, plain_error, stratified_error;
};
PiStudy run_pi_study(int max_power_of_four = 9, int seeds = 8);

struct Lab1dState {
  lab::Integrand integrand = lab::Integrand::Square;
  lab::Pdf pdf = lab::Pdf::Uniform;
  lab::Estimator estimator{lab::Integrand::Square, lab::Pdf::Uniform};
  std::vector<std::uint64_t> histogram = std::vector<std::uint64_t>(kLabBins, 0);
  std::vector<LabHistoryPoint> history;
  std::uint64_t seed = 1;
  bool running = true;
  std::array<float, 3> sized_for{};  // the window's size and font size the lab's window was last sized for
  int samples_per_frame = 64;
  std::uint64_t max_samples = 1u << 20;

  PiStudy pi;
  std::future<PiStudy> pi_job;
  bool plot_pi = false;  // the fourth plot: pi's study instead of this pair's error

  // f typed as an expression: used while `typed` holds one, else `integrand`.
  std::string f_field = "x^2";  // the text field
  std::string f_error;          // why the last text was refused (the lab keeps its f)
  std::optional<lab::Expression> typed;
  double typed_exact = 0.0;  // its integral by adaptive quadrature (NaN: not finite)

  // Changing f or p (or the seed) starts over: the old samples estimate another integral.
  void select(lab::Integrand f, lab::Pdf p);
  // Parses `text` as f(x); on success uses it (and starts over), else sets f_error.
  bool type_f(const std::string& text);
  double f(double x) const { return typed ? (*typed)(x) : lab::integrand(integrand, x); }
  double exact() const { return typed ? typed_exact : lab::exact_integral(integrand); }
  std::string f_name() const { return typed ? typed->text() : std::string(lab::integrand_name(integrand)); }
  void reset();
  // Draws `count` samples by the inverse CDF (stops at max_samples).
  void step(int count);
  std::uint64_t count() const { return estimator.count(); }

 private:
  std::uint64_t next_record_ = 1;
  std::uint64_t stream_ = 0;  // sample index: the state is reproducible from the seed
};

// Draws the lab's window; `open` false hides it (its close button).
void draw_lab1d_window(Lab1dState& state, bool* open, float area_width, float area_height);

}  // namespace pdflab::ui
