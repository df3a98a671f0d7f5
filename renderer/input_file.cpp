#include "renderer/input_file.h"

#include "renderer/error.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace pdflab {

namespace {

[[noreturn]] void refuse(const std::string& path, const std::string& what, const std::string& reason) {
  throw InputError("cannot read " + what + " '" + path + "': " + reason);
}

// What stands at `st` when it is not a file pdflab can read; empty when it is.
std::string not_readable(const struct stat& st, InputKind kind) {
  if (S_ISREG(st.st_mode)) return {};
  if (S_ISDIR(st.st_mode)) return "it is a folder, not a file";
  if (S_ISFIFO(st.st_mode)) return "it is a pipe (FIFO), not a file; give the file itself";
  if (S_ISSOCK(st.st_mode)) return "it is a socket, not a file";
  if (S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode))
    return kind == InputKind::FileOrDevice ? std::string() : "it is a device, not a file";
  return "it is not a regular file";
}

int open_checked(const std::string& path, const std::string& what, InputKind kind, std::uint64_t* size) {
  // O_NONBLOCK: opening a FIFO for reading returns at once instead of waiting
  // for a writer; it is then refused by its type.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) refuse(path, what, std::strerror(errno));
  struct stat st{};
  if (::fstat(fd, &st) != 0) {
    const int e = errno;
    ::close(fd);
    refuse(path, what, std::strerror(e));
  }
  if (const std::string problem = not_readable(st, kind); !problem.empty()) {
    ::close(fd);
    refuse(path, what, problem);
  }
  // Reads block as usual from here on (a regular file or a device).
  const int flags = ::fcntl(fd, F_GETFL);
  if (flags < 0 || ::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) != 0) {
    const int e = errno;
    ::close(fd);
    refuse(path, what, std::strerror(e));
  }
  if (size) *size = S_ISREG(st.st_mode) ? static_cast<std::uint64_t>(st.st_size) : 0;
  return fd;
}

}  // namespace

std::FILE* open_input_file(const std::string& path, const std::string& what, InputKind kind, std::uint64_t* size) {
  const int fd = open_checked(path, what, kind, size);
  std::FILE* f = ::fdopen(fd, "rb");
  if (!f) {
    const int e = errno;
    ::close(fd);
    refuse(path, what, std::strerror(e));
  }
  return f;
}

void check_input_file(const std::string& path, const std::string& what) {
  ::close(open_checked(path, what, InputKind::RegularFile, nullptr));
}

std::string read_input_file(const std::string& path, const std::string& what, std::size_t max_bytes) {
  std::uint64_t size = 0;
  std::FILE* f = open_input_file(path, what, InputKind::RegularFile, &size);
  if (size > max_bytes) {
    std::fclose(f);
    refuse(path, what, "larger than " + std::to_string(max_bytes) + " bytes");
  }
  std::string text(static_cast<std::size_t>(size), '\0');
  const std::size_t got = text.empty() ? 0 : std::fread(text.data(), 1, text.size(), f);
  const bool failed = std::ferror(f) != 0;
  std::fclose(f);
  if (failed) refuse(path, what, "read error");
  text.resize(got);
  return text;
}

}  // namespace pdflab
