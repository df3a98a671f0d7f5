#pragma once
// Image files. Every writer goes through write_file_atomic: a temporary file in
// the same folder, then rename, so a crash or a full disk never leaves half a file.
#include <cstdint>
#include <cstdio>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace pdflab {

enum class ImageFormat { Png, Pfm, Hdr, Exr };
enum class Transfer { Gamma2, Srgb };  // Gamma2: the book's sqrt

// From the extension (case-insensitive). Throws InputError naming the path.
ImageFormat image_format_for(const std::string& path);

// Throws InputError when the folder of `path` does not exist or is not writable.
void check_output_path(const std::string& path);

// Throws InputError when two of `paths` (empty ones ignored) name the same
// file: the second write would replace the first.
void check_distinct_outputs(const std::vector<std::string>& paths);

// Throws IoError (with the path and the system's reason) on failure; the target
// is then untouched.
void write_file_atomic(const std::string& path, std::span<const std::uint8_t> bytes);

// A file written piece by piece under a temporary name in the target's folder
// and renamed over the target by commit(): for files too large to build in
// memory first. Destroyed without commit(), it removes the temporary file and
// the target stays as it was. Every failure throws IoError naming the target.
class AtomicFile {
 public:
  explicit AtomicFile(const std::string& path);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  void write(const void* data, std::size_t size);
  // For a library that writes the temporary file by name itself (OpenEXR):
  // closes this object's stream; commit() then only syncs and renames.
  const std::string& release_to_writer();
  // Flushes, syncs to disk, closes and renames.
  void commit();
  const std::string& path() const { return path_; }

 private:
  [[noreturn]] void fail(int error);
  std::string path_, temp_;
  std::FILE* file_ = nullptr;
  bool committed_ = false;
};

// Linear float RGB, row 0 at the top.
std::vector<std::uint8_t> encode_png(const std::vector<float>& rgb, int width, int height, Transfer transfer,
                                     float exposure = 1.0f);
std::vector<std::uint8_t> encode_pfm(const std::vector<float>& rgb, int width, int height);
std::vector<std::uint8_t> encode_hdr(const std::vector<float>& rgb, int width, int height);

// Tone-maps and writes in the format named by the extension.
void write_image(const std::string& path, const std::vector<float>& rgb, int width, int height,
                 Transfer transfer = Transfer::Gamma2);

class Film;
// The film's mean in the format named by the extension, streamed from the film
// where the format allows (PFM and EXR hold no image-sized buffer besides the
// film; EXR adds the variance-of-the-mean and count layers and the attributes).
void write_film_image(const std::string& path, const Film& film, Transfer transfer = Transfer::Gamma2,
                      const std::vector<std::pair<std::string, std::string>>& attributes = {});

// A reference image: EXR by the extension, otherwise PFM; mean RGB with row 0
// at the top. Throws InputError naming the file for anything else.
std::vector<float> read_image_linear(const std::string& path, int& width, int& height);

// Reads a PFM written by encode_pfm (or any little/big-endian colour PFM).
// Throws InputError on a malformed file.
std::vector<float> read_pfm(const std::string& path, int& width, int& height);

// 8-bit value of a linear channel as the PNG writer maps it.
std::uint8_t tone_map_channel(float linear, Transfer transfer, float exposure = 1.0f);

}  // namespace pdflab
