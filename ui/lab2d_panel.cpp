#include "ui/lab2d_panel.h"
#include "ui/style.h"

#include "renderer/error.h"
#include "renderer/scene/environment.h"
#include "ui/layout_report.h"
#include "ui/teach_draw.h"
#include "ui/view_texture.h"

#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace pdflab::ui {

namespace {

constexpr ImU32 kDot = IM_COL32(80, 255, 140, 220);
constexpr ImU32 kRow = IM_COL32(255, 190, 60, 255);
constexpr ImU32 kCdf = IM_COL32(90, 170, 255, 255);
constexpr ImU32 kBars = IM_COL32(255, 190, 60, 120);
constexpr ImU32 kSun = IM_COL32(255, 80, 80, 255);

lab::TestMap test_map_of(Lab2dState::Source s) {
  switch (s) {
    case Lab2dState::Source::SubTexelSun: return lab::TestMap::SubTexelSun;
    case Lab2dState::Source::BlackHalf: return lab::TestMap::BlackHalf;
    case Lab2dState::Source::Constant: return lab::TestMap::Constant;
    default: return lab::TestMap::SunSky;
  }
}

std::string size_text(int w, int h) { return std::to_string(w) + " x " + std::to_string(h); }

}  // namespace

std::string_view lab2d_source_name(Lab2dState::Source s) {
  return s == Lab2dState::Source::Scene ? "the scene's map" : lab::test_map_name(test_map_of(s));
}

int lab2d_row_at(double fraction, int height) {
  if (height <= 0 || !std::isfinite(fraction)) return 0;
  return std::clamp(static_cast<int>(std::floor(fraction * height)), 0, height - 1);
}

Lab2dState::Lab2dState() = default;
Lab2dState::~Lab2dState() = default;

bool Lab2dState::choose(Source s) {
  try {
    lab::LabMap m;
    if (s == Source::Scene) {
      if (!scene_environment) throw InputError("the scene has no environment map");
      m = lab::scene_test_map(*scene_environment);
    } else {
      m = lab::make_test_map(test_map_of(s), sun_sky_path);
    }
    // The same resolution on the new map where it has one.
    const int width = lab ? lab->map().width : 0;
    auto next = std::make_unique<lab::Lab2d>(std::move(m));
    for (int l = 0; l < next->levels(); ++l)
      if (next->map(l).width == width) next->set_level(l);
    lab = std::move(next);
    ++generation;
    source = s;
    row = -1;
    error.clear();
    return true;
  } catch (const std::exception& e) {
    error = e.what();
    return false;
  }
}

void Lab2dState::set_scene_environment(std::shared_ptr<const Environment> environment) {
  if (environment == scene_environment) return;
  scene_environment = std::move(environment);
  if (source != Source::Scene) return;
  if (scene_environment) choose(Source::Scene);
  else choose(Source::SunSky);
}

void Lab2dState::set_level(int level) {
  if (!lab || level == lab->level()) return;
  // The picked row stays at the same place on the sphere.
  const int before = picked_row(), height = lab->map().height;
  lab->set_level(level);
  if (row >= 0) row = lab2d_row_at((before + 0.5) / height, lab->map().height);
}

int Lab2dState::picked_row() const {
  if (!lab) return 0;
  if (row >= 0) return std::min(row, lab->map().height - 1);
  if (lab->sun()) {
    int x, y;
    lab->environment().texel_of(lab->sun()->direction, x, y);
    return y;
  }
  const std::vector<double> p = lab->marginal_pmf();
  return static_cast<int>(std::max_element(p.begin(), p.end()) - p.begin());
}

void Lab2dState::step() {
  if (!lab || !running || lab->count() >= max_samples) return;
  lab->draw(static_cast<int>(std::min<std::uint64_t>(static_cast<std::uint64_t>(samples_per_frame), max_samples - lab->count())));
}

namespace {

// The map tone-mapped for the screen (c / (1 + c) per channel, then sRGB's
// gamma): a sky of 0.5 shows, a sun of 20000 is white.
std::vector<std::uint8_t> tone_map(const lab::LatLongMap& m) {
  std::vector<std::uint8_t> out(static_cast<std::size_t>(m.width) * static_cast<std::size_t>(m.height) * 4, 255);
  for (std::size_t i = 0; i < static_cast<std::size_t>(m.width) * static_cast<std::size_t>(m.height); ++i)
    for (std::size_t c = 0; c < 3; ++c) {
      const float v = m.rgb[i * 3 + c];
      const float t = std::pow(v / (1.0f + v), 1.0f / 2.2f);
      out[i * 4 + c] = static_cast<std::uint8_t>(std::lround(std::clamp(t, 0.0f, 1.0f) * 255.0f));
    }
  return out;
}

void map_view(Lab2dState& s, ImVec2 size) {
  const lab::Lab2d& lab = *s.lab;
  const lab::LatLongMap& m = lab.map();
  if (!s.texture) s.texture = std::make_unique<ViewTexture>();
  if (s.texture_generation != s.generation || s.texture_level != lab.level()) {
    const std::vector<std::uint8_t> rgba = tone_map(m);
    s.texture->upload(rgba.data(), m.width, m.height);
    s.texture_generation = s.generation;
    s.texture_level = lab.level();
  }
  const ImVec2 p0 = ImGui::GetCursorScreenPos();
  const ImVec2 p1(p0.x + size.x, p0.y + size.y);
  ImGui::InvisibleButton("##lab2d_map", size);
  layout::item("lab2d.map");
  // The press picks the row where it landed (its frame may already see the
  // release), a drag the row under the pointer.
  if (ImGui::IsItemActivated()) s.row = lab2d_row_at((ImGui::GetIO().MouseClickedPos[0].y - p0.y) / size.y, m.height);
  else if (ImGui::IsItemActive() && ImGui::IsMouseDown(0))
    s.row = lab2d_row_at((ImGui::GetIO().MousePos.y - p0.y) / size.y, m.height);
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("Click or drag: the row whose conditional CDF is shown");
  ImDrawList* dl = ImGui::GetWindowDrawList();
  dl->AddImage(reinterpret_cast<ImTextureID>(static_cast<std::intptr_t>(s.texture->id())), p0, p1);
  // The texel grid where texels are large enough to see.
  if (size.x / static_cast<float>(m.width) >= 6.0f) {
    for (int x = 1; x < m.width; ++x) {
      const float gx = p0.x + size.x * static_cast<float>(x) / static_cast<float>(m.width);
      dl->AddLine(ImVec2(gx, p0.y), ImVec2(gx, p1.y), IM_COL32(255, 255, 255, 40));
    }
    for (int y = 1; y < m.height; ++y) {
      const float gy = p0.y + size.y * static_cast<float>(y) / static_cast<float>(m.height);
      dl->AddLine(ImVec2(p0.x, gy), ImVec2(p1.x, gy), IM_COL32(255, 255, 255, 40));
    }
  }
  dl->PushClipRect(p0, p1, true);
  for (const auto& [u, v] : lab.dots()) {
    const ImVec2 c(p0.x + u * size.x, p0.y + v * size.y);
    dl->AddRectFilled(ImVec2(c.x - 1.0f, c.y - 1.0f), ImVec2(c.x + 1.0f, c.y + 1.0f), kDot);
  }
  if (lab.sun()) {
    double u, v;
    lab.environment().map_coordinates(lab.sun()->direction, u, v);
    dl->AddCircle(ImVec2(p0.x + static_cast<float>(u) * size.x, p0.y + static_cast<float>(v) * size.y), 7.0f, kSun, 0, 1.5f);
  }
  const int row = s.picked_row();
  const float y0 = p0.y + size.y * static_cast<float>(row) / static_cast<float>(m.height);
  const float y1 = p0.y + size.y * static_cast<float>(row + 1) / static_cast<float>(m.height);
  dl->AddRect(ImVec2(p0.x, y0 - 1.0f), ImVec2(p1.x, std::max(y1, y0 + 1.0f) + 1.0f), kRow, 0.0f, 0, 1.5f);
  dl->PopClipRect();
  dl->AddRect(p0, p1, IM_COL32(120, 120, 130, 255));
}

// Cells' values as a heat map `size` from the cursor: log10 from lo to hi,
// or (diverging) blue below zero and red above, to +-hi.
void heat_map(const char* id, const std::vector<double>& values, ImVec2 size, double lo, double hi, bool diverging) {
  const ImVec2 p0 = ImGui::GetCursorScreenPos();
  ImGui::InvisibleButton(id, size);
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const float cw = size.x / lab::kHistogramColumns, ch = size.y / lab::kHistogramRows;
  for (int r = 0; r < lab::kHistogramRows; ++r)
    for (int c = 0; c < lab::kHistogramColumns; ++c) {
      const double v = values[static_cast<std::size_t>(r * lab::kHistogramColumns + c)];
      ImU32 colour;
      if (diverging) {
        const auto t = static_cast<float>(std::clamp(std::abs(v) / hi, 0.0, 1.0));
        const auto k = static_cast<int>(40.0f + 215.0f * t);
        colour = v < 0.0 ? IM_COL32(30, 30 + k / 3, 40 + k, 255) : IM_COL32(40 + k, 30 + k / 4, 30, 255);
      } else {
        colour = v > 0.0 ? draw::colormap(static_cast<float>((std::log10(v) - std::log10(lo)) / (std::log10(hi) - std::log10(lo))))
                         : IM_COL32(0, 0, 0, 255);
      }
      const ImVec2 a(p0.x + static_cast<float>(c) * cw, p0.y + static_cast<float>(r) * ch);
      dl->AddRectFilled(a, ImVec2(a.x + cw, a.y + ch), colour);
    }
  dl->AddRect(p0, ImVec2(p0.x + size.x, p0.y + size.y), IM_COL32(120, 120, 130, 255));
}

void histogram_view(const Lab2dState& s, float width) {
  const lab::Lab2d& lab = *s.lab;
  const double n = static_cast<double>(lab.count());
  std::vector<double> observed(lab.histogram().size()), expected(lab.histogram().size()), z(lab.histogram().size());
  double hi = 0.0;
  for (std::size_t i = 0; i < observed.size(); ++i) {
    observed[i] = static_cast<double>(lab.histogram()[i]);
    expected[i] = lab.cell_probability()[i] * n;
    z[i] = expected[i] > 0.0 ? (observed[i] - expected[i]) / std::sqrt(expected[i]) : 0.0;
    hi = std::max({hi, observed[i], expected[i]});
  }
  hi = std::max(hi, 1.0);
  const double lo = std::max(0.5, hi * 1e-4);
  const float gap = ImGui::GetStyle().ItemSpacing.x;
  const ImVec2 cell((width - gap) * 0.5f, (width - gap) * 0.25f);
  // Two by two: the histogram beside N times the pdf, the residuals beside the verdict.
  // Titles wrap at the cell's width (a large UI scale), each pair kept level.
  const float top_h = std::max(ImGui::CalcTextSize("samples (32 x 16 cells)", nullptr, false, cell.x).y,
                               ImGui::CalcTextSize("E = N x pdf over a cell", nullptr, false, cell.x).y);
  const auto title = [&](const char* text, float h) {
    const float y = ImGui::GetCursorPosY();
    ImGui::PushTextWrapPos(ImGui::GetCursorPosX() + cell.x);
    ImGui::TextUnformatted(text);
    ImGui::PopTextWrapPos();
    ImGui::SetCursorPosY(y + h + ImGui::GetStyle().ItemSpacing.y);
  };
  ImGui::BeginGroup();
  title("samples (32 x 16 cells)", top_h);
  heat_map("##observed", observed, cell, lo, hi, false);
  title("(O - E) / sqrt(E)", ImGui::GetTextLineHeight());
  heat_map("##residual", z, cell, 0.0, 4.0, true);
  ImGui::EndGroup();
  ImGui::SameLine();
  ImGui::BeginGroup();
  title("E = N x pdf over a cell", top_h);
  heat_map("##expected", expected, cell, lo, hi, false);
  ImGui::PushTextWrapPos(ImGui::GetCursorPosX() + cell.x);
  const stats::ChiSquareResult r = lab.chi_square();
  if (!lab.environment().sampleable()) {
    ImGui::TextColored(kRed, "the map has no light: nothing to sample");
  } else if (lab.count() < 1000) {
    ImGui::TextColored(kDim, "chi-square: collecting samples...");
  } else {
    const ImVec4 verdict = r.p_value > 1e-3 && r.zero_cell_hits == 0 ? kGreen : kRed;
    ImGui::TextColored(verdict, "chi-square %.1f", r.statistic);
    ImGui::TextColored(verdict, "%d dof, p = %.3g", r.dof, r.p_value);
    if (r.zero_cell_hits)
      ImGui::TextColored(kRed, "%llu samples where the pdf is 0", static_cast<unsigned long long>(r.zero_cell_hits));
  }
  ImGui::TextColored(kDim, "counts: log colours");
  ImGui::TextColored(kDim, "%.2g to %.2g", lo, hi);
  ImGui::TextColored(kDim, "residuals: blue below E, red above");
  ImGui::PopTextWrapPos();
  ImGui::EndGroup();
}

// A CDF as a line and its pmf as bars (scaled to the plot), over `degrees`.
// With `log_bars` the bars span six decades below the largest (a sun's row
// otherwise flattens the sky's to nothing; in the sun's row a sky texel has
// a few 1e-5 of the sun's texel).
void cdf_plot(const char* title, const std::vector<double>& cdf, double degrees, const char* x_label, ImVec2 size,
              int mark, bool log_bars) {
  const auto n = static_cast<int>(cdf.size()) - 1;
  std::vector<double> xs(cdf.size()), bars(static_cast<std::size_t>(n));
  for (int i = 0; i <= n; ++i) xs[static_cast<std::size_t>(i)] = degrees * i / n;
  double top = 0.0;
  for (int i = 0; i < n; ++i) top = std::max(top, cdf[static_cast<std::size_t>(i) + 1] - cdf[static_cast<std::size_t>(i)]);
  for (int i = 0; i < n; ++i) {
    const double p = cdf[static_cast<std::size_t>(i) + 1] - cdf[static_cast<std::size_t>(i)];
    double& bar = bars[static_cast<std::size_t>(i)];
    bar = top > 0.0 ? p / top : 0.0;
    if (log_bars) bar = bar > 0.0 ? std::max(0.0, 1.0 + std::log10(bar) / 6.0) : 0.0;
  }
  const draw::Plot plot(title, size, {0.0, degrees}, {0.0, 1.05}, x_label);
  // Bars without gaps: a row of 256 columns is narrower than a gap and its bar.
  for (int i = 0; i < n; ++i)
    if (bars[static_cast<std::size_t>(i)] > 0.0)
      plot.list()->AddRectFilled(plot.at(degrees * i / n, bars[static_cast<std::size_t>(i)]),
                                 plot.at(degrees * (i + 1) / n, 0.0), kBars);
  if (mark >= 0) {
    const ImVec2 a = plot.at(degrees * mark / n, 0.0), b = plot.at(degrees * (mark + 1) / n, 1.05);
    plot.list()->AddRect(ImVec2(a.x - 1.0f, b.y), ImVec2(std::max(b.x, a.x + 1.0f) + 1.0f, a.y), kRow, 0.0f, 0, 1.2f);
  }
  plot.line(xs, cdf, kCdf, 2.0f);
  char top_text[64];
  std::snprintf(top_text, sizeof top_text, log_bars ? "probability (log: 6 decades up to %.3g)" : "probability (largest %.3g = 1)", top);
  plot.legend({{"CDF", kCdf}, {top_text, kBars}}, true);
}

// The pdf's peak against the texel count, log-log: slope 1 while the sun
// fits in a texel, bending under the sun's exact density once it does not.
void peak_plot(const lab::Lab2d& lab, ImVec2 size) {
  const std::vector<lab::Lab2d::LevelFigures>& study = lab.resolution_study();
  std::vector<double> texels, peak, guide;
  for (const lab::Lab2d::LevelFigures& f : study) {
    texels.push_back(static_cast<double>(f.width) * f.height);
    peak.push_back(f.peak_pdf);
  }
  if (study.size() < 2 || !(peak.back() > 0.0)) {
    ImGui::Dummy(size);
    return;
  }
  for (double t : texels) guide.push_back(peak.back() * t / texels.back());
  const double exact = lab.sun_exact_density();
  std::vector<double> all = peak;
  if (exact > 0.0) all.push_back(exact);
  const draw::Plot plot("pdf peak vs texels", size, {texels.back() * 0.6, texels.front() * 1.6, true},
                        draw::fit_axis(all, true, 0.1), "texels (log)");
  plot.line(texels, guide, IM_COL32(170, 170, 170, 150), 1.0f);
  if (exact > 0.0) plot.hline(exact, kSun);
  plot.line(texels, peak, kCdf, 2.0f);
  const ImVec2 at = plot.at(texels[static_cast<std::size_t>(lab.level())], peak[static_cast<std::size_t>(lab.level())]);
  plot.list()->AddCircleFilled(at, 4.0f, kRow);
  std::vector<std::pair<std::string, ImU32>> legend = {{"peak", kCdf}, {"~ texels", IM_COL32(170, 170, 170, 150)}};
  if (exact > 0.0) legend.emplace_back("the sun's exact", kSun);
  plot.legend(legend, true);
}

void resolution_table(Lab2dState& s) {
  const lab::Lab2d& lab = *s.lab;
  const std::vector<lab::Lab2d::LevelFigures>& study = lab.resolution_study();
  const bool sun = lab.sun().has_value();
  if (sun)
    ImGui::TextWrapped("The sun: %.3g sr; a sampler exact to the radiance puts %.4g /sr on it (its luminance over the "
                       "map's integral). Each resolution (click one to sample it):",
                       lab.sun()->solid_angle(), lab.sun_exact_density());
  else
    ImGui::TextWrapped("No sun known on this map: the figures are the brightest texel's. Each resolution (click one to sample it):");
  const ImGuiTableFlags flags = ImGuiTableFlags_Borders | ImGuiTableFlags_RowBg | ImGuiTableFlags_SizingStretchProp;
  // The table on the left, the peak against the texel count on the right.
  const float table_width = ImGui::GetContentRegionAvail().x * 0.64f;
  if (!ImGui::BeginTable("##resolutions", sun ? 6 : 4, flags, ImVec2(table_width, 0.0f))) return;
  share_columns(sun ? std::initializer_list<float>{1.0f, 1.3f, 1.0f, 0.9f, 1.0f, 1.1f}
                    : std::initializer_list<float>{1.0f, 1.3f, 1.2f, 1.2f});
  ImGui::TableNextRow(ImGuiTableRowFlags_Headers);
  const char* heads_sun[] = {"texels", "sun's texel (sr)", "sun / texel", "P(texel)", "peak (1/sr)", "peak / exact"};
  const char* heads[] = {"texels", "brightest texel (sr)", "P(texel)", "peak (1/sr)"};
  for (int c = 0; c < (sun ? 6 : 4); ++c) {
    ImGui::TableSetColumnIndex(c);
    ImGui::TextUnformatted(sun ? heads_sun[c] : heads[c]);
  }
  int chosen = -1;
  for (std::size_t l = 0; l < study.size(); ++l) {
    const lab::Lab2d::LevelFigures& f = study[l];
    ImGui::TableNextRow();
    ImGui::TableSetColumnIndex(0);
    const std::string label = size_text(f.width, f.height) + "##level" + std::to_string(l);
    if (ImGui::Selectable(label.c_str(), static_cast<int>(l) == lab.level(), ImGuiSelectableFlags_SpanAllColumns))
      chosen = static_cast<int>(l);
    layout::item(("lab2d.level." + std::to_string(f.width)).c_str());
    const auto cell = [](int column, const char* fmt, double v) {
      ImGui::TableSetColumnIndex(column);
      ImGui::Text(fmt, v);
    };
    if (sun) {
      cell(1, "%.3g", f.sun_texel_solid_angle);
      cell(2, "%.3g", lab.sun()->solid_angle() / f.sun_texel_solid_angle);
      cell(3, "%.4f", f.sun_pdf * f.sun_texel_solid_angle);
      cell(4, "%.4g", f.peak_pdf);
      cell(5, "%.3g", f.peak_pdf / lab.sun_exact_density());
    } else {
      cell(1, "%.3g", f.peak_solid_angle);
      cell(2, "%.4f", f.peak_probability);
      cell(3, "%.4g", f.peak_pdf);
    }
  }
  ImGui::EndTable();
  const float table_height = ImGui::GetItemRectSize().y;
  ImGui::SameLine();
  peak_plot(lab, ImVec2(ImGui::GetContentRegionAvail().x, table_height));
  if (chosen >= 0) s.set_level(chosen);
}

}  // namespace

void draw_lab2d_window(Lab2dState& s, bool* open) {
  // Sized as the 1D lab: follows the window and the UI scale.
  if (!draw::begin_lab_window("2D lab: sampling an environment map (D)", open, s.sized_for, 72.0f, 56.0f)) return;
  const float font = ImGui::GetFontSize();
  if (!s.lab && !s.choose(s.scene_environment ? Lab2dState::Source::Scene : s.source)) s.choose(Lab2dState::Source::Constant);
  if (!s.lab) {
    ImGui::TextColored(kRed, "%s", s.error.c_str());
    ImGui::End();
    return;
  }
  s.step();
  lab::Lab2d& lab = *s.lab;

  // The controls wrap onto the next row rather than run past the window's edge.
  const ImGuiStyle& style = ImGui::GetStyle();
  const auto labelled = [&](float item, const char* label) { return item + style.ItemInnerSpacing.x + ImGui::CalcTextSize(label).x; };
  const auto button_width = [&](const char* label) { return ImGui::CalcTextSize(label).x + style.FramePadding.x * 2.0f; };
  const auto same_line_if_fits = [&](float width) {
    ImGui::SameLine();
    if (ImGui::GetContentRegionAvail().x < width) ImGui::NewLine();
  };
  ImGui::SetNextItemWidth(font * 13.0f);
  if (ImGui::BeginCombo("map", std::string(lab2d_source_name(s.source)).c_str())) {
    for (int i = 0; i < static_cast<int>(Lab2dState::Source::Count); ++i) {
      const auto v = static_cast<Lab2dState::Source>(i);
      if (v == Lab2dState::Source::Scene && !s.scene_environment) continue;
      if (ImGui::Selectable(std::string(lab2d_source_name(v)).c_str(), v == s.source) && v != s.source) s.choose(v);
    }
    ImGui::EndCombo();
  }
  same_line_if_fits(labelled(font * 6.0f, "resolution"));
  ImGui::SetNextItemWidth(font * 6.0f);
  if (ImGui::BeginCombo("resolution", size_text(lab.map().width, lab.map().height).c_str())) {
    for (int l = 0; l < lab.levels(); ++l)
      if (ImGui::Selectable(size_text(lab.map(l).width, lab.map(l).height).c_str(), l == lab.level())) s.set_level(l);
    ImGui::EndCombo();
  }
  same_line_if_fits(labelled(font * 8.0f, "row"));
  int row = s.picked_row();
  ImGui::SetNextItemWidth(font * 8.0f);
  if (ImGui::SliderInt("row", &row, 0, lab.map().height - 1)) s.row = row;
  const char* run_label = s.running ? "Pause" : "Run";
  same_line_if_fits(button_width(run_label));
  if (ImGui::Button(run_label)) s.running = !s.running;
  same_line_if_fits(button_width("Reset"));
  if (ImGui::Button("Reset")) lab.reset();
  same_line_if_fits(labelled(font * 6.0f, "samples/frame"));
  ImGui::SetNextItemWidth(font * 6.0f);
  ImGui::SliderInt("samples/frame", &s.samples_per_frame, 1, 20000, "%d", ImGuiSliderFlags_Logarithmic);
  same_line_if_fits(ImGui::GetFrameHeight() + style.ItemInnerSpacing.x + ImGui::CalcTextSize("log bars").x);
  ImGui::Checkbox("log bars", &s.log_bars);
  layout::item("lab2d.log_bars");
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("The CDF plots' probabilities on a log scale (six decades)");
  if (!s.error.empty()) ImGui::TextColored(kRed, "%s", s.error.c_str());
  ImGui::TextWrapped("N = %llu directions by Environment::sample: u1 picks the row from the marginal CDF, u2 the column "
                     "from that row's conditional CDF; the density is P(texel) / the texel's solid angle.",
                     static_cast<unsigned long long>(lab.count()));

  const float gap = ImGui::GetStyle().ItemSpacing.x;
  const float avail = ImGui::GetContentRegionAvail().x;
  const float map_width = (avail - gap) * 0.5f;
  ImGui::BeginGroup();
  ImGui::PushTextWrapPos(ImGui::GetCursorPosX() + map_width);
  ImGui::Text("the map, %s, and the latest %zu samples", size_text(lab.map().width, lab.map().height).c_str(), lab.dots().size());
  ImGui::PopTextWrapPos();
  map_view(s, ImVec2(map_width, map_width * 0.5f));
  ImGui::EndGroup();
  ImGui::SameLine();
  histogram_view(s, avail - map_width - gap);

  const float rest = ImGui::GetContentRegionAvail().y;
  // The table below: two lines of text, and a header and six rows.
  const float table_height = ImGui::GetTextLineHeightWithSpacing() * 2.0f +
                             7.0f * (font + 2.0f * style.CellPadding.y + 1.0f) + 2.0f * style.ItemSpacing.y;
  const ImVec2 plot((avail - gap) * 0.5f, std::max(font * 7.0f, rest - table_height));
  const int picked = s.picked_row();
  const double theta0 = 180.0 * picked / lab.map().height, theta1 = 180.0 * (picked + 1) / lab.map().height;
  cdf_plot("marginal: P(row) and its CDF", lab.marginal_cdf(), 180.0, "theta (degrees from the zenith)", plot, picked,
           s.log_bars);
  ImGui::SameLine();
  char title[96];
  std::snprintf(title, sizeof title, "row %d (theta %.1f-%.1f): P(column | row)", picked, theta0, theta1);
  cdf_plot(title, lab.conditional_cdf(picked), 360.0, "phi (degrees)", plot, -1, s.log_bars);
  resolution_table(s);
  ImGui::End();
}

}  // namespace pdflab::ui
