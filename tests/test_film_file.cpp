// Film files and merging through the library: a film survives a round trip bit
// for bit; renders of disjoint sample ranges merge into the render of their
// union; films that do not belong together are refused; a damaged, truncated or
// foreign file is refused with a message, never read; the EXR a film writes is
// what OpenEXR's own reader sees.
#include "renderer/error.h"
#include "renderer/film/exr_io.h"
#include "renderer/film/film_file.h"
#include "renderer/film/image_io.h"
#include "renderer/metrics/reference.h"
#include "renderer/scene/scene_loader.h"
#include "tests/render_support.h"
#include "tests/support.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <sys/stat.h>
#include <zlib.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

namespace pdflab {
namespace {

using testing::render_to_completion;
using testing::slurp;
using testing::TempDir;

const std::string kBookScene = std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes/cornell_book.json";
const std::string kMix = "mix:cosine=0.5,light=0.5";
constexpr auto kTimeout = std::chrono::seconds(120);

std::shared_ptr<Scene> small_scene(int width = 24, int height = 16) {
  auto scene = std::make_shared<Scene>(load_scene_file(kBookScene));
  scene->camera.width = width;
  scene->camera.height = height;
  scene->prepare();
  return scene;
}

FilmInfo describe(const Scene& scene, const std::string& strategy, std::uint64_t seed, std::uint32_t first,
                  std::uint32_t spp, const DropCounts& dropped = {}) {
  FilmInfo info;
  info.scene_hash = film_scene_hash(scene);
  info.scene_file = kBookScene;
  info.width = scene.camera.width;
  info.height = scene.camera.height;
  info.max_depth = scene.max_depth;
  info.strategy = Strategy::parse(strategy).to_string();
  info.ranges = {SampleRange{seed, first, first + spp}};
  info.dropped = dropped;
  info.seconds = 0.5;
  return info;
}

void write_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

void expect_refused(const std::string& path, const std::string& needle) {
  try {
    (void)read_film_file(path);
    ADD_FAILURE() << "read a film from " << path;
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_NE(what.find(needle), std::string::npos) << "lacks '" << needle << "': " << what;
  }
}

double max_relative_difference(double a, double b) {
  const double scale = std::max(std::abs(a), std::abs(b));
  return scale == 0.0 ? 0.0 : std::abs(a - b) / scale;
}

class FilmFileTest : public ::testing::Test {
 protected:
  TempDir dir_{"pdflab-film"};
};

TEST_F(FilmFileTest, RoundTripKeepsEveryBitAndTheDescription) {
  const auto scene = small_scene();
  const auto r = render_to_completion(scene, kMix, 8, 3, 2, kTimeout, 16);
  FilmInfo info = describe(*scene, kMix, 3, 16, 8, r.stats.dropped);
  info.dropped.by_reason = {1, 2, 3};  // any counts come back as written
  const std::string path = dir_.file("a.film");
  write_film_file(path, info, r.film);
  const FilmFile back = read_film_file(path);
  EXPECT_EQ(back.info.scene_hash, info.scene_hash);
  EXPECT_EQ(back.info.scene_file, info.scene_file);
  EXPECT_EQ(back.info.width, 24);
  EXPECT_EQ(back.info.height, 16);
  EXPECT_EQ(back.info.max_depth, scene->max_depth);
  EXPECT_EQ(back.info.strategy, info.strategy);
  EXPECT_EQ(back.info.ranges, info.ranges);
  EXPECT_EQ(back.info.dropped.by_reason, info.dropped.by_reason);
  EXPECT_EQ(back.info.seconds, info.seconds);
  EXPECT_EQ(back.film.sums(), r.film.sums());
  EXPECT_EQ(back.film.squares(), r.film.squares());
  EXPECT_EQ(back.film.counts(), r.film.counts());
  EXPECT_EQ(back.film.drop_masks(), r.film.drop_masks());
  EXPECT_EQ(dir_.entries(), std::vector<std::string>{"a.film"}) << "a temporary file was left behind";
}

// [0, N) and [N, 2N) of one seed, added, are the render of [0, 2N): counts
// exactly, sums to double rounding (a pixel adds its samples in another
// grouping), the mean image to far better than 1e-6.
TEST_F(FilmFileTest, MergedRangesEqualOneRenderOfTheirUnion) {
  const auto scene = small_scene();
  constexpr std::uint32_t kN = 16;
  const auto whole = render_to_completion(scene, kMix, 2 * kN, 7, 2, kTimeout);
  const auto first = render_to_completion(scene, kMix, kN, 7, 2, kTimeout, 0);
  const auto second = render_to_completion(scene, kMix, kN, 7, 1, kTimeout, kN);
  const FilmInfo a = describe(*scene, kMix, 7, 0, kN), b = describe(*scene, kMix, 7, kN, kN);
  ASSERT_EQ(merge_problem("a", a, "b", b), "");
  Film merged = first.film;
  merged.add_film(second.film);
  const FilmInfo info = merged_info(a, b);
  ASSERT_EQ(info.ranges.size(), 1u) << "touching ranges are one range";
  EXPECT_EQ(info.ranges.front(), (SampleRange{7, 0, 2 * kN}));
  EXPECT_EQ(merged.counts(), whole.film.counts());
  double worst_sum = 0.0, worst_square = 0.0;
  for (std::size_t i = 0; i < merged.sums().size(); ++i) {
    worst_sum = std::max(worst_sum, max_relative_difference(merged.sums()[i], whole.film.sums()[i]));
    worst_square = std::max(worst_square, max_relative_difference(merged.squares()[i], whole.film.squares()[i]));
  }
  EXPECT_LT(worst_sum, 1e-12);
  EXPECT_LT(worst_square, 1e-12);
  // The halves really differ (a merge of the same samples would be caught above only by the counts).
  EXPECT_NE(first.film.sums(), second.film.sums());
  const auto m = merged.mean_rgb(), w = whole.film.mean_rgb();
  for (std::size_t i = 0; i < m.size(); ++i) ASSERT_LE(max_relative_difference(m[i], w[i]), 1e-6) << "value " << i;
  std::printf("merge of [0,%u) and [%u,%u): counts equal, largest relative difference of sums %.2e, squares %.2e\n",
              kN, kN, 2 * kN, worst_sum, worst_square);
}

// Two seeds over the same indices are independent samples: their merge holds
// both, and its mean is the average of the two renders' means.
TEST_F(FilmFileTest, MergedSeedsAreTheAverageOfTheirRenders) {
  const auto scene = small_scene();
  const auto one = render_to_completion(scene, kMix, 8, 1, 2, kTimeout);
  const auto two = render_to_completion(scene, kMix, 8, 2, 2, kTimeout);
  const FilmInfo a = describe(*scene, kMix, 1, 0, 8), b = describe(*scene, kMix, 2, 0, 8);
  ASSERT_EQ(merge_problem("one.film", a, "two.film", b), "");
  const FilmInfo info = merged_info(a, b);
  EXPECT_EQ(info.spp(), 16u);
  EXPECT_EQ(info.ranges_text(), "seed 1 samples [0, 8), seed 2 samples [0, 8)");
  Film merged = one.film;
  merged.add_film(two.film);
  for (std::size_t p = 0; p < merged.pixel_count(); ++p) {
    ASSERT_EQ(merged.count(p), 16u);
    double m[3], m1[3], m2[3];
    merged.mean(p, m);
    one.film.mean(p, m1);
    two.film.mean(p, m2);
    for (int c = 0; c < 3; ++c) ASSERT_NEAR(m[c], 0.5 * (m1[c] + m2[c]), 1e-12 * (1.0 + std::abs(m[c])));
  }
  EXPECT_NE(one.film.sums(), two.film.sums());
}

TEST_F(FilmFileTest, MismatchesAndOverlapsAreRefusedNamingBothFiles) {
  const auto scene = small_scene();
  const FilmInfo base = describe(*scene, kMix, 1, 0, 8);
  const auto refuses = [&](FilmInfo other, const std::string& needle) {
    const std::string problem = merge_problem("first.film", base, "second.film", other);
    EXPECT_NE(problem.find("'first.film'"), std::string::npos) << problem;
    EXPECT_NE(problem.find("'second.film'"), std::string::npos) << problem;
    EXPECT_NE(problem.find(needle), std::string::npos) << "lacks '" << needle << "': " << problem;
  };
  FilmInfo other = base;
  other.ranges = {SampleRange{1, 8, 16}};
  EXPECT_EQ(merge_problem("first.film", base, "second.film", other), "");

  other = base;
  other.ranges = {SampleRange{1, 8, 16}};
  other.scene_hash ^= 1;
  refuses(other, "different scenes");
  other = describe(*small_scene(24, 17), kMix, 1, 8, 8);
  refuses(other, "different image sizes");
  other = base;
  other.ranges = {SampleRange{1, 8, 16}};
  other.max_depth = 5;
  refuses(other, "different maximum depths");
  other = describe(*scene, "cosine", 1, 8, 8);
  refuses(other, "different strategies");
  other = describe(*scene, kMix, 1, 4, 8);  // [4, 12) overlaps [0, 8)
  refuses(other, "overlap");
  other = describe(*scene, kMix, 1, 0, 8);  // the same film twice
  refuses(other, "counted twice");
  // An overlap hidden among several ranges of a merged film.
  other.ranges = {SampleRange{2, 0, 8}, SampleRange{1, 7, 9}};
  refuses(other, "overlap");
}

TEST_F(FilmFileTest, SceneHashIsTheSceneFilesContentHash) {
  const auto a = small_scene(), b = small_scene(100, 50);
  EXPECT_NE(film_scene_hash(*a), 0u);
  EXPECT_EQ(film_scene_hash(*a), film_scene_hash(*b)) << "the size is checked on its own";
  const Scene other = load_scene_file(std::string(PDFLAB_SOURCE_DIR) + "/assets/scenes/small_light.json");
  EXPECT_NE(film_scene_hash(*a), film_scene_hash(other));
  char hex[24];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(film_scene_hash(*a)));
  EXPECT_EQ(hex, a->content_hash);
}

// Every way a file can be wrong, each with its own message; and each prefix of
// a good file (truncated anywhere) is refused.
TEST_F(FilmFileTest, DamagedTruncatedAndForeignFilesAreRefused) {
  const auto scene = small_scene(8, 4);
  const auto r = render_to_completion(scene, kMix, 4, 1, 1, kTimeout);
  const std::string good_path = dir_.file("good.film");
  write_film_file(good_path, describe(*scene, kMix, 1, 0, 4), r.film);
  const std::string good = slurp(good_path);
  const std::string bad = dir_.file("bad.film");

  write_bytes(bad, "");
  expect_refused(bad, "too short");
  write_bytes(bad, slurp(kBookScene));
  expect_refused(bad, "not a pdflab film");
  write_bytes(bad, std::string("\x89PNG\r\n\x1a\n", 8) + std::string(64, '\0'));
  expect_refused(bad, "not a pdflab film");

  std::string damaged = good;
  damaged[8] = 3;  // the version
  write_bytes(bad, damaged);
  expect_refused(bad, "version 3");
  damaged = good;
  damaged[20] ^= 0x01;  // the width, inside the header's checksum
  write_bytes(bad, damaged);
  expect_refused(bad, "header's checksum");
  damaged = good;
  damaged[good.size() - 40] ^= 0x10;  // a count, inside the data's checksum
  write_bytes(bad, damaged);
  expect_refused(bad, "data's checksum");
  write_bytes(bad, good + "x");
  expect_refused(bad, "after the end");

  int refused = 0;
  for (std::size_t n = 0; n < good.size(); n += (n < 200 ? 1 : 97)) {
    write_bytes(bad, good.substr(0, n));
    EXPECT_THROW((void)read_film_file(bad), InputError) << "a prefix of " << n << " bytes";
    ++refused;
  }
  expect_refused(dir_.file("missing.film"), "cannot read");
  expect_refused(dir_.path().string(), "is a folder");
  std::printf("%d truncated prefixes and 9 damaged or foreign files refused\n", refused);
  EXPECT_NO_THROW((void)read_film_file(good_path));
}

// Issue 33, item 13: the data's checksum runs on from the header's, so one
// film's header on another's data (of the same size: A's ranges claimed for
// B's samples, merging B twice) is refused; a version 1 film, whose data
// checksum starts afresh, is still read.
TEST_F(FilmFileTest, HeaderIsUnderTheDataChecksumAndVersionOneStillReads) {
  const auto scene = small_scene(8, 4);
  const auto a = render_to_completion(scene, kMix, 4, 1, 1, kTimeout, 0);
  const auto b = render_to_completion(scene, kMix, 4, 1, 1, kTimeout, 4);
  write_film_file(dir_.file("a.film"), describe(*scene, kMix, 1, 0, 4), a.film);
  write_film_file(dir_.file("b.film"), describe(*scene, kMix, 1, 4, 4), b.film);
  const std::string fa = slurp(dir_.file("a.film")), fb = slurp(dir_.file("b.film"));
  std::uint32_t header = 0;
  std::memcpy(&header, fa.data() + 12, 4);
  const std::size_t data_start = 16 + header + 4;
  ASSERT_EQ(fa.size(), fb.size());
  // A's preamble, header and header checksum; B's data and data checksum.
  write_bytes(dir_.file("swapped.film"), fa.substr(0, data_start) + fb.substr(data_start));
  expect_refused(dir_.file("swapped.film"), "data's checksum");

  // The same film as version 1 wrote it: version 1, the header's CRC over it,
  // the data's CRC from zero.
  std::string v1 = fa;
  v1[8] = 1;
  const auto head_crc = static_cast<std::uint32_t>(crc32_z(0, reinterpret_cast<const Bytef*>(v1.data()), 16 + header));
  std::memcpy(v1.data() + 16 + header, &head_crc, 4);
  const auto data_crc = static_cast<std::uint32_t>(
      crc32_z(0, reinterpret_cast<const Bytef*>(v1.data() + data_start), v1.size() - data_start - 4));
  std::memcpy(v1.data() + v1.size() - 4, &data_crc, 4);
  write_bytes(dir_.file("v1.film"), v1);
  FilmFile old;
  ASSERT_NO_THROW(old = read_film_file(dir_.file("v1.film")));
  EXPECT_EQ(old.film.sums(), a.film.sums());
  EXPECT_EQ(old.info.ranges, describe(*scene, kMix, 1, 0, 4).ranges);
}

// The fuzzer's seeds (tests/fuzz/film_seeds/) are films of both versions
// that read: a mutation starts from a valid film.
TEST_F(FilmFileTest, EveryFuzzSeedReads) {
  int versions[3] = {0, 0, 0};
  for (const auto& e : std::filesystem::directory_iterator(std::string(PDFLAB_SOURCE_DIR) + "/tests/fuzz/film_seeds")) {
    SCOPED_TRACE(e.path().filename().string());
    EXPECT_NO_THROW((void)read_film_file(e.path().string()));
    const std::string bytes = slurp(e.path());
    ASSERT_GE(bytes.size(), 12u);
    ++versions[std::min<int>(2, static_cast<unsigned char>(bytes[8]))];
  }
  EXPECT_GT(versions[1], 0) << "a version 1 seed";
  EXPECT_GT(versions[2], 0) << "a version 2 seed";
}

// Issue 33, item 10: a named pipe given as a film is refused at once (open()
// of a FIFO for reading waits for a writer: forever, in a batch job).
TEST_F(FilmFileTest, AFifoIsRefusedWithoutWaiting) {
  const std::string fifo = dir_.file("pipe.film");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const auto start = std::chrono::steady_clock::now();
  expect_refused(fifo, "pipe (FIFO)");
  int w = 0, h = 0;
  EXPECT_THROW((void)read_pfm(fifo, w, h), InputError);
  EXPECT_THROW((void)read_exr(fifo, w, h), InputError);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 10.0);
}

// The EXR as OpenEXR reads it, channel by channel, against the film.
TEST_F(FilmFileTest, ExrHoldsMeanVarianceAndCountAsOpenExrReadsThem) {
  const auto scene = small_scene(20, 37);  // more rows than one strip of 16, and a partial last strip
  const auto r = render_to_completion(scene, kMix, 8, 1, 2, kTimeout);
  const std::string path = dir_.file("image.exr");
  write_exr(path, r.film, {{"pdflab.strategy", kMix}});

  Imf::InputFile in(path.c_str());
  const auto& channels = in.header().channels();
  for (const char* name : {"R", "G", "B", "variance.R", "variance.G", "variance.B"}) {
    ASSERT_NE(channels.findChannel(name), nullptr) << name;
    EXPECT_EQ(channels.findChannel(name)->type, Imf::FLOAT) << name;
  }
  // A float count (exact to 2^24): image tools read an unsigned one as a fraction of 2^32.
  ASSERT_NE(channels.findChannel("count"), nullptr);
  EXPECT_EQ(channels.findChannel("count")->type, Imf::FLOAT);
  const auto dw = in.header().dataWindow();
  ASSERT_EQ(dw.max.x - dw.min.x + 1, 20);
  ASSERT_EQ(dw.max.y - dw.min.y + 1, 37);
  const std::size_t n = r.film.pixel_count();
  std::vector<float> mean(3 * n), variance(3 * n);
  std::vector<float> count(n);
  Imf::FrameBuffer fb;
  const char* mean_names[3] = {"R", "G", "B"};
  const char* var_names[3] = {"variance.R", "variance.G", "variance.B"};
  for (int c = 0; c < 3; ++c) {
    fb.insert(mean_names[c], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(mean.data() + c), 12, 12 * 20));
    fb.insert(var_names[c], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(variance.data() + c), 12, 12 * 20));
  }
  fb.insert("count", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(count.data()), 4, 4 * 20));
  in.setFrameBuffer(fb);
  in.readPixels(dw.min.y, dw.max.y);
  for (std::size_t p = 0; p < n; ++p) {
    double m[3], v[3];
    r.film.moments(p, Film::reciprocals(r.film.count(p)), m, v);
    ASSERT_EQ(count[p], 8.0f);
    for (std::size_t c = 0; c < 3; ++c) {
      ASSERT_EQ(mean[3 * p + c], static_cast<float>(m[c])) << "pixel " << p;
      ASSERT_EQ(variance[3 * p + c], static_cast<float>(v[c])) << "pixel " << p;
    }
  }
  // pdflab's own reader (for references) sees the same mean.
  int w = 0, h = 0;
  EXPECT_EQ(read_exr(path, w, h), r.film.mean_rgb());
  EXPECT_EQ(read_exr_attribute(path, "pdflab.strategy"), kMix);
  // And the PFM streamed from the film is the same mean, bit for bit.
  write_film_image(dir_.file("image.pfm"), r.film);
  EXPECT_EQ(read_pfm(dir_.file("image.pfm"), w, h), r.film.mean_rgb());
}

// Issue 33, item 11: an EXR with part of a layer (R and B without G, one
// variance channel) is refused, naming what is missing; it read as 0 before.
TEST_F(FilmFileTest, ExrWithPartOfALayerIsRefused) {
  const auto write_channels = [&](const std::string& path, const std::vector<const char*>& names) {
    Imf::Header header(2, 2);
    for (const char* c : names) header.channels().insert(c, Imf::Channel(Imf::FLOAT));
    std::vector<float> values(4, 0.5f);
    Imf::OutputFile out(path.c_str(), header);
    Imf::FrameBuffer fb;
    for (const char* c : names) fb.insert(c, Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(values.data()), 4, 8));
    out.setFrameBuffer(fb);
    out.writePixels(2);
  };
  int w = 0, h = 0;
  write_channels(dir_.file("rb.exr"), {"R", "B"});
  try {
    (void)read_exr(dir_.file("rb.exr"), w, h);
    ADD_FAILURE() << "read an EXR without G";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("G missing"), std::string::npos) << e.what();
  }
  write_channels(dir_.file("onevar.exr"), {"R", "G", "B", "variance.G"});
  EXPECT_EQ(read_exr(dir_.file("onevar.exr"), w, h).size(), 12u);
  EXPECT_THROW((void)read_exr_variance(dir_.file("onevar.exr")), InputError);
  EXPECT_THROW((void)load_reference(dir_.file("onevar.exr")), InputError);
  write_channels(dir_.file("whole.exr"), {"R", "G", "B"});
  EXPECT_TRUE(read_exr_variance(dir_.file("whole.exr")).empty()) << "no variance layer at all is allowed";
}

TEST_F(FilmFileTest, ExrReaderRefusesWhatIsNotAnExr) {
  const std::string bad = dir_.file("bad.exr");
  write_bytes(bad, slurp(kBookScene));
  int w = 0, h = 0;
  EXPECT_THROW((void)read_exr(bad, w, h), InputError);
  write_bytes(bad, std::string("\x76\x2f\x31\x01\x02\x00\x00\x00", 8));  // the magic number, then nothing
  EXPECT_THROW((void)read_exr(bad, w, h), InputError);
  write_bytes(dir_.file("x.png"), std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_THROW((void)read_image_linear(dir_.file("x.png"), w, h), InputError);
}

}  // namespace
}  // namespace pdflab
