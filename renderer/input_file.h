#pragma once
// Files pdflab reads (scenes, films, references and their sidecars) are
// opened without blocking and checked for what they are before a byte is
// read: a named pipe (FIFO) given by mistake would otherwise hold open() until
// some other program wrote to it, forever on a command line or a batch job.
#include <cstdint>
#include <cstdio>
#include <string>

namespace pdflab {

enum class InputKind {
  RegularFile,      // a file whose size is known: films, images, sidecars
  FileOrDevice,     // also a character or block device (/dev/zero is bounded by the reader's limit)
};

// Opens `path` for reading in blocking mode once it is known to be a file of
// `kind`. Throws InputError "cannot read WHAT 'PATH': REASON" (a folder, a
// pipe, a socket, a device where a file is needed, or the system's reason).
// `size` receives the file's size (0 for a device). The caller closes it.
std::FILE* open_input_file(const std::string& path, const std::string& what, InputKind kind = InputKind::RegularFile,
                           std::uint64_t* size = nullptr);

// The same checks for a library that opens the file by name itself (OpenEXR):
// opened, checked and closed again.
void check_input_file(const std::string& path, const std::string& what);

// The whole of a regular file of at most `max_bytes` (InputError beyond).
std::string read_input_file(const std::string& path, const std::string& what, std::size_t max_bytes);

}  // namespace pdflab
