#pragma once
// Film files: a render's whole accumulation (sums, squares, counts, drop masks)
// with what it is an estimate of (scene, size, depth, strategy) and which
// samples it holds (seed and sample-index ranges), so a render can be resumed
// and renders of disjoint ranges merged. The format is docs/film_format.md.
#include "renderer/film/film.h"
#include "renderer/integrator/integrator.h"

#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace pdflab {

// Version 2: the data's checksum continues the header's, so a header cannot be
// put on another film's data unnoticed. Version 1 files are still read.
inline constexpr std::uint32_t kFilmFormatVersion = 2;

// Samples first .. end - 1 of the sequence of `seed`, in every pixel.
struct SampleRange {
  std::uint64_t seed = 0;
  std::uint32_t first = 0, end = 0;
  std::uint32_t size() const { return end - first; }
  bool operator==(const SampleRange&) const = default;
};

struct FilmInfo {
  std::uint64_t scene_hash = 0;  // film_scene_hash
  std::string scene_file;        // where the scene was read from: for messages and --resume
  int width = 0, height = 0, max_depth = 0;
  std::string strategy;          // Strategy::to_string()
  // Disjoint for each seed; a render writes one, a merge keeps them all
  // (sorted by seed then first sample, touching ranges joined).
  std::vector<SampleRange> ranges;
  DropCounts dropped;            // samples dropped as invalid, by reason
  double seconds = 0.0;          // rendering time, summed over merged films

  // Samples per pixel: the sum of the ranges' sizes.
  std::uint64_t spp() const;
  // "seed 1 samples [0, 64)", ranges separated by ", ".
  std::string ranges_text() const;
  // Every seed of its ranges, once each, in order.
  std::vector<std::uint64_t> seeds() const;
};

struct Scene;
// Scene::content_hash (the reference cache's key: the scene file's content
// without size, depth and description, scene_loader.cpp) as a number; 0 for a
// scene built in code.
std::uint64_t film_scene_hash(const Scene& scene);

struct FilmFile {
  FilmInfo info;
  Film film;
};

// Writes atomically (temporary file, then rename), streaming the film without
// another copy of it in memory. Throws IoError with the path and the reason.
void write_film_file(const std::string& path, const FilmInfo& info, const Film& film);

// Throws InputError naming `path` and the problem when the file is not a
// pdflab film, is of another format version, is truncated or longer than its
// header says, fails a checksum or holds inconsistent values. Never allocates
// more than the file's own size justifies.
FilmFile read_film_file(const std::string& path);
// The same from an open stream of `size` bytes (the fuzzer reads from memory).
FilmFile read_film_stream(std::FILE* stream, std::uint64_t size, const std::string& name);

// What an image's header (EXR's attributes) says about the estimate in it:
// scene, its hash, strategy, spp, sample ranges, depth, `version`, and the
// seed when there is one (a reference made from the image knows which random
// numbers to avoid).
std::vector<std::pair<std::string, std::string>> film_image_attributes(const FilmInfo& info, const std::string& version);

// Empty when film `b` may be added to film `a`: the same scene, size, depth and
// strategy, and no sample of one seed in both. Otherwise one sentence naming
// both files and what differs.
std::string merge_problem(const std::string& a_name, const FilmInfo& a, const std::string& b_name, const FilmInfo& b);
// `a` with `b`'s ranges, drops and time added (merge_problem must be empty).
FilmInfo merged_info(const FilmInfo& a, const FilmInfo& b);

}  // namespace pdflab
