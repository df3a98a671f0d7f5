#pragma once
#include <stdexcept>
#include <string>
#include <string_view>

namespace pdflab {

// Text bound for a terminal: control bytes (NUL, ESC, a newline...) and bytes
// that are not well-formed UTF-8 become \xNN; printable ASCII and valid UTF-8
// stay as they are. Idempotent. Every message that quotes what a user or a
// file supplied (a key, a path, a film's strategy) goes through it, so the
// message stays one line and cannot be cut by a NUL or steer the terminal.
std::string printable(std::string_view text);

// Bad input from the user (scene file, strategy string, command line, output path).
// The command line turns it into one message and exit status 2. The message is
// made printable() here, whatever it quotes.
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& what) : std::runtime_error(printable(what)) {}
  explicit InputError(const char* what) : InputError(std::string(what)) {}
};

// A failure of the environment while doing something valid (disk full, I/O error).
class IoError : public std::runtime_error {
 public:
  explicit IoError(const std::string& what) : std::runtime_error(printable(what)) {}
  explicit IoError(const char* what) : IoError(std::string(what)) {}
};

}  // namespace pdflab
