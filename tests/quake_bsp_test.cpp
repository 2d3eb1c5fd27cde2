// Tests of the Quake map reader and importer (vislib/scene/quake_bsp.h, import_bsp.cpp): small maps
// generated here (tests/support/bsp_writer.h) for triangulation order, the axis conversion, the
// import options, the visibility rows and every kind of bad file; the three LibreQuake maps of
// ../shared/scenes/librequake against their MANIFEST.txt (skipped when ../shared is absent), and
// lqdm1 re-encoded as BSP2 and 2PSB importing to the identical scene.
#include "vislib/scene/quake_bsp.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <set>

#include "tests/scene_builders.h"
#include "tests/support/bsp_writer.h"
#include "tests/support/ray_oracle.h"
#include "tests/test_support.h"
#include "vislib/bake/bake.h"
#include "vislib/bake/bsp_cells.h"
#include "vislib/bake/bsp_portals.h"
#include "vislib/bake/cell_visibility.h"
#include "vislib/base/error.h"
#include "vislib/base/file_util.h"
#include "vislib/base/random.h"
#include "vislib/eval/embree_scene.h"
#include "vislib/kernel/segment_run_cache.h"
#include "vislib/scene/import.h"
#include "vislib/scene/quake_bsp_volumes.h"
#include "vislib/scene/scene_fingerprint.h"

using namespace vislib;
using namespace vislib_test;

namespace {

// Appends face `verts` (map vertex indices, in winding order) with texinfo `ti`; its edges are
// stored forward (surfedge +e) or, with `reversed`, backward (surfedge -e).
void add_face(QuakeBsp& m, const std::vector<uint32_t>& verts, uint32_t ti, bool reversed) {
  BspFace f;
  f.first_edge = uint32_t(m.surfedges.size());
  f.edge_count = uint32_t(verts.size());
  f.texinfo = ti;
  for (size_t k = 0; k < verts.size(); ++k) {
    uint32_t a = verts[k], b = verts[(k + 1) % verts.size()];
    int32_t e = int32_t(m.edges.size());
    m.edges.push_back(reversed ? std::array<uint32_t, 2>{b, a} : std::array<uint32_t, 2>{a, b});
    m.surfedges.push_back(reversed ? -e : e);
  }
  m.faces.push_back(f);
}

// The tiny map: world faces 0 "floor" (a quad at z = 0), 1 "*water1" (a pentagon at z = 32,
// edges stored backward), 2 "sky4" (a triangle); model 1 holds face 3 "door" (a quad). One node
// splits at z = 16: leaf 1 (empty, below; marks faces 0 and 2) and leaf 2 (water, above; marks
// face 1). Leaf 1 sees leaves 1 and 2, leaf 2 only itself.
QuakeBsp tiny_map(BspFormat format = BspFormat::bsp29) {
  QuakeBsp m;
  m.format = format;
  m.entities = "{\n\"classname\" \"worldspawn\"\n}\n";
  m.texture_names = {"floor", "*water1", "sky4", "door"};
  for (uint32_t i = 0; i < 4; ++i) {
    BspTexinfo t;
    t.miptex = i;
    m.texinfo.push_back(t);
  }
  m.vertices = {{0, 0, 0},   {64, 0, 0},   {64, 64, 0},  {0, 64, 0},  {0, 0, 32},
                {64, 0, 32}, {64, 64, 32}, {32, 96, 32}, {0, 64, 32}, {100, 0, 0},
                {120, 0, 0}, {120, 0, 50}, {100, 0, 50}};
  m.edges.push_back({0, 0});  // edge 0 is never used (surfedge 0 has no sign)
  m.surfedges.push_back(0);
  add_face(m, {0, 1, 2, 3}, 0, false);
  add_face(m, {4, 5, 6, 7, 8}, 1, true);
  add_face(m, {0, 1, 4}, 2, false);
  add_face(m, {9, 10, 11, 12}, 3, false);
  m.planes = {{{0, 0, 1}, 16, 2}, {{1, 0, 0}, 110, 0}};
  BspNode n0;
  n0.plane = 0;
  n0.children = {-3, -2};  // front: leaf 2, back: leaf 1
  n0.mins = {0, 0, 0};
  n0.maxs = {64, 96, 32};
  n0.face_count = 0;
  BspNode n1;
  n1.plane = 1;
  n1.children = {-1, -1};
  n1.mins = {100, 0, 0};
  n1.maxs = {120, 0, 50};
  m.nodes = {n0, n1};
  BspLeaf solid;
  solid.contents = kBspContentsSolid;
  BspLeaf below;
  below.contents = kBspContentsEmpty;
  below.visofs = 0;
  below.first_marksurface = 0;
  below.marksurface_count = 2;
  below.maxs = {64, 96, 16};
  BspLeaf above;
  above.contents = kBspContentsWater;
  above.visofs = 1;
  above.first_marksurface = 2;
  above.marksurface_count = 1;
  above.mins = {0, 0, 16};
  above.maxs = {64, 96, 32};
  m.leaves = {solid, below, above};
  m.marksurfaces = {0, 2, 1};
  m.visibility = {0x03, 0x02};
  BspModel world;
  world.maxs = {64, 96, 32};
  world.headnode = {0, 0, 0, 0};
  world.visleafs = 2;
  world.first_face = 0;
  world.face_count = 3;
  BspModel door;
  door.mins = {100, 0, 0};
  door.maxs = {120, 0, 50};
  door.headnode = {1, 0, 0, 0};
  door.first_face = 3;
  door.face_count = 1;
  m.models = {world, door};
  return m;
}

// 17 vis leaves with run-length coded rows of 3 bytes: leaf 1 sees {1}, leaf 5 {5, 17}, leaf 17
// {17}; the others have no row (visofs -1: they see everything).
QuakeBsp rle_map() {
  QuakeBsp m = tiny_map();
  m.leaves.resize(18, m.leaves[1]);
  for (size_t i = 1; i < 18; ++i) {
    m.leaves[i].contents = kBspContentsEmpty;
    m.leaves[i].visofs = -1;
    m.leaves[i].marksurface_count = 0;
  }
  m.visibility = {0x01, 0x00, 0x02, 0x10, 0x00, 0x01, 0x01, 0x00, 0x02, 0x01};
  m.leaves[1].visofs = 0;
  m.leaves[5].visofs = 3;
  m.leaves[17].visofs = 7;
  m.models[0].visleafs = 17;
  return m;
}

std::string write_map(const std::string& dir, const std::string& name, const std::string& bytes) {
  std::string path = dir + "/" + name;
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

// The file offset of lump `l` (its directory entry).
uint32_t lump_offset(const std::string& bytes, int l) {
  const unsigned char* p = reinterpret_cast<const unsigned char*>(bytes.data()) + 4 + 8 * l;
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

// The message of the InputError that parsing `bytes` throws ("" if none).
std::string parse_error(const std::string& bytes) {
  try {
    parse_quake_bsp("map.bsp", bytes);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

Scene load(const std::string& path, BspModels models = BspModels::world,
           BspLiquids liquids = BspLiquids::opaque) {
  LoadOptions o;
  o.bsp_models = models;
  o.bsp_liquids = liquids;
  return load_scene(path, o);
}

}  // namespace

TEST(QuakeBsp, WorldFacesFanTriangulatedInFaceOrderWithOwnVertexBlocks) {
  std::string dir = temp_dir("quake_bsp_order");
  Scene s = load(write_map(dir, "tiny.bsp", encode_bsp(tiny_map())));
  ASSERT_EQ(s.triangle_count(), 6u);  // 2 + 3 + 1: model 1 (the door) is out by default
  ASSERT_EQ(s.vertex_count(), 12u);   // 4 + 5 + 3
  using T = std::array<uint32_t, 3>;
  EXPECT_EQ(s.triangles[0], (T{0, 1, 2}));
  EXPECT_EQ(s.triangles[1], (T{0, 2, 3}));
  EXPECT_EQ(s.triangles[2], (T{4, 5, 6}));
  EXPECT_EQ(s.triangles[3], (T{4, 6, 7}));
  EXPECT_EQ(s.triangles[4], (T{4, 7, 8}));
  EXPECT_EQ(s.triangles[5], (T{9, 10, 11}));
  EXPECT_EQ(s.triangle_object, (std::vector<uint32_t>{0, 0, 1, 1, 1, 2}));
  ASSERT_EQ(s.objects.size(), 3u);
  EXPECT_EQ(s.objects[0].name, "face0_floor");
  EXPECT_EQ(s.objects[1].name, "face1_*water1");
  EXPECT_EQ(s.objects[2].name, "face2_sky4");  // sky faces are kept
}

TEST(QuakeBsp, ZUpBecomesYUpByAProperRotation) {
  std::string dir = temp_dir("quake_bsp_axes");
  Scene s = load(write_map(dir, "tiny.bsp", encode_bsp(tiny_map())));
  // Quake (x, y, z) -> (x, z, -y): vertex 2 of face 0 is (64, 64, 0), the pentagon's fourth corner
  // (32, 96, 32) and the backward-stored edges keep the winding as the face lists it.
  EXPECT_EQ(s.positions[0][2], (Vec3{64, 0, -64}));
  EXPECT_EQ(s.positions[0][4 + 3], (Vec3{32, 32, -96}));
  EXPECT_EQ(s.positions[0][4 + 1], (Vec3{64, 32, 0}));
  // A rotation: lengths and orientation (the sign of the triple product) are kept.
  Vec3 a{1, 2, 3}, b{-4, 5, 0.5}, c{0.25, -1, 7};
  Vec3 ra = quake_to_scene(a), rb = quake_to_scene(b), rc = quake_to_scene(c);
  EXPECT_EQ(dot(cross(ra, rb), rc), dot(cross(a, b), c));
  EXPECT_EQ(length(ra), length(a));
  EXPECT_EQ(scene_to_quake(ra), a);
  // Up is up: Quake +z is scene +y.
  EXPECT_EQ(quake_to_scene({0, 0, 1}), (Vec3{0, 1, 0}));
}

TEST(QuakeBsp, PlayerStartsAreReadFromTheEntitiesInSceneCoordinates) {
  QuakeBsp m = tiny_map();
  m.entities =
      "{\n\"classname\" \"worldspawn\"\n\"wad\" \"x.wad\"\n}\n"
      "{\n\"origin\" \"16 -32 24\"\n\"classname\" \"info_player_start\"\n}\n"
      "{ \"classname\" \"light\" \"origin\" \"0 0 64\" }\n"
      "{ \"classname\" \"info_player_deathmatch\" \"origin\" \"1.5 2 3\" \"angle\" \"90\" }\n"
      "{ \"classname\" \"info_player_coop\" \"origin\" \"1 2\" }\n"  // malformed origin
      "{ \"classname\" \"info_player_start2\" \"origin\" \"4 5 6\" }\n"
      "{ \"classname\" \"info_player_deathmatch\" \"origin\" \"7 8 9\" \n"  // unclosed
      "{ \"classname\" \"info_player_start\" \"origin\" \"0 0 0\" }\n";
  const std::vector<BspEntityPoint> starts = bsp_player_starts(m);
  ASSERT_EQ(starts.size(), 3u);
  EXPECT_EQ(starts[0].classname, "info_player_start");
  EXPECT_EQ(starts[0].origin, quake_to_scene({16, -32, 24}));
  EXPECT_EQ(starts[1].classname, "info_player_deathmatch");
  EXPECT_EQ(starts[1].origin, quake_to_scene({1.5, 2, 3}));
  EXPECT_EQ(starts[2].classname, "info_player_start2");
  m.entities = "{ \"classname\" \"worldspawn\" }";
  EXPECT_TRUE(bsp_player_starts(m).empty());
}

TEST(QuakeBsp, OptionsSelectModelsAndLiquids) {
  std::string dir = temp_dir("quake_bsp_options");
  std::string path = write_map(dir, "tiny.bsp", encode_bsp(tiny_map()));
  Scene all = load(path, BspModels::all);
  ASSERT_EQ(all.triangle_count(), 8u);
  EXPECT_EQ(all.objects.back().name, "face3_door");
  Scene omit = load(path, BspModels::world, BspLiquids::omit);
  ASSERT_EQ(omit.triangle_count(), 3u);
  EXPECT_EQ(omit.objects[1].name, "face2_sky4");
  EXPECT_EQ(omit.positions[0][4], (Vec3{0, 0, 0}));  // the sky triangle's first corner
  // See-through liquids: the same triangles as opaque ones, on see-through objects ('*' only).
  Scene opaque = load(path);
  Scene see = load(path, BspModels::world, BspLiquids::see_through);
  ASSERT_EQ(see.triangle_count(), opaque.triangle_count());
  ASSERT_EQ(see.objects.size(), opaque.objects.size());
  size_t liquid_objects = 0;
  for (const auto& o : see.objects) {
    const bool liquid = o.name.find("_*") != std::string::npos;
    EXPECT_EQ(o.see_through, liquid) << o.name;
    liquid_objects += liquid;
  }
  EXPECT_GT(liquid_objects, 0u);
  EXPECT_EQ(opaque.has_see_through(), false);
  // The face -> triangle table behind both.
  QuakeBsp m = tiny_map();
  LoadOptions o;
  o.bsp_liquids = BspLiquids::omit;
  o.bsp_models = BspModels::all;
  auto ft = bsp_face_triangles(m, o);
  ASSERT_EQ(ft.size(), 4u);
  EXPECT_TRUE(ft[0].imported && ft[0].first_triangle == 0 && ft[0].triangle_count == 2);
  EXPECT_FALSE(ft[1].imported);
  EXPECT_EQ(ft[1].triangle_count, 0u);
  EXPECT_TRUE(ft[2].imported && ft[2].first_triangle == 2 && ft[2].triangle_count == 1);
  EXPECT_TRUE(ft[3].imported && ft[3].first_triangle == 3 && ft[3].triangle_count == 2);
}

// load_bsp_scene reads the file once for both uses: the scene, warnings and errors of load_scene,
// and the map of read_quake_bsp.
TEST(QuakeBsp, LoadBspSceneGivesTheSceneOfLoadSceneAndTheMapItImported) {
  std::string dir = temp_dir("quake_bsp_load_once");
  QuakeBsp m = tiny_map();
  m.faces[0].edge_count = 2;  // a face of fewer than 3 edges: a warning
  const std::string path = write_map(dir, "tiny.bsp", encode_bsp(m));
  for (BspModels models : {BspModels::world, BspModels::all}) {
    LoadOptions o;
    o.bsp_models = models;
    std::vector<std::string> warnings, once_warnings;
    const Scene scene = load_scene(path, o, &warnings);
    QuakeBsp map;
    const Scene once = load_bsp_scene(path, o, map, &once_warnings);
    EXPECT_EQ(scene_fingerprint(once), scene_fingerprint(scene));
    EXPECT_EQ(once.positions, scene.positions);
    EXPECT_EQ(once_warnings, warnings);
    ASSERT_EQ(warnings.size(), 1u);
    const QuakeBsp read = read_quake_bsp(path);
    EXPECT_EQ(map.entities, read.entities);
    EXPECT_EQ(map.visibility, read.visibility);
    EXPECT_EQ(map.marksurfaces, read.marksurfaces);
    EXPECT_EQ(map.surfedges, read.surfedges);
    EXPECT_EQ(map.leaves.size(), read.leaves.size());
    EXPECT_EQ(map.nodes.size(), read.nodes.size());
    EXPECT_EQ(map.faces.size(), read.faces.size());
    EXPECT_EQ(map.models.size(), read.models.size());
  }
  // A bad map: the same error as load_scene's.
  const std::string bad = write_map(dir, "bad.bsp", encode_bsp(tiny_map()).substr(0, 50));
  std::string expected, got;
  try {
    load_scene(bad);
  } catch (const InputError& e) {
    expected = e.what();
  }
  QuakeBsp map;
  try {
    load_bsp_scene(bad, {}, map);
  } catch (const InputError& e) {
    got = e.what();
  }
  EXPECT_NE(expected, "");
  EXPECT_EQ(got, expected);
}

TEST(QuakeBsp, EveryFormatReadsBackTheSameMap) {
  for (BspFormat f : {BspFormat::bsp29, BspFormat::bsp2, BspFormat::bsp2rmq}) {
    QuakeBsp m = parse_quake_bsp("map.bsp", encode_bsp(tiny_map(f)));
    EXPECT_EQ(m.format, f);
    EXPECT_EQ(m.faces.size(), 4u);
    EXPECT_EQ(m.nodes[0].children, (std::array<int32_t, 2>{-3, -2}));
    EXPECT_EQ(m.nodes[1].children, (std::array<int32_t, 2>{-1, -1}));
    EXPECT_EQ(m.leaves[2].contents, kBspContentsWater);
    EXPECT_EQ(m.leaves[2].mins, (std::array<float, 3>{0, 0, 16}));
    EXPECT_EQ(m.marksurfaces, (std::vector<uint32_t>{0, 2, 1}));
    EXPECT_EQ(m.face_vertices(1), (std::vector<uint32_t>{4, 5, 6, 7, 8}));
    EXPECT_EQ(m.texture_names[1], "*water1");
    EXPECT_EQ(m.entities, tiny_map().entities);
  }
}

TEST(QuakeBsp, VisibilityRowsDecodeRunLengthsAndBitKIsLeafKPlusOne) {
  QuakeBsp m = parse_quake_bsp("map.bsp", encode_bsp(rle_map()));
  EXPECT_EQ(bsp_leaf_sees(m, 1), (std::vector<uint32_t>{1}));
  EXPECT_EQ(bsp_leaf_sees(m, 5), (std::vector<uint32_t>{5, 17}));
  EXPECT_EQ(bsp_leaf_sees(m, 17), (std::vector<uint32_t>{17}));
  EXPECT_EQ(bsp_leaf_sees(m, 2).size(), 17u);  // no row: everything
  EXPECT_TRUE(bsp_leaf_sees(m, 0).empty());    // the solid leaf has no row
}

TEST(QuakeBsp, DrawnTrianglesAreTheFacesMarkedInEverySeenLeaf) {
  QuakeBsp m = parse_quake_bsp("map.bsp", encode_bsp(tiny_map()));
  EXPECT_EQ(bsp_leaf_sees(m, 1), (std::vector<uint32_t>{1, 2}));
  EXPECT_EQ(bsp_leaf_sees(m, 2), (std::vector<uint32_t>{2}));
  EXPECT_EQ(bsp_leaf_drawn_faces(m, 1), (std::vector<uint32_t>{0, 1, 2}));
  EXPECT_EQ(bsp_leaf_drawn_faces(m, 2), (std::vector<uint32_t>{1}));
  LoadOptions o;
  auto ft = bsp_face_triangles(m, o);
  EXPECT_EQ(bsp_leaf_drawn_triangles(m, ft, 1), (std::vector<uint32_t>{0, 1, 2, 3, 4, 5}));
  EXPECT_EQ(bsp_leaf_drawn_triangles(m, ft, 2), (std::vector<uint32_t>{2, 3, 4}));
  o.bsp_liquids = BspLiquids::omit;
  ft = bsp_face_triangles(m, o);
  EXPECT_EQ(bsp_leaf_drawn_triangles(m, ft, 1), (std::vector<uint32_t>{0, 1, 2}));
  EXPECT_TRUE(bsp_leaf_drawn_triangles(m, ft, 2).empty());
}

TEST(QuakeBsp, PointLeafWalksTheTreeFrontWhenStrictlyInFront) {
  QuakeBsp m = parse_quake_bsp("map.bsp", encode_bsp(tiny_map()));
  EXPECT_EQ(bsp_point_leaf(m, {10, 10, 5}), 1u);
  EXPECT_EQ(bsp_point_leaf(m, {10, 10, 20}), 2u);
  EXPECT_EQ(bsp_point_leaf(m, {10, 10, 16}), 1u);  // on the plane: back, as the engine
}

TEST(QuakeBsp, LeafVolumesAreTheBoundsClippedByThePathPlanes) {
  QuakeBsp m = parse_quake_bsp("map.bsp", encode_bsp(tiny_map()));
  std::vector<BspLeafPiece> pieces = bsp_leaf_pieces(m);
  ASSERT_EQ(pieces.size(), 2u);
  EXPECT_EQ(pieces[0].leaf, 2u);  // front child first: above z = 16
  EXPECT_EQ(pieces[1].leaf, 1u);
  // Corners come from clipping large squares: exact up to rounding (1e-9 of the sizes here).
  EXPECT_NEAR(pieces[0].volume.volume(), 64.0 * 96 * 16, 1e-6);
  EXPECT_NEAR(pieces[1].volume.volume(), 64.0 * 96 * 16, 1e-6);
  Box3 b = pieces[0].volume.bounds();
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(b.min[k], (Vec3{0, 0, 16})[k], 1e-9);
    EXPECT_NEAR(b.max[k], (Vec3{64, 96, 32})[k], 1e-9);
  }
  EXPECT_EQ(pieces[0].volume.faces.size(), 6u);
  EXPECT_EQ(pieces[1].volume.halfspaces.size(), 7u);  // the box's six and the node's plane
}

// The view region keeps kBspLeafInset from every plane: the tiny map's leaves are 64 x 96 x 16
// boxes, so their regions are 62 x 94 x 14. A slab 1/16 unit thick is too thin for the full inset
// and takes the largest halving that leaves a volume and keeps the near clearance (1/32 would
// leave exactly none, 1/64 is nearer the walls than sqrt(3) near), else the clearance itself. A
// sheet 1/64 thick, thinner than twice the clearance, is inset by half its largest inset (its
// half thickness) and clips its near distance so that its eyes still clear the walls.
TEST(QuakeBsp, ViewRegionKeepsTheNearClearanceFromTheLeafsWalls) {
  QuakeBsp m = parse_quake_bsp("map.bsp", encode_bsp(tiny_map()));
  const std::vector<BspLeafPiece> pieces = bsp_leaf_pieces(m);
  const BspViewRegion r = bsp_leaf_view_region(pieces[0].volume, kDefaultNear);
  EXPECT_EQ(r.inset, kBspLeafInset);
  EXPECT_EQ(r.near_limit, std::numeric_limits<double>::infinity());
  EXPECT_NEAR(r.volume.volume(), 62.0 * 94 * 14, 1e-6);
  const Box3 b = r.volume.bounds();
  EXPECT_NEAR(b.min.z, 17, 1e-9);
  EXPECT_NEAR(b.max.z, 31, 1e-9);

  const double clearance = kNearClearanceFactor * kDefaultNear;
  std::vector<HalfSpace> slab = {{{1, 0, 0}, 10}, {{-1, 0, 0}, 0},     {{0, 1, 0}, 10},
                                 {{0, -1, 0}, 0}, {{0, 0, 1}, 0.0625}, {{0, 0, -1}, 0}};
  ConvexPolytope thin = inset_polytope(ConvexPolytope{slab, {}}, 0);
  ASSERT_FALSE(thin.empty());
  const BspViewRegion t = bsp_leaf_view_region(thin, kDefaultNear);
  EXPECT_EQ(t.inset, clearance);
  EXPECT_EQ(t.near_limit, std::numeric_limits<double>::infinity());
  EXPECT_NEAR(t.volume.volume(),
              (10 - 2 * clearance) * (10 - 2 * clearance) * (0.0625 - 2 * clearance), 1e-9);
  // A larger near distance takes a larger clearance: the slab is then too thin for it.
  EXPECT_LT(bsp_leaf_view_region(thin, 0.02).near_limit, 0.02);
  std::vector<HalfSpace> sheet = slab;
  sheet[4].offset = 1.0 / 64;
  const BspViewRegion z =
      bsp_leaf_view_region(inset_polytope(ConvexPolytope{sheet, {}}, 0), kDefaultNear);
  EXPECT_NEAR(z.inset, 1.0 / 256, 1e-12);
  EXPECT_NEAR(z.near_limit, z.inset / kNearClearanceFactor, 1e-15);
  EXPECT_LT(z.near_limit, kDefaultNear);
  const Box3 zb = z.volume.bounds();
  EXPECT_GE(zb.min.z, z.inset - 1e-12);
  EXPECT_LE(zb.max.z, 1.0 / 64 - z.inset + 1e-12);
}

TEST(QuakeBsp, BadFilesNameTheLumpAndTheByte) {
  const std::string good = encode_bsp(tiny_map());
  auto expect = [](const std::string& msg, const std::string& part) {
    EXPECT_NE(msg.find(part), std::string::npos) << "'" << part << "' not in: " << msg;
  };
  // Truncated: the header, then the last lump (models, directory entry at byte 4 + 14 * 8).
  expect(parse_error(good.substr(0, 50)), "header: truncated");
  std::string msg = parse_error(good.substr(0, good.size() - 10));
  expect(msg, "models lump (directory entry at byte 116)");
  expect(msg, "do not lie within the file");
  // Unsupported versions.
  std::string v30 = good;
  v30[0] = 30;
  expect(parse_error(v30), "BSP version 30 (Half-Life) is not supported");
  // A face's edge range out of range: face 1 is the second 20-byte record of the faces lump.
  QuakeBsp m = tiny_map();
  m.faces[1].first_edge = 1000;
  std::string bad = encode_bsp(m);
  msg = parse_error(bad);
  expect(msg, "faces lump (at byte " + std::to_string(lump_offset(bad, 7)));
  expect(msg, "face 1: edges 1000 + 5 out of range (17 surfedges)");
  expect(msg, "(byte " + std::to_string(lump_offset(bad, 7) + 20) + ")");
  // A marksurface naming a face that does not exist.
  m = tiny_map();
  m.marksurfaces[2] = 99;
  bad = encode_bsp(m);
  msg = parse_error(bad);
  expect(msg, "marksurfaces lump");
  expect(msg, "marksurface 2: face 99 out of range");
  expect(msg, "(byte " + std::to_string(lump_offset(bad, 11) + 4) + ")");
  // A surfedge, an edge and a texinfo out of range.
  m = tiny_map();
  m.surfedges[3] = -77;
  expect(parse_error(encode_bsp(m)), "surfedge 3: edge -77 out of range");
  m = tiny_map();
  m.edges[2][1] = 13;
  expect(parse_error(encode_bsp(m)), "edge 2: vertex 13 out of range (13 vertices)");
  m = tiny_map();
  m.texinfo[3].miptex = 4;
  expect(parse_error(encode_bsp(m)), "texinfo 3: texture 4 out of range (4 textures)");
  // A visibility row whose zero run passes its end, and a row offset outside the lump.
  m = tiny_map();
  m.visibility = {0x03, 0x00, 0x05};
  bad = encode_bsp(m);
  msg = parse_error(bad);
  expect(msg, "visibility lump");
  expect(msg, "the row of leaf 2 (at lump offset 1): a run of 5 zero bytes passes the row's end");
  expect(msg, "(byte " + std::to_string(lump_offset(bad, 4) + 1) + ")");
  m = tiny_map();
  m.leaves[2].visofs = 2;
  expect(parse_error(encode_bsp(m)), "leaf 2: visibility offset 2 is outside the visibility lump");
  // A cyclic node tree and a child leaf out of range (BSP2: 32-bit children).
  m = tiny_map();
  m.nodes[0].children[0] = 0;
  expect(parse_error(encode_bsp(m)), "node 0 is reached twice");
  m = tiny_map(BspFormat::bsp2);
  m.nodes[0].children[1] = -9;
  expect(parse_error(encode_bsp(m)), "node 0: child leaf 8 out of range (3 leaves)");
  // A lump that is not a whole number of records (the planes' length one byte longer).
  bad = good;
  bad[4 + 8 * 1 + 4] = char(uint8_t(bad[4 + 8 * 1 + 4]) + 1);
  expect(parse_error(bad), "planes lump");
  expect(parse_error(bad), "is not a whole number of 20-byte records");
  // No world model; model 0's visleafs out of range.
  m = tiny_map();
  m.models.clear();
  expect(parse_error(encode_bsp(m)), "no models");
  m = tiny_map();
  m.models[0].visleafs = 3;
  expect(parse_error(encode_bsp(m)), "model 0: visleafs 3 out of range");
}

TEST(QuakeBsp, CliInfoReportsQuakeUnitsAndExitsTwoOnABadMap) {
  std::string dir = temp_dir("quake_bsp_cli");
  std::string good = write_map(dir, "tiny.bsp", encode_bsp(tiny_map()));
  std::string out;
  ASSERT_EQ(run_pvs("info " + good, &out), 0) << out;
  EXPECT_NE(out.find("Quake units"), std::string::npos) << out;
  EXPECT_NE(out.find("(x, y, z) -> (x, z, -y)"), std::string::npos) << out;
  ASSERT_EQ(run_pvs("info --json --bsp-models all " + good, &out), 0) << out;
  EXPECT_NE(out.find("\"triangles\": 8"), std::string::npos) << out;
  ASSERT_EQ(run_pvs("info --json --bsp-liquids omit " + good, &out), 0) << out;
  EXPECT_NE(out.find("\"triangles\": 3"), std::string::npos) << out;
  ASSERT_EQ(run_pvs("info --json --bsp-liquids see-through " + good, &out), 0) << out;
  EXPECT_EQ(out.find("\"see_through_triangles\": 0"), std::string::npos) << out;
  QuakeBsp m = tiny_map();
  m.faces[1].first_edge = 1000;
  std::string bad = write_map(dir, "bad.bsp", encode_bsp(m));
  EXPECT_EQ(run_pvs("info " + bad, &out), 2) << out;
  EXPECT_NE(out.find("bad.bsp: faces lump (at byte"), std::string::npos) << out;
  std::string full = encode_bsp(tiny_map());
  std::string cut = write_map(dir, "cut.bsp", full.substr(0, full.size() - 10));
  EXPECT_EQ(run_pvs("info " + cut, &out), 2) << out;
  EXPECT_NE(out.find("cut.bsp: header: models lump"), std::string::npos) << out;
}

// The fuzz target's committed seeds (fuzz/corpus/bsp) are these generated maps; with
// VISLIB_WRITE_BSP_SEEDS=1 the test rewrites them instead.
TEST(QuakeBsp, FuzzSeedsAreTheGeneratedMaps) {
  QuakeBsp broken = tiny_map();
  broken.visibility = {0x03, 0x00, 0x05};
  const std::vector<std::pair<std::string, std::string>> seeds = {
      {"tiny29.bsp", encode_bsp(tiny_map(BspFormat::bsp29))},
      {"tiny2.bsp", encode_bsp(tiny_map(BspFormat::bsp2))},
      {"tiny2psb.bsp", encode_bsp(tiny_map(BspFormat::bsp2rmq))},
      {"rle29.bsp", encode_bsp(rle_map())},
      {"badrow29.bsp", encode_bsp(broken)}};
  const std::string dir = source_dir() + "/fuzz/corpus/bsp";
  const char* write = std::getenv("VISLIB_WRITE_BSP_SEEDS");
  for (const auto& [name, bytes] : seeds) {
    if (write && std::string(write) == "1") {
      std::filesystem::create_directories(dir);
      write_map(dir, name, bytes);
    }
    ASSERT_TRUE(std::filesystem::exists(dir + "/" + name)) << name;
    EXPECT_EQ(read_file(dir + "/" + name), bytes) << name << " differs from the generated map";
  }
}

// The three LibreQuake maps against ../shared/scenes/librequake/MANIFEST.txt and the facts of the
// engine's rules: every leaf sees itself, leaf 0 is the only solid leaf, the mean visible-leaf
// shares, what e1m2's empty leaves see, e2m3's faces in no leaf's marksurfaces.
struct ManifestMap {
  const char* name;
  size_t leaves, visleafs, faces, world_faces, models;
  double share;
};

TEST(QuakeBspLibreQuake, MapsMatchTheManifestAndTheEngineRules) {
  const ManifestMap maps[] = {{"lqdm1.bsp", 348, 321, 1493, 1455, 4, 0.502},
                              {"e1m2.bsp", 3333, 2599, 9927, 8731, 85, 0.202},
                              {"e2m3.bsp", 2846, 1872, 11154, 9378, 128, 0.140}};
  bool any = false;
  for (const auto& mm : maps) {
    auto path = librequake(mm.name);
    if (!path) continue;
    any = true;
    SCOPED_TRACE(mm.name);
    QuakeBsp m = read_quake_bsp(*path);
    EXPECT_EQ(m.format, BspFormat::bsp29);
    EXPECT_EQ(m.leaves.size(), mm.leaves);
    EXPECT_EQ(m.visleaf_count(), mm.visleafs);
    EXPECT_EQ(m.faces.size(), mm.faces);
    EXPECT_EQ(m.models.size(), mm.models);
    EXPECT_EQ(m.models[0].face_count, mm.world_faces);
    const uint32_t n = m.visleaf_count();
    double share = 0;
    size_t empty = 0, empty_sees_liquid = 0, empty_sees_sky = 0;
    for (uint32_t l = 0; l < m.leaves.size(); ++l)
      EXPECT_EQ(m.leaves[l].contents == kBspContentsSolid, l == 0) << "leaf " << l;
    for (uint32_t l = 1; l <= n; ++l) {
      std::vector<uint32_t> sees = bsp_leaf_sees(m, l);
      EXPECT_TRUE(std::binary_search(sees.begin(), sees.end(), l)) << "leaf " << l;
      share += double(sees.size()) / n;
      if (m.leaves[l].contents != kBspContentsEmpty) continue;
      ++empty;
      bool liquid = false, sky = false;
      for (uint32_t k : sees) {
        liquid |= bsp_contents_liquid(m.leaves[k].contents);
        sky |= m.leaves[k].contents == kBspContentsSky;
      }
      empty_sees_liquid += liquid;
      empty_sees_sky += sky;
    }
    EXPECT_NEAR(share / n, mm.share, 0.0005);
    std::vector<uint8_t> marked(m.faces.size(), 0);
    for (uint32_t f : m.marksurfaces) marked[f] = 1;
    size_t unmarked = 0;
    for (uint32_t k = 0; k < m.models[0].face_count; ++k)
      unmarked += !marked[m.models[0].first_face + k];
    if (std::string(mm.name) == "e1m2.bsp") {
      EXPECT_EQ(empty, 2473u);
      EXPECT_EQ(empty_sees_liquid, 1694u);
      EXPECT_EQ(empty_sees_sky, 0u);
    }
    const size_t expected_unmarked = std::string(mm.name) == "e2m3.bsp" ? 93 : 0;
    EXPECT_EQ(unmarked, expected_unmarked);
  }
  if (!any) GTEST_SKIP() << "../shared/scenes/librequake is absent";
}

TEST(QuakeBspLibreQuake, Lqdm1ImportsItsWorldFacesAndDrawnTrianglesFollowTheFaces) {
  auto path = librequake("lqdm1.bsp");
  if (!path) GTEST_SKIP() << "../shared/scenes/librequake is absent";
  QuakeBsp m = read_quake_bsp(*path);
  Scene s = load_scene(*path);
  size_t expected = 0;
  for (uint32_t k = 0; k < m.models[0].face_count; ++k)
    expected += std::max<uint32_t>(m.faces[m.models[0].first_face + k].edge_count, 2) - 2;
  EXPECT_EQ(s.triangle_count(), expected);
  EXPECT_EQ(s.objects.size(), 1455u);
  auto ft = bsp_face_triangles(m, LoadOptions{});
  // Each drawn triangle's object is the face it came from (the object name carries the index).
  for (uint32_t leaf : {1u, 100u, 321u}) {
    std::vector<uint32_t> faces = bsp_leaf_drawn_faces(m, leaf);
    std::vector<uint32_t> tris = bsp_leaf_drawn_triangles(m, ft, leaf);
    std::vector<uint32_t> from;
    for (uint32_t t : tris) {
      const std::string& name = s.objects[s.triangle_object[t]].name;
      from.push_back(uint32_t(std::stoul(name.substr(4, name.find('_') - 4))));
    }
    from.erase(std::unique(from.begin(), from.end()), from.end());
    EXPECT_EQ(from, faces) << "leaf " << leaf;
  }
}

TEST(QuakeBspLibreQuake, Lqdm1ReencodedAsBsp2And2psbImportsToTheIdenticalScene) {
  auto path = librequake("lqdm1.bsp");
  if (!path) GTEST_SKIP() << "../shared/scenes/librequake is absent";
  const std::string dir = temp_dir("quake_bsp_bsp2");
  const QuakeBsp m = read_quake_bsp(*path);
  for (BspModels models : {BspModels::world, BspModels::all}) {
    const Scene original = load(*path, models);
    for (BspFormat f : {BspFormat::bsp2, BspFormat::bsp2rmq, BspFormat::bsp29}) {
      QuakeBsp re = m;
      re.format = f;
      const std::string p = write_map(dir, "lqdm1_re.bsp", encode_bsp(re));
      const Scene s = load(p, models);
      EXPECT_EQ(s.positions, original.positions);
      EXPECT_EQ(s.triangles, original.triangles);
      EXPECT_EQ(s.triangle_object, original.triangle_object);
      ASSERT_EQ(s.objects.size(), original.objects.size());
      for (size_t i = 0; i < s.objects.size(); ++i)
        ASSERT_EQ(s.objects[i].name, original.objects[i].name);
      const QuakeBsp back = read_quake_bsp(p);
      EXPECT_EQ(back.format, f);
      EXPECT_EQ(back.visibility, m.visibility);
      for (uint32_t l = 0; l < m.leaves.size(); l += 7)
        EXPECT_EQ(bsp_leaf_sees(back, l), bsp_leaf_sees(m, l)) << "leaf " << l;
    }
  }
}

namespace {

// True when `p` lies inside every half-space of `v` by more than `margin` (units).
bool strictly_inside(const ConvexPolytope& v, Vec3 p, double margin) {
  for (const HalfSpace& h : v.halfspaces)
    if (dot(h.normal, p) - h.offset > -margin * length(h.normal)) return false;
  return true;
}

}  // namespace

// Leaf volumes of lqdm1 (quake_bsp_volumes.h): one piece per vis leaf, the pieces' volumes sum to
// the world box's, random points of each piece walk down the tree to its leaf, and no sampled point
// of one piece lies strictly inside another (an independent check of disjointness: the half-spaces
// of the other piece, not the tree walk).
TEST(QuakeBspLibreQuake, Lqdm1LeafVolumesPartitionTheBoundsAndPointsWalkToTheirLeaf) {
  auto path = librequake("lqdm1.bsp");
  if (!path) GTEST_SKIP() << "../shared/scenes/librequake is absent";
  const QuakeBsp m = read_quake_bsp(*path);
  const std::vector<BspLeafPiece> pieces = bsp_leaf_pieces(m);
  std::vector<int> count(m.leaves.size(), 0);
  double sum = 0;
  for (const auto& p : pieces) {
    ++count[p.leaf];
    sum += p.volume.volume();
    if (p.leaf != 0) {
      EXPECT_FALSE(p.volume.empty()) << "leaf " << p.leaf;
    }
  }
  for (uint32_t l = 1; l <= m.visleaf_count(); ++l) EXPECT_EQ(count[l], 1) << "leaf " << l;
  const auto& w = m.models[0];
  const double box =
      double(w.maxs[0] - w.mins[0]) * double(w.maxs[1] - w.mins[1]) * double(w.maxs[2] - w.mins[2]);
  EXPECT_NEAR(sum / box, 1.0, 1e-12);

  std::mt19937_64 rng(36);
  std::uniform_real_distribution<double> u01(0, 1);
  std::vector<std::pair<Vec3, size_t>> samples;  // (point, piece)
  for (size_t i = 0; i < pieces.size(); ++i) {
    const auto& p = pieces[i];
    if (p.volume.empty()) continue;
    std::vector<Vec3> corners;
    for (const auto& f : p.volume.faces) corners.insert(corners.end(), f.begin(), f.end());
    for (int k = 0; k < 10; ++k) {  // a random convex combination of the corners
      Vec3 q{0, 0, 0};
      double total = 0;
      for (const Vec3& c : corners) {
        double wgt = std::pow(u01(rng), 3);
        q = q + c * wgt;
        total += wgt;
      }
      q = q * (1 / total);
      samples.push_back({q, i});
      if (p.leaf != 0) {
        EXPECT_EQ(bsp_point_leaf(m, q), p.leaf) << "piece " << i;
      }
    }
  }
  std::vector<Box3> boxes;
  for (const auto& p : pieces) boxes.push_back(p.volume.bounds());
  size_t overlaps = 0;
  for (const auto& [q, i] : samples)
    for (size_t j = 0; j < pieces.size(); ++j) {
      if (j == i || pieces[j].volume.empty()) continue;
      const Box3& b = boxes[j];
      if (q.x < b.min.x || q.y < b.min.y || q.z < b.min.z || q.x > b.max.x || q.y > b.max.y ||
          q.z > b.max.z)
        continue;
      overlaps += strictly_inside(pieces[j].volume, q, 1e-9);
    }
  EXPECT_EQ(overlaps, 0u);
  std::printf("lqdm1: %zu pieces (%d of the solid leaf 0), %zu sampled points\n", pieces.size(),
              count[0], samples.size());
}

namespace {

// Rays from random eyes inside every non-sky vis leaf of a map against the triangles the engine
// draws from that leaf (bsp_leaf_drawn_triangles): Embree first hits, each one outside the set
// re-cast by the double-precision brute-force first hit.
struct RayCheck {
  size_t leaves = 0, rays = 0, no_hit = 0, recast = 0, ambiguous = 0;
  std::vector<std::pair<uint32_t, uint32_t>> misses;  // (leaf, triangle) hit but not drawn
  std::vector<uint32_t> missed_faces;                 // their map faces, sorted, unique
  std::map<std::string, size_t> ambiguous_textures;   // texture of Embree's hit where ambiguous
  double seconds = 0;
};

RayCheck check_rays(const std::string& path, int eyes, int dirs, uint64_t seed) {
  RayCheck out;
  const auto t0 = std::chrono::steady_clock::now();
  const QuakeBsp m = read_quake_bsp(path);
  const Scene scene = load_scene(path);
  const auto faces = bsp_face_triangles(m, LoadOptions{});
  std::vector<uint32_t> face_of(scene.triangle_count());
  for (uint32_t f = 0; f < faces.size(); ++f)
    for (uint32_t k = 0; k < faces[f].triangle_count; ++k) face_of[faces[f].first_triangle + k] = f;
  const Box3 box = scene.bounds();
  const EmbreeScene embree(scene, 0, (box.min + box.max) * 0.5);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u01(0, 1);
  std::normal_distribution<double> gauss(0, 1);
  const double z_near = 0.01;  // Quake units
  for (const auto& p : bsp_leaf_pieces(m)) {
    if (p.leaf == 0 || p.volume.empty() || m.leaves[p.leaf].contents == kBspContentsSky) continue;
    ++out.leaves;
    const std::vector<uint32_t> drawn = bsp_leaf_drawn_triangles(m, faces, p.leaf);
    std::vector<Vec3> corners;
    for (const auto& f : p.volume.faces) corners.insert(corners.end(), f.begin(), f.end());
    for (int e = 0; e < eyes; ++e) {
      Vec3 q{0, 0, 0};
      double total = 0;
      for (const Vec3& c : corners) {
        double wgt = std::pow(u01(rng), 3);
        q = q + c * wgt;
        total += wgt;
      }
      const Vec3 eye = quake_to_scene(q * (1 / total));
      for (int r = 0; r < dirs; ++r) {
        const Vec3 dir{gauss(rng), gauss(rng), gauss(rng)};
        ++out.rays;
        const Hit h = embree.first_hit(eye, dir, z_near);
        if (h.tri != kNoHit && std::binary_search(drawn.begin(), drawn.end(), h.tri)) continue;
        ++out.recast;
        const OracleSample exact = brute_force_first_hit(scene, 0, eye, dir, z_near);
        if (exact.ambiguous) {
          ++out.ambiguous;
          if (h.tri != kNoHit) ++out.ambiguous_textures[m.face_texture(face_of[h.tri])];
        } else if (exact.tri == kNoHit) {
          ++out.no_hit;
        } else if (!std::binary_search(drawn.begin(), drawn.end(), exact.tri)) {
          out.misses.push_back({p.leaf, exact.tri});
          out.missed_faces.push_back(face_of[exact.tri]);
        }
      }
    }
  }
  std::sort(out.missed_faces.begin(), out.missed_faces.end());
  out.missed_faces.erase(std::unique(out.missed_faces.begin(), out.missed_faces.end()),
                         out.missed_faces.end());
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

void print(const char* map, const RayCheck& c) {
  std::printf(
      "%s: %zu rays from %zu leaves, %zu re-cast, %zu ambiguous, %zu without a hit, %zu "
      "hits the map's vis does not draw (%zu faces), %.2f s\n",
      map, c.rays, c.leaves, c.recast, c.ambiguous, c.no_hit, c.misses.size(),
      c.missed_faces.size(), c.seconds);
}

}  // namespace

// The map's own sets, held against rays: from random eyes inside every vis leaf of lqdm1 (a sealed
// map without sky or liquids), random rays' first hits (Embree; each hit outside the set re-cast by
// the double-precision brute-force first hit) must be triangles the engine draws from that leaf.
// Checks the face -> triangle ids rule, the axis conversion and the leaf volumes together against
// the compiler's conservative vis. Ambiguous re-casts (edges, grazing hits) are skipped, counted.
// Budget: well under a second (Release).
TEST(QuakeBspLibreQuake, Lqdm1RaysFromEveryLeafHitOnlyTrianglesTheEngineDraws) {
  auto path = librequake("lqdm1.bsp");
  if (!path) GTEST_SKIP() << "../shared/scenes/librequake is absent";
  const RayCheck c = check_rays(*path, 4, 64, 3601);
  print("lqdm1", c);
  EXPECT_EQ(c.leaves, 321u);
  EXPECT_EQ(c.no_hit, 0u);  // the map is sealed
  EXPECT_LE(c.ambiguous, c.rays / 1000);
  for (const auto& [leaf, tri] : c.misses)
    ADD_FAILURE() << "leaf " << leaf << " sees triangle " << tri
                  << ", which the engine does not draw from there";
}

// The same on e1m2 and e2m3 (opt-in: VISLIB_LONG_TESTS=1; about a minute and a half here). A
// sampled check with failure-rate thresholds: unambiguous hits the map's vis does not draw, and
// rays that leave the map through a crack, each at most 1 in 10^4 rays. Ambiguous re-casts are
// counted and their textures printed, not bounded: these maps hold coplanar face pairs (a face on
// each side of a sky or liquid boundary) that Embree may take either of.
TEST(QuakeBspLibreQuake, LongRaysFromEveryLeafOfE1m2AndE2m3) {
  VISLIB_REQUIRE_LONG_TESTS();
  for (const char* name : {"e1m2.bsp", "e2m3.bsp"}) {
    auto path = librequake(name);
    if (!path) GTEST_SKIP() << "../shared/scenes/librequake is absent";
    const RayCheck c = check_rays(*path, 4, 64, 3602);
    print(name, c);
    EXPECT_LE(c.no_hit, c.rays / 10000) << name;
    EXPECT_LE(c.misses.size(), c.rays / 10000) << name;
    std::printf("%s: missed faces:", name);
    for (uint32_t f : c.missed_faces) std::printf(" %u", f);
    std::printf("\n%s: textures of ambiguous hits:", name);
    for (const auto& [tex, k] : c.ambiguous_textures) std::printf(" %s %zu", tex.c_str(), k);
    std::printf("\n");
  }
}

// ---- Baking a map over its own leaves (vislib/bake/bsp_cells.h: bsp_leaf_cells) ----

namespace {

// A random point of convex polytope `v` (Quake coordinates): a random convex combination of its
// corners, weighted towards a few of them so that points near faces and edges come up too.
Vec3 random_point(const ConvexPolytope& v, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u01(0, 1);
  Vec3 q{0, 0, 0};
  double total = 0;
  for (const auto& f : v.faces)
    for (const Vec3& c : f) {
      double wgt = std::pow(u01(rng), 3);
      q = q + c * wgt;
      total += wgt;
    }
  return q * (1 / total);
}

// Bakes `cells` of `scene` on `threads` threads into `path`; the file's bytes.
std::string bake_file(const Scene& scene, const ViewCells& cells, const BakeSettings& s,
                      const std::string& path, int threads) {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
  bake(scene, cells, s, {}, {path, path + ".ckpt", false});
  return read_file(path);
}

// The tiny map's two leaves baked on 1 and 2 threads (the same bytes, checked) and once more for
// the report; each cell's set is checked against bake_cell, which bakes it alone.
struct TwoLeafBake {
  std::string bytes;
  BakeReport report;
};
TwoLeafBake bake_two_leaves(const Scene& scene, const ViewCells& cells, const BakeSettings& s,
                            const std::string& dir) {
  TwoLeafBake out;
  out.bytes = bake_file(scene, cells, s, dir + "/one.pvs", 1);
  EXPECT_EQ(out.bytes, bake_file(scene, cells, s, dir + "/two.pvs", 2));
  out.report = bake(scene, cells, s, {}, {dir + "/r.pvs", dir + "/r.ckpt", false});
  pvs::Reader r = pvs::Reader::from_memory(out.bytes);
  for (uint32_t c = 0; c < 2; ++c) EXPECT_EQ(r.read_cell(c), bake_cell(scene, cells, c, s));
  return out;
}

// The view region of each cell of `cells` (Quake coordinates), by cell.
std::vector<ConvexPolytope> cell_regions(const QuakeBsp& m, const ViewCells& cells) {
  std::vector<ConvexPolytope> out(cells.layout.cell_count());
  for (const BspLeafPiece& p : bsp_leaf_pieces(m)) {
    const uint32_t c = cells.layout.leaf_cell[p.leaf];
    if (c != pvs::kNoCell && !p.volume.empty())
      out[c] = bsp_leaf_view_region(p.volume, kDefaultNear).volume;
  }
  return out;
}

// Rays from random points of each cell's region: the unambiguous double-precision first hits
// (brute_force_first_hit) that are not in the cell's set, as (cell, triangle).
std::vector<std::pair<uint32_t, uint32_t>> ray_misses(const Scene& scene, const QuakeBsp& m,
                                                      const ViewCells& cells, pvs::Reader& r,
                                                      int eyes, int dirs, uint64_t seed,
                                                      size_t* rays) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0, 1);
  const std::vector<ConvexPolytope> regions = cell_regions(m, cells);
  std::vector<std::pair<uint32_t, uint32_t>> misses;
  const Box3 box = scene.bounds();
  const EmbreeScene embree(scene, 0, (box.min + box.max) * 0.5);
  for (uint32_t c = 0; c < cells.layout.cell_count(); ++c) {
    const std::vector<uint32_t> set = r.read_cell(c);
    for (int e = 0; e < eyes; ++e) {
      const Vec3 eye = quake_to_scene(random_point(regions[c], rng));
      for (int k = 0; k < dirs; ++k) {
        const Vec3 dir{gauss(rng), gauss(rng), gauss(rng)};
        ++*rays;
        const Hit h = embree.first_hit(eye, dir, kDefaultNear);
        if (h.tri != kNoHit && std::binary_search(set.begin(), set.end(), h.tri)) continue;
        const OracleSample exact = brute_force_first_hit(scene, 0, eye, dir, kDefaultNear);
        if (exact.ambiguous || exact.tri == kNoHit) continue;
        if (!std::binary_search(set.begin(), set.end(), exact.tri))
          misses.push_back({c, exact.tri});
      }
    }
  }
  return misses;
}

// 16 eyes a cell, 64 rays each (ray_misses): a failure for every first hit missing from the set.
void expect_every_ray_in_the_sets(const Scene& scene, const QuakeBsp& m, const ViewCells& cells,
                                  pvs::Reader& r, uint64_t seed, BspLiquids liquids) {
  size_t rays = 0;
  const auto misses = ray_misses(scene, m, cells, r, 16, 64, seed, &rays);
  EXPECT_GT(rays, 0u);
  for (const auto& [c, tri] : misses)
    ADD_FAILURE() << "cell " << c << " misses triangle " << tri << " (liquids " << int(liquids)
                  << ")";
}

}  // namespace

// A region's segments: its 12 box edges once each (every edge belongs to two faces), then per
// face the chords parallel to its longest edge, evenly spaced at most `spacing` apart.
TEST(QuakeBake, RegionSegmentsAreEdgesOnceThenChordsAtMostTheSpacingApart) {
  ConvexPolytope box;
  box.halfspaces = {{{-1, 0, 0}, 0}, {{1, 0, 0}, 64}, {{0, -1, 0}, 0},
                    {{0, 1, 0}, 32}, {{0, 0, -1}, 0}, {{0, 0, 1}, 16}};
  box = inset_polytope(box, 0);
  ASSERT_EQ(box.faces.size(), 6u);
  EXPECT_EQ(bsp_region_segments(box, 0).size(), 12u);
  // 64 x 32 faces (z = 0, 16): one chord at 16, none across the 16-wide faces.
  const std::vector<Segment> s16 = bsp_region_segments(box, 16);
  ASSERT_EQ(s16.size(), 14u);
  for (size_t i = 12; i < 14; ++i) {
    const Vec3 a = scene_to_quake(s16[i].from), b = scene_to_quake(s16[i].to);
    EXPECT_NEAR(std::fabs(b.x - a.x), 64, 1e-9);  // along the longest edge
    EXPECT_NEAR(a.y, 16, 1e-9);
    EXPECT_NEAR(b.y, 16, 1e-9);
  }
  // Spacing 8: 3 chords on each 64 x 32 face, 1 on each 64 x 16 and 32 x 16 face.
  EXPECT_EQ(bsp_region_segments(box, 8).size(), 12u + 2 * 3 + 2 * 1 + 2 * 1);
  // Spacing 10 over a width of 32: 4 equal steps of 8 (at most 10 apart), 3 chords.
  EXPECT_EQ(bsp_region_segments(box, 10).size(), 12u + 2 * 3 + 2 * 1 + 2 * 1);
}

// A face laid over a portal closes it, though the portal's corners (from float planes) miss the
// face's by 1e-4 units: before the edge band, such a portal of e1m2 (under a floor face) counted
// as open, its runs' eyes lay on the floor, the near plane cut it away and they saw the sky
// through it (417 false witnesses on the whole map). A face over half of a portal cuts the
// portal's segments to the open half, clear of the face by the clearance; a face meeting the
// portal only along an edge (within the band) covers nothing.
TEST(QuakeBake, PortalCoverClosesAPortalUnderAFaceAndCutsSegmentsToTheOpenPart) {
  BspPortal p;  // 16 x 8 on z = 324, normal -z: counter-clockwise seen from below
  const double e = 1e-4;
  p.polygon = {
      {0 - e, 8 + e, 324}, {16 + e, 8 + e, 324}, {16 + e, 0 - e, 324}, {0 - e, 0 - e, 324}};
  p.normal = {0, 0, -1};
  p.area = (16 + 2 * e) * (8 + 2 * e);
  auto scene_with = [](const std::vector<std::array<Vec3, 4>>& quads) {
    Scene s;
    for (const auto& q : quads)
      vislib_test::add_quad(s, quake_to_scene(q[0]), quake_to_scene(q[1]), quake_to_scene(q[2]),
                            quake_to_scene(q[3]));
    return s;
  };
  const Scene floor = scene_with({{{{0, 0, 324}, {16, 0, 324}, {16, 8, 324}, {0, 8, 324}}}});
  const BspPortalCover closed = bsp_portal_cover(p, floor);
  EXPECT_TRUE(closed.closed);
  EXPECT_EQ(closed.parts.size(), 2u);
  // Half of it: open, one part, and a chord along x loses [8 - clearance, 16].
  const Scene half = scene_with({{{{8, 0, 324}, {16, 0, 324}, {16, 8, 324}, {8, 8, 324}}}});
  const BspPortalCover open = bsp_portal_cover(p, half);
  EXPECT_FALSE(open.closed);
  ASSERT_EQ(open.parts.size(), 2u);
  const double clearance = 0.02;
  const std::vector<Segment> pieces =
      bsp_portal_open_pieces({{0.5, 4, 324}, {15.5, 4, 324}}, p, open, clearance, 1e-6);
  ASSERT_EQ(pieces.size(), 1u);
  EXPECT_EQ(pieces[0].from, (Vec3{0.5, 4, 324}));
  EXPECT_NEAR(pieces[0].to.x, 8 - clearance, 1e-9);
  // A chord across the cover's edge at an angle keeps the part before it only.
  const std::vector<Segment> slant =
      bsp_portal_open_pieces({{12, 1, 324}, {4, 7, 324}}, p, open, clearance, 1e-6);
  ASSERT_EQ(slant.size(), 1u);
  EXPECT_NEAR(slant[0].from.x, 8 - clearance, 1e-9);
  EXPECT_EQ(slant[0].to, (Vec3{4, 7, 324}));
  // A cover in the middle splits a chord in two.
  const Scene middle = scene_with({{{{6, 0, 324}, {10, 0, 324}, {10, 8, 324}, {6, 8, 324}}}});
  const std::vector<Segment> two = bsp_portal_open_pieces(
      {{0.5, 4, 324}, {15.5, 4, 324}}, p, bsp_portal_cover(p, middle), clearance, 1e-6);
  ASSERT_EQ(two.size(), 2u);
  EXPECT_NEAR(two[0].to.x, 6 - clearance, 1e-9);
  EXPECT_NEAR(two[1].from.x, 10 + clearance, 1e-9);
  // The next leaf's floor, meeting the portal along its edge y = 8 (within the band): no part.
  const Scene next = scene_with({{{{0, 8, 324}, {16, 8, 324}, {16, 16, 324}, {0, 16, 324}}}});
  const BspPortalCover beside = bsp_portal_cover(p, next);
  EXPECT_FALSE(beside.closed);
  EXPECT_TRUE(beside.parts.empty());
  // A face off the plane (a ceiling 4 units above) covers nothing.
  EXPECT_TRUE(
      bsp_portal_cover(p, scene_with({{{{0, 0, 328}, {16, 0, 328}, {16, 8, 328}, {0, 8, 328}}}}))
          .parts.empty());
}

// A leaf thinner than twice the near clearance (a slab 0.015 units thick over the tiny map's
// floor) with a face 10 units under the floor: no eye of the leaf's region may see it, since the
// floor lies between. Before its region kept the clearance, the slab was its own region, its eyes
// lay on the floor's plane, the near plane cut the floor away and the bake saw the face under it.
TEST(QuakeBake, EyesOfALeafThinnerThanTheNearDistanceDoNotSeeThroughItsFloor) {
  QuakeBsp m = tiny_map();
  m.models[0].maxs = {64, 64, 0.015f};
  m.vertices[9] = {16, 16, -10};
  m.vertices[10] = {48, 16, -10};
  m.vertices[11] = {48, 48, -10};
  m.vertices[12] = {16, 48, -10};
  m.faces[3] = m.faces[0];  // replaced below: the door's quad becomes the face under the floor
  m.faces.pop_back();
  add_face(m, {9, 10, 11, 12}, 0, false);
  m.models[0].face_count = 4;
  m.models.pop_back();  // no door model
  const std::string dir = temp_dir("quake_thin_leaf");
  const std::string path = write_map(dir, "thin.bsp", encode_bsp(m));
  const QuakeBsp parsed = read_quake_bsp(path);
  const Scene scene = load_scene(path);
  ASSERT_EQ(scene.triangle_count(), 2u + 3 + 1 + 2);  // floor, water, sky, the face under
  BspCellOptions o;
  o.leaves = {1};
  const ViewCells cells = bsp_leaf_cells(parsed, o);
  EXPECT_EQ(cells.near_limit.size(), 1u);
  const double limit = cells.near_limit.empty() ? kDefaultNear : cells.near_limit[0];
  EXPECT_LT(limit, kDefaultNear);
  EXPECT_EQ(nlohmann::json::parse(cells.description)["leaves_near_clipped"], 1);
  for (const Segment& seg : cells.segments[0])
    for (const Vec3& p : {seg.from, seg.to}) {
      const double z = scene_to_quake(p).z;
      EXPECT_GE(z, kNearClearanceFactor * limit - 1e-12);
      EXPECT_LE(z, 0.015 - kNearClearanceFactor * limit + 1e-7);
    }
  BakeSettings s;
  s.region.segment.resolution = 32;
  s.region.runs = 1;
  pvs::Reader r = pvs::Reader::from_memory(bake_file(scene, cells, s, dir + "/thin.pvs", 1));
  const std::vector<uint32_t> seen = r.read_cell(0);
  EXPECT_FALSE(seen.empty());
  for (uint32_t t = 6; t < 8; ++t)
    EXPECT_FALSE(std::binary_search(seen.begin(), seen.end(), t))
        << "triangle " << t << " under the floor is seen from the leaf";
}

// The adaptive face sweep: the cells' segments are the regions' edges, every face is swept, the
// metadata records the rule, the bytes do not depend on the thread count, and each set holds what
// the edges alone see.
TEST(QuakeBake, AdaptiveFaceSweepIsRecordedDeterministicAndHoldsTheEdgesSets) {
  const std::string dir = temp_dir("quake_adaptive");
  const std::string path = write_map(dir, "tiny.bsp", encode_bsp(tiny_map()));
  const QuakeBsp m = read_quake_bsp(path);
  const Scene scene = load_scene(path);
  BspCellOptions o;
  o.adaptive = AdaptiveSpacing{32, 4};
  const ViewCells cells = bsp_leaf_cells(m, o);
  ASSERT_EQ(cells.sweeps.size(), 2u);
  EXPECT_EQ(cells.sweeps[0].size(), 6u);  // a box region: six faces
  BspCellOptions edges_only;
  edges_only.face_spacing = 0;
  const ViewCells edges = bsp_leaf_cells(m, edges_only);
  ASSERT_EQ(cells.segments.size(), edges.segments.size());
  for (size_t c = 0; c < cells.segments.size(); ++c) {
    ASSERT_EQ(cells.segments[c].size(), edges.segments[c].size());
    for (size_t i = 0; i < cells.segments[c].size(); ++i)
      EXPECT_TRUE(cells.segments[c][i].from == edges.segments[c][i].from &&
                  cells.segments[c][i].to == edges.segments[c][i].to);
  }
  const nlohmann::json d = nlohmann::json::parse(cells.description);
  EXPECT_EQ(d["face_sweep"], "adaptive");
  EXPECT_EQ(d["chord_coarse"], 32);
  EXPECT_EQ(d["chord_floor"], 4);
  BakeSettings s;
  s.region.segment.resolution = 32;
  const std::string one = bake_file(scene, cells, s, dir + "/one.pvs", 1);
  EXPECT_EQ(one, bake_file(scene, cells, s, dir + "/two.pvs", 2));
  pvs::Reader r = pvs::Reader::from_memory(one);
  for (uint32_t c = 0; c < 2; ++c) {
    const std::vector<uint32_t> all = r.read_cell(c), base = bake_cell(scene, edges, c, s);
    EXPECT_TRUE(std::includes(all.begin(), all.end(), base.begin(), base.end())) << c;
    uint64_t run = 0;
    EXPECT_EQ(bake_cell(scene, cells, c, s, nullptr, {}, &run), all);
    EXPECT_GT(run, edges.segments[c].size());
  }
}

// One cell per empty or liquid leaf in leaf order, the leaf recorded in the layout, every segment
// inside its leaf's volume and at least the inset from its boundary, the scene options and the
// region rule in the metadata.
TEST(QuakeBake, CellsAreTheLeavesAndTheirSegmentsLieInTheInsetVolume) {
  const QuakeBsp m = parse_quake_bsp("map.bsp", encode_bsp(tiny_map()));
  BspCellOptions o;
  o.scene.bsp_liquids = BspLiquids::see_through;
  const ViewCells cells = bsp_leaf_cells(m, o);
  ASSERT_EQ(cells.layout.kind, pvs::LayoutKind::BspTree);
  ASSERT_EQ(cells.layout.cell_leaf, (std::vector<uint32_t>{1, 2}));
  ASSERT_EQ(cells.segments.size(), 2u);
  // Leaf 1 spans z in [0, 16] of the bounds (0, 0, 0)-(64, 96, 32); leaf 2 z in [16, 32].
  const double z0[2] = {0, 16};
  for (uint32_t c = 0; c < 2; ++c) {
    EXPECT_GT(cells.segments[c].size(), 12u);
    for (const Segment& s : cells.segments[c])
      for (const Vec3& p : {s.from, s.to}) {
        const Vec3 q = scene_to_quake(p);
        EXPECT_EQ(bsp_point_leaf(m, q), cells.layout.cell_leaf[c]);
        EXPECT_GE(q.x, kBspLeafInset - 1e-9);
        EXPECT_LE(q.x, 64 - kBspLeafInset + 1e-9);
        EXPECT_GE(q.y, kBspLeafInset - 1e-9);
        EXPECT_LE(q.y, 96 - kBspLeafInset + 1e-9);
        EXPECT_GE(q.z, z0[c] + kBspLeafInset - 1e-9);
        EXPECT_LE(q.z, z0[c] + 16 - kBspLeafInset + 1e-9);
      }
  }
  EXPECT_LT(bsp_leaf_cells(m, {0.0, {}, {}}).segments[0].size(), cells.segments[0].size());
  const nlohmann::json d = nlohmann::json::parse(cells.description);
  EXPECT_EQ(d["kind"], "bsp-leaves");
  EXPECT_EQ(d["face_spacing"], kBspFaceSpacing);
  EXPECT_EQ(d["inset"], kBspLeafInset);
  EXPECT_EQ(d["bsp_liquids"], "see-through");
  EXPECT_EQ(d["bsp_models"], "world");
  o.leaves = {2};
  EXPECT_EQ(bsp_leaf_cells(m, o).layout.cell_leaf, (std::vector<uint32_t>{2}));
  o.leaves = {0};
  EXPECT_THROW(bsp_leaf_cells(m, o), std::invalid_argument);
}

// The bake over the tiny map's leaves: byte-identical on one and two threads, a BSP-tree layout
// whose lookup finds each leaf's cell, and every triangle a ray from a random point of a region
// hits (double-precision brute force, the oracle) is in that cell's set.
TEST(QuakeBake, SetsHoldEveryTriangleARayFromTheRegionHitsOnAnyThreadCount) {
  const std::string dir = temp_dir("quake_bake_tiny");
  const std::string path = write_map(dir, "tiny.bsp", encode_bsp(tiny_map()));
  for (BspLiquids liquids : {BspLiquids::opaque, BspLiquids::see_through}) {
    const Scene scene = load(path, BspModels::world, liquids);
    const QuakeBsp m = read_quake_bsp(path);
    BspCellOptions o;
    o.scene.bsp_liquids = liquids;
    const ViewCells cells = bsp_leaf_cells(m, o);
    BakeSettings s;
    s.region.segment.resolution = 32;
    const std::string one = bake_file(scene, cells, s, dir + "/one.pvs", 1);
    const std::string two = bake_file(scene, cells, s, dir + "/two.pvs", 2);
    EXPECT_EQ(one, two);
    pvs::Reader r = pvs::Reader::from_memory(one);
    ASSERT_EQ(r.cell_count(), 2u);
    EXPECT_EQ(r.info().layout.cell_leaf, cells.layout.cell_leaf);
    const nlohmann::json meta = nlohmann::json::parse(r.info().metadata);
    EXPECT_EQ(meta["cells"]["kind"], "bsp-leaves");
    for (uint32_t c = 0; c < 2; ++c) {
      EXPECT_EQ(r.read_cell(c), bake_cell(scene, cells, c, s));
      const Vec3 centre = quake_to_scene({32, 48, c == 0 ? 8.0 : 24.0});
      const double p[3] = {centre.x, centre.y, centre.z};
      EXPECT_EQ(r.info().layout.find_cell(p), std::optional<uint32_t>(c));
    }
    expect_every_ray_in_the_sets(scene, m, cells, r, 3603, liquids);
  }
}

// Portals: the tiny map's two leaves meet on one portal (z = 16), whose chords both cells run,
// each with the directions that leave it (the normal points from the lower leaf, leaf 1, into the
// upper); the bake computes each run once for both. Every ray from a region hits a triangle of
// its cell's set (the triangles above and below are seen only through the portal or on the
// leaf's own walls), the bytes do not depend on the thread count, and the sets are those of
// baking each cell alone.
TEST(QuakeBake, PortalSweepRunsEachPortalOnceForBothLeavesAndHoldsEveryRayFromTheRegions) {
  const std::string dir = temp_dir("quake_bake_portals");
  const std::string path = write_map(dir, "tiny.bsp", encode_bsp(tiny_map()));
  for (BspLiquids liquids : {BspLiquids::opaque, BspLiquids::see_through}) {
    const Scene scene = load(path, BspModels::world, liquids);
    const QuakeBsp m = read_quake_bsp(path);
    BspCellOptions o;
    o.scene.bsp_liquids = liquids;
    o.sweep = BspSweep::Portals;
    EXPECT_THROW(bsp_leaf_cells(m, o), std::invalid_argument);  // no scene
    const ViewCells cells = bsp_leaf_cells(m, o, &scene);
    ASSERT_EQ(cells.segments.size(), 2u);
    ASSERT_EQ(cells.segments[0].size(), cells.segments[1].size());
    ASSERT_GT(cells.segments[0].size(), 4u);  // the portal's edges and chords
    for (size_t i = 0; i < cells.segments[0].size(); ++i) {
      const Segment &a = cells.segments[0][i], &b = cells.segments[1][i];
      EXPECT_TRUE(a.from == b.from && a.to == b.to && a.side_normal == b.side_normal);
      EXPECT_EQ(a.side, 0);
      EXPECT_EQ(b.side, 1);
      EXPECT_NEAR(dot(a.side_normal, quake_to_scene({0, 0, 1})), 1.0, 1e-12);
      for (const Vec3& e : {a.from, a.to}) EXPECT_NEAR(scene_to_quake(e).z, 16.0, 1e-9);
    }
    EXPECT_EQ(nlohmann::json::parse(cells.description)["sweep"], "portals");
    BakeSettings s;
    s.region.segment.resolution = 32;
    const TwoLeafBake baked = bake_two_leaves(scene, cells, s, dir);
    EXPECT_EQ(baked.report.segment_runs_shared, cells.segments[0].size());
    pvs::Reader r = pvs::Reader::from_memory(baked.bytes);
    expect_every_ray_in_the_sets(scene, m, cells, r, 3605, liquids);
    // Witnesses: a portal run's eye lies on the portal and is moved back along its ray into the
    // cell's region, or gives none when the ray does not pass through it (here every run's
    // witness lies on the portal's edges, beyond the region's 1-unit inset: only the leaves' own
    // triangles, on or in their volumes, get one). Each lies in the region and re-casts.
    const std::vector<ConvexPolytope> regions = cell_regions(m, cells);
    RegionOptions ro = s.region;
    for (uint32_t c = 0; c < 2; ++c) {
      const std::vector<uint32_t> set = r.read_cell(c);
      const std::vector<CellWitnessRay> w = cell_witness_rays(scene, cells, c, ro, set);
      EXPECT_EQ(w.size(), cells.own[c].size()) << "cell " << c;
      size_t recast = 0;
      for (const CellWitnessRay& x : w) {
        EXPECT_TRUE(strictly_inside(regions[c], scene_to_quake(x.eye), 0)) << "triangle " << x.tri;
        const OracleSample hit = brute_force_first_hit(scene, 0, x.eye, x.dir, kDefaultNear);
        recast += hit.tri == x.tri;
      }
      EXPECT_GE(recast * 10, w.size() * 9) << "cell " << c;  // ties aside, each re-casts
    }
  }
}

// The adaptive sweep of a portal inserts the same chords for both of its leaves (judged by both
// sides' runs, from what the portal's edges see), so the second leaf takes every one of the
// first's runs from the cache: shared runs = computed runs; so does each strip of a portal cut
// into strips (AdaptiveSpacing::piece), each its own family. Bytes as each cell baked alone, at 1
// and 2 threads; the witness re-run, which keeps one side a run, judges the same chords.
TEST(QuakeBake, AdaptivePortalSweepInsertsTheSameChordsForBothLeavesAndRunsEachOnce) {
  const std::string dir = temp_dir("quake_bake_adaptive_portals");
  const std::string path = write_map(dir, "tiny.bsp", encode_bsp(tiny_map()));
  const Scene scene = load(path, BspModels::world, BspLiquids::see_through);
  const QuakeBsp m = read_quake_bsp(path);
  for (double piece : {0.0, 16.0, -1.0}) {
    SCOPED_TRACE(piece);
    BspCellOptions o;
    o.scene.bsp_liquids = BspLiquids::see_through;
    o.sweep = BspSweep::Portals;
    // -1: whole chords, each inserted chord looking only toward its parent's new ids.
    o.adaptive =
        AdaptiveSpacing{32, 2, std::max(piece, 0.0), piece < 0 ? ChordTiles::New : ChordTiles::All};
    const ViewCells cells = bsp_leaf_cells(m, o, &scene);
    ASSERT_EQ(cells.sweeps.size(), 2u);
    ASSERT_EQ(cells.sweeps[0].size(), cells.sweeps[1].size());
    if (piece <= 0) {
      ASSERT_EQ(cells.sweeps[0].size(), 1u);
    } else {
      ASSERT_GT(cells.sweeps[0].size(), 1u);
    }
    std::set<SegmentRunCache::Key> families;
    for (size_t k = 0; k < cells.sweeps[0].size(); ++k) {
      EXPECT_EQ(sweep_family_key(cells.sweeps[0][k]), sweep_family_key(cells.sweeps[1][k]));
      families.insert(sweep_family_key(cells.sweeps[0][k]));
    }
    EXPECT_EQ(families.size(), cells.sweeps[0].size());
    BakeSettings s;
    s.region.segment.resolution = 32;
    const TwoLeafBake baked =
        bake_two_leaves(scene, cells, s,
                        temp_dir("quake_bake_adaptive_portals_p" + std::to_string(int(piece + 1))));
    // More than the polygon's edges: the sweep ran chords, and each was computed once.
    EXPECT_GT(baked.report.segment_runs_shared, cells.segments[0].size());
    EXPECT_EQ(baked.report.segment_runs_computed, baked.report.segment_runs_shared);
    pvs::Reader r = pvs::Reader::from_memory(baked.bytes);
    expect_every_ray_in_the_sets(scene, m, cells, r, 3607, BspLiquids::see_through);
    // The witness re-run finds a witness for each of the own triangles at least (a re-run that
    // chose other chords would see other ids: every id it returns is in the set).
    for (uint32_t c = 0; c < 2; ++c) {
      const std::vector<uint32_t> set = r.read_cell(c);
      for (const CellWitnessRay& w : cell_witness_rays(scene, cells, c, s.region, set))
        EXPECT_TRUE(std::binary_search(set.begin(), set.end(), w.tri));
    }
  }
}

// The CLI: a .bsp baked over its leaves (inspect --at finds the leaf's cell); options that place
// cells otherwise, or a scene that is not a map, exit 2 naming the option or the file.
TEST(QuakeBake, CliBakesLeavesAndRefusesOtherPlacementsAndOtherScenes) {
  const std::string dir = temp_dir("quake_bake_cli");
  const std::string map = write_map(dir, "tiny.bsp", encode_bsp(tiny_map()));
  std::string out;
  ASSERT_EQ(run_pvs("bake -q " + map + " --cells bsp-leaves --res 16 --face-spacing 32 -o " + dir +
                        "/tiny.pvs",
                    &out),
            0)
      << out;
  // Shards merge into the whole bake's bytes.
  const std::string common = "bake -q " + map + " --cells bsp-leaves --res 16 --face-spacing 32 ";
  ASSERT_EQ(run_pvs(common + "--shard 0/2 -o " + dir + "/s0.pvs", &out), 0) << out;
  ASSERT_EQ(run_pvs(common + "--shard 1/2 -o " + dir + "/s1.pvs", &out), 0) << out;
  ASSERT_EQ(run_pvs("merge -q " + dir + "/s1.pvs " + dir + "/s0.pvs -o " + dir + "/m.pvs", &out), 0)
      << out;
  EXPECT_EQ(read_file(dir + "/m.pvs"), read_file(dir + "/tiny.pvs"));
  // The default sweep is the portals'; --sweep faces and the spacings' defaults are recorded.
  auto cells_of = [&](const std::string& options) {
    EXPECT_EQ(run_pvs("bake -q " + map + " --cells bsp-leaves --res 16 " + options + " -o " + dir +
                          "/d.pvs",
                      &out),
              0)
        << out;
    pvs::Reader r = pvs::Reader::from_memory(read_file(dir + "/d.pvs"));
    return nlohmann::json::parse(r.info().metadata)["cells"];
  };
  ASSERT_EQ(run_pvs("bake " + map + " --cells bsp-leaves --dry-run -o " + dir + "/d.pvs", &out), 0)
      << out;
  // One portal, its chords run once for both leaves.
  EXPECT_NE(out.find("distinct segments in all (a portal's serve both of its leaves"),
            std::string::npos)
      << out;
  nlohmann::json c = cells_of("");
  EXPECT_EQ(c["sweep"], "portals");
  EXPECT_EQ(c["portal_edges"], "own");
  EXPECT_EQ(c["face_spacing"], kBspPortalSpacing);
  EXPECT_EQ(c["face_sweep"], "adaptive");
  EXPECT_EQ(c["chord_coarse"], kBspPortalChords.coarse);
  EXPECT_EQ(c["chord_floor"], kBspPortalChords.floor);
  EXPECT_EQ(c["chord_piece"], kBspPortalChords.piece);
  EXPECT_EQ(c["chord_tiles"], "new-every-face");
  EXPECT_EQ(c["chord_crossed"], true);
  EXPECT_EQ(c["chord_new"], kBspPortalChords.new_to_family ? "family" : "neighbours");
  EXPECT_EQ(c["chord_tile_margin"], kChordTileMargin);
  EXPECT_EQ(c["chord_tile_size"], kChordTileSize);
  c = cells_of("--chord-tiles all");
  EXPECT_EQ(c["chord_tiles"], "all");
  EXPECT_FALSE(c.contains("chord_tile_margin"));
  EXPECT_FALSE(c.contains("chord_tile_size"));
  EXPECT_EQ(cells_of("--chord-tile-size 32")["chord_tile_size"], 32);
  c = cells_of("--chord-tiles new-every-face");
  EXPECT_EQ(c["chord_tiles"], "new-every-face");
  EXPECT_EQ(c["chord_tile_size"], kChordTileSize);
  c = cells_of("--chord-tiles new");
  EXPECT_EQ(c["chord_tiles"], "new");
  EXPECT_EQ(c["chord_cross_floor"], kBspPortalChords.crossed_floor);
  EXPECT_FALSE(cells_of("--chord-cross off").contains("chord_crossed"));
  EXPECT_FALSE(cells_of("--chord-cross off").contains("chord_cross_floor"));
  EXPECT_EQ(cells_of("--chord-cross-floor 8")["chord_cross_floor"], 8.0);
  // Kept between the floor and the coarse spacing when only those are given.
  EXPECT_EQ(cells_of("--chord-floor 32")["chord_cross_floor"], 32.0);
  EXPECT_EQ(cells_of("--chord-coarse 8")["chord_cross_floor"], 8.0);
  EXPECT_EQ(cells_of("--chord-new neighbours")["chord_new"], "neighbours");
  EXPECT_EQ(cells_of("--chord-new family")["chord_new"], "family");
  EXPECT_EQ(
      run_pvs("bake " + map + " --cells bsp-leaves --chord-new both -o " + dir + "/x.pvs", &out),
      2);
  EXPECT_NE(out.find("--chord-new"), std::string::npos) << out;
  EXPECT_EQ(cells_of("--portal-edges shared")["portal_edges"], "shared");
  for (const char* bad : {"--portal-edges both", "--sweep faces --portal-edges own"}) {
    EXPECT_EQ(run_pvs("bake " + map + " --cells bsp-leaves " + bad + " -o " + dir + "/x.pvs", &out),
              2)
        << bad;
    EXPECT_NE(out.find("--portal-edges"), std::string::npos) << out;
  }
  EXPECT_FALSE(cells_of("--sweep faces").contains("portal_edges"));
  for (const char* bad : {"--chord-cross-floor 2", "--chord-cross-floor 512",
                          "--chord-cross off --chord-cross-floor 8"}) {
    EXPECT_EQ(run_pvs("bake " + map + " --cells bsp-leaves " + bad + " -o " + dir + "/x.pvs", &out),
              2)
        << bad;
    EXPECT_NE(out.find("--chord-cross-floor"), std::string::npos) << out;
  }
  c = cells_of("--face-sweep even");
  EXPECT_EQ(c["face_sweep"], "even");
  EXPECT_FALSE(c.contains("chord_coarse"));
  EXPECT_EQ(cells_of("--chord-floor 16")["chord_floor"], 16.0);
  c = cells_of("--sweep faces");
  EXPECT_EQ(c["sweep"], "faces");
  EXPECT_EQ(c["face_spacing"], kBspFaceSpacing);
  EXPECT_EQ(c["face_sweep"], "even");
  c = cells_of("--sweep faces --face-sweep adaptive");
  EXPECT_EQ(c["chord_coarse"], AdaptiveSpacing{}.coarse);
  EXPECT_EQ(c["chord_floor"], AdaptiveSpacing{}.floor);
  EXPECT_EQ(c["chord_piece"], 0.0);
  EXPECT_EQ(cells_of("--sweep faces --face-spacing 4")["face_spacing"], 4.0);
  EXPECT_EQ(run_pvs("bake " + map + " --cells bsp-leaves --sweep edges -o " + dir + "/x.pvs", &out),
            2);
  EXPECT_NE(out.find("--sweep"), std::string::npos) << out;
  EXPECT_EQ(
      run_pvs("bake " + map + " --cells bsp-leaves --chord-tiles all --chord-tile-size 8 -o " +
                  dir + "/x.pvs",
              &out),
      2);
  EXPECT_NE(out.find("--chord-tile-size"), std::string::npos) << out;
  // Leaf 2 (water, above z = 16): Quake (32, 48, 24) is scene (32, 24, -48).
  ASSERT_EQ(run_pvs("inspect --json " + dir + "/tiny.pvs --at 32,24,-48", &out), 0) << out;
  EXPECT_NE(out.find("\"leaf\": 2"), std::string::npos) << out;
  EXPECT_EQ(run_pvs("bake " + map + " --cells bsp-leaves --walkable -o " + dir + "/x.pvs", &out),
            2);
  EXPECT_NE(out.find("--walkable"), std::string::npos) << out;
  EXPECT_EQ(run_pvs("bake " + map + " --cells bsp-leaves --cell-size 8 -o " + dir + "/x.pvs", &out),
            2);
  EXPECT_NE(out.find("--cell-size"), std::string::npos) << out;
  EXPECT_EQ(run_pvs("bake " + map + " --face-spacing 8 --walkable -o " + dir + "/x.pvs", &out), 2);
  EXPECT_NE(out.find("--face-spacing"), std::string::npos) << out;
  // --leaves: a list of A, A-B and A-B/K items; anything else exits 2 naming the option.
  for (const char* bad : {"5-", "x", "3-1", "1-4/0", "-3", "1,,2", "2 3"}) {
    EXPECT_EQ(
        run_pvs("bake " + map + " --cells bsp-leaves --leaves '" + bad + "' -o " + dir + "/x.pvs",
                &out),
        2)
        << bad;
    EXPECT_NE(out.find("--leaves"), std::string::npos) << out;
  }
  const std::string glb = dir + "/scene.glb";
  ASSERT_EQ(run_pvs("generate city --blocks 2,2 -o " + glb, &out), 0) << out;
  EXPECT_EQ(run_pvs("bake " + glb + " --cells bsp-leaves -o " + dir + "/x.pvs", &out), 2);
  EXPECT_NE(out.find("scene.glb"), std::string::npos) << out;
  EXPECT_NE(out.find(".bsp"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(dir + "/x.pvs"));
}

namespace {

// Bakes leaves `leaves` ("" for all) of lqdm1 through the CLI at --res 128 on two threads, then
// holds each cell's set against rays from random points of its region (ray_misses). Prints the
// bake's seconds, the cells, the mean set size and the misses.
void bake_lqdm1_and_cast(const std::string& path, const std::string& leaves, size_t cells_expected,
                         int eyes, int dirs, const std::string& options = "") {
  const std::string dir = temp_dir("quake_bake_lqdm1");
  const std::string out_pvs = dir + "/lqdm1.pvs";
  std::string out;
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_EQ(run_pvs("bake -q " + path + " --cells bsp-leaves --res 128 -j 2 -o " + out_pvs +
                        (leaves.empty() ? "" : " --leaves " + leaves) + options,
                    &out),
            0)
      << out;
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const QuakeBsp m = read_quake_bsp(path);
  const Scene scene = load_scene(path);
  BspCellOptions o;
  if (!leaves.empty()) {
    const std::vector<uint32_t> all = bsp_cell_leaves(m);
    const uint32_t lo = uint32_t(std::stoul(leaves)),
                   hi = uint32_t(std::stoul(leaves.substr(leaves.find('-') + 1)));
    for (uint32_t l : all)
      if (l >= lo && l <= hi) o.leaves.push_back(l);
  }
  const ViewCells cells = bsp_leaf_cells(m, o);
  pvs::Reader r = pvs::Reader::from_memory(read_file(out_pvs));
  ASSERT_EQ(r.cell_count(), cells_expected);
  EXPECT_EQ(r.info().layout.cell_leaf, cells.layout.cell_leaf);
  EXPECT_EQ(r.info().scene_fingerprint, scene_fingerprint(scene));
  double total = 0;
  for (uint32_t c = 0; c < r.cell_count(); ++c) total += double(r.read_cell(c).size());
  size_t rays = 0;
  const auto misses = ray_misses(scene, m, cells, r, eyes, dirs, 3604, &rays);
  std::printf(
      "lqdm1 leaves %s%s: %u cells baked in %.1f s (CLI, --res 128 -j 2; budget 90 s for leaves "
      "1-4 on the 2-core host), mean set %.1f of %zu "
      "triangles; %zu rays from random points of the regions, %zu hits not in the set\n",
      leaves.empty() ? "all" : leaves.c_str(), options.c_str(), r.cell_count(), seconds,
      total / r.cell_count(), scene.triangle_count(), rays, misses.size());
  // A sampled check with a failure-rate threshold: the sweep samples each portal with chords, so
  // a triangle seen only between two chords, or between two pixel rays, can be missed
  // (docs/quake.md measures how often).
  EXPECT_LE(misses.size(), rays / 1000);
  for (const auto& [c, tri] : misses)
    std::printf("  cell %u (leaf %u) misses triangle %u\n", c, cells.layout.cell_leaf[c], tri);
}

}  // namespace

// lqdm1 baked over a fixed subset of its leaves through the CLI (the whole map takes minutes:
// the opt-in test below). Time budget: 58 s wall on the 2-core host while other jobs loaded
// it (about 170 runs at 0.07-0.11 CPU s each: 15-20 s on two idle cores), Release.
TEST(QuakeBakeLibreQuake, Lqdm1LeavesOneToFourBakeThroughTheCliAndHoldTheirRays) {
  auto path = librequake("lqdm1.bsp");
  if (!path) GTEST_SKIP() << "../shared/scenes/librequake is absent";
  bake_lqdm1_and_cast(*path, "1-4", 4, 16, 256);
}

// The same with every refinement chord computing its whole cube (--chord-tiles all, where the
// default computes only the tiles toward the ids that made it): the sets hold the rays as well.
// Time budget: 20 s wall on the 2-core host (the bake about 4 s).
TEST(QuakeBakeLibreQuake, Lqdm1LeavesOneToFourWithWholeCubeChordsHoldTheirRays) {
  auto path = librequake("lqdm1.bsp");
  if (!path) GTEST_SKIP() << "../shared/scenes/librequake is absent";
  bake_lqdm1_and_cast(*path, "1-4", 4, 16, 256, " --chord-tiles all");
}

// The same with the tiles toward new ids on every cube face they span (--chord-tiles
// new-every-face, where the default computes the whole cube for ids seen across a face's edge).
// Time budget: 20 s wall on the 2-core host.
TEST(QuakeBakeLibreQuake, Lqdm1LeavesOneToFourWithTilesOnEveryFaceHoldTheirRays) {
  auto path = librequake("lqdm1.bsp");
  if (!path) GTEST_SKIP() << "../shared/scenes/librequake is absent";
  bake_lqdm1_and_cast(*path, "1-4", 4, 16, 256, " --chord-tiles new-every-face");
}

// Crossed chords (the default; --chord-cross off leaves them out): lqdm1's leaves 132, 162 and
// 243 see triangles 4066, 2869 and 350 through patches of their portals that are thin across the
// chords parallel to a portal's longest edge, so no chord of that family lands on them; rays from
// random eyes of the leaves hit them (`pvs vis-compare lqdm1.bsp OUT.pvs`, 4 eyes a leaf, on the
// whole map baked with --chord-cross off --chord-tiles new). The perpendicular family crosses
// those patches, and the sets keep everything the first family found. Time budget: 20 s wall on
// the 2-core host.
TEST(QuakeBakeLibreQuake, CrossedChordsFindWhatIsSeenThroughPatchesThinAcrossTheFirstChords) {
  auto path = librequake("lqdm1.bsp");
  if (!path) GTEST_SKIP() << "../shared/scenes/librequake is absent";
  const std::string dir = temp_dir("quake_bake_crossed");
  const std::pair<uint32_t, uint32_t> seen[] = {{132, 4066}, {162, 2869}, {243, 350}};
  std::vector<std::vector<uint32_t>> sets[2];
  for (int crossed = 0; crossed < 2; ++crossed) {
    const std::string pvs = dir + "/c" + std::to_string(crossed) + ".pvs";
    std::string out;
    ASSERT_EQ(
        run_pvs("bake -q " + *path + " --cells bsp-leaves --res 128 -j 2 --leaves 132,162,243 -o " +
                    pvs + (crossed ? "" : " --chord-cross off"),
                &out),
        0)
        << out;
    pvs::Reader r = pvs::Reader::from_memory(read_file(pvs));
    ASSERT_EQ(r.cell_count(), 3u);
    for (uint32_t c = 0; c < 3; ++c) {
      ASSERT_EQ(r.info().layout.cell_leaf[c], seen[c].first);
      sets[crossed].push_back(r.read_cell(c));
    }
  }
  for (uint32_t c = 0; c < 3; ++c) {
    const std::vector<uint32_t>&one = sets[0][c], &both = sets[1][c];
    EXPECT_TRUE(std::includes(both.begin(), both.end(), one.begin(), one.end())) << c;
    EXPECT_FALSE(std::binary_search(one.begin(), one.end(), seen[c].second)) << c;
    EXPECT_TRUE(std::binary_search(both.begin(), both.end(), seen[c].second)) << c;
  }
}

// Where lqdm1's open portals meet along a line, their clear parts' edges lie a few clearances
// apart, and with BspCellOptions::share_edges (`--portal-edges shared`) one run serves them all:
// each such segment carries the first edge's ends and every
// member portal's plane (Segment::run_planes), its own at run_plane, so the bake keys them as one
// run split by each plane (3,277 edges, 2,443 runs). Each member still counts
// as an edge of its own portal's sweep (its base), whose polygon has a vertex within
// kSharedRunEdgeDistance of each end. Without the sharing every edge is its own run.
TEST(QuakeBakeLibreQuake, PortalEdgesMeetingAlongALineShareOneRunSplitByEachPortalsPlane) {
  auto path = librequake("lqdm1.bsp");
  if (!path) GTEST_SKIP() << "../shared/scenes/librequake is absent";
  const QuakeBsp m = read_quake_bsp(*path);
  const Scene scene = load_scene(*path);
  BspCellOptions o;
  o.sweep = BspSweep::Portals;
  o.adaptive = kBspPortalChords;
  o.share_edges = true;
  const ViewCells cells = bsp_leaf_cells(m, o, &scene);
  std::set<SegmentRunCache::Key> runs;
  size_t segments = 0;
  std::map<SegmentRunCache::Key, std::array<Vec3, kMaxSidePlanes>> planes_of;
  size_t shared = 0;
  for (uint32_t c = 0; c < cells.segments.size(); ++c)
    for (const Segment& s : cells.segments[c]) {
      ASSERT_FALSE((s.side_normal == Vec3{0, 0, 0}));
      const SegmentRunCache::Key key = SegmentRunCache::key_of(s.from, s.to, run_key_normal(s));
      runs.insert(key);
      segments += s.side == 0;  // each portal's edge once (every leaf is a cell)
      if (s.run_planes[0] == Vec3{0, 0, 0}) continue;
      ++shared;
      EXPECT_TRUE(s.run_planes[size_t(s.run_plane)] == s.side_normal);
      EXPECT_FALSE((s.run_planes[1] == Vec3{0, 0, 0}));  // two portals or more
      const auto [it, first] = planes_of.emplace(key, s.run_planes);
      EXPECT_TRUE(it->second == s.run_planes);  // one run, one split for every member
      bool own = false;                         // an edge of its own portal's sweep
      for (const FaceSweep& f : cells.sweeps[c]) {
        if (!(f.side_normal == s.side_normal)) continue;
        bool from = false, to = false;
        for (const Vec3& v : f.face) {
          from = from || length(v - s.from) <= kSharedRunEdgeDistance;
          to = to || length(v - s.to) <= kSharedRunEdgeDistance;
        }
        own = own || (from && to);
      }
      EXPECT_TRUE(own) << "cell " << c;
    }
  EXPECT_GT(shared, 0u);
  EXPECT_EQ(segments, 3277u);  // each portal's edges, as each would run alone
  EXPECT_EQ(runs.size(), 2443u);
  o.share_edges = false;  // each edge its own run (the default)
  const ViewCells own = bsp_leaf_cells(m, o, &scene);
  EXPECT_EQ(nlohmann::json::parse(own.description)["portal_edges"], "own");
  std::set<SegmentRunCache::Key> own_runs;
  for (const std::vector<Segment>& segs : own.segments)
    for (const Segment& s : segs) {
      EXPECT_TRUE((s.run_planes[0] == Vec3{0, 0, 0}));
      own_runs.insert(SegmentRunCache::key_of(s.from, s.to, run_key_normal(s)));
    }
  EXPECT_EQ(own_runs.size(), 3277u);
}

// --leaves picks the listed leaves of a real map: every 10th from 1 to 40, and 3.
TEST(QuakeBakeLibreQuake, LeavesListAndStrideSelectThoseLeaves) {
  auto path = librequake("lqdm1.bsp");
  if (!path) GTEST_SKIP() << "../shared/scenes/librequake is absent";
  const std::string dir = temp_dir("quake_bake_leaves");
  std::string out;
  ASSERT_EQ(run_pvs("bake " + *path + " --cells bsp-leaves --leaves 1-40/10,3 --dry-run -o " + dir +
                        "/x.pvs",
                    &out),
            0)
      << out;
  EXPECT_NE(out.find("5 cells (bsp-leaves)"), std::string::npos) << out;
}

// The whole of lqdm1 (opt-in: VISLIB_LONG_TESTS=1; tens of minutes on the 2-core host).
TEST(QuakeBakeLibreQuake, LongLqdm1WholeBakeHoldsItsRays) {
  VISLIB_REQUIRE_LONG_TESTS();
  auto path = librequake("lqdm1.bsp");
  if (!path) GTEST_SKIP() << "../shared/scenes/librequake is absent";
  bake_lqdm1_and_cast(*path, "", 321, 4, 64);
}

// vis-compare and pvs check re-cast through RayCrossingIndex: on the maps (their T-junction fans
// hold exactly degenerate triangles, their coordinates run to thousands of units) it must give
// the brute force's crossings, line for line.
TEST(QuakeBspLibreQuake, RayCrossingIndexGivesTheBruteForceCrossingsOnTheMaps) {
  bool any = false;
  for (const char* name : {"lqdm1.bsp", "e1m2.bsp"}) {
    auto path = librequake(name);
    if (!path) continue;
    any = true;
    const Scene scene = load(*path);
    const RayCrossingIndex index(scene, 0);
    const Box3 b = scene.bounds();
    Rng rng(5);
    size_t crossings = 0;
    for (int i = 0; i < 1000; ++i) {
      const Vec3 eye{rng.uniform(b.min.x, b.max.x), rng.uniform(b.min.y, b.max.y),
                     rng.uniform(b.min.z, b.max.z)};
      Vec3 dir{rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)};
      if (i % 5 == 0) dir.y = 0;  // level lines, along the maps' many horizontal floors' planes
      if (!(length(dir) > 0)) continue;
      dir = dir * (1.0 / length(dir));
      const std::vector<RayCrossing> want = ray_crossings(scene, 0, eye, dir);
      const std::vector<RayCrossing> got = index.crossings(eye, dir);
      crossings += want.size();
      ASSERT_EQ(got.size(), want.size()) << name << " line " << i;
      for (size_t k = 0; k < want.size(); ++k) {
        ASSERT_EQ(got[k].tri, want[k].tri) << name << " line " << i;
        ASSERT_EQ(got[k].lambda, want[k].lambda);
        ASSERT_EQ(got[k].min_bary, want[k].min_bary);
      }
    }
    EXPECT_GT(crossings, 1000u) << name;
  }
  if (!any) GTEST_SKIP() << "../shared/scenes/librequake is absent";
}
