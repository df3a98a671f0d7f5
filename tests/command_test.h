#pragma once
// The fixture the command-line tests of bench and sweep share: a workspace of
// their own, the binary run in it, the bad-input check (exit 2, a message
// naming the problem, nothing written) and a small reference of the book's box.
#include "tests/support.h"

#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

namespace pdflab::testing {

// A PNG file's width and height, from its IHDR; (0, 0) where it is no PNG.
inline std::pair<unsigned, unsigned> png_size(const std::string& png) {
  if (png.size() < 24 || png.substr(1, 3) != "PNG") return {0u, 0u};
  const auto be32 = [&](std::size_t at) {
    unsigned v = 0;
    for (std::size_t i = 0; i < 4; ++i) v = (v << 8) | static_cast<unsigned char>(png[at + i]);
    return v;
  };
  return {be32(16), be32(20)};
}

class CommandTest : public ::testing::Test {
 protected:
  explicit CommandTest(const std::string& prefix) : ws_(prefix) {}

  std::filesystem::path work() const { return ws_.work(); }
  std::string in_work(const std::string& name) const { return ws_.in_work(name); }
  std::vector<std::string> work_entries() const { return ws_.work_entries(); }
  ChildResult run(const std::vector<std::string>& args) const {
    const ChildResult r = ws_.run(args);
    if (!r.started) ADD_FAILURE() << "could not start " << PDFLAB_BINARY;
    return r;
  }

  // A 12x8 reference of the book's box (non-square, so a swapped width and
  // height would show), rendered with `strategy`.
  void render_reference(const std::string& strategy, const std::string& name = "ref.pfm") const {
    const ChildResult r =
        run({"render", "--scene", std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes/cornell_book.json", "--strategy",
             strategy, "--spp", "256", "--width", "12", "--height", "8", "--threads", "2", "--quiet", "--out",
             in_work(name)});
    ASSERT_EQ(r.status, 0) << r.err;
  }

  // Exit 2, one message containing `needle`, and the work folder as it was.
  void expect_bad_input(const std::vector<std::string>& args, const std::string& needle) const {
    const std::vector<std::string> before = work_entries();
    const ChildResult r = run(args);
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_NE(r.err.find("error"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << "message lacks '" << needle << "': " << r.err;
    EXPECT_EQ(r.err.find("internal"), std::string::npos) << r.err;
    EXPECT_EQ(work_entries(), before) << "bad input left files behind";
  }

 private:
  CommandWorkspace ws_;
};

}  // namespace pdflab::testing
