#include "ui/figure_export.h"

#include "renderer/error.h"
#include "renderer/film/image_io.h"
#include "renderer/metrics/svg_plot.h"

#include <imgui.h>
#include <imgui_internal.h>  // ImTextCharFromUtf8
#include <stb_image_write.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fcntl.h>
#include <memory>
#include <sstream>
#include <unistd.h>

namespace pdflab::ui {

namespace fs = std::filesystem;

namespace {

constexpr const char* kFigureFont = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
constexpr float kFigureFontPixels = 15.0f;

using Rgb = std::array<std::uint8_t, 3>;
constexpr Rgb kInk{30, 30, 36}, kDimInk{95, 95, 105}, kPaper{255, 255, 255};

Rgb to_rgb(const Colour& c) {
  const auto byte = [](float v) { return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); };
  return {byte(c[0]), byte(c[1]), byte(c[2])};
}

// An RGB8 canvas, row 0 at the top.
struct Canvas {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;
  Canvas(int w, int h) : width(w), height(h), rgb(3 * static_cast<std::size_t>(w) * static_cast<std::size_t>(h), 255) {}
  void blend(int x, int y, const Rgb& c, float alpha) {
    if (x < 0 || y < 0 || x >= width || y >= height || !(alpha > 0.0f)) return;
    std::uint8_t* p = &rgb[3 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x))];
    for (int i = 0; i < 3; ++i)
      p[i] = static_cast<std::uint8_t>(std::lround(static_cast<float>(p[i]) * (1.0f - alpha) + static_cast<float>(c[static_cast<std::size_t>(i)]) * alpha));
  }
  void fill(int x0, int y0, int w, int h, const Rgb& c) {
    for (int y = y0; y < y0 + h; ++y)
      for (int x = x0; x < x0 + w; ++x) blend(x, y, c, 1.0f);
  }
  void frame(int x0, int y0, int w, int h, const Rgb& c) {
    fill(x0, y0, w, 1, c);
    fill(x0, y0 + h - 1, w, 1, c);
    fill(x0, y0, 1, h, c);
    fill(x0 + w - 1, y0, 1, h, c);
  }
};

// Text from a font atlas of its own (no ImGui context): glyphs rasterised
// once at one size, one texel to a pixel, blended onto the canvas.
class FigureFont {
 public:
  FigureFont() {
    ImFontConfig cfg;
    cfg.OversampleH = cfg.OversampleV = 1;
    cfg.PixelSnapH = true;
    std::error_code ec;
    font_ = fs::exists(kFigureFont, ec) ? atlas_.AddFontFromFileTTF(kFigureFont, kFigureFontPixels, &cfg) : nullptr;
    if (!font_) {
      cfg.SizePixels = 13.0f;
      font_ = atlas_.AddFontDefault(&cfg);
    }
    atlas_.GetTexDataAsAlpha8(&pixels_, &atlas_w_, &atlas_h_);
  }
  int line_height() const { return static_cast<int>(std::ceil(font_->FontSize * 1.3f)); }
  int width(const std::string& text) const {
    float w = 0.0f;
    for_each_glyph(text, [&](const ImFontGlyph& g) { w += g.AdvanceX; });
    return static_cast<int>(std::ceil(w));
  }
  void draw(Canvas& c, int x, int y, const std::string& text, const Rgb& colour) const {
    float pen = static_cast<float>(x);
    for_each_glyph(text, [&](const ImFontGlyph& g) {
      if (g.Visible) {
        const int gx = static_cast<int>(std::lround(pen + g.X0)), gy = static_cast<int>(std::lround(static_cast<float>(y) + g.Y0));
        const int gw = static_cast<int>(std::lround(g.X1 - g.X0)), gh = static_cast<int>(std::lround(g.Y1 - g.Y0));
        const int u0 = static_cast<int>(std::lround(g.U0 * static_cast<float>(atlas_w_)));
        const int v0 = static_cast<int>(std::lround(g.V0 * static_cast<float>(atlas_h_)));
        for (int dy = 0; dy < gh; ++dy)
          for (int dx = 0; dx < gw; ++dx) {
            const int u = u0 + dx, v = v0 + dy;
            if (u < 0 || v < 0 || u >= atlas_w_ || v >= atlas_h_) continue;
            const float a = static_cast<float>(pixels_[static_cast<std::size_t>(v) * static_cast<std::size_t>(atlas_w_) + static_cast<std::size_t>(u)]) / 255.0f;
            c.blend(gx + dx, gy + dy, colour, a);
          }
      }
      pen += g.AdvanceX;
    });
  }

 private:
  template <typename F>
  void for_each_glyph(const std::string& text, F&& f) const {
    const char* s = text.c_str();
    const char* end = s + text.size();
    while (s < end) {
      unsigned int c = 0;
      const int n = ImTextCharFromUtf8(&c, s, end);
      if (n <= 0) break;
      s += n;
      if (const ImFontGlyph* g = font_->FindGlyph(static_cast<ImWchar>(c))) f(*g);
    }
  }
  ImFontAtlas atlas_;
  ImFont* font_ = nullptr;
  unsigned char* pixels_ = nullptr;
  int atlas_w_ = 0, atlas_h_ = 0;
};

const FigureFont& figure_font() {
  static const FigureFont font;  // built once, on first use (the UI thread)
  return font;
}

void append_bytes(void* context, void* data, int size) {
  auto* out = static_cast<std::vector<std::uint8_t>*>(context);
  const auto* p = static_cast<const std::uint8_t*>(data);
  out->insert(out->end(), p, p + size);
}

// The legend's lines under the colour bar: what grey means in the weight views.
std::vector<std::string> legend_notes(ViewMode mode) {
  if (mode == ViewMode::BestWeight) return {"grey: w does not matter there"};
  if (mode == ViewMode::TechniqueShare) return {"grey: no light found yet, or lights seen directly"};
  return {};
}

}  // namespace

FigureGeometry view_figure_geometry(ViewMode mode, const ViewLayer& layer, const FigureCaption& caption,
                                    int min_width) {
  const FigureFont& font = figure_font();
  const int line = font.line_height(), margin = line;
  FigureGeometry g;
  g.scale = layer.width > 0 ? std::clamp((std::max(1, min_width) + layer.width - 1) / layer.width, 1, 16) : 1;
  const int image_w = layer.width * g.scale, image_h = layer.height * g.scale;
  int widest = image_w;
  widest = std::max(widest, font.width(caption.title));
  widest = std::max(widest, font.width(layer.scale.title));
  for (const std::string& l : caption.lines) widest = std::max(widest, font.width(l));
  for (const std::string& l : legend_notes(mode)) widest = std::max(widest, font.width(l));
  g.width = widest + 2 * margin;
  g.image_x = margin + (widest - image_w) / 2;
  g.image_y = margin + line + line / 3;
  // Under the image: the scale's title, the bar, its labels, the notes, the caption.
  const int bar = line;
  g.height = g.image_y + image_h + line / 2 + line + bar + line + line / 2 +
             line * static_cast<int>(legend_notes(mode).size() + caption.lines.size()) + margin;
  return g;
}

std::vector<std::uint8_t> view_figure_rgb(ViewMode mode, const ViewLayer& layer, const FigureCaption& caption,
                                          int min_width, int& width, int& height) {
  if (layer.width <= 0 || layer.height <= 0 ||
      layer.rgba.size() != 4 * static_cast<std::size_t>(layer.width) * static_cast<std::size_t>(layer.height))
    throw InputError("no view to export: the view shows the image");
  const FigureFont& font = figure_font();
  const FigureGeometry g = view_figure_geometry(mode, layer, caption, min_width);
  const int line = font.line_height(), margin = line;
  Canvas c(g.width, g.height);
  int y = margin;
  font.draw(c, margin, y, caption.title, kInk);
  // The view, pixel for pixel enlarged (its noise is what it shows).
  for (int py = 0; py < layer.height * g.scale; ++py)
    for (int px = 0; px < layer.width * g.scale; ++px) {
      const std::size_t src = 4 * (static_cast<std::size_t>(py / g.scale) * static_cast<std::size_t>(layer.width) +
                                   static_cast<std::size_t>(px / g.scale));
      c.blend(g.image_x + px, g.image_y + py, {layer.rgba[src], layer.rgba[src + 1], layer.rgba[src + 2]}, 1.0f);
    }
  const int image_w = layer.width * g.scale;
  y = g.image_y + layer.height * g.scale + line / 2;
  font.draw(c, g.image_x, y, layer.scale.title, kInk);
  y += line;
  // The colour bar, its ticks and the labels that fit without running into each other.
  const int bar = line;
  const ColourScale& s = layer.scale;
  for (int px = 0; px < image_w; ++px) {
    const double t = image_w > 1 ? static_cast<double>(px) / (image_w - 1) : 0.0;
    const Rgb colour = to_rgb(s.diverging ? diverging_colour(2.0 * t - 1.0) : sequential_colour(t));
    c.fill(g.image_x + px, y, 1, bar, colour);
  }
  c.frame(g.image_x, y, image_w, bar, kDimInk);
  const std::vector<LegendTick> ticks = legend_ticks(s);
  std::vector<float> centre, text_width;
  for (const LegendTick& t : ticks) {
    const int x = g.image_x + static_cast<int>(std::lround(t.position * (image_w - 1)));
    c.fill(x, y + bar - 3, 1, 6, kInk);
    centre.push_back(static_cast<float>(x - g.image_x));
    text_width.push_back(static_cast<float>(font.width(t.label)));
  }
  for (const std::size_t i : labels_that_fit(centre, text_width, static_cast<float>(image_w), 6.0f)) {
    const float left = std::clamp(centre[i] - text_width[i] * 0.5f, 0.0f, std::max(0.0f, static_cast<float>(image_w) - text_width[i]));
    font.draw(c, g.image_x + static_cast<int>(std::lround(left)), y + bar + 3, ticks[i].label, kInk);
  }
  y += bar + line + line / 2;
  for (const std::string& l : legend_notes(mode)) {
    font.draw(c, g.image_x, y, l, kDimInk);
    y += line;
  }
  for (const std::string& l : caption.lines) {
    font.draw(c, margin, y, l, kDimInk);
    y += line;
  }
  width = c.width;
  height = c.height;
  return std::move(c.rgb);
}

std::vector<std::uint8_t> view_figure_png(ViewMode mode, const ViewLayer& layer, const FigureCaption& caption,
                                          int min_width) {
  int w = 0, h = 0;
  const std::vector<std::uint8_t> rgb = view_figure_rgb(mode, layer, caption, min_width, w, h);
  std::vector<std::uint8_t> out;
  if (!stbi_write_png_to_func(append_bytes, &out, w, h, 3, rgb.data(), w * 3)) throw IoError("PNG encoding failed");
  return out;
}

std::string weight_curve_csv(const WeightCurveStatus& c) {
  std::ostringstream out;
  out << "w,relative_efficiency,largest_path_share\n";
  char row[96];
  for (std::size_t i = 0; i < c.weight.size() && i < c.relative_efficiency.size(); ++i) {
    const double share = i < c.largest_share.size() ? static_cast<double>(c.largest_share[i]) : NAN;
    std::snprintf(row, sizeof row, "%.6g,%.6g,%.6g\n", static_cast<double>(c.weight[i]),
                  static_cast<double>(c.relative_efficiency[i]), share);
    out << row;
  }
  return out.str();
}

std::string weight_curve_svg(const WeightCurveStatus& c, const std::string& a, const std::string& b,
                             const std::string& title) {
  PlotSeries s;
  s.label = "predicted efficiency / best";
  for (std::size_t i = 0; i < c.weight.size() && i < c.relative_efficiency.size(); ++i) {
    s.x.push_back(c.weight[i]);
    s.y.push_back(c.relative_efficiency[i]);
  }
  PlotOptions o;
  o.title = title;
  o.x_label = "w: the share of " + a + " (1 - w: " + b + ")";
  o.y_label = "predicted efficiency, relative to the best";
  o.x_min = 0.0;
  o.x_max = 1.0;
  if (c.best >= 0.0) {
    o.marker_x = c.best;
    o.marker_lo = c.best;
    o.marker_hi = c.best;
    char label[48];
    std::snprintf(label, sizeof label, "predicted best w = %.2f", c.best);
    o.marker_label = label;
  }
  return linear_svg({s}, o);
}

std::string convergence_csv(const ConvergenceRecorder& rec) {
  std::ostringstream out;
  out << "curve,label,estimated,width,height,spp,seconds,relative_rms_error\n";
  const auto rows = [&](const Curve& c, const std::string& name) {
    char row[160];
    for (const CurvePoint& p : c.points) {
      std::snprintf(row, sizeof row, ",%s,%d,%d,%.0f,%.6g,%.6g\n", c.estimated ? "yes" : "no", c.width, c.height, p.spp,
                    p.seconds, p.error);
      // The label may hold commas (a mixture): quoted.
      out << name << ",\"" << c.label << "\"" << row;
    }
  };
  for (std::size_t i = 0; i < rec.pins().size(); ++i) rows(rec.pins()[i], "pin " + std::to_string(i + 1));
  rows(rec.live(), "now");
  return out.str();
}

std::string convergence_svg(const ConvergenceRecorder& rec, bool against_spp, const std::string& title) {
  std::vector<PlotSeries> series;
  const auto add = [&](const Curve& c, const std::string& prefix) {
    if (c.points.empty()) return;
    PlotSeries s;
    s.label = prefix + curve_label(c);
    for (const CurvePoint& p : c.points) {
      s.x.push_back(against_spp ? p.spp : p.seconds);
      s.y.push_back(p.error);
    }
    series.push_back(std::move(s));
  };
  for (std::size_t i = 0; i < rec.pins().size(); ++i) add(rec.pins()[i], "pin: ");
  add(rec.live(), "now: ");
  PlotOptions o;
  o.title = title;
  o.x_label = against_spp ? "samples per pixel" : "rendering time (s)";
  o.y_label = "relative RMS error sqrt(relMSE)";
  o.guide_slope = -0.5;
  o.guide_label = "1/sqrt(N) slope";
  return loglog_svg(series, o);
}

std::vector<std::string> save_figure_files(const std::string& folder, const std::string& kind,
                                           const std::vector<FigureFile>& files, std::time_t when) {
  if (folder.empty()) throw InputError("the screenshot folder is empty");
  std::error_code ec;
  fs::create_directories(folder, ec);
  if (ec) throw IoError("cannot create the folder '" + folder + "': " + ec.message());
  char stamp[32];
  std::tm local{};
  localtime_r(&when, &local);
  std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", &local);
  for (int n = 1; n < 100000; ++n) {
    const std::string stem =
        (fs::path(folder) / ("pdflab-" + std::string(stamp) + "-" + std::to_string(n) + "-" + kind)).string();
    std::vector<std::string> paths;
    bool taken = false;
    for (const FigureFile& f : files) {
      paths.push_back(stem + "." + f.extension);
      taken = taken || fs::exists(paths.back(), ec);
    }
    if (taken) continue;
    // The first file's name, created exclusively, reserves the stem.
    const int fd = ::open(paths.front().c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd < 0) {
      if (errno == EEXIST) continue;
      throw IoError("cannot save a figure in '" + folder + "': " + std::strerror(errno));
    }
    ::close(fd);
    try {
      for (std::size_t i = 0; i < files.size(); ++i) write_file_atomic(paths[i], files[i].bytes);
    } catch (...) {
      for (const std::string& p : paths) fs::remove(p, ec);
      throw;
    }
    return paths;
  }
  throw IoError("no free figure name in '" + folder + "'");
}

}  // namespace pdflab::ui
