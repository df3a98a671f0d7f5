// Film statistics against hand computations, and the image files: PFM exact
// round trip and row order, PNG size and tone curve, atomic writes that never
// leave a temporary behind or damage an existing file.
#include "renderer/error.h"
#include "renderer/film/film.h"
#include "renderer/film/image_io.h"

#include "tests/support.h"

#include <gtest/gtest.h>
#include <stb_image.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <stdexcept>
#include <span>
#include <string>
#include <vector>

namespace pdflab {
namespace {

namespace fs = std::filesystem;

using testing::TempDir;

std::vector<std::uint8_t> read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_text(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

std::string read_text(const std::string& path) {
  const auto b = read_bytes(path);
  return {b.begin(), b.end()};
}

// ---- Film ---------------------------------------------------------------------

TEST(Film, MeanAndVarianceOfMeanByHand) {
  Film film(2, 1);
  // Pixel 0, red: 1, 2, 3, 4 -> mean 2.5, sample variance 5/3, variance of the mean 5/12.
  // Green: constant 7 -> variance 0. Blue: 0, 10, 0, 10 -> mean 5, s^2 = 100/3, /4.
  const Vec3 values[4] = {{1, 7, 0}, {2, 7, 10}, {3, 7, 0}, {4, 7, 10}};
  for (const Vec3& v : values) film.add(0, v);
  EXPECT_EQ(film.count(0), 4u);
  EXPECT_EQ(film.count(1), 0u);
  double m[3], var[3];
  film.mean(0, m);
  EXPECT_DOUBLE_EQ(m[0], 2.5);
  EXPECT_DOUBLE_EQ(m[1], 7.0);
  EXPECT_DOUBLE_EQ(m[2], 5.0);
  film.variance_of_mean(0, var);
  EXPECT_NEAR(var[0], 5.0 / 12.0, 1e-12);
  EXPECT_EQ(var[1], 0.0);
  EXPECT_NEAR(var[2], 100.0 / 12.0, 1e-12);

  // An empty pixel has mean 0 and no variance; one sample has no variance either.
  film.mean(1, m);
  EXPECT_EQ(m[0], 0.0);
  film.add(1, Vec3(3.0f));
  film.variance_of_mean(1, var);
  EXPECT_EQ(var[0], 0.0);
  film.mean(1, m);
  EXPECT_EQ(m[2], 3.0);
}

TEST(Film, VarianceSurvivesALargeMean) {
  // Radiance of a bright light with small noise: the spread must not drown in
  // the mean. 1000 + {1, 2, 3, 4}: variance of the mean is still 5/12.
  Film film(1, 1);
  for (int i = 1; i <= 4; ++i) film.add(0, Vec3(1000.0f + static_cast<float>(i)));
  double var[3];
  film.variance_of_mean(0, var);
  EXPECT_NEAR(var[0], 5.0 / 12.0, 1e-6);
}

TEST(Film, MeanImageIsRowMajorFromTheTop) {
  Film film(3, 2);
  for (std::size_t p = 0; p < film.pixel_count(); ++p) {
    film.add(p, Vec3(static_cast<float>(p)));
    film.add(p, Vec3(static_cast<float>(p) + 2.0f));
  }
  const std::vector<float> rgb = film.mean_rgb();
  ASSERT_EQ(rgb.size(), 18u);
  for (std::size_t p = 0; p < 6; ++p) EXPECT_EQ(rgb[3 * p + 1], static_cast<float>(p) + 1.0f);

  film.clear();
  EXPECT_EQ(film.count(4), 0u);
  EXPECT_EQ(film.mean_rgb()[12], 0.0f);
}

// ---- PFM --------------------------------------------------------------------------

std::vector<float> test_pattern(int width, int height) {
  std::vector<float> rgb(static_cast<std::size_t>(width) * height * 3);
  for (std::size_t i = 0; i < rgb.size(); ++i) rgb[i] = static_cast<float>(i) * 0.1f + 0.03125f;
  // Values that a text or rounded path would change.
  rgb[0] = 1e-40f;  // subnormal
  rgb[1] = -0.0f;
  rgb[2] = std::numeric_limits<float>::max();
  rgb[3] = 1.0f / 3.0f;
  return rgb;
}

TEST(Pfm, RoundTripIsExact) {
  TempDir dir;
  const int w = 5, h = 3;
  const std::vector<float> rgb = test_pattern(w, h);
  write_image(dir.file("a.pfm"), rgb, w, h);
  int rw = 0, rh = 0;
  const std::vector<float> back = read_pfm(dir.file("a.pfm"), rw, rh);
  EXPECT_EQ(rw, w);
  EXPECT_EQ(rh, h);
  ASSERT_EQ(back.size(), rgb.size());
  EXPECT_EQ(std::memcmp(back.data(), rgb.data(), rgb.size() * sizeof(float)), 0);
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"a.pfm"});
}

TEST(Pfm, RowsAreBottomToTopOnDisk) {
  TempDir dir;
  const int w = 2, h = 3;
  const std::vector<float> rgb = test_pattern(w, h);
  write_image(dir.file("rows.pfm"), rgb, w, h);
  const std::vector<std::uint8_t> bytes = read_bytes(dir.file("rows.pfm"));
  const std::string header = "PF\n2 3\n-1.0\n";  // negative scale: little-endian
  ASSERT_EQ(bytes.size(), header.size() + static_cast<std::size_t>(w * h * 3) * 4);
  EXPECT_EQ(std::string(bytes.begin(), bytes.begin() + static_cast<long>(header.size())), header);
  const std::size_t row_floats = static_cast<std::size_t>(w) * 3;
  for (int disk_row = 0; disk_row < h; ++disk_row) {
    const int image_row = h - 1 - disk_row;
    EXPECT_EQ(std::memcmp(bytes.data() + header.size() + disk_row * row_floats * 4,
                          rgb.data() + static_cast<std::size_t>(image_row) * row_floats, row_floats * 4),
              0)
        << "disk row " << disk_row << " should hold image row " << image_row;
  }
}

TEST(Pfm, BigEndianFilesAreSwapped) {
  TempDir dir;
  std::string text = "PF\n1 1\n1.0\n";
  const float px[3] = {0.5f, 2.0f, -3.0f};
  for (float f : px) {
    std::uint32_t u;
    std::memcpy(&u, &f, 4);
    for (int shift = 24; shift >= 0; shift -= 8) text.push_back(static_cast<char>((u >> shift) & 0xff));
  }
  write_text(dir.file("be.pfm"), text);
  int w = 0, h = 0;
  const auto rgb = read_pfm(dir.file("be.pfm"), w, h);
  ASSERT_EQ(rgb.size(), 3u);
  EXPECT_EQ(rgb[0], 0.5f);
  EXPECT_EQ(rgb[1], 2.0f);
  EXPECT_EQ(rgb[2], -3.0f);
}

TEST(Pfm, MalformedFilesAreInputErrors) {
  TempDir dir;
  write_text(dir.file("grey.pfm"), "Pf\n1 1\n-1.0\n\0\0\0\0");
  write_text(dir.file("short.pfm"), "PF\n2 2\n-1.0\n0123456789");
  write_text(dir.file("zero.pfm"), "PF\n0 2\n-1.0\n");
  int w = 0, h = 0;
  EXPECT_THROW((void)read_pfm(dir.file("grey.pfm"), w, h), InputError);
  EXPECT_THROW((void)read_pfm(dir.file("short.pfm"), w, h), InputError);
  EXPECT_THROW((void)read_pfm(dir.file("zero.pfm"), w, h), InputError);
  EXPECT_THROW((void)read_pfm(dir.file("missing.pfm"), w, h), InputError);
}

// ---- PNG and tone mapping ------------------------------------------------------------

std::uint32_t big_endian_u32(const std::uint8_t* p) {
  return (std::uint32_t(p[0]) << 24) | (std::uint32_t(p[1]) << 16) | (std::uint32_t(p[2]) << 8) | p[3];
}

TEST(ToneMap, GammaTwoIsTheBooks) {
  // sqrt(0.25) = 0.5, * 256 = 128.
  EXPECT_EQ(tone_map_channel(0.25f, Transfer::Gamma2), 128);
  EXPECT_EQ(tone_map_channel(0.0625f, Transfer::Gamma2), 64);
  EXPECT_EQ(tone_map_channel(0.0625f, Transfer::Gamma2, 4.0f), 128);  // exposure scales before the curve
  EXPECT_EQ(tone_map_channel(1.0f, Transfer::Gamma2), 255);           // clamped at 0.999 * 256
  EXPECT_EQ(tone_map_channel(100.0f, Transfer::Gamma2), 255);
  EXPECT_EQ(tone_map_channel(0.0f, Transfer::Gamma2), 0);
  EXPECT_EQ(tone_map_channel(-1.0f, Transfer::Gamma2), 0);
  EXPECT_EQ(tone_map_channel(std::numeric_limits<float>::quiet_NaN(), Transfer::Gamma2), 0);
  EXPECT_EQ(tone_map_channel(std::numeric_limits<float>::infinity(), Transfer::Gamma2), 255);
  EXPECT_EQ(tone_map_channel(1.0f, Transfer::Srgb), 255);
  EXPECT_EQ(tone_map_channel(0.0f, Transfer::Srgb), 0);
  // sRGB is brighter than gamma 2 in the mid-tones: 0.25 -> 0.537 -> 137.
  EXPECT_EQ(tone_map_channel(0.25f, Transfer::Srgb), 137);
}

TEST(Png, SizeAndPixels) {
  TempDir dir;
  const int w = 7, h = 3;
  std::vector<float> rgb(static_cast<std::size_t>(w) * h * 3, 0.0f);
  rgb[0] = 0.25f;                      // top-left red
  rgb[rgb.size() - 1] = 1.0f;          // bottom-right blue
  write_image(dir.file("img.png"), rgb, w, h);
  const std::vector<std::uint8_t> png = read_bytes(dir.file("img.png"));
  ASSERT_GT(png.size(), 33u);
  const std::uint8_t signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  EXPECT_EQ(std::memcmp(png.data(), signature, 8), 0);
  // The first chunk is IHDR: length 13, then width, height, bit depth, colour type.
  EXPECT_EQ(big_endian_u32(png.data() + 8), 13u);
  EXPECT_EQ(std::memcmp(png.data() + 12, "IHDR", 4), 0);
  EXPECT_EQ(big_endian_u32(png.data() + 16), static_cast<std::uint32_t>(w));
  EXPECT_EQ(big_endian_u32(png.data() + 20), static_cast<std::uint32_t>(h));
  EXPECT_EQ(png[24], 8);  // bits per channel
  EXPECT_EQ(png[25], 2);  // truecolour RGB

  int dw = 0, dh = 0, channels = 0;
  unsigned char* pixels = stbi_load_from_memory(png.data(), static_cast<int>(png.size()), &dw, &dh, &channels, 3);
  ASSERT_NE(pixels, nullptr);
  EXPECT_EQ(dw, w);
  EXPECT_EQ(dh, h);
  EXPECT_EQ(pixels[0], 128);  // row 0 of the image is the first row of the file
  EXPECT_EQ(pixels[1], 0);
  EXPECT_EQ(pixels[static_cast<std::size_t>(w) * h * 3 - 1], 255);
  stbi_image_free(pixels);
}

TEST(Hdr, HeaderNamesTheSize) {
  const std::vector<float> rgb(4 * 2 * 3, 0.5f);
  const std::vector<std::uint8_t> hdr = encode_hdr(rgb, 4, 2);
  const std::string text(hdr.begin(), hdr.end());
  EXPECT_EQ(text.rfind("#?RADIANCE", 0), 0u);
  EXPECT_NE(text.find("-Y 2 +X 4"), std::string::npos);
}

TEST(ImageFormat, FollowsTheExtension) {
  EXPECT_EQ(image_format_for("a/b.png"), ImageFormat::Png);
  EXPECT_EQ(image_format_for("B.PFM"), ImageFormat::Pfm);
  EXPECT_EQ(image_format_for("x.Hdr"), ImageFormat::Hdr);
  for (const char* bad : {"a.jpg", "noext", "dir.png/file", "a.png.bak"}) {
    try {
      (void)image_format_for(bad);
      ADD_FAILURE() << bad << " accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    }
  }
}

TEST(CheckOutputPath, RejectsMissingAndNonFolderParents) {
  TempDir dir;
  write_text(dir.file("plain"), "x");
  fs::create_directory(dir.path() / "sub");
  EXPECT_NO_THROW(check_output_path(dir.file("out.png")));
  EXPECT_THROW(check_output_path(dir.file("missing/out.png")), InputError);
  EXPECT_THROW(check_output_path(dir.file("plain/out.png")), InputError);
  EXPECT_THROW(check_output_path(dir.file("sub")), InputError);
  EXPECT_THROW(check_output_path(""), InputError);
}

// ---- Atomic writes -----------------------------------------------------------------------

std::span<const std::uint8_t> as_bytes(const std::string& s) {
  return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()};
}

TEST(WriteFileAtomic, WritesAndReplacesWithoutLeftovers) {
  TempDir dir;
  write_file_atomic(dir.file("t.bin"), as_bytes("first"));
  EXPECT_EQ(read_text(dir.file("t.bin")), "first");
  write_file_atomic(dir.file("t.bin"), as_bytes("second, longer"));
  EXPECT_EQ(read_text(dir.file("t.bin")), "second, longer");
  write_file_atomic(dir.file("t.bin"), as_bytes(""));
  EXPECT_EQ(read_text(dir.file("t.bin")), "");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"t.bin"});
}

// Runs as root in CI, so permissions cannot make a write fail: use paths the
// kernel refuses whoever asks.
TEST(WriteFileAtomic, MissingFolderThrowsIoError) {
  TempDir dir;
  const std::string target = dir.file("missing/t.bin");
  try {
    write_file_atomic(target, as_bytes("data"));
    FAIL() << "write into a missing folder succeeded";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(target), std::string::npos) << e.what();
  }
  EXPECT_TRUE(dir.entries().empty());
}

TEST(WriteFileAtomic, ParentIsAFileThrowsIoError) {
  TempDir dir;
  write_text(dir.file("plain"), "keep me");
  EXPECT_THROW(write_file_atomic(dir.file("plain/t.bin"), as_bytes("data")), IoError);
  EXPECT_EQ(read_text(dir.file("plain")), "keep me");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"plain"});
}

TEST(WriteFileAtomic, TargetThatIsAFolderStaysIntact) {
  TempDir dir;
  fs::create_directory(dir.path() / "t.bin");
  write_text(dir.file("t.bin/inside"), "keep me");
  EXPECT_THROW(write_file_atomic(dir.file("t.bin"), as_bytes("data")), IoError);
  EXPECT_TRUE(fs::is_directory(dir.path() / "t.bin"));
  EXPECT_EQ(read_text(dir.file("t.bin/inside")), "keep me");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"t.bin"});
}

// A write that fails half way (here: the file size limit, the same errno path
// as a full disk) must leave the previous file untouched and no temporary.
// The limit is set in a child process so the test runner keeps its own.
TEST(WriteFileAtomic, FailedWriteKeepsTheOldFile) {
  TempDir dir;
  const std::string target = dir.file("t.bin");
  write_text(target, "the old contents");
  const std::string big(1 << 20, 'n');

  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    std::signal(SIGXFSZ, SIG_IGN);  // get EFBIG instead of being killed
    const rlimit limit{4096, 4096};
    if (::setrlimit(RLIMIT_FSIZE, &limit) != 0) ::_exit(10);
    try {
      write_file_atomic(target, as_bytes(big));
    } catch (const IoError&) {
      ::_exit(0);
    } catch (...) {
      ::_exit(11);
    }
    ::_exit(12);  // the write claimed success
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status)) << "child died with a signal";
  EXPECT_EQ(WEXITSTATUS(status), 0) << "10: setrlimit failed, 11: wrong exception type, 12: no exception";
  EXPECT_EQ(read_text(target), "the old contents");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"t.bin"});
}

}  // namespace
}  // namespace pdflab
