#include "renderer/error.h"

#include <cstdio>

namespace pdflab {

// Messages go to a terminal: control bytes and invalid UTF-8 from a binary
// file or a JSON string (unknown key "\n...") become \xNN, valid UTF-8 stays.
std::string printable(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  const auto escape = [&](unsigned char c) {
    char buf[8];
    std::snprintf(buf, sizeof buf, "\\x%02X", c);
    out += buf;
  };
  for (std::size_t i = 0; i < s.size();) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
      ++i;
      continue;
    }
    // Length of a well-formed UTF-8 sequence starting here (0: none).
    std::size_t n = c >= 0xC2 && c <= 0xDF ? 2 : c >= 0xE0 && c <= 0xEF ? 3 : c >= 0xF0 && c <= 0xF4 ? 4 : 0;
    if (n > 0 && i + n <= s.size()) {
      for (std::size_t k = 1; k < n; ++k)
        if ((static_cast<unsigned char>(s[i + k]) & 0xC0) != 0x80) n = 0;
      // Overlong three- and four-byte forms, surrogates and code points past U+10FFFF.
      const auto c1 = n > 0 ? static_cast<unsigned char>(s[i + 1]) : 0;
      if ((c == 0xE0 && c1 < 0xA0) || (c == 0xED && c1 >= 0xA0) || (c == 0xF0 && c1 < 0x90) || (c == 0xF4 && c1 >= 0x90))
        n = 0;
    } else {
      n = 0;
    }
    if (n == 0) {
      escape(c);
      ++i;
    } else {
      out.append(s.substr(i, n));
      i += n;
    }
  }
  return out;
}

}  // namespace pdflab
