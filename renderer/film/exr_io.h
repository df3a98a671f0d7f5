#pragma once
// OpenEXR files (the OpenEXR library, Debian's libopenexr-dev): the HDR format
// that tev, pbrt and Mitsuba read and write.
#include "renderer/film/film.h"

#include <string>
#include <utility>
#include <vector>

namespace pdflab {

// Text attributes stored in the header (strategy, spp, seed, ...).
using ImageAttributes = std::vector<std::pair<std::string, std::string>>;

// A film as a scanline EXR: R, G, B (the mean, 32-bit float), variance.R,
// variance.G, variance.B (the variance of the mean, 32-bit float) and count
// (samples in the pixel, 32-bit float: exact up to 2^24), ZIP-compressed, written 16 rows at
// a time so that no image-sized buffer exists besides the film. Atomic
// (temporary file, then rename); IoError on failure.
void write_exr(const std::string& path, const Film& film, const ImageAttributes& attributes = {});
// An RGB image (row 0 at the top) as an EXR with R, G, B only.
void write_exr(const std::string& path, const std::vector<float>& rgb, int width, int height,
               const ImageAttributes& attributes = {});

// R, G and B of any EXR as float RGB, row 0 at the top (a file without all
// three is refused, naming those missing). InputError naming the file and the
// library's reason for anything it cannot read.
std::vector<float> read_exr(const std::string& path, int& width, int& height);

// The variance.R, variance.G and variance.B layers (as write_exr(film) writes
// them) as float RGB, or empty when the file has none of them; InputError
// when it has some but not all.
std::vector<float> read_exr_variance(const std::string& path);

// The named string attribute of an EXR file, or empty when it has none.
std::string read_exr_attribute(const std::string& path, const std::string& name);

}  // namespace pdflab
