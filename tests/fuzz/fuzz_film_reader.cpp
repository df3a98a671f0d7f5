// libFuzzer target for the film-file reader (scripts/fuzz.sh builds and runs
// it). Any input must either read or be refused with an InputError naming the
// file; any other exception, a sanitizer report, a hang, an allocation beyond
// the input's size, or a film that reads but breaks what merge and resume rely
// on is a finding. Each input is read twice: as it is, and with its two CRC-32
// fields recomputed (the second, in version 2, running on from the first), so
// that mutations reach the checks behind the checksums.
#include "renderer/error.h"
#include "renderer/film/film_file.h"

#include <zlib.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

namespace {

[[noreturn]] void broken(const char* what) {
  std::fprintf(stderr, "fuzz_film_reader: invariant broken: %s\n", what);
  std::abort();
}

void read_once(const std::uint8_t* data, std::size_t size) {
  // fmemopen refuses a zero-sized buffer; an empty file is one byte of nothing.
  static const std::uint8_t empty = 0;
  std::FILE* f = fmemopen(const_cast<std::uint8_t*>(size ? data : &empty), size ? size : 1, "rb");
  if (!f) return;
  try {
    const pdflab::FilmFile film = pdflab::read_film_stream(f, size, "fuzz.film");
    const pdflab::FilmInfo& info = film.info;
    if (film.film.width() != info.width || film.film.height() != info.height) broken("film size differs from header");
    if (info.ranges.empty()) broken("a film without samples");
    for (std::size_t p = 0; p < film.film.pixel_count(); ++p)
      if (film.film.count(p) != info.spp()) broken("a count differs from the ranges");
    // A film read back must merge with itself only as an overlap.
    if (pdflab::merge_problem("a", info, "b", info).empty()) broken("a film merges with itself");
  } catch (const pdflab::InputError& e) {
    if (std::string(e.what()).find("'fuzz.film'") == std::string::npos) broken("message does not name the file");
  }
  std::fclose(f);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  read_once(data, size);
  // The same bytes with valid checksums (layout: docs/film_format.md).
  if (size < 24) return 0;
  std::uint32_t header = 0;
  std::memcpy(&header, data + 12, 4);
  if (header > size - 24) return 0;
  std::vector<std::uint8_t> fixed(data, data + size);
  const std::size_t header_end = 16 + header;
  const auto head_crc = static_cast<std::uint32_t>(crc32_z(0, fixed.data(), header_end));
  std::memcpy(fixed.data() + header_end, &head_crc, 4);
  const std::size_t payload = header_end + 4;
  // Version 1 checksums the data alone; version 2 runs on from the header's CRC.
  std::uint32_t version = 0;
  std::memcpy(&version, data + 8, 4);
  const auto data_crc = static_cast<std::uint32_t>(
      crc32_z(version == 1 ? 0 : head_crc, fixed.data() + payload, size - payload - 4));
  std::memcpy(fixed.data() + size - 4, &data_crc, 4);
  read_once(fixed.data(), fixed.size());
  return 0;
}
