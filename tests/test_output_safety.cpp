// Output safety through the real binary: a full disk is an internal failure
// (status 1) with a message naming the file and the system's reason, and the
// files that were there before stay byte for byte as they were, with no
// temporary left behind; an unwritable folder is bad input (status 2) refused
// before rendering.
//
// The full disk is a 64 KiB tmpfs when the test may mount one (root with
// CAP_SYS_ADMIN, as in CI); otherwise the child gets a 64 KiB file size limit
// (RLIMIT_FSIZE), whose EFBIG takes the same path through the writer as ENOSPC.
#include "tests/support.h"

#include <gtest/gtest.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

namespace pdflab {
namespace {

namespace fs = std::filesystem;
using pdflab::testing::ChildOptions;
using pdflab::testing::ChildResult;
using pdflab::testing::listing;
using pdflab::testing::run_pdflab;
using pdflab::testing::slurp;

const std::string kBookScene = std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes/cornell_book.json";
constexpr long long kDiskBytes = 64 * 1024;

class OutputSafety : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "pdflab-output-XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    root_ = pattern;
    fs::create_directory(disk());
    fs::create_directory(root_ / "io");
    // PDFLAB_TEST_NO_MOUNT=1 tries the fallback where mounting would work.
    const char* no_mount = std::getenv("PDFLAB_TEST_NO_MOUNT");
    mounted_ = !(no_mount && *no_mount) && ::mount("tmpfs", disk().c_str(), "tmpfs", 0, "size=64k") == 0;
    std::printf("full disk simulated by %s\n", mounted_ ? "a 64 KiB tmpfs" : "RLIMIT_FSIZE = 64 KiB (cannot mount here)");
  }
  void TearDown() override {
    if (mounted_) ::umount(disk().c_str());
    std::error_code ec;
    fs::remove_all(root_, ec);
  }

  fs::path disk() const { return root_ / "disk"; }

  // `limited`: apply the file size limit when there is no tmpfs.
  ChildResult render(const std::string& out, int size, bool limited, std::vector<std::string> extra = {}) const {
    std::vector<std::string> args = {"render", "--scene", kBookScene, "--strategy", "cosine", "--spp", "1",
                                     "--out", out, "--width", std::to_string(size), "--height",
                                     std::to_string(size), "--threads", "2", "--quiet"};
    args.insert(args.end(), extra.begin(), extra.end());
    ChildOptions o;
    o.cwd = root_;
    o.capture = root_ / "io";
    o.deadline_seconds = 60.0;
    if (limited && !mounted_) o.file_size_limit = kDiskBytes;
    return run_pdflab(args, o);
  }

  fs::path root_;
  bool mounted_ = false;
};

TEST_F(OutputSafety, FullDiskIsAnErrorAndEarlierFilesSurvive) {
  // Earlier results: a small image and its stats (a few KiB, well within the disk).
  const std::string old_image = (disk() / "old.pfm").string();
  const std::string old_stats = (disk() / "old.json").string();
  ChildResult r = render(old_image, 8, false, {"--stats-json", old_stats});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string image_bytes = slurp(old_image);
  const std::string stats_bytes = slurp(old_stats);
  ASSERT_EQ(image_bytes.size(), 12u + 8u * 8u * 12u);  // "PF\n8 8\n-1.0\n" and the floats

  // 128 x 128 PFM is 196 KiB: more than the disk holds. Once as a new file,
  // once replacing the old image, once with the stats after it.
  const std::vector<std::vector<std::string>> attempts = {
      {(disk() / "new.pfm").string()},
      {old_image},
      {(disk() / "new.pfm").string(), "--stats-json", old_stats},
  };
  for (const auto& attempt : attempts) {
    const std::string& target = attempt[0];
    SCOPED_TRACE("--out " + target + (attempt.size() > 1 ? " --stats-json" : ""));
    r = render(target, 128, true, std::vector<std::string>(attempt.begin() + 1, attempt.end()));
    ASSERT_TRUE(r.exited) << "killed by a signal:\n" << r.err;
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_EQ(r.err.rfind("pdflab: error: cannot write '" + target + "': ", 0), 0u) << r.err;
    const char* reason = mounted_ ? std::strerror(ENOSPC) : std::strerror(EFBIG);
    EXPECT_NE(r.err.find(reason), std::string::npos) << "no '" << reason << "' in:\n" << r.err;
    EXPECT_EQ(r.out, "") << "a failed render printed a summary";
    EXPECT_EQ(slurp(old_image), image_bytes) << "the earlier image changed";
    EXPECT_EQ(slurp(old_stats), stats_bytes) << "the earlier stats changed";
    EXPECT_EQ(listing(disk()), (std::vector<std::string>{"old.json", "old.pfm"})) << "a temporary was left behind";
  }

  // The disk still works for what fits.
  r = render((disk() / "small.png").string(), 8, true);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(listing(disk()), (std::vector<std::string>{"old.json", "old.pfm", "small.png"}));
}

TEST_F(OutputSafety, UnwritableFolderIsBadInput) {
  fs::path folder;
  if (mounted_) {
    // Read-only for everyone, root included.
    ASSERT_EQ(::mount("tmpfs", disk().c_str(), "tmpfs", MS_REMOUNT | MS_RDONLY, "size=64k"), 0) << std::strerror(errno);
    folder = disk();
  } else if (::geteuid() != 0) {
    folder = root_ / "locked";
    fs::create_directory(folder);
    fs::permissions(folder, fs::perms::owner_read | fs::perms::owner_exec);
  } else {
    GTEST_SKIP() << "root without mount(2): no folder refuses root's writes here";
  }
  for (const std::string& out : {(folder / "image.png").string(), (folder / "image.pfm").string()}) {
    const ChildResult r = render(out, 8, false);
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_NE(r.err.find("is not writable"), std::string::npos) << r.err;
    EXPECT_EQ(r.out, "");
  }
  EXPECT_TRUE(listing(folder).empty());
}

}  // namespace
}  // namespace pdflab
