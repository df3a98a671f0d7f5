#pragma once
#include <stdexcept>
#include <string>

namespace pdflab {

// Bad input from the user (scene file, strategy string, command line, output path).
// The command line turns it into one message and exit status 2.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A failure of the environment while doing something valid (disk full, I/O error).
class IoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace pdflab
