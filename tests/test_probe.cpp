// The pixel probe: it finds the first diffuse surface behind a pixel, its
// directions come from the techniques in proportion to their weights, the
// material's own (bsdf) lobe it shows is the technique's density, and its
// in-app chi-square check passes for every strategy at several pixels of the
// book's scene (and fails when the pdf it is handed is wrong).
#include "renderer/metrics/probe.h"
#include "renderer/scene/scene_loader.h"
#include "tests/render_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <set>
#include <string>
#include <vector>

namespace pdflab {
namespace {

Scene book() {
  Scene s = load_scene_file(PDFLAB_SOURCE_DIR "/assets/scenes/cornell_book.json");
  s.camera.width = s.camera.height = 100;
  s.prepare();
  return s;
}

TEST(Probe, FindsTheFirstDiffuseSurface) {
  const Scene s = book();
  const ProbePoint floor = first_diffuse_hit(s, 50, 97);  // bottom centre: the floor
  ASSERT_TRUE(floor.found);
  EXPECT_NEAR(floor.point.y, 0.0f, 1e-2f);
  EXPECT_NEAR(floor.normal.y, 1.0f, 1e-5f);
  EXPECT_EQ(floor.specular_bounces, 0);
  const ProbePoint ceiling = first_diffuse_hit(s, 50, 10);
  ASSERT_TRUE(ceiling.found);
  EXPECT_NEAR(ceiling.point.y, 555.0f, 1e-2f);
  EXPECT_NEAR(ceiling.normal.y, -1.0f, 1e-5f);
  const ProbePoint through_glass = first_diffuse_hit(s, 70, 85);  // the glass sphere, lower right
  ASSERT_TRUE(through_glass.found);
  EXPECT_GE(through_glass.specular_bounces, 1);
}

// The light taken in, L cos, traced by brute force (what path guiding learns): a
// density over the sphere, zero below the surface, brightest towards the lamp
// from the book's floor, and the same for the same seed.
TEST(Probe, IncidentLightMapIsADensityBrightestTowardsTheLamp) {
  const Scene s = book();
  const ProbePoint at = first_diffuse_hit(s, 50, 97);
  ASSERT_TRUE(at.found);
  constexpr int kW = 48, kH = 24;
  const std::vector<float> map = incident_light_map(s, at, kW, kH, 16, 5);
  ASSERT_EQ(map.size(), static_cast<std::size_t>(kW * kH));
  double integral = 0.0;
  std::size_t brightest = 0;
  for (std::size_t i = 0; i < map.size(); ++i) {
    EXPECT_GE(map[i], 0.0f);
    if (i >= map.size() / 2) {
      EXPECT_EQ(map[i], 0.0f) << "below the surface, cell " << i;
    }
    integral += map[i];
    if (map[i] > map[brightest]) brightest = i;
  }
  EXPECT_NEAR(integral * 4.0 * 3.141592653589793 / (kW * kH), 1.0, 1e-4);
  // The lamp's centre in the map, against the brightest cell (the lamp spans a few cells).
  float u = 0.0f, v = 0.0f;
  direction_to_map(at, normalize(Vec3(278.0f, 554.0f, 279.5f) - at.point), u, v);
  const int col = static_cast<int>(brightest % kW), row = static_cast<int>(brightest / kW);
  int dc = std::abs(col - static_cast<int>(u * kW));
  dc = std::min(dc, kW - dc);  // the azimuth wraps
  EXPECT_LE(dc, 3) << "brightest column " << col << ", the lamp's " << u * kW;
  EXPECT_LE(std::abs(row - static_cast<int>(v * kH)), 3) << "brightest row " << row << ", the lamp's " << v * kH;
  EXPECT_EQ(map, incident_light_map(s, at, kW, kH, 16, 5));
}

// Under a sky of one radiance everywhere, the light a floor takes in is
// L cos: the map is the cosine lobe's density, cos(theta) / pi, row by row.
TEST(Probe, IncidentLightMapIsWeightedByTheCosine) {
  const Scene s = *testing::sky_floor(20, 20);
  const ProbePoint at = first_diffuse_hit(s, 10, 10);
  ASSERT_TRUE(at.found);
  constexpr int kW = 16, kH = 16;
  const std::vector<float> map = incident_light_map(s, at, kW, kH, 64, 3);
  for (int row = 0; row < kH / 2; ++row) {
    // A cell's mean of cos / pi: z runs from 1 - 2 row / kH to 1 - 2 (row + 1) / kH.
    const double z = 1.0 - (2.0 * row + 1.0) / kH;
    double mean = 0.0;
    for (int col = 0; col < kW; ++col) mean += map[static_cast<std::size_t>(row * kW + col)] / kW;
    EXPECT_NEAR(mean, z / 3.141592653589793, 0.01) << "row " << row;
  }
}

TEST(Probe, DirectionsComeFromTheTechniquesInProportionToTheirWeights) {
  const Scene s = book();
  const SamplingPlan plan = SamplingPlan::make(Strategy::parse("mix:cosine=0.25,light=0.75"), s);
  const ProbePoint at = first_diffuse_hit(s, 50, 97);
  const auto dirs = probe_directions(plan, at, 4000, 3);
  ASSERT_EQ(dirs.size(), 4000u);
  int light = 0;
  for (const auto& d : dirs) light += d.technique == static_cast<int>(Technique::Light);
  EXPECT_NEAR(light / 4000.0, 0.75, 5 * std::sqrt(0.75 * 0.25 / 4000));
}

TEST(Probe, ChiSquareCheckPassesForEveryStrategy) {
  const Scene s = book();
  const char* strategies[] = {"cosine", "uniform-hemisphere", "uniform-sphere", "light", "light-sa",
                              "mix:cosine=0.5,light=0.5", "mix:cosine=0.5,light-sa=0.5"};
  const int pixels[][2] = {{50, 97}, {5, 50}, {95, 50}, {50, 60}};
  int checks = 0;
  for (const auto& px : pixels) {
    const ProbePoint at = first_diffuse_hit(s, px[0], px[1]);
    ASSERT_TRUE(at.found);
    for (const char* st : strategies) {
      const SamplingPlan plan = SamplingPlan::make(Strategy::parse(st), s);
      // alpha 1e-4 per check: 28 checks keep the family's false alarms below 0.3%.
      const ProbeChiSquare c = probe_chi_square(plan, at, 20000, 11, 16, 32, 1e-4);
      EXPECT_TRUE(c.passed) << st << " at pixel " << px[0] << "," << px[1] << ": p " << c.result.p_value
                            << ", zero-cell hits " << c.result.zero_cell_hits;
      ++checks;
    }
  }
  EXPECT_EQ(checks, 28);
}

TEST(Probe, ChiSquareCheckFailsWhenThePdfDisagreesWithTheSampler) {
  const Scene s = book();
  SamplingPlan plan = SamplingPlan::make(Strategy::parse("mix:cosine=0.5,light=0.5"), s);
  // The sampler still picks techniques by the CDF (50/50); the pdf now claims 70/30.
  plan.weight[static_cast<int>(Technique::Cosine)] = 0.7f;
  plan.weight[static_cast<int>(Technique::Light)] = 0.3f;
  const ProbeChiSquare c = probe_chi_square(plan, first_diffuse_hit(s, 50, 97), 20000, 11);
  EXPECT_FALSE(c.passed) << "p " << c.result.p_value;
  EXPECT_LT(c.result.p_value, 1e-6);
}

// The probe lists the light choice at the clicked point: in the starved box
// (a beacon 1.6e9 times the ceiling light's power beside it, facing up) the
// floor is behind the beacon, which keeps only the defensive floor's share;
// by power alone it would take all but 6e-10 of the choices.
TEST(Probe, ListsTheLightChoiceAtThePoint) {
  Scene s = load_scene_file(PDFLAB_SOURCE_DIR "/assets/scenes/starved_light.json");
  s.camera.width = s.camera.height = 100;
  s.prepare();
  const ProbePoint floor = first_diffuse_hit(s, 50, 97);
  ASSERT_TRUE(floor.found);
  for (const char* strategy : {"nee-mis", "mix:cosine=0.5,light-sa=0.5"}) {
    SCOPED_TRACE(strategy);
    const SamplingPlan plan = SamplingPlan::make(Strategy::parse(strategy), s);
    const ProbeLightChoice choice = probe_light_choice(s, plan, floor);
    ASSERT_EQ(choice.rows.size(), 2u);
    EXPECT_EQ(choice.rows[0].label, "light (quad)");
    EXPECT_EQ(choice.rows[1].label, "beacon (quad)");
    EXPECT_TRUE(choice.rows[0].receives);
    EXPECT_FALSE(choice.rows[1].receives);
    EXPECT_LT(choice.rows[0].share, 1e-9f);
    EXPECT_NEAR(choice.rows[0].probability, 1.0f - kLightChoiceFloor / 2.0f, 1e-6f);
    EXPECT_NEAR(choice.rows[1].probability, kLightChoiceFloor / 2.0f, 1e-6f);
  }
  // The book's light chooses uniformly, wherever the point is.
  const SamplingPlan book = SamplingPlan::make(Strategy::parse("mix:cosine=0.5,light=0.5"), s);
  const ProbeLightChoice uniform = probe_light_choice(s, book, floor);
  EXPECT_EQ(uniform.set, "light targets");
  ASSERT_EQ(uniform.rows.size(), 2u);
  EXPECT_EQ(uniform.rows[1].probability, 0.5f);
  EXPECT_TRUE(probe_light_choice(s, SamplingPlan::make(Strategy::parse("cosine"), s), floor).rows.empty());
}

// Of many lights, the probe's rows stay apart: bulbs of one material carry
// their object numbers, a light of its own material keeps its plain label.
TEST(Probe, LabelsManyLightsOfOneMaterialApart) {
  Scene s = load_scene_file(PDFLAB_SOURCE_DIR "/assets/scenes/many_lights.json");
  s.prepare();
  const SamplingPlan plan = SamplingPlan::make(Strategy::parse("nee-mis+lights:tree"), s);
  const std::vector<std::string> labels = target_labels(s, plan.emitters);
  ASSERT_EQ(labels.size(), plan.emitters.size());
  ASSERT_GT(labels.size(), 400u);
  EXPECT_EQ(std::set<std::string>(labels.begin(), labels.end()).size(), labels.size());
  EXPECT_EQ(std::count(labels.begin(), labels.end(), "panel (quad)"), 1);
  const std::string& bulb = labels.back();
  EXPECT_NE(bulb.find(" #" + std::to_string(plan.emitters.spheres.back().index) + " (sphere)"), std::string::npos) << bulb;
}

TEST(Probe, PdfMapShowsTheLightAboveTheFloor) {
  const Scene s = book();
  const SamplingPlan plan = SamplingPlan::make(Strategy::parse("light"), s);
  const ProbePoint at = first_diffuse_hit(s, 50, 97);
  const int w = 256, h = 128;
  const auto map = pdf_map(plan, at, w, h);
  // Towards the light's centre the map shows the light's density.
  const Vec3 to_light = normalize(Vec3(278, 554, 279.5f) - at.point);
  float u, v;
  direction_to_map(at, to_light, u, v);
  const std::size_t at_light = static_cast<std::size_t>(v * h) * w + static_cast<std::size_t>(u * w);
  EXPECT_NEAR(map[at_light], plan.pdf(at.point, at.normal, to_light), 0.05f * map[at_light] + 1e-3f);
  EXPECT_GT(map[at_light], 0.0f);
  // Below the floor (the lower half of the map) the light pdf is zero.
  for (int r = h / 2; r < h; ++r)
    for (int c = 0; c < w; ++c) ASSERT_EQ(map[static_cast<std::size_t>(r) * w + c], 0.0f) << r << "," << c;
}

// Veach's scene at its own size: four microfacet plates and a lambertian backdrop.
Scene veach() {
  Scene s = load_scene_file(PDFLAB_SOURCE_DIR "/assets/scenes/veach_mis.json");
  s.prepare();
  return s;
}

// The first probe point down the image's middle column whose material is `name`.
ProbePoint find_point(const Scene& s, const std::string& name) {
  for (int y = 0; y < s.camera.height; ++y) {
    const ProbePoint at = first_diffuse_hit(s, s.camera.width / 2, y);
    if (at.found && s.material_names[at.material] == name) return at;
  }
  return {};
}

// The integral of a map over the sphere: every cell spans 4 pi / (w h).
double map_integral(const std::vector<float>& map, int w, int h) {
  double sum = 0.0;
  for (float v : map) sum += v;
  return sum * 4.0 * 3.14159265358979323846 / (static_cast<double>(w) * h);
}

// The material's own lobe beside the light lobe: at a lambertian point it is
// the cosine lobe, at a microfacet point GGX's visible normals reflected; it
// is the bsdf technique's density (the probe's strategy map for `bsdf` is the
// same map), it integrates to one over the sphere, and the directions the
// probe draws with `bsdf` carry that very density.
TEST(Probe, BsdfLobeIsTheTechniquesDensityAndIntegratesToOne) {
  const Scene s = veach();
  const SamplingPlan bsdf = SamplingPlan::make(Strategy::parse("bsdf"), s);
  const int w = 512, h = 256;
  for (const char* name : {"backdrop", "plate1", "plate2", "plate3", "plate4"}) {
    const ProbePoint at = find_point(s, name);
    ASSERT_TRUE(at.found) << name;
    const Material& m = s.materials[at.material];
    EXPECT_EQ(at.surface.glossy, m.type == MaterialType::Microfacet) << name;
    if (at.surface.glossy) {
      EXPECT_EQ(at.surface.alpha, m.alpha) << name;
    }
    EXPECT_GT(dot(at.surface.outgoing, at.normal), 0.0f) << name;

    // Cell averages over 8 x 8 points: the narrowest lobe (alpha 0.005,
    // about 0.01 rad) spans several points.
    const std::vector<float> lobe = bsdf_pdf_map(s, at, w, h, 8);
    const double integral = map_integral(lobe, w, h);
    std::printf("[probe] %s (alpha %g): the bsdf lobe integrates to %.5f, its largest cell %.4g\n", name,
                at.surface.glossy ? at.surface.alpha : 0.0f, integral, *std::max_element(lobe.begin(), lobe.end()));
    EXPECT_NEAR(integral, 1.0, 5e-3) << name;

    // At cell centres the map is the technique's pdf, and the strategy map of
    // `bsdf` is the same map (it sees the surface too).
    const std::vector<float> centres = bsdf_pdf_map(s, at, 64, 32);
    const std::vector<float> strategy = pdf_map(bsdf, at, 64, 32);
    EXPECT_EQ(centres, strategy) << name;
    const std::vector<ProbeSample> drawn = probe_directions(bsdf, at, 2000, 5);
    ASSERT_EQ(drawn.size(), 2000u);
    int below = 0;
    for (const ProbeSample& d : drawn) {
      ASSERT_EQ(d.technique, static_cast<int>(Technique::Bsdf));
      const float p = bsdf_pdf(s, at, d.direction);
      EXPECT_NEAR(d.pdf, p, 1e-3f * p) << name;
      below += dot(d.direction, at.normal) <= 0.0f;
      if (!at.surface.glossy) {
        EXPECT_NEAR(p, dot(d.direction, at.normal) / 3.14159265f, 1e-5f) << name;
      }
    }
    if (!at.surface.glossy) {
      EXPECT_EQ(below, 0);
    }
    // The lobe's mass where the probe's draws fall: the 10% of cells the lobe
    // weighs most hold the draws in the same share as the lobe's mass there.
    const int cw = 64, ch = 32;
    const std::vector<float> coarse = bsdf_pdf_map(s, at, cw, ch, 16);
    std::vector<float> sorted = coarse;
    std::sort(sorted.begin(), sorted.end(), std::greater<>());
    const float cut = sorted[sorted.size() / 10];
    double mass = 0.0;
    for (float v : coarse)
      if (v > cut) mass += v * 4.0 * 3.14159265358979323846 / (cw * ch);
    int inside = 0;
    for (const ProbeSample& d : drawn) {
      float u, v;
      direction_to_map(at, d.direction, u, v);
      const int col = std::min(cw - 1, static_cast<int>(u * cw)), row = std::min(ch - 1, static_cast<int>(v * ch));
      inside += coarse[static_cast<std::size_t>(row) * cw + col] > cut;
    }
    const double share = inside / 2000.0;
    EXPECT_NEAR(share, mass, 5.0 * std::sqrt(mass * (1.0 - mass) / 2000.0) + 1e-3) << name;
  }
}

TEST(Probe, TheBsdfLobeSaysWhatItIs) {
  const Scene s = veach();
  EXPECT_NE(bsdf_lobe_name(s, find_point(s, "backdrop")).find("cosine lobe"), std::string::npos);
  EXPECT_NE(bsdf_lobe_name(s, find_point(s, "plate4")).find("GGX visible normals, alpha 0.005"), std::string::npos);
  EXPECT_EQ(delta_lobe_note(s, find_point(s, "plate4")), "");
  // Through the book's glass sphere: the clicked surface is a delta lobe.
  const Scene b = book();
  const ProbePoint through_glass = first_diffuse_hit(b, 70, 85);
  ASSERT_TRUE(through_glass.found);
  const std::string note = delta_lobe_note(b, through_glass);
  EXPECT_NE(note.find("glass"), std::string::npos) << note;
  EXPECT_NE(note.find("delta lobe"), std::string::npos) << note;
}

// The in-app chi-square check at a microfacet point tests the bsdf technique
// against that point's own lobe: GGX's visible normals reflected on Veach's
// plates (alpha 0.07 and 0.005; the expected counts then crowd into a few cells, where a cosine lobe
// would spread over the hemisphere), reflected or refracted on the frosted
// sphere (most of the expected mass below the surface, where a reflecting lobe
// has none). Both samplers pass there, alone and mixed with light-sa.
TEST(Probe, ChiSquareCheckUsesTheClickedPointsOwnLobe) {
  const auto largest_share = [](const ProbeChiSquare& c) {
    double total = 0.0;
    for (double e : c.expected) total += e;
    return *std::max_element(c.expected.begin(), c.expected.end()) / total;
  };
  const auto share_below = [](const ProbeChiSquare& c) {
    double total = 0.0, below = 0.0;
    for (std::size_t i = 0; i < c.expected.size(); ++i) {
      total += c.expected[i];
      if (static_cast<int>(i) / c.phi_cells >= c.z_cells / 2) below += c.expected[i];
    }
    return below / total;
  };
  const char* strategies[] = {"bsdf", "mix:bsdf=0.5,light-sa=0.5"};
  const Scene v = veach();
  for (const char* name : {"plate2", "plate4"}) {
    const ProbePoint at = find_point(v, name);
    ASSERT_TRUE(at.found && at.surface.glossy) << name;
    for (const char* st : strategies) {
      const ProbeChiSquare c = probe_chi_square(SamplingPlan::make(Strategy::parse(st), v), at, 20000, 13, 16, 32, 1e-3);
      EXPECT_TRUE(c.passed) << name << " " << st << ": p " << c.result.p_value;
      std::printf("[probe] %s %s: p %.3g, largest cell %.3f of the expected mass\n", name, st, c.result.p_value,
                  largest_share(c));
      if (std::string(st) == "bsdf") {
        EXPECT_GT(largest_share(c), 0.05) << name;  // a cosine lobe: below 0.01
      }
    }
  }
  Scene f = load_scene_file(PDFLAB_SOURCE_DIR "/assets/scenes/frosted_glass.json");
  f.camera.width = f.camera.height = 100;
  f.prepare();
  ProbePoint at;
  for (int y = 60; y < 100 && !at.found; ++y)
    for (int x = 0; x < 100; ++x) {
      const ProbePoint p = first_diffuse_hit(f, x, y);
      if (p.found && p.surface.transmits) {
        at = p;
        break;
      }
    }
  ASSERT_TRUE(at.found) << "no pixel sees the frosted sphere";
  EXPECT_FLOAT_EQ(at.surface.eta, 1.5f);  // seen from outside
  EXPECT_NE(bsdf_lobe_name(f, at).find("refracted"), std::string::npos) << bsdf_lobe_name(f, at);
  for (const char* st : strategies) {
    const ProbeChiSquare c = probe_chi_square(SamplingPlan::make(Strategy::parse(st), f), at, 20000, 17, 16, 32, 1e-3);
    std::printf("[probe] frosted sphere %s: p %.3g, %.3f of the expected mass below the surface\n", st,
                c.result.p_value, share_below(c));
    EXPECT_TRUE(c.passed) << st << ": p " << c.result.p_value;
    if (std::string(st) == "bsdf") {
      EXPECT_GT(share_below(c), 0.5);
    }
  }
}

}  // namespace
}  // namespace pdflab
