// A corpus of malformed scene files and command lines, run against the real
// binary. Each one must be refused as bad input: exit status 2, one short
// printable message that names the problem, within a second, nothing on
// stdout, and no file written anywhere (neither the working folder nor the
// fixtures). The files live in tests/bad_input/ (every file there must have a
// row here); inputs that are awkward to keep in git (binary bytes, 10000 levels
// of nesting, a folder, a device) are made by the test.
//
// test_cli.cpp covers the first example of each class (unknown flag, missing
// scene, syntax error, ...); this table adds the long tail.
#include "renderer/film/film.h"
#include "renderer/film/film_file.h"
#include "renderer/film/image_io.h"
#include "renderer/scene/scene_loader.h"
#include "tests/support.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace pdflab {
namespace {

namespace fs = std::filesystem;
using pdflab::testing::ChildOptions;
using pdflab::testing::ChildResult;
using pdflab::testing::listing;
using pdflab::testing::run_pdflab;

const std::string kSource = PDFLAB_SOURCE_DIR;
const std::string kBookScene = kSource + "/assets/scenes/cornell_book.json";
const fs::path kBadInputDir = kSource + "/tests/bad_input";
// A refusal takes well under a second of the program's own CPU time; an
// instrumented build (ASan shadows every allocation, such as the 64 MiB read of
// /dev/zero) gets more.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
constexpr double kMaxSeconds = 3.0;
#else
constexpr double kMaxSeconds = 1.0;
#endif

struct Case {
  std::string what;               // for messages
  std::vector<std::string> args;  // after the program name
  std::string needle;             // must appear in the message
  double max_cpu_seconds = kMaxSeconds;
};

void write_bytes(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out << bytes;
  ASSERT_TRUE(out.good()) << path;
}

class MalformedInput : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "pdflab-malformed-XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    root_ = pattern;
    for (const char* d : {"work", "io", "gen"}) fs::create_directory(root_ / d);
    make_fixtures();
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(root_, ec);
  }

  fs::path work() const { return root_ / "work"; }
  std::string gen(const std::string& name) const { return (root_ / "gen" / name).string(); }

  void make_fixtures() {
    // Bytes of no text format, including NUL and a PNG signature.
    std::string binary = "\x89PNG\r\n\x1a\n";
    binary.push_back('\0');
    for (int i = 0; i < 512; ++i) binary.push_back(static_cast<char>((i * 167 + 13) & 0xFF));
    write_bytes(gen("binary.json"), binary);
    write_bytes(gen("deep_arrays.json"), std::string(10000, '[') + std::string(10000, ']'));
    write_bytes(gen("deep_in_name.json"), "{\"name\": " + std::string(10000, '[') + std::string(10000, ']') + "}");
    std::string objects;
    for (int i = 0; i < 10000; ++i) objects += "{\"a\":";
    write_bytes(gen("deep_objects.json"), objects + "1" + std::string(10000, '}'));
    write_bytes(gen("deep_unterminated.json"), std::string(100000, '['));
    std::string nul_in_string = "{\"name\": \"a";
    nul_in_string.push_back('\0');
    write_bytes(gen("nul_in_string.json"), nul_in_string + "b\"}");
    // A key with an escaped newline and one in Latin-1: the message must stay one printable line.
    write_bytes(gen("newline_in_key.json"), "{\"li\\nghts\": 1}");
    write_bytes(gen("latin1_key.json"), "{\"cam\xE9ra\": 1}");
    fs::create_directory(gen("folder.json"));
    fs::create_directory(gen("folder.png"));
    write_bytes(gen("notes.txt"), "not a folder");
    // Named pipes where a scene, a film or a reference is read: open() would
    // wait for a writer forever (issue 33, item 10).
    for (const char* fifo : {"fifo.json", "fifo.film", "fifo.pfm", "fifo.exr"})
      ASSERT_EQ(::mkfifo(gen(fifo).c_str(), 0600), 0) << fifo;
    // Films whose strategy text holds control bytes (an escape sequence, a
    // newline): quoted in every message (issue 33, item 13).
    write_film(gen("plain.film"), "cosine");
    write_film(gen("escape.film"), "cos\x1b[31mine\nrm");

    // For bench: a valid 8x8 reference, and PFMs whose headers lie.
    const std::vector<float> rgb(8 * 8 * 3, 0.5f);
    const auto pfm = encode_pfm(rgb, 8, 8);
    write_bytes(gen("ref.pfm"), std::string(pfm.begin(), pfm.end()));
    write_bytes(gen("huge_header.pfm"), "PF\n16384 16384\n-1.0\n" + std::string(64, '\0'));
    write_bytes(gen("short_data.pfm"), "PF\n8 8\n-1.0\n" + std::string(100, '\0'));
  }

  // A valid 8x8 film of the book's box, one sample a pixel, whose header
  // names `strategy`.
  static void write_film(const std::string& path, const std::string& strategy) {
    const Scene scene = load_scene_file(kBookScene);
    FilmInfo info;
    info.scene_hash = film_scene_hash(scene);
    info.scene_file = kBookScene;
    info.width = info.height = 8;
    info.max_depth = scene.max_depth;
    info.strategy = strategy;
    info.ranges = {SampleRange{1, 0, 1}};
    Film film(8, 8);
    for (std::size_t p = 0; p < film.pixel_count(); ++p) film.add(p, Vec3(0.5f));
    write_film_file(path, info, film);
  }

  std::vector<std::string> render(std::vector<std::string> extra = {}) const {
    std::vector<std::string> a = {"render", "--scene", kBookScene, "--strategy", "cosine", "--spp", "1",
                                  "--out", "image.png", "--width", "8", "--height", "8", "--threads", "2", "--quiet"};
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  }
  std::vector<std::string> bench(std::vector<std::string> extra = {}) const {
    std::vector<std::string> a = {"bench", "--scene", kBookScene, "--strategies", "cosine", "--spp", "1",
                                  "--reference", gen("ref.pfm"), "--csv", "out.csv", "--threads", "2", "--quiet"};
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  }
  // The same command line with `flag`'s value replaced (or the flag removed when value is null).
  static std::vector<std::string> with(std::vector<std::string> args, const std::string& flag, const char* value) {
    const auto it = std::find(args.begin(), args.end(), flag);
    if (it == args.end() || it + 1 == args.end()) {
      ADD_FAILURE() << "no " << flag;
      return args;
    }
    if (value) {
      *(it + 1) = value;
    } else {
      args.erase(it, it + 2);
    }
    return args;
  }

  ChildResult run(const std::vector<std::string>& args) const {
    ChildOptions o;
    o.cwd = work();
    o.capture = root_ / "io";
    o.deadline_seconds = 20.0;
    return run_pdflab(args, o);
  }

  fs::path root_;
};

// Every line printable ASCII: no raw control bytes or binary from the input.
bool printable_lines(const std::string& s) {
  return std::all_of(s.begin(), s.end(), [](char c) {
    const auto u = static_cast<unsigned char>(c);
    return u == '\n' || (u >= 0x20 && u < 0x7f);
  });
}

// The checks for one case; returns whether all held (failures are reported by gtest).
bool expect_refused(const ChildResult& r, const Case& c, const std::vector<std::string>& work_after,
                    const std::vector<std::string>& fixtures_before, const std::vector<std::string>& fixtures_after) {
  const int failures_before = ::testing::UnitTest::GetInstance()->current_test_info()->result()->total_part_count();
  SCOPED_TRACE(c.what);
  EXPECT_TRUE(r.started);
  EXPECT_FALSE(r.timed_out) << "still running after 20 s";
  EXPECT_TRUE(r.exited) << "killed by a signal; stderr:\n" << r.err;
  EXPECT_EQ(r.status, 2) << "stderr:\n" << r.err;
  // "Within a second" of the program's own time: CPU time, which a busy
  // machine (ctest -j, sanitizers) does not inflate the way it does wall time.
  EXPECT_LT(r.cpu_seconds, c.max_cpu_seconds) << "took " << r.cpu_seconds << " s of CPU (" << r.seconds << " s wall)";
  EXPECT_EQ(r.err.rfind("pdflab: error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find(c.needle), std::string::npos) << "message lacks '" << c.needle << "':\n" << r.err;
  for (const char* crash : {"internal error", "terminate called", "what()", "Sanitizer", "runtime error", "Aborted"})
    EXPECT_EQ(r.err.find(crash), std::string::npos) << "stderr shows '" << crash << "':\n" << r.err;
  EXPECT_LE(std::count(r.err.begin(), r.err.end(), '\n'), 2) << "more than a short message:\n" << r.err;
  EXPECT_LE(r.err.size(), 600u) << r.err;
  EXPECT_TRUE(printable_lines(r.err)) << "unprintable bytes in the message:\n" << r.err;
  EXPECT_EQ(r.out, "") << "bad input printed a result";
  EXPECT_TRUE(work_after.empty()) << "files were written: " << ::testing::PrintToString(work_after);
  EXPECT_EQ(fixtures_after, fixtures_before) << "the fixtures changed";
  // Each EXPECT above that failed added a part to the test result.
  return ::testing::UnitTest::GetInstance()->current_test_info()->result()->total_part_count() == failures_before;
}

// Expected message for every file in tests/bad_input/ (the JSON path, or the
// line of a syntax error). The strategy is `cosine` unless listed below.
const std::map<std::string, std::string> kSceneFileNeedles = {
    {"camera_along_vup.json", "camera: vup is zero or parallel to the viewing direction"},
    {"camera_lookat_is_lookfrom.json", "camera: lookfrom and lookat are the same point"},
    {"camera_zero_vup.json", "camera: vup is zero or parallel to the viewing direction"},
    {"degenerate_box.json", "objects[1]: box 'max' must exceed 'min' on every axis"},
    {"degenerate_quad_parallel.json", "objects[0]: degenerate quad: u and v are parallel"},
    {"degenerate_quad_zero_edge.json", "objects[0]: degenerate quad: u is zero"},
    {"duplicate_nested_key.json", "objects[1].radius: the key appears twice"},
    {"duplicate_objects.json", "objects: the key appears twice"},
    {"dielectric_ior_zero.json", "materials.white.ior: must be > 0"},
    {"empty.json", "empty.json: the scene is empty"},
    {"environment_and_background.json", "environment: camera.background is given too"},
    {"environment_missing_file.json", "environment.file: cannot read environment map"},
    {"environment_negative_scale.json", "environment.scale: must be >= 0"},
    {"environment_unknown_format.json", "tests/bad_input/sky.png': unknown environment map format '.png'"},
    {"environment_unknown_key.json", "environment: unknown key 'intensity'"},
    {"empty_objects.json", "objects: the scene has no objects"},
    {"fractional_width.json", "camera.width: expected an integer"},
    {"huge_coordinate.json", "objects[1].center[1]: magnitude is too large"},
    {"image_16384_square.json", "camera: image size 16384x16384 has 268435456 pixels, more than the limit"},
    {"infinity_literal.json", "JSON syntax error at line 3"},
    {"light_choice_unknown.json", "light_choice: unknown light choice 'nearest' (allowed: power, uniform, tree)"},
    {"light_choice_wrong_type.json", "light_choice: expected a string, found number"},
    {"max_depth_zero.json", "camera.max_depth: must be in 1..10000, found 0"},
    {"metal_fuzz_above_one.json", "materials.white.fuzz: must be in 0..1"},
    {"missing_camera.json", "top level: missing key 'camera'"},
    {"missing_radius.json", "objects[1]: missing key 'radius'"},
    {"nan_literal.json", "JSON syntax error at line 6"},
    {"negative_albedo.json", "materials.white.albedo: colour components must be >= 0"},
    {"negative_radius.json", "objects[1].radius: must be > 0"},
    {"no_targets.json", "has none"},
    {"overflow_number.json", "1e999"},
    {"syntax_error.json", "JSON syntax error at line 5"},
    {"top_level_array.json", "top level: expected an object, found array"},
    {"truncated.json", "JSON syntax error at line 5"},
    {"unknown_key_material.json", "materials.white: unknown key 'fuzz'"},
    {"unknown_key_object.json", "objects[1]: unknown key 'rotate_y'"},
    {"unknown_key_top.json", "top level: unknown key 'lights'"},
    {"unknown_material_name.json", "objects[1].material: unknown material 'gold'"},
    {"unknown_material_type.json", "materials.white.type: unknown material type 'phong'"},
    {"unknown_object_type.json", "objects[1].type: unknown object type 'cylinder'"},
    {"vfov_180.json", "camera.vfov: must be between 0 and 180"},
    {"vfov_zero.json", "camera.vfov: must be between 0 and 180"},
    {"whitespace_only.json", "whitespace_only.json: the scene is empty"},
    {"width_16385.json", "camera.width: must be in 1..16384, found 16385"},
    {"wrong_type_importance.json", "objects[1].importance: expected true or false, found string"},
    {"wrong_type_material_name.json", "objects[1].material: expected a string, found number"},
    {"wrong_type_objects.json", "objects: expected an array, found object"},
    {"wrong_type_vector.json", "camera.lookfrom: expected an array of 3 numbers"},
    {"wrong_type_width.json", "camera.width: expected an integer, found string"},
    {"zero_radius.json", "objects[1].radius: must be > 0"},
};
const std::set<std::string> kNeedsLightStrategy = {"no_targets.json"};

TEST_F(MalformedInput, BaseCommandsSucceed) {
  // Every case changes one thing in these: they must work as they are.
  for (const auto& args : {render(), bench()}) {
    const ChildResult r = run(args);
    EXPECT_TRUE(r.exited);
    EXPECT_EQ(r.status, 0) << args[0] << ": " << r.err;
  }
  EXPECT_EQ(listing(work()), (std::vector<std::string>{"image.png", "out.csv"}));
}

TEST_F(MalformedInput, EveryBadInputFileHasAnExpectation) {
  std::set<std::string> on_disk;
  for (const auto& e : fs::directory_iterator(kBadInputDir)) on_disk.insert(e.path().filename().string());
  std::set<std::string> expected;
  for (const auto& [name, needle] : kSceneFileNeedles) expected.insert(name);
  EXPECT_EQ(on_disk, expected) << "add a row to kSceneFileNeedles for each new file in tests/bad_input/";
}

TEST_F(MalformedInput, AllAreRefusedCleanly) {
  std::vector<Case> cases;

  // Scene files from tests/bad_input/.
  for (const auto& [name, needle] : kSceneFileNeedles) {
    auto args = with(render(), "--scene", (kBadInputDir / name).c_str());
    if (kNeedsLightStrategy.count(name)) args = with(args, "--strategy", "light");
    cases.push_back({"scene " + name, args, needle});
  }

  // Scene inputs made here.
  const std::vector<std::pair<std::string, std::string>> generated = {
      {"binary.json", "binary.json: JSON syntax error at line 1, column 1"},
      {"deep_arrays.json", "top level: expected an object, found array"},
      {"deep_in_name.json", "name: expected a string, found array"},
      {"deep_objects.json", "top level: unknown key 'a'"},
      {"deep_unterminated.json", "JSON syntax error"},
      {"nul_in_string.json", "JSON syntax error at line 1"},
      {"newline_in_key.json", "unknown key 'li\\x0Aghts'"},
      {"latin1_key.json", "ill-formed UTF-8 byte; last read: '\"cam\\xE9r'"},
      {"folder.json", "it is a folder"},
      {"fifo.json", "cannot read scene"},
  };
  for (const auto& [name, needle] : generated)
    cases.push_back({"scene " + name, with(render(), "--scene", gen(name).c_str()), needle});
  // The one refusal that must read its limit first: 64 MiB of page faults,
  // which cost about 0.5-1 s of CPU on a loaded virtual machine.
  cases.push_back({"scene /dev/zero", with(render(), "--scene", "/dev/zero"), "larger than 64 MiB", 4 * kMaxSeconds});
  cases.push_back({"scene ''", with(render(), "--scene", ""), "cannot read scene ''"});

  // Render command lines.
  const std::vector<std::pair<std::vector<std::string>, std::string>> render_lines = {
      {with(render(), "--spp", "4294967296"), "--spp"},
      {with(render(), "--spp", "1073741825"), "--spp"},
      {render({"--spp", "8"}), "--spp"},
      {render({"--seed", "-1"}), "--seed: must be an integer in 0..18446744073709551615, not '-1'"},
      {render({"--seed", "18446744073709551616"}), "--seed"},
      {render({"--seed", "0x10"}), "--seed"},
      {with(render(), "--width", "16385"), "--width"},
      {with(render(), "--width", "8.5"), "--width"},
      {with(with(render(), "--width", "16384"), "--height", "16384"),
       "--width/--height: image size 16384x16384 has 268435456 pixels"},
      {with(with(render(), "--width", "4097"), "--height", "4096"), "image size 4097x4096"},
      {with(with(render(), "--width", "16384"), "--height", "1025"), "image size 16384x1025"},
      {with(render(), "--threads", "1025"), "--threads"},
      {with(render(), "--threads", "two"), "--threads"},
      {with(render(), "--strategy", ""), "empty strategy"},
      {with(render(), "--strategy", "  "), "empty strategy"},
      {with(render(), "--strategy", "Cosine"), "unknown strategy 'Cosine'"},
      {with(render(), "--strategy", "mix:"), "the mixture lists no technique"},
      {with(render(), "--strategy", "mix:cosine"), "term 'cosine' is not TECHNIQUE=WEIGHT"},
      {with(render(), "--strategy", "mix:cosine=nan,light=1"), "weight 'nan'"},
      {with(render(), "--strategy", "mix:cosine=inf,light=1"), "weight 'inf'"},
      {with(render(), "--strategy", "mix:cosine=1e39,light=1"), "weight '1e39'"},
      {with(render(), "--strategy", "mix:cosine=0,light=0"), "all weights are zero"},
      {with(render(), "--strategy", "mix:cosine=1,,light=1"), "is not TECHNIQUE=WEIGHT"},
      {render({"--transfer", "linear"}), "--transfer"},
      {with(render(), "--out", ""), "output file"},
      {with(render(), "--out", gen("folder.png").c_str()), "is a folder"},
      {with(render(), "--out", (gen("notes.txt") + "/image.png").c_str()), "does not exist"},
      {render({"--stats-json", "image.png"}), "is named twice"},
      {render({"--stats-json", "./image.png"}), "is named twice"},
      {render({"stray"}), "stray"},
      {with(render(), "--strategy", "mix:cosine=1.2e-10,light=1"), "below 2^-32"},
      {render({"--reference", gen("fifo.pfm")}), "it is a pipe (FIFO)"},
      {render({"--reference", gen("fifo.exr")}), "it is a pipe (FIFO)"},
      {render({"--reference", gen("fifo.film")}), "it is a pipe (FIFO)"},
      {{"render", "--resume", gen("fifo.film"), "--spp", "2", "--quiet"}, "cannot read film"},
      {{"merge", gen("fifo.film"), "--out", "m.exr"}, "it is a pipe (FIFO)"},
      {{"merge", gen("plain.film"), gen("fifo.film"), "--out", "m.exr"}, "it is a pipe (FIFO)"},
      {{"render", "--resume", gen("escape.film"), "--spp", "2", "--quiet"}, "cos\\x1B[31mine\\x0Arm"},
      {{"merge", gen("plain.film"), gen("escape.film"), "--out", "m.exr"}, "cos\\x1B[31mine\\x0Arm"},
      {{"rendr", "--scene", kBookScene}, "rendr"},
      {{"render"}, "--scene"},
      {{"--bogus"}, "--bogus"},
      {{"--spp", "0"}, "--spp"},
  };
  for (const auto& [args, needle] : render_lines) {
    std::string line;
    for (const auto& a : args) line += " '" + a + "'";
    cases.push_back({"pdflab" + line, args, needle});
  }

  // Bench command lines.
  const std::vector<std::pair<std::vector<std::string>, std::string>> bench_lines = {
      {bench({"--seconds", "1"}), "exactly one of --seconds"},
      {with(bench(), "--spp", nullptr), "exactly one of --seconds"},
      {bench({"--seed", "-5"}), "--seed"},
      {with(bench(), "--strategies", ";;"), "lists no strategy"},
      {with(bench(), "--strategies", "cosine;bogus"), "unknown strategy 'bogus'"},
      {with(bench(), "--reference", gen("huge_header.pfm").c_str()), "more than the limit"},
      {with(bench(), "--reference", gen("short_data.pfm").c_str()), "PFM data is truncated"},
      {with(bench(), "--reference", kBookScene.c_str()), "is not a colour PFM image"},
      {with(bench(), "--reference", gen("nothing.pfm").c_str()), "cannot read"},
      {with(bench(), "--reference", gen("folder.json").c_str()), "folder.json"},
      {with(bench(), "--reference", gen("fifo.pfm").c_str()), "it is a pipe (FIFO)"},
      {bench({"--plot", "out.csv"}), "is named twice"},
      {with(bench(), "--csv", (gen("notes.txt") + "/out.csv").c_str()), "does not exist"},
  };
  for (const auto& [args, needle] : bench_lines) {
    std::string line;
    for (const auto& a : args) line += " '" + a + "'";
    cases.push_back({"pdflab" + line, args, needle});
  }

  const std::vector<std::string> fixtures = listing(root_ / "gen");
  const std::vector<std::string> bad_input_files = listing(kBadInputDir);
  int clean = 0;
  double slowest = 0.0;
  for (const Case& c : cases) {
    const ChildResult r = run(c.args);
    slowest = std::max(slowest, r.cpu_seconds);
    std::vector<std::string> fixtures_after = listing(root_ / "gen");
    for (const auto& f : listing(kBadInputDir)) fixtures_after.push_back("bad_input/" + f);
    std::vector<std::string> fixtures_before = fixtures;
    for (const auto& f : bad_input_files) fixtures_before.push_back("bad_input/" + f);
    if (expect_refused(r, c, listing(work()), fixtures_before, fixtures_after)) ++clean;
    // Leave the next case a clean folder even if this one wrote something.
    for (const auto& e : fs::directory_iterator(work())) fs::remove_all(e.path());
  }
  std::printf("malformed inputs: %zu tried, %d handled cleanly (exit 2, message, nothing written); slowest %.3f s CPU\n",
              cases.size(), clean, slowest);
  EXPECT_EQ(clean, static_cast<int>(cases.size()));
}

}  // namespace
}  // namespace pdflab
