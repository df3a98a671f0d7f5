#include "ui/lab1d_panel.h"
#include "ui/style.h"

#include "renderer/sampling/rng.h"
#include "ui/teach_draw.h"

#include <imgui.h>
#include <imgui_stdlib.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

namespace pdflab::ui {

namespace {

constexpr ImU32 kF = IM_COL32(90, 170, 255, 255);
constexpr ImU32 kP = IM_COL32(255, 190, 60, 255);
constexpr ImU32 kHist = IM_COL32(255, 190, 60, 110);
constexpr ImU32 kExact = IM_COL32(120, 220, 120, 255);
constexpr ImU32 kPlain = IM_COL32(255, 100, 80, 255);
constexpr ImU32 kStrat = IM_COL32(90, 170, 255, 255);

// 53 random bits: with 24, u = 0 would come up once in 16 million samples,
// and the pdfs that vanish at 0 make that sample special.
double unit_double(Rng& rng) {
  const std::uint64_t hi = rng.next_u32(), lo = rng.next_u32();
  return static_cast<double>(((hi << 32) | lo) >> 11) * 0x1.0p-53;
}

std::vector<double> linspace(double a, double b, int n) {
  std::vector<double> v(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) v[static_cast<std::size_t>(i)] = a + (b - a) * i / (n - 1);
  return v;
}

}  // namespace

int lab_bin(double x, int bins) {
  if (!(x >= lab::kLow) || !(x < lab::kHigh) || bins <= 0) return -1;
  return std::min(bins - 1, static_cast<int>((x - lab::kLow) / (lab::kHigh - lab::kLow) * bins));
}

PiStudy run_pi_study(int max_power_of_four, int seeds) {
  PiStudy study;
  for (int k = 1; k <= max_power_of_four; ++k) {
    const std::uint64_t n = std::uint64_t{1} << (2 * k);
    double plain = 0.0, strat = 0.0;
    for (int s = 1; s <= seeds; ++s) {
      const double a = lab::estimate_pi(n, static_cast<std::uint64_t>(s)) - std::numbers::pi;
      const double b = lab::estimate_pi_stratified(n, static_cast<std::uint64_t>(s)) - std::numbers::pi;
      plain += a * a;
      strat += b * b;
    }
    study.n.push_back(static_cast<double>(n));
    study.plain_error.push_back(std::sqrt(plain / seeds));
    study.stratified_error.push_back(std::sqrt(strat / seeds));
  }
  return study;
}

void Lab1dState::select(lab::Integrand f, lab::Pdf p) {
  if (f != integrand) typed.reset();
  integrand = f;
  pdf = p;
  reset();
}

bool Lab1dState::type_f(const std::string& text) {
  try {
    lab::Expression e = lab::Expression::parse(text);
    typed_exact = lab::integrate(e.function(), lab::kLow, lab::kHigh);
    typed = std::move(e);
    f_error.clear();
  } catch (const std::exception& e) {
    f_error = e.what();
    return false;
  }
  reset();
  return true;
}

void Lab1dState::reset() {
  estimator = typed ? lab::Estimator(typed->function(), pdf) : lab::Estimator(integrand, pdf);
  std::fill(histogram.begin(), histogram.end(), 0);
  history.clear();
  next_record_ = 1;
  stream_ = 0;
}

void Lab1dState::step(int count) {
  // Each call draws from its own stream, keyed by (seed, call index): a run is
  // reproducible from the seed and the calls made, whatever the frame rate.
  Rng rng(mix64(seed) ^ stream_, 0x5eed);
  for (int i = 0; i < count && estimator.count() < max_samples; ++i) {
    const double u = unit_double(rng);
    const double x = lab::inverse_cdf(pdf, u);
    estimator.add(u);
    const int b = lab_bin(x, static_cast<int>(histogram.size()));
    if (b >= 0) ++histogram[static_cast<std::size_t>(b)];
    if (estimator.count() >= next_record_) {
      history.push_back({estimator.count(), estimator.mean(), estimator.standard_error()});
      // About 25 points per decade: even spacing on the log axis.
      next_record_ = std::max(next_record_ + 1, static_cast<std::uint64_t>(static_cast<double>(next_record_) * 1.1));
    }
  }
  ++stream_;
}

namespace {

void curves_plot(const Lab1dState& s, ImVec2 size) {
  const std::vector<double> xs = linspace(lab::kLow, lab::kHigh, 241);
  std::vector<double> fs, ps;
  for (double x : xs) {
    fs.push_back(s.f(x));
    ps.push_back(lab::pdf(s.pdf, x));
  }
  std::vector<double> all = fs;
  all.insert(all.end(), ps.begin(), ps.end());
  all.push_back(0.0);
  const draw::Plot plot("f(x) and p(x)", size, {lab::kLow, lab::kHigh}, draw::fit_axis(all, false), "x");
  plot.line(xs, fs, kF, 2.0f);
  plot.line(xs, ps, kP, 2.0f);
  plot.legend({{"f(x) = " + s.f_name(), kF},
               {"p(x) " + std::string(lab::pdf_name(s.pdf)), kP}},
              true);
}

void histogram_plot(const Lab1dState& s, ImVec2 size) {
  const int bins = static_cast<int>(s.histogram.size());
  const double width = (lab::kHigh - lab::kLow) / bins;
  std::vector<double> density(s.histogram.size(), 0.0);
  const double n = static_cast<double>(std::max<std::uint64_t>(1, s.count()));
  for (std::size_t i = 0; i < density.size(); ++i) density[i] = static_cast<double>(s.histogram[i]) / (n * width);
  const std::vector<double> xs = linspace(lab::kLow, lab::kHigh, 241);
  std::vector<double> ps;
  for (double x : xs) ps.push_back(lab::pdf(s.pdf, x));
  std::vector<double> all = density;
  all.insert(all.end(), ps.begin(), ps.end());
  all.push_back(0.0);
  const std::string title = "samples by inverse CDF (" + std::to_string(s.count()) + ") vs p(x)";
  const draw::Plot plot(title.c_str(), size, {lab::kLow, lab::kHigh}, draw::fit_axis(all, false), "x");
  plot.bars(lab::kLow, width, density, kHist);
  plot.line(xs, ps, kP, 2.0f);
  plot.legend({{"histogram / (N dx)", kHist}, {"p(x)", kP}}, true);
}

void estimate_plot(const Lab1dState& s, ImVec2 size) {
  std::vector<double> ns, mean, lo, hi;
  for (const LabHistoryPoint& h : s.history) {
    ns.push_back(static_cast<double>(h.n));
    mean.push_back(h.mean);
    lo.push_back(h.mean - h.standard_error);
    hi.push_back(h.mean + h.standard_error);
  }
  const double exact = s.exact();
  std::vector<double> all = mean;
  all.push_back(exact);
  // The first few estimates can be wild; keep the exact value in clear view.
  for (std::size_t i = 0; i < lo.size(); ++i)
    if (ns[i] >= 16.0) all.insert(all.end(), {lo[i], hi[i]});
  draw::Axis y = draw::fit_axis(all, false, 0.1);
  const double span = std::max(y.hi - y.lo, std::abs(exact) * 0.05);
  y = {std::min(y.lo, exact - span * 0.5), std::max(y.hi, exact + span * 0.5), false};
  const draw::Axis x{1.0, std::max(10.0, ns.empty() ? 10.0 : ns.back()), true};
  const draw::Plot plot("running estimate +- standard error", size, x, y, "N (log)");
  plot.band(ns, lo, hi, IM_COL32(90, 170, 255, 70));
  plot.hline(exact, kExact);
  plot.line(ns, mean, kF, 2.0f);
  plot.legend({{"estimate", kF}, {"+- 1 std. error", IM_COL32(90, 170, 255, 120)}, {"exact", kExact}});
}

// |estimate - exact| against N for the current f and p, log-log, beside the
// standard error and a 1/sqrt(N) guide: a finite variance shows as slope -1/2.
void error_plot(const Lab1dState& s, ImVec2 size) {
  const double exact = s.exact();
  std::vector<double> ns, err, se;
  for (const LabHistoryPoint& h : s.history) {
    const double e = std::abs(h.mean - exact);
    if (!(e > 0.0) || !std::isfinite(e) || !(h.standard_error > 0.0)) continue;
    ns.push_back(static_cast<double>(h.n));
    err.push_back(e);
    se.push_back(h.standard_error);
  }
  if (ns.size() < 2 || !std::isfinite(exact)) {
    ImGui::TextColored(kDim, std::isfinite(exact) ? "|error| vs N: collecting samples..."
                                                  : "|error| vs N: the exact integral is not finite");
    ImGui::Dummy(ImVec2(size.x, size.y - ImGui::GetTextLineHeightWithSpacing()));
    return;
  }
  std::vector<double> guide;
  for (double n : ns) guide.push_back(se.front() * std::sqrt(ns.front() / n));
  std::vector<double> all = err;
  all.insert(all.end(), se.begin(), se.end());
  const draw::Plot plot("|estimate - exact| vs N (log-log)", size, {1.0, std::max(10.0, ns.back()), true},
                        draw::fit_axis(all, true), "N (log)");
  plot.line(ns, guide, IM_COL32(170, 170, 170, 150), 1.0f);
  plot.line(ns, se, IM_COL32(90, 170, 255, 160), 1.4f);
  plot.line(ns, err, kPlain, 2.0f);
  plot.legend({{"|error|", kPlain}, {"standard error", IM_COL32(90, 170, 255, 160)},
               {"~N^-1/2", IM_COL32(170, 170, 170, 150)}});
}

void pi_plot(Lab1dState& s, ImVec2 size) {
  if (s.pi.n.empty()) {
    if (!s.pi_job.valid()) s.pi_job = std::async(std::launch::async, [] { return run_pi_study(); });
    if (s.pi_job.wait_for(std::chrono::seconds(0)) == std::future_status::ready) s.pi = s.pi_job.get();
  }
  if (s.pi.n.empty()) {
    ImGui::TextColored(kDim, "estimating pi... (running)");
    ImGui::Dummy(ImVec2(size.x, size.y - ImGui::GetTextLineHeightWithSpacing()));
    return;
  }
  const PiStudy& p = s.pi;
  // Reference slopes through the first plain point: N^-1/2 (plain), N^-3/4
  // (jittered points on a smooth boundary in 2D).
  std::vector<double> half, three_quarter;
  for (double n : p.n) {
    half.push_back(p.plain_error.front() * std::sqrt(p.n.front() / n));
    three_quarter.push_back(p.stratified_error.front() * std::pow(p.n.front() / n, 0.75));
  }
  std::vector<double> all = p.plain_error;
  all.insert(all.end(), p.stratified_error.begin(), p.stratified_error.end());
  const draw::Plot plot("pi: RMS error vs N (8 seeds)", size, {p.n.front() * 0.7, p.n.back() * 1.4, true},
                        draw::fit_axis(all, true), "N (log)");
  plot.line(p.n, half, IM_COL32(255, 100, 80, 110), 1.0f);
  plot.line(p.n, three_quarter, IM_COL32(90, 170, 255, 110), 1.0f);
  plot.line(p.n, p.plain_error, kPlain, 2.0f);
  plot.line(p.n, p.stratified_error, kStrat, 2.0f);
  plot.legend({{"uniform points  ~N^-1/2", kPlain}, {"stratified (jittered)  ~N^-3/4", kStrat}});
}

}  // namespace

void draw_lab1d_window(Lab1dState& s, bool* open, float area_width, float area_height) {
  // The lab is about no image: it may cover the side panel too. Its size
  // follows the window and the UI scale (fonts 64 wide by 48 high at most):
  // set when it opens and whenever the window or the scale changes.
  (void)area_width;
  (void)area_height;
  if (!draw::begin_lab_window("1D lab: Monte Carlo on [0, 2] (L)", open, s.sized_for, 64.0f, 48.0f)) return;
  const float font = ImGui::GetFontSize();
  if (s.running) s.step(s.samples_per_frame);

  lab::Integrand f = s.integrand;
  lab::Pdf p = s.pdf;
  bool pick = false;  // a fixed f chosen (also the one already selected, to leave a typed one)
  ImGui::SetNextItemWidth(ImGui::GetFontSize() * 8.0f);
  if (ImGui::BeginCombo("f(x)", s.typed ? "typed" : std::string(lab::integrand_name(f)).c_str())) {
    for (int i = 0; i < static_cast<int>(lab::Integrand::Count); ++i) {
      const auto v = static_cast<lab::Integrand>(i);
      if (ImGui::Selectable(std::string(lab::integrand_name(v)).c_str(), !s.typed && v == f)) {
        f = v;
        pick = true;
      }
    }
    ImGui::EndCombo();
  }
  ImGui::SameLine();
  ImGui::SetNextItemWidth(ImGui::GetFontSize() * 10.0f);
  if (ImGui::InputTextWithHint("= f(x) (Enter)", "e.g. sin(pi*x)^2", &s.f_field, ImGuiInputTextFlags_EnterReturnsTrue))
    s.type_f(s.f_field);
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("Any f of x on [0, 2]: + - * / ^, sin cos tan exp ln log10 sqrt abs min max, pi, e");
  ImGui::SameLine();
  ImGui::SetNextItemWidth(ImGui::GetFontSize() * 8.0f);
  if (ImGui::BeginCombo("p(x)", std::string(lab::pdf_name(p)).c_str())) {
    for (int i = 0; i < static_cast<int>(lab::Pdf::Count); ++i) {
      const auto v = static_cast<lab::Pdf>(i);
      if (ImGui::Selectable(std::string(lab::pdf_name(v)).c_str(), v == p)) p = v;
    }
    ImGui::EndCombo();
  }
  if (pick && s.typed) s.typed.reset();
  if (pick || f != s.integrand || p != s.pdf) s.select(f, p);
  // The controls wrap onto the next row rather than run past the window's edge.
  const ImGuiStyle& style = ImGui::GetStyle();
  const auto button_width = [&](const char* label) { return ImGui::CalcTextSize(label).x + style.FramePadding.x * 2.0f; };
  const auto same_line_if_fits = [&](float width) {
    ImGui::SameLine();
    if (ImGui::GetContentRegionAvail().x < width) ImGui::NewLine();
  };
  const char* run_label = s.running ? "Pause" : "Run";
  same_line_if_fits(button_width(run_label));
  if (ImGui::Button(run_label)) s.running = !s.running;
  same_line_if_fits(button_width("Reset"));
  if (ImGui::Button("Reset")) s.reset();
  const float slider_width = ImGui::GetFontSize() * 7.0f;
  same_line_if_fits(slider_width + style.ItemInnerSpacing.x + ImGui::CalcTextSize("samples/frame").x);
  ImGui::SetNextItemWidth(slider_width);
  ImGui::SliderInt("samples/frame", &s.samples_per_frame, 1, 4096, "%d", ImGuiSliderFlags_Logarithmic);

  if (!s.f_error.empty()) ImGui::TextColored(kRed, "%s", s.f_error.c_str());
  const double exact = s.exact();
  // An integral that diverges (1/x from 0) has no exact value to show, nor an error.
  char exact_text[96];
  if (std::isfinite(exact))
    std::snprintf(exact_text, sizeof exact_text, "exact %.5f%s   error %+.2e", exact, s.typed ? " (adaptive quadrature)" : "",
                  s.estimator.mean() - exact);
  else
    std::snprintf(exact_text, sizeof exact_text, "exact: none, the integral diverges");
  ImGui::TextWrapped("N = %llu   estimate %.5f +- %.5f   %s", static_cast<unsigned long long>(s.count()),
                     s.estimator.mean(), s.estimator.standard_error(), exact_text);
  if (s.typed) {
    ImGui::TextColored(kDim, "A typed f: whether f/p has a finite variance is for the error plot to show.");
  } else if (!lab::has_finite_variance(s.integrand, s.pdf)) {
    ImGui::TextColored(kRed,
                       "Infinite variance: p(x) falls to zero faster than f(x) somewhere. Still unbiased, but the\n"
                       "standard error is not to be trusted and the error does not fall like 1/sqrt(N).");
  } else if (s.count() > 1 && s.estimator.standard_error() < 1e-6 * std::abs(s.estimator.mean())) {
    // (Not exactly zero: E[x^2] - E[x]^2 keeps a rounding residue.)
    ImGui::TextColored(kGreen, "Zero variance: p(x) is proportional to f(x), every sample gives the exact value.");
  } else {
    ImGui::TextColored(kDim, "Finite variance: the standard error falls like 1/sqrt(N).");
  }

  const ImVec2 avail = ImGui::GetContentRegionAvail();
  const float gap = ImGui::GetStyle().ItemSpacing.x;
  const ImVec2 cell((avail.x - gap) * 0.5f, std::max(font * 9.0f, (avail.y - ImGui::GetStyle().ItemSpacing.y) * 0.5f));
  curves_plot(s, cell);
  ImGui::SameLine();
  histogram_plot(s, cell);
  estimate_plot(s, cell);
  ImGui::SameLine();
  ImGui::BeginGroup();
  int which = s.plot_pi ? 1 : 0;
  ImGui::RadioButton("error of this f, p", &which, 0);
  ImGui::SameLine();
  ImGui::RadioButton("pi, stratified or not", &which, 1);
  s.plot_pi = which == 1;
  const ImVec2 rest(cell.x, cell.y - ImGui::GetFrameHeightWithSpacing());
  if (s.plot_pi) pi_plot(s, rest);
  else error_plot(s, rest);
  ImGui::EndGroup();
  ImGui::End();
}

}  // namespace pdflab::ui
