// Regression inputs for the scene loader: every file in tests/fuzz_regressions/
// once broke the loader's contract. scripts/fuzz.sh leaves each crash it finds
// in build/fuzz/crashes/; copy it here (any name) and this test keeps it fixed:
// the input must be refused with an InputError (no other exception, no crash
// under the sanitizer builds) whose message starts with the origin and is one
// printable line.
//
// The first two came from the malformed-input work, not from the fuzzer (which
// has found no crash so far): their messages carried a raw byte of invalid
// UTF-8 and a raw newline from the JSON key into the terminal. The fuzz target
// checks the same property of every message.
#include "renderer/error.h"
#include "renderer/scene/scene_loader.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace pdflab {
namespace {

namespace fs = std::filesystem;

TEST(FuzzRegressions, EveryInputIsRefusedWithAPrintableMessage) {
  const fs::path dir = fs::path(PDFLAB_SOURCE_DIR) / "tests" / "fuzz_regressions";
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_regular_file()) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  ASSERT_FALSE(files.empty()) << "no regression inputs in " << dir;

  for (const fs::path& file : files) {
    SCOPED_TRACE(file.filename().string());
    std::ifstream in(file, std::ios::binary);
    const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    const std::string origin = file.filename().string();
    try {
      (void)load_scene_text(text, origin);
      ADD_FAILURE() << "loaded without an error";
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_EQ(message.rfind(origin + ": ", 0), 0u) << message;
      EXPECT_TRUE(std::all_of(message.begin(), message.end(),
                              [](char c) { return static_cast<unsigned char>(c) >= 0x20 && c != 0x7f; }))
          << "unprintable byte in: " << message;
    }
  }
}

}  // namespace
}  // namespace pdflab
