#pragma once
// 64-bit FNV-1a: file checksums and cache keys (not security).
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

namespace pdflab {

inline std::uint64_t fnv1a64(const void* data, std::size_t size, std::uint64_t hash = 0xcbf29ce484222325ULL) {
  const auto* bytes = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < size; ++i) {
    hash ^= bytes[i];
    hash *= 0x100000001b3ULL;
  }
  return hash;
}

// As 16 lower-case hex digits.
inline std::string fnv1a_hex(const void* data, std::size_t size) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(fnv1a64(data, size)));
  return text;
}

}  // namespace pdflab
