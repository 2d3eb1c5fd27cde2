// Visible sets under a similarity transform of the scene (docs/visibility-math.md §6
// "Invariance under transformation"): the scene moved 1e5 units, rotated 37 degrees about a
// tilted axis (the cube orientation with it) and scaled by 0.0254, and every id that differs
// classified by tests/support/invariance.h. Nothing may be a defect.
#include "tests/support/invariance.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "tests/test_support.h"
#include "vislib/bake/view_cells.h"
#include "vislib/base/cubemap.h"
#include "vislib/base/random.h"
#include "vislib/scene/generate.h"
#include "vislib/scene/import.h"
#include "vislib/scene/scene_transform.h"

namespace vislib {
namespace {

// The transform of the check: 37 degrees about (0.3, 1, 0.5), scale 0.0254 (inches to
// metres), then 1e5 along every axis.
Similarity far_transform() {
  Similarity s;
  s.rotation = axis_angle_rotation({0.3, 1, 0.5}, 37);
  s.scale = 0.0254;
  s.translation = {1e5, 1e5, 1e5};
  return s;
}

struct Segment {
  Vec3 v0, v1;
};

// `count` segments: the diagonals of the view regions of walkable cells picked at random (seeded).
std::vector<Segment> random_cell_segments(const Scene& scene, const WalkableOptions& wo,
                                          size_t count, uint64_t seed) {
  const ViewCells cells = walkable_cells(scene, wo);
  const uint32_t n = cells.layout.cell_count();
  Rng rng(seed);
  std::vector<Segment> out;
  for (size_t i = 0; i < count && n > 0; ++i) {
    const pvs::Box b = cells.layout.view_region(uint32_t(rng.below(n)));
    out.push_back({{b.min[0], b.min[1], b.min[2]}, {b.max[0], b.max[1], b.max[2]}});
  }
  return out;
}

struct Totals {
  size_t visible = 0, differing = 0, grazing = 0, ties = 0, defects = 0;
  double max_ulps = 0;
};

// Classifies every segment, prints one line per differing id and a summary; returns the totals.
Totals run_segments(const Scene& a, const std::vector<Segment>& segs, int n, const char* name) {
  const Similarity sim = far_transform();
  Scene b = a;
  transform_scene(b, sim);
  SegmentOptions so;
  so.resolution = n;
  Totals tot;
  for (size_t i = 0; i < segs.size(); ++i) {
    const InvarianceReport rep = classify_invariance(a, b, sim, segs[i].v0, segs[i].v1, so);
    tot.visible += rep.visible_a;
    tot.differing += rep.diffs.size();
    tot.grazing += rep.count(InvarianceClass::Grazing);
    tot.ties += rep.count(InvarianceClass::DepthTie);
    tot.defects += rep.count(InvarianceClass::Defect);
    std::printf(
        "%s segment %zu (%.17g,%.17g,%.17g -> %.17g,%.17g,%.17g): %zu visible, %zu moved, %zu "
        "differ\n",
        name, i, segs[i].v0.x, segs[i].v0.y, segs[i].v0.z, segs[i].v1.x, segs[i].v1.y, segs[i].v1.z,
        rep.visible_a, rep.visible_b, rep.diffs.size());
    for (const InvarianceEvidence& e : rep.diffs) {
      if (e.cls == InvarianceClass::Grazing) tot.max_ulps = std::max(tot.max_ulps, e.ulps_needed);
      std::printf(
          "  id %u only %s: %s (face %d x %d y %d t %.9g, piece %.3g, edge %.3g = %.3g "
          "ulps-scaled, depth gap "
          "%.3g, %zu rays): %s\n",
          e.id, e.in_original ? "original" : "moved", invariance_class_name(e.cls), e.face, e.x,
          e.y, e.t, e.piece_length, e.edge_distance, e.ulps_needed, e.depth_gap, e.rays,
          e.why.c_str());
    }
  }
  std::printf(
      "%s: %zu visible ids, %zu differ: %zu grazing (largest %.3g of %g ulps-scaled), %zu depth "
      "ties, %zu defects\n",
      name, tot.visible, tot.differing, tot.grazing, tot.max_ulps, kInvarianceUlps, tot.ties,
      tot.defects);
  return tot;
}

// The check on one scene: 4 random walkable cells' diagonals at resolution n, every differing id a
// grazing ray within kInvarianceUlps or a depth tie, none a defect. Prints the time against
// `budget_s`.
void expect_only_grazing_and_ties(const Scene& a, const WalkableOptions& wo, uint64_t seed, int n,
                                  const char* name, double budget_s) {
  const auto start = std::chrono::steady_clock::now();
  const auto segs = random_cell_segments(a, wo, 4, seed);
  ASSERT_EQ(segs.size(), 4u);
  const Totals t = run_segments(a, segs, n, name);
  EXPECT_GT(t.visible, 0u);
  EXPECT_EQ(t.defects, 0u);
  EXPECT_LE(t.max_ulps, kInvarianceUlps);
  std::printf("time budget %.0f s: took %.1f s\n", budget_s,
              std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
}

TEST(SceneTransform, AxisAngleGivesARotationMovingTheAxisNowhere) {
  const Mat3 r = axis_angle_rotation({0.3, 1, 0.5}, 37);
  EXPECT_TRUE(is_rotation(r));
  const Vec3 axis = r * Vec3{0.3, 1, 0.5};
  EXPECT_NEAR(axis.x, 0.3, 1e-15);
  EXPECT_NEAR(axis.y, 1, 1e-15);
  EXPECT_NEAR(axis.z, 0.5, 1e-15);
  // 90 degrees about +y takes +x to -z (right-handed).
  const Vec3 x = axis_angle_rotation({0, 1, 0}, 90) * Vec3{1, 0, 0};
  EXPECT_NEAR(x.x, 0, 1e-15);
  EXPECT_NEAR(x.z, -1, 1e-15);
  EXPECT_THROW(axis_angle_rotation({0, 0, 0}, 10), std::invalid_argument);
}

TEST(SceneTransform, MovesEveryVertexAndRefusesANonSimilarity) {
  CityOptions co;
  co.blocks_x = co.blocks_z = 1;
  Scene s = generate_city(co);
  const Scene orig = s;
  const Similarity sim = far_transform();
  transform_scene(s, sim);
  ASSERT_EQ(s.vertex_count(), orig.vertex_count());
  for (uint32_t v = 0; v < s.vertex_count(); v += 7) {
    const Vec3 p = orig.positions[0][v], q = s.positions[0][v];
    const Vec3 back = (Vec3{q.x - 1e5, q.y - 1e5, q.z - 1e5}) * (1 / 0.0254);
    const Vec3 expect = sim.rotation * p;
    EXPECT_NEAR(back.x, expect.x, 1e-6);
    EXPECT_NEAR(back.y, expect.y, 1e-6);
    EXPECT_NEAR(back.z, expect.z, 1e-6);
  }
  Similarity bad;
  bad.scale = 0;
  EXPECT_THROW(transform_scene(s, bad), std::invalid_argument);
}

// A generated city, its copy moved far, rotated and scaled: the differing ids are all grazing
// rays or depth ties within the stated bound.
TEST(Invariance, GeneratedCityDiffersOnlyByGrazingRaysAndTies) {
  CityOptions co;
  co.blocks_x = co.blocks_z = 2;
  co.panel_size = 4;
  expect_only_grazing_and_ties(generate_city(co), WalkableOptions{}, 7, 64, "city 2x2", 20);
}

// The classifier is not blind: a triangle of the moved copy pushed 1 km down (not a similarity of
// the original) is reported as a defect, with the ray that shows it.
TEST(Invariance, ClassifierReportsATriangleThatMovedAsADefect) {
  CityOptions co;
  co.blocks_x = co.blocks_z = 1;
  const Scene a = generate_city(co);
  const auto segs = random_cell_segments(a, WalkableOptions{}, 1, 7);
  ASSERT_EQ(segs.size(), 1u);
  SegmentOptions so;
  so.resolution = 32;
  so.want_witnesses = true;
  const SegmentResult base = segment_visibility(a, segs[0].v0, segs[0].v1, so);
  ASSERT_FALSE(base.visible.empty());
  // A visible triangle from the middle of the id order.
  const uint32_t victim = base.visible[base.visible.size() / 2];
  const Similarity sim = far_transform();
  Scene b = a;
  transform_scene(b, sim);
  // Detach the victim's corners from the shared vertices and move them 1 km (scaled) down.
  for (int k = 0; k < 3; ++k) {
    Vec3 p = b.positions[0][b.triangles[victim][k]];
    b.positions[0].push_back(p + Vec3{0, -1000 * sim.scale, 0});
    b.triangles[victim][k] = uint32_t(b.positions[0].size() - 1);
  }
  const InvarianceReport rep = classify_invariance(a, b, sim, segs[0].v0, segs[0].v1, so);
  bool found = false;
  for (const InvarianceEvidence& e : rep.diffs)
    if (e.id == victim) {
      found = true;
      EXPECT_EQ(e.cls, InvarianceClass::Defect) << e.why;
      EXPECT_TRUE(e.in_original);
    }
  EXPECT_TRUE(found) << "triangle " << victim << " should differ";
}

std::string vec_text(Vec3 v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "%.17g,%.17g,%.17g", v.x, v.y, v.z);
  return buf;
}

std::vector<uint32_t> visible_of(const std::string& json_path) {
  std::ifstream in(json_path);
  return nlohmann::json::parse(in)["visible"].get<std::vector<uint32_t>>();
}

// `pvs segment --rotate --scale --translate` moves scene, segment, cube and near together: the same
// set as `pvs export` with the same options and `pvs segment` on the export with the segment, the
// printed rotation and the near distance moved by hand.
TEST(InvarianceCli, SegmentTransformMatchesTheExportedMovedScene) {
  const std::string dir = vislib_test::temp_dir("invariance_cli");
  const std::string city = dir + "/c.glb", moved = dir + "/moved.obj";
  std::string out, err;
  ASSERT_EQ(vislib_test::run_pvs("generate city --blocks 1,1 -o " + city, &out), 0) << out;
  const std::string tr = " --rotate 37,0.3,1,0.5 --scale 0.0254 --translate 1e5,1e5,1e5";
  ASSERT_EQ(vislib_test::run_pvs_split("export " + city + tr + " -o " + moved, &out, &err), 0)
      << err;
  const Similarity sim = far_transform();
  EXPECT_NE(
      err.find("rotation (row-major, for --orientation): " +
               std::string(vec_text({sim.rotation.m[0], sim.rotation.m[1], sim.rotation.m[2]}))),
      std::string::npos)
      << err;
  const Scene a = load_scene(city);
  const auto segs = random_cell_segments(a, WalkableOptions{}, 1, 3);
  ASSERT_EQ(segs.size(), 1u);
  const std::string seg =
      " --res 32 --from " + vec_text(segs[0].v0) + " --to " + vec_text(segs[0].v1);
  ASSERT_EQ(vislib_test::run_pvs("segment " + city + seg + tr + " --json " + dir + "/t.json", &out),
            0)
      << out;
  std::string orient;
  for (double x : sim.rotation.m) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%s%.17g", orient.empty() ? "" : ",", x);
    orient += buf;
  }
  char near[64];
  std::snprintf(near, sizeof near, "%.17g", kDefaultNear * sim.scale);
  ASSERT_EQ(vislib_test::run_pvs("segment " + moved + " --res 32 --from " +
                                     vec_text(apply(sim, segs[0].v0)) + " --to " +
                                     vec_text(apply(sim, segs[0].v1)) + " --orientation " + orient +
                                     " --near " + near + " --json " + dir + "/m.json",
                                 &out),
            0)
      << out;
  const auto t = visible_of(dir + "/t.json"), m = visible_of(dir + "/m.json");
  EXPECT_FALSE(t.empty());
  EXPECT_EQ(t, m);
  // A zero axis is refused, naming the option, before any output.
  EXPECT_EQ(vislib_test::run_pvs(
                "segment " + city + seg + " --rotate 10,0,0,0 --json " + dir + "/bad.json", &out),
            2);
  EXPECT_NE(out.find("--rotate"), std::string::npos) << out;
  // So are a non-finite angle and a transform that leaves the range of double.
  EXPECT_EQ(vislib_test::run_pvs(
                "segment " + city + seg + " --rotate nan,0,1,0 --json " + dir + "/bad.json", &out),
            2);
  EXPECT_NE(out.find("--rotate"), std::string::npos) << out;
  EXPECT_EQ(
      vislib_test::run_pvs(
          "export " + city + " --scale 1e308 --translate 1e308,0,0 -o " + dir + "/bad.obj", &out),
      2);
  EXPECT_NE(out.find("--scale"), std::string::npos) << out;
  EXPECT_FALSE(std::ifstream(dir + "/bad.json").good());
  EXPECT_FALSE(std::ifstream(dir + "/bad.obj").good());
}

// A shared map: 4 random walkable cells' diagonals, N = 128.
void check_shared_map(const std::string& path, const char* name) {
  WalkableOptions wo;
  wo.cell_size = 16;  // Sauerbraten units (a player is about 15 tall)
  wo.eye = {10, 14};
  expect_only_grazing_and_ties(load_scene(path), wo, 38, 128, name, 60);
}

TEST(Invariance, PandoraDiffersOnlyByGrazingRaysAndTies) {
  VISLIB_REQUIRE_SHARED(shared);
  check_shared_map(shared + "/scenes/sauer_pandora/pandora.obj", "sauer_pandora");
}

TEST(Invariance, Fdm6DiffersOnlyByGrazingRaysAndTies) {
  VISLIB_REQUIRE_SHARED(shared);
  check_shared_map(shared + "/scenes/sauer_fdm6/fdm6.obj", "sauer_fdm6");
}

}  // namespace
}  // namespace vislib
