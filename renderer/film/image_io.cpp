#include "renderer/film/image_io.h"

#include "renderer/error.h"
#include "renderer/film/exr_io.h"
#include "renderer/film/film.h"
#include "renderer/input_file.h"

#include <stb_image_write.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace pdflab {

namespace fs = std::filesystem;

ImageFormat image_format_for(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".png") return ImageFormat::Png;
  if (ext == ".pfm") return ImageFormat::Pfm;
  if (ext == ".hdr") return ImageFormat::Hdr;
  if (ext == ".exr") return ImageFormat::Exr;
  throw InputError("output file '" + path + "': unknown image format '" + ext + "' (use .png, .pfm, .hdr or .exr)");
}

void check_output_path(const std::string& path) {
  if (path.empty()) throw InputError("output file name is empty");
  fs::path dir = fs::path(path).parent_path();
  if (dir.empty()) dir = ".";
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw InputError("output file '" + path + "': folder '" + dir.string() + "' does not exist");
  if (::access(dir.c_str(), W_OK) != 0)
    throw InputError("output file '" + path + "': folder '" + dir.string() + "' is not writable");
  if (fs::is_directory(path, ec)) throw InputError("output file '" + path + "' is a folder");
}

void check_distinct_outputs(const std::vector<std::string>& paths) {
  std::vector<fs::path> seen;
  for (const std::string& p : paths) {
    if (p.empty()) continue;
    std::error_code ec;
    fs::path canonical = fs::weakly_canonical(fs::absolute(p, ec), ec);
    if (ec) canonical = fs::path(p).lexically_normal();
    if (std::find(seen.begin(), seen.end(), canonical) != seen.end())
      throw InputError("output file '" + p + "' is named twice; each output needs its own file");
    seen.push_back(std::move(canonical));
  }
}

AtomicFile::AtomicFile(const std::string& path) : path_(path) {
  static std::atomic<unsigned> counter{0};
  temp_ = path + ".tmp." + std::to_string(::getpid()) + "." + std::to_string(counter++);
  file_ = std::fopen(temp_.c_str(), "wb");
  if (!file_) throw IoError("cannot write '" + path_ + "': " + std::strerror(errno));
}

AtomicFile::~AtomicFile() {
  if (committed_) return;
  if (file_) std::fclose(file_);
  std::remove(temp_.c_str());
}

void AtomicFile::fail(int error) {
  if (file_) std::fclose(file_);
  file_ = nullptr;
  std::remove(temp_.c_str());
  committed_ = true;  // nothing left to clean up
  throw IoError("cannot write '" + path_ + "': " + std::strerror(error));
}

void AtomicFile::write(const void* data, std::size_t size) {
  if (!file_) throw std::logic_error("AtomicFile::write after release_to_writer");
  if (std::fwrite(data, 1, size, file_) != size) fail(errno);
}

const std::string& AtomicFile::release_to_writer() {
  if (file_ && std::fclose(file_) != 0) {
    file_ = nullptr;
    fail(errno);
  }
  file_ = nullptr;
  return temp_;
}

void AtomicFile::commit() {
  if (committed_) throw std::logic_error("AtomicFile::commit twice");
  if (file_) {
    if (std::fflush(file_) != 0 || ::fsync(::fileno(file_)) != 0) fail(errno);
    const bool closed = std::fclose(file_) == 0;
    file_ = nullptr;
    if (!closed) fail(errno);
  } else {
    // Written by another library: sync it through a descriptor of our own.
    const int fd = ::open(temp_.c_str(), O_RDONLY);
    if (fd < 0) fail(errno);
    const bool synced = ::fsync(fd) == 0;
    const int e = errno;
    ::close(fd);
    if (!synced) fail(e);
  }
  if (std::rename(temp_.c_str(), path_.c_str()) != 0) fail(errno);
  committed_ = true;
}

void write_file_atomic(const std::string& path, std::span<const std::uint8_t> bytes) {
  AtomicFile file(path);
  file.write(bytes.data(), bytes.size());
  file.commit();
}

std::uint8_t tone_map_channel(float linear, Transfer transfer, float exposure) {
  float x = linear * exposure;
  if (!(x > 0.0f)) return 0;  // also NaN
  if (transfer == Transfer::Gamma2) {
    x = std::sqrt(x);
  } else {
    x = x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.0f / 2.4f) - 0.055f;
  }
  // The book's mapping: clamp to [0, 0.999], scale by 256.
  return static_cast<std::uint8_t>(256.0f * std::clamp(x, 0.0f, 0.999f));
}

namespace {

void append_to_vector(void* context, void* data, int size) {
  auto* out = static_cast<std::vector<std::uint8_t>*>(context);
  const auto* bytes = static_cast<const std::uint8_t*>(data);
  out->insert(out->end(), bytes, bytes + size);
}

}  // namespace

std::vector<std::uint8_t> encode_png(const std::vector<float>& rgb, int width, int height, Transfer transfer,
                                     float exposure) {
  std::vector<std::uint8_t> pixels(rgb.size());
  for (std::size_t i = 0; i < rgb.size(); ++i) pixels[i] = tone_map_channel(rgb[i], transfer, exposure);
  std::vector<std::uint8_t> out;
  if (!stbi_write_png_to_func(append_to_vector, &out, width, height, 3, pixels.data(), width * 3))
    throw IoError("PNG encoding failed");
  return out;
}

std::vector<std::uint8_t> encode_pfm(const std::vector<float>& rgb, int width, int height) {
  // PFM: rows bottom to top; a negative scale means little-endian floats.
  const std::string header = "PF\n" + std::to_string(width) + " " + std::to_string(height) + "\n-1.0\n";
  std::vector<std::uint8_t> out(header.begin(), header.end());
  const std::size_t row_bytes = static_cast<std::size_t>(width) * 3 * sizeof(float);
  out.resize(header.size() + row_bytes * static_cast<std::size_t>(height));
  std::uint8_t* dst = out.data() + header.size();
  for (int y = height - 1; y >= 0; --y, dst += row_bytes)
    std::memcpy(dst, rgb.data() + static_cast<std::size_t>(y) * width * 3, row_bytes);
  static_assert(std::endian::native == std::endian::little, "PFM writer assumes a little-endian host");
  return out;
}

std::vector<std::uint8_t> encode_hdr(const std::vector<float>& rgb, int width, int height) {
  std::vector<std::uint8_t> out;
  if (!stbi_write_hdr_to_func(append_to_vector, &out, width, height, 3, rgb.data()))
    throw IoError("HDR encoding failed");
  return out;
}

void write_image(const std::string& path, const std::vector<float>& rgb, int width, int height, Transfer transfer) {
  std::vector<std::uint8_t> bytes;
  switch (image_format_for(path)) {
    case ImageFormat::Png: bytes = encode_png(rgb, width, height, transfer); break;
    case ImageFormat::Pfm: bytes = encode_pfm(rgb, width, height); break;
    case ImageFormat::Hdr: bytes = encode_hdr(rgb, width, height); break;
    case ImageFormat::Exr: write_exr(path, rgb, width, height); return;
  }
  write_file_atomic(path, bytes);
}

void write_film_image(const std::string& path, const Film& film, Transfer transfer,
                      const std::vector<std::pair<std::string, std::string>>& attributes) {
  const int w = film.width(), h = film.height();
  switch (image_format_for(path)) {
    case ImageFormat::Exr: write_exr(path, film, attributes); return;
    case ImageFormat::Pfm: {
      AtomicFile file(path);
      const std::string header = "PF\n" + std::to_string(w) + " " + std::to_string(h) + "\n-1.0\n";
      file.write(header.data(), header.size());
      std::vector<float> row(3 * static_cast<std::size_t>(w));
      for (int y = h - 1; y >= 0; --y) {  // PFM rows run bottom to top
        const std::size_t first = static_cast<std::size_t>(y) * static_cast<std::size_t>(w);
        for (std::size_t x = 0; x < static_cast<std::size_t>(w); ++x) {
          double m[3];
          film.mean(first + x, m);
          for (std::size_t c = 0; c < 3; ++c) row[3 * x + c] = static_cast<float>(m[c]);
        }
        file.write(row.data(), row.size() * sizeof(float));
      }
      file.commit();
      return;
    }
    case ImageFormat::Png: {
      // Tone-mapped straight from the film (3 bytes a pixel, not a float image
      // first), and stb's encoded file goes to disk without another copy.
      const std::size_t pixels = film.pixel_count();
      std::vector<std::uint8_t> bytes(3 * pixels);
      for (std::size_t p = 0; p < pixels; ++p) {
        double m[3];
        film.mean(p, m);
        for (std::size_t c = 0; c < 3; ++c) bytes[3 * p + c] = tone_map_channel(static_cast<float>(m[c]), transfer);
      }
      struct Sink {
        AtomicFile file;
        std::exception_ptr error;
      } sink{AtomicFile(path), nullptr};
      const auto put = [](void* context, void* data, int size) {
        auto* s = static_cast<Sink*>(context);
        try {  // no exception may cross stb's C frames
          if (!s->error) s->file.write(data, static_cast<std::size_t>(size));
        } catch (...) {
          s->error = std::current_exception();
        }
      };
      if (!stbi_write_png_to_func(put, &sink, w, h, 3, bytes.data(), w * 3)) throw IoError("PNG encoding failed");
      if (sink.error) std::rethrow_exception(sink.error);
      sink.file.commit();
      return;
    }
    case ImageFormat::Hdr: write_image(path, film.mean_rgb(), w, h, transfer); return;
  }
}

std::vector<float> read_image_linear(const std::string& path, int& width, int& height) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".exr") return read_exr(path, width, height);
  return read_pfm(path, width, height);  // which says what else is wrong
}

std::vector<float> read_pfm(const std::string& path, int& width, int& height) {
  check_input_file(path, "image");  // a folder, a pipe or a device is refused before it is opened as a stream
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("cannot read '" + path + "': " + std::strerror(errno));
  std::string magic;
  double scale = 0.0;
  long w = 0, h = 0;
  in >> magic >> w >> h >> scale;
  if (!in || magic != "PF" || w <= 0 || h <= 0 || w > kMaxImageSide || h > kMaxImageSide || scale == 0.0)
    throw InputError("'" + path + "' is not a colour PFM image (expected 'PF', width, height, scale)");
  if (const std::string problem = image_size_problem(w, h); !problem.empty())
    throw InputError("'" + path + "': " + problem);
  in.get();  // the single whitespace byte after the scale
  // A header can claim any size: compare with the file before allocating.
  const std::streamoff data_start = in.tellg();
  in.seekg(0, std::ios::end);
  const std::streamoff file_size = in.tellg();
  in.seekg(data_start);
  const auto needed = static_cast<std::streamoff>(w) * h * 3 * static_cast<std::streamoff>(sizeof(float));
  if (data_start < 0 || file_size < 0 || file_size - data_start < needed)
    throw InputError("'" + path + "': PFM data is truncated (the header says " + std::to_string(w) + "x" +
                     std::to_string(h) + ")");
  width = static_cast<int>(w);
  height = static_cast<int>(h);
  const std::size_t row = static_cast<std::size_t>(w) * 3;
  std::vector<float> rgb(row * static_cast<std::size_t>(h));
  for (long y = h - 1; y >= 0; --y) {
    in.read(reinterpret_cast<char*>(rgb.data() + static_cast<std::size_t>(y) * row),
            static_cast<std::streamsize>(row * sizeof(float)));
    if (!in) throw InputError("'" + path + "': PFM data is truncated");
  }
  if (scale > 0.0) {  // big-endian file
    for (float& f : rgb) {
      std::uint32_t u;
      std::memcpy(&u, &f, 4);
      u = __builtin_bswap32(u);
      std::memcpy(&f, &u, 4);
    }
  }
  return rgb;
}

}  // namespace pdflab
