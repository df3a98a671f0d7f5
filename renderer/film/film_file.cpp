#include "renderer/film/film_file.h"

#include "renderer/error.h"
#include "renderer/film/image_io.h"
#include "renderer/input_file.h"
#include "renderer/scene/scene.h"

#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <sys/stat.h>

namespace pdflab {

static_assert(std::endian::native == std::endian::little, "film files store the host's little-endian numbers as they are");

namespace {

constexpr char kMagic[8] = {'P', 'D', 'F', 'L', 'F', 'I', 'L', 'M'};
constexpr std::size_t kMaxText = 4096;          // strategy and scene path
constexpr std::uint32_t kMaxRanges = 65536;
constexpr std::uint32_t kMaxHeaderBytes = 1u << 22;
constexpr std::size_t kPreambleBytes = 16;      // magic, version, header length
// Per pixel: 3 sums and 3 squares (f64), a count (u32), a drop mask (u8).
constexpr std::uint64_t kPayloadBytesPerPixel = 6 * 8 + 4 + 1;

std::string quoted(const std::string& name) { return "'" + name + "'"; }

// Little-endian fields into a byte string, and back out with bounds checks.
class HeaderWriter {
 public:
  void u32(std::uint32_t v) { raw(&v, 4); }
  void u64(std::uint64_t v) { raw(&v, 8); }
  void f64(double v) { raw(&v, 8); }
  void text(const std::string& s) {
    u32(static_cast<std::uint32_t>(s.size()));
    raw(s.data(), s.size());
  }
  void raw(const void* p, std::size_t n) {
    const auto* b = static_cast<const std::uint8_t*>(p);
    bytes.insert(bytes.end(), b, b + n);
  }
  std::vector<std::uint8_t> bytes;
};

class HeaderReader {
 public:
  HeaderReader(const std::uint8_t* data, std::size_t size, const std::string& name)
      : p_(data), end_(data + size), name_(name) {}
  std::uint32_t u32() { return take<std::uint32_t>(); }
  std::uint64_t u64() { return take<std::uint64_t>(); }
  double f64() { return take<double>(); }
  std::string text(const char* what) {
    const std::uint32_t n = u32();
    if (n > kMaxText) bad(std::string(what) + " is " + std::to_string(n) + " bytes long (at most " +
                          std::to_string(kMaxText) + ")");
    need(n);
    std::string s(reinterpret_cast<const char*>(p_), n);
    p_ += n;
    return s;
  }
  bool at_end() const { return p_ == end_; }
  [[noreturn]] void bad(const std::string& problem) const {
    throw InputError("film " + quoted(name_) + ": " + problem);
  }

 private:
  template <class T>
  T take() {
    need(sizeof(T));
    T v;
    std::memcpy(&v, p_, sizeof(T));
    p_ += sizeof(T);
    return v;
  }
  void need(std::size_t n) const {
    if (static_cast<std::size_t>(end_ - p_) < n) bad("the header ends before its last field (corrupt)");
  }
  const std::uint8_t* p_;
  const std::uint8_t* end_;
  const std::string& name_;
};

std::uint32_t crc(std::uint32_t state, const void* data, std::size_t n) {
  return static_cast<std::uint32_t>(crc32_z(state, static_cast<const Bytef*>(data), n));
}

std::vector<std::uint8_t> encode_header(const FilmInfo& info) {
  HeaderWriter h;
  h.u32(static_cast<std::uint32_t>(info.width));
  h.u32(static_cast<std::uint32_t>(info.height));
  h.u32(static_cast<std::uint32_t>(info.max_depth));
  h.u64(info.scene_hash);
  h.text(info.strategy);
  h.text(info.scene_file);
  h.u32(static_cast<std::uint32_t>(info.ranges.size()));
  for (const SampleRange& r : info.ranges) {
    h.u64(r.seed);
    h.u32(r.first);
    h.u32(r.end);
  }
  h.u32(static_cast<std::uint32_t>(kDropReasonCount));
  for (std::uint64_t d : info.dropped.by_reason) h.u64(d);
  h.f64(info.seconds);
  return h.bytes;
}

// Sorted by seed then first sample; touching ranges of one seed joined. False
// when two ranges of one seed overlap.
bool normalise_ranges(std::vector<SampleRange>& ranges) {
  std::sort(ranges.begin(), ranges.end(), [](const SampleRange& a, const SampleRange& b) {
    return a.seed != b.seed ? a.seed < b.seed : a.first < b.first;
  });
  std::vector<SampleRange> out;
  for (const SampleRange& r : ranges) {
    if (!out.empty() && out.back().seed == r.seed) {
      if (r.first < out.back().end) return false;
      if (r.first == out.back().end) {
        out.back().end = r.end;
        continue;
      }
    }
    out.push_back(r);
  }
  ranges = std::move(out);
  return true;
}

template <class T>
void read_array(std::FILE* f, std::vector<T>& v, std::uint32_t& state, const HeaderReader& h) {
  // In pieces, so a short read is noticed early and the checksum runs on warm data.
  constexpr std::size_t kPiece = 1 << 16;
  for (std::size_t i = 0; i < v.size(); i += kPiece) {
    const std::size_t n = std::min(kPiece, v.size() - i);
    if (std::fread(v.data() + i, sizeof(T), n, f) != n) h.bad("the data ends early (truncated)");
    state = crc(state, v.data() + i, n * sizeof(T));
  }
}

}  // namespace

std::uint64_t film_scene_hash(const Scene& scene) {
  if (scene.content_hash.empty()) return 0;
  return std::strtoull(scene.content_hash.c_str(), nullptr, 16);
}

std::vector<std::pair<std::string, std::string>> film_image_attributes(const FilmInfo& info, const std::string& version) {
  char hash[24];
  std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(info.scene_hash));
  std::vector<std::pair<std::string, std::string>> a = {{"pdflab.scene", info.scene_file},
                                                        {"pdflab.sceneHash", hash},
                                                        {"pdflab.strategy", info.strategy},
                                                        {"pdflab.spp", std::to_string(info.spp())},
                                                        {"pdflab.samples", info.ranges_text()},
                                                        {"pdflab.maxDepth", std::to_string(info.max_depth)},
                                                        {"pdflab.version", version}};
  // The seeds: a reference made from this image knows which random numbers
  // to avoid, also when it is a merge of several ranges or seeds.
  const std::vector<std::uint64_t> seeds = info.seeds();
  std::string list;
  for (std::uint64_t seed : seeds) {
    if (!list.empty()) list += ',';
    list += std::to_string(seed);
  }
  a.emplace_back("pdflab.seeds", list);
  if (seeds.size() == 1) a.emplace_back("pdflab.seed", list);
  return a;
}

std::vector<std::uint64_t> FilmInfo::seeds() const {
  std::vector<std::uint64_t> out;
  for (const SampleRange& r : ranges)
    if (std::find(out.begin(), out.end(), r.seed) == out.end()) out.push_back(r.seed);
  return out;
}

std::uint64_t FilmInfo::spp() const {
  std::uint64_t n = 0;
  for (const SampleRange& r : ranges) n += r.size();
  return n;
}

std::string FilmInfo::ranges_text() const {
  std::string s;
  for (const SampleRange& r : ranges) {
    if (!s.empty()) s += ", ";
    s += "seed " + std::to_string(r.seed) + " samples [" + std::to_string(r.first) + ", " + std::to_string(r.end) + ")";
  }
  return s.empty() ? "no samples" : s;
}

void write_film_file(const std::string& path, const FilmInfo& info, const Film& film) {
  if (film.width() != info.width || film.height() != info.height)
    throw std::invalid_argument("write_film_file: the film's size differs from its description");
  const std::vector<std::uint8_t> header = encode_header(info);
  AtomicFile file(path);
  std::uint8_t preamble[kPreambleBytes];
  std::memcpy(preamble, kMagic, 8);
  const std::uint32_t version = kFilmFormatVersion;
  const auto header_size = static_cast<std::uint32_t>(header.size());
  std::memcpy(preamble + 8, &version, 4);
  std::memcpy(preamble + 12, &header_size, 4);
  std::uint32_t state = crc(crc(0, preamble, sizeof preamble), header.data(), header.size());
  file.write(preamble, sizeof preamble);
  file.write(header.data(), header.size());
  file.write(&state, 4);

  // The data's CRC runs on from the header's: it covers the whole file, so a
  // header copied onto another film's data fails it.
  const auto put = [&](const auto& v) {
    const std::size_t bytes = v.size() * sizeof(v[0]);
    state = crc(state, v.data(), bytes);
    file.write(v.data(), bytes);
  };
  put(film.sums());
  put(film.squares());
  put(film.counts());
  put(film.drop_masks());
  file.write(&state, 4);
  file.commit();
}

FilmFile read_film_stream(std::FILE* f, std::uint64_t size, const std::string& name) {
  HeaderReader top(nullptr, 0, name);
  std::uint8_t preamble[kPreambleBytes] = {};
  const std::size_t got = std::fread(preamble, 1, kPreambleBytes, f);
  if (got >= 8 && std::memcmp(preamble, kMagic, 8) != 0) top.bad("not a pdflab film (no film signature)");
  if (got < kPreambleBytes || size < kPreambleBytes)
    top.bad("too short to be a pdflab film (" + std::to_string(size) + " bytes; truncated?)");
  if (std::memcmp(preamble, kMagic, 8) != 0) top.bad("not a pdflab film (no film signature)");
  std::uint32_t version = 0, header_size = 0;
  std::memcpy(&version, preamble + 8, 4);
  std::memcpy(&header_size, preamble + 12, 4);
  if (version != kFilmFormatVersion && version != 1)
    top.bad("film format version " + std::to_string(version) + "; this pdflab reads versions 1 and " +
            std::to_string(kFilmFormatVersion));
  if (header_size > kMaxHeaderBytes || kPreambleBytes + header_size + 4 > size)
    top.bad("the header ends after the end of the file (truncated or corrupt)");

  std::vector<std::uint8_t> header(header_size);
  std::uint32_t stored_crc = 0;
  if (std::fread(header.data(), 1, header.size(), f) != header.size() || std::fread(&stored_crc, 4, 1, f) != 1)
    top.bad("the header ends early (truncated)");
  if (crc(crc(0, preamble, sizeof preamble), header.data(), header.size()) != stored_crc)
    top.bad("the header's checksum does not match (corrupt)");

  HeaderReader h(header.data(), header.size(), name);
  FilmFile out;
  FilmInfo& info = out.info;
  const std::uint32_t width = h.u32(), height = h.u32(), depth = h.u32();
  if (const std::string problem = image_size_problem(width, height); !problem.empty()) h.bad(problem);
  if (depth < 1 || depth > 100000) h.bad("maximum depth " + std::to_string(depth) + " is outside 1..100000");
  info.width = static_cast<int>(width);
  info.height = static_cast<int>(height);
  info.max_depth = static_cast<int>(depth);
  info.scene_hash = h.u64();
  info.strategy = h.text("the strategy");
  info.scene_file = h.text("the scene path");
  const std::uint32_t range_count = h.u32();
  if (range_count < 1 || range_count > kMaxRanges)
    h.bad(std::to_string(range_count) + " sample ranges (1.." + std::to_string(kMaxRanges) + " expected)");
  for (std::uint32_t i = 0; i < range_count; ++i) {
    SampleRange r;
    r.seed = h.u64();
    r.first = h.u32();
    r.end = h.u32();
    if (r.end <= r.first) h.bad("sample range " + std::to_string(i) + " is empty or reversed (corrupt)");
    info.ranges.push_back(r);
  }
  if (!normalise_ranges(info.ranges)) h.bad("two of its sample ranges overlap (corrupt)");
  if (info.spp() > std::numeric_limits<std::uint32_t>::max()) h.bad("more samples per pixel than a count holds");
  if (h.u32() != static_cast<std::uint32_t>(kDropReasonCount)) h.bad("an unknown number of drop reasons (corrupt)");
  for (std::uint64_t& d : info.dropped.by_reason) d = h.u64();
  info.seconds = h.f64();
  if (!std::isfinite(info.seconds) || info.seconds < 0.0) h.bad("its render time is not a finite number >= 0");
  if (!h.at_end()) h.bad("the header is longer than its fields (corrupt)");

  const std::uint64_t pixels = std::uint64_t{width} * height;
  const std::uint64_t expected = kPreambleBytes + header_size + 4 + pixels * kPayloadBytesPerPixel + 4;
  if (size < expected)
    h.bad("truncated: " + std::to_string(size) + " bytes, its header promises " + std::to_string(expected));
  if (size > expected)
    h.bad(std::to_string(size - expected) + " bytes after the end of the film (corrupt or not a film)");

  // The size is now backed by the file itself: allocating is safe.
  Film& film = out.film;
  film.reset(info.width, info.height);
  // Version 1 checksummed the data alone; version 2 runs on from the header's.
  std::uint32_t state = version == 1 ? 0 : stored_crc;
  read_array(f, film.sums(), state, h);
  read_array(f, film.squares(), state, h);
  read_array(f, film.counts(), state, h);
  read_array(f, film.drop_masks(), state, h);
  if (std::fread(&stored_crc, 4, 1, f) != 1) h.bad("the data ends early (truncated)");
  if (state != stored_crc) h.bad("the data's checksum does not match (corrupt)");

  const auto spp = static_cast<std::uint32_t>(info.spp());
  for (std::size_t p = 0; p < film.pixel_count(); ++p) {
    if (film.counts()[p] != spp)
      h.bad("pixel " + std::to_string(p) + " holds " + std::to_string(film.counts()[p]) +
            " samples, its sample ranges say " + std::to_string(spp) + " (corrupt)");
    if (film.drop_masks()[p] >> kDropReasonCount) h.bad("pixel " + std::to_string(p) + " has unknown drop bits (corrupt)");
  }
  for (std::size_t i = 0; i < film.sums().size(); ++i)
    if (!std::isfinite(film.sums()[i]) || !std::isfinite(film.squares()[i]) || film.squares()[i] < 0.0)
      h.bad("value " + std::to_string(i) + " is not finite or a negative square (corrupt)");
  return out;
}

FilmFile read_film_file(const std::string& path) {
  std::uint64_t size = 0;
  std::FILE* f = open_input_file(path, "film", InputKind::RegularFile, &size);  // never waits on a pipe
  try {
    FilmFile out = read_film_stream(f, size, path);
    std::fclose(f);
    return out;
  } catch (...) {
    std::fclose(f);
    throw;
  }
}

std::string merge_problem(const std::string& a_name, const FilmInfo& a, const std::string& b_name, const FilmInfo& b) {
  const std::string both = "cannot merge " + quoted(b_name) + " with " + quoted(a_name) + ": ";
  const auto differ = [&](const std::string& what, const std::string& va, const std::string& vb) {
    return both + "they render different " + what + " (" + quoted(a_name) + ": " + va + ", " + quoted(b_name) +
           ": " + vb + ")";
  };
  if (a.scene_hash != b.scene_hash) {
    char ha[24], hb[24];
    std::snprintf(ha, sizeof ha, "%016llx", static_cast<unsigned long long>(a.scene_hash));
    std::snprintf(hb, sizeof hb, "%016llx", static_cast<unsigned long long>(b.scene_hash));
    return differ("scenes", a.scene_file + " content " + ha, b.scene_file + " content " + hb);
  }
  if (a.width != b.width || a.height != b.height)
    return differ("image sizes", std::to_string(a.width) + "x" + std::to_string(a.height),
                  std::to_string(b.width) + "x" + std::to_string(b.height));
  if (a.max_depth != b.max_depth)
    return differ("maximum depths", std::to_string(a.max_depth), std::to_string(b.max_depth));
  if (a.strategy != b.strategy) return differ("strategies", a.strategy, b.strategy);
  for (const SampleRange& ra : a.ranges)
    for (const SampleRange& rb : b.ranges)
      if (ra.seed == rb.seed && ra.first < rb.end && rb.first < ra.end)
        return both + "their sample ranges overlap, so those samples would be counted twice (" + quoted(a_name) +
               ": " + a.ranges_text() + "; " + quoted(b_name) + ": " + b.ranges_text() + ")";
  if (a.spp() + b.spp() > std::numeric_limits<std::uint32_t>::max())
    return both + "together they hold more samples per pixel than a count holds";
  return {};
}

FilmInfo merged_info(const FilmInfo& a, const FilmInfo& b) {
  FilmInfo out = a;
  out.ranges.insert(out.ranges.end(), b.ranges.begin(), b.ranges.end());
  if (!normalise_ranges(out.ranges)) throw std::invalid_argument("merged_info: overlapping ranges");
  out.dropped += b.dropped;
  out.seconds += b.seconds;
  return out;
}

}  // namespace pdflab
