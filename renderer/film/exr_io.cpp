#include "renderer/film/exr_io.h"

#include "renderer/error.h"
#include "renderer/film/image_io.h"
#include "renderer/input_file.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStringAttribute.h>

#include <algorithm>
#include <array>
#include <exception>

namespace pdflab {

namespace {

constexpr int kRowsPerStrip = 16;  // ZIP compresses 16 rows per block

const char* const kMeanChannels[3] = {"R", "G", "B"};
const char* const kVarianceChannels[3] = {"variance.R", "variance.G", "variance.B"};
constexpr const char* kCountChannel = "count";

Imf::Header make_header(int width, int height, const ImageAttributes& attributes) {
  Imf::Header header(width, height);
  header.compression() = Imf::ZIP_COMPRESSION;
  for (const auto& [name, value] : attributes) header.insert(name, Imf::StringAttribute(value));
  for (const char* c : kMeanChannels) header.channels().insert(c, Imf::Channel(Imf::FLOAT));
  return header;
}

// Strips of rows filled by `fill(y0, rows)` into the slices `frame(y0, rows)` describes.
template <class Frame, class Fill>
void write_strips(const std::string& path, const Imf::Header& header, int height, Frame frame, Fill fill) {
  AtomicFile file(path);
  try {
    Imf::OutputFile out(file.release_to_writer().c_str(), header, 1);
    for (int y0 = 0; y0 < height; y0 += kRowsPerStrip) {
      const int rows = std::min(kRowsPerStrip, height - y0);
      fill(y0, rows);
      out.setFrameBuffer(frame(y0, rows));
      out.writePixels(rows);
    }
  } catch (const std::exception& e) {
    throw IoError("cannot write '" + path + "': " + e.what());
  }
  file.commit();
}

Imf::Slice strip_slice(Imf::PixelType type, const void* base, int y0, int width, int rows, std::size_t x_stride) {
  return Imf::Slice::Make(type, base, IMATH_NAMESPACE::V2i(0, y0), width, rows, x_stride, x_stride * width);
}

}  // namespace

void write_exr(const std::string& path, const Film& film, const ImageAttributes& attributes) {
  const int w = film.width(), h = film.height();
  Imf::Header header = make_header(w, h, attributes);
  for (const char* c : kVarianceChannels) header.channels().insert(c, Imf::Channel(Imf::FLOAT));
  // FLOAT, not UINT: image tools (OpenImageIO's oiiotool, and what is built on
  // it) read an unsigned channel as a fraction of 2^32 (8 samples as 1.9e-9);
  // a float holds every count up to 2^24 = 16,777,216 samples exactly.
  header.channels().insert(kCountChannel, Imf::Channel(Imf::FLOAT));

  const std::size_t strip_pixels = static_cast<std::size_t>(w) * kRowsPerStrip;
  std::vector<float> mean(3 * strip_pixels), variance(3 * strip_pixels);
  std::vector<float> count(strip_pixels);
  const auto fill = [&](int y0, int rows) {
    const std::size_t first = static_cast<std::size_t>(y0) * static_cast<std::size_t>(w);
    for (std::size_t i = 0; i < static_cast<std::size_t>(rows) * static_cast<std::size_t>(w); ++i) {
      double m[3], v[3];
      film.moments(first + i, Film::reciprocals(film.count(first + i)), m, v);
      for (int c = 0; c < 3; ++c) {
        mean[3 * i + static_cast<std::size_t>(c)] = static_cast<float>(m[c]);
        variance[3 * i + static_cast<std::size_t>(c)] = static_cast<float>(v[c]);
      }
      count[i] = static_cast<float>(film.count(first + i));
    }
  };
  const auto frame = [&](int y0, int rows) {
    Imf::FrameBuffer fb;
    for (int c = 0; c < 3; ++c) {
      fb.insert(kMeanChannels[c], strip_slice(Imf::FLOAT, mean.data() + c, y0, w, rows, 3 * sizeof(float)));
      fb.insert(kVarianceChannels[c], strip_slice(Imf::FLOAT, variance.data() + c, y0, w, rows, 3 * sizeof(float)));
    }
    fb.insert(kCountChannel, strip_slice(Imf::FLOAT, count.data(), y0, w, rows, sizeof(float)));
    return fb;
  };
  write_strips(path, header, h, frame, fill);
}

void write_exr(const std::string& path, const std::vector<float>& rgb, int width, int height,
               const ImageAttributes& attributes) {
  const Imf::Header header = make_header(width, height, attributes);
  const auto frame = [&](int y0, int rows) {
    Imf::FrameBuffer fb;
    const float* strip = rgb.data() + 3 * static_cast<std::size_t>(y0) * static_cast<std::size_t>(width);
    for (int c = 0; c < 3; ++c)
      fb.insert(kMeanChannels[c], strip_slice(Imf::FLOAT, strip + c, y0, width, rows, 3 * sizeof(float)));
    return fb;
  };
  write_strips(path, header, height, frame, [](int, int) {});
}

namespace {

// Three float channels of an EXR as interleaved RGB; empty when the file has
// none of them.
std::vector<float> read_exr_channels(const std::string& path, const char* const (&names)[3], int& width, int& height) {
  check_input_file(path, "EXR");  // OpenEXR opens by name: a pipe would hold it
  try {
    Imf::InputFile in(path.c_str(), 1);
    const IMATH_NAMESPACE::Box2i dw = in.header().dataWindow();
    const long long w = static_cast<long long>(dw.max.x) - dw.min.x + 1;
    const long long h = static_cast<long long>(dw.max.y) - dw.min.y + 1;
    if (const std::string problem = image_size_problem(w, h); !problem.empty())
      throw InputError("'" + path + "': " + problem);
    std::string missing;
    int found = 0;
    for (const char* c : names) {
      if (in.header().channels().findChannel(c)) ++found;
      else missing += (missing.empty() ? "" : ", ") + std::string(c);
    }
    if (found == 0) return {};
    // Part of a layer is a damaged or foreign file: a missing channel would
    // read as 0 (a green-less reference, a variance of nothing).
    if (found < 3)
      throw InputError("EXR '" + path + "' has " + std::to_string(found) + " of the channels " + names[0] + ", " +
                       names[1] + ", " + names[2] + ": " + missing + " missing");
    std::vector<float> rgb(3 * static_cast<std::size_t>(w) * static_cast<std::size_t>(h), 0.0f);
    Imf::FrameBuffer fb;
    for (int c = 0; c < 3; ++c)
      fb.insert(names[c], Imf::Slice::Make(Imf::FLOAT, rgb.data() + c, dw, 3 * sizeof(float),
                                           3 * sizeof(float) * static_cast<std::size_t>(w)));
    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);
    width = static_cast<int>(w);
    height = static_cast<int>(h);
    return rgb;
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError("cannot read EXR '" + path + "': " + e.what());
  }
}

}  // namespace

std::vector<float> read_exr(const std::string& path, int& width, int& height) {
  std::vector<float> rgb = read_exr_channels(path, kMeanChannels, width, height);
  if (rgb.empty()) throw InputError("'" + path + "': an EXR image without R, G or B channels");
  return rgb;
}

std::vector<float> read_exr_variance(const std::string& path) {
  int w = 0, h = 0;
  return read_exr_channels(path, kVarianceChannels, w, h);
}

std::string read_exr_attribute(const std::string& path, const std::string& name) {
  check_input_file(path, "EXR");
  try {
    Imf::InputFile in(path.c_str(), 1);
    const auto* a = in.header().findTypedAttribute<Imf::StringAttribute>(name);
    return a ? a->value() : std::string();
  } catch (const std::exception& e) {
    throw InputError("cannot read EXR '" + path + "': " + e.what());
  }
}

}  // namespace pdflab
