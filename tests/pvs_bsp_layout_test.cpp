// Tests of the BSP-tree cell layout (format version 2, docs/pvs-format.md "BSP tree"): round trip,
// the walk down the planes (points on either side and exactly on a plane), the rejection of bad
// trees naming the offset, version rules (version-1 files unchanged, layout 2 needs version 2),
// the golden file of version 2, the runtime's lookup and neighbours, and lqdm1's tree built into
// the layout (random points of each leaf volume find that leaf's cell through the file).
//
// The golden file is tests/golden/pvs_v2_bsp_tree.pvs. It is never regenerated silently: run the
// test binary with VISLIB_UPDATE_GOLDEN=1 only when shipping a new version's golden file.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <random>

#include "runtime/pvs_runtime.h"
#include "tests/pvs_file_edit.h"
#include "tests/test_support.h"
#include "vislib/bake/bsp_cells.h"
#include "vislib/base/file_util.h"
#include "vislib/scene/quake_bsp.h"
#include "vislib/scene/quake_bsp_volumes.h"

using namespace vislib_test;

namespace {

constexpr int32_t leaf_ref(uint32_t leaf) {
  return -int32_t(leaf) - 1;
}

// A tree over the box [-10, 10]^3: node 0 splits at x = 0 (back: leaf 1), node 1 at z = 2 (back:
// leaf 3), node 2 at y = 5 (front: leaf 2, a sky leaf without a cell; back: leaf 4). Leaf 0 is the
// solid leaf, in no node. Cells: 0 = leaf 1, 1 = leaf 3, 2 = leaf 4; each pair shares a face.
pvs::CellLayout small_tree() {
  pvs::CellLayout L;
  L.kind = pvs::LayoutKind::BspTree;
  L.planes = {{{1, 0, 0}, 0}, {{0, 0, 1}, 2}, {{0, 1, 0}, 5}};
  L.nodes = {{0, {1, leaf_ref(1)}}, {1, {2, leaf_ref(3)}}, {2, {leaf_ref(2), leaf_ref(4)}}};
  L.root = 0;
  L.leaf_cell = {pvs::kNoCell, 0, pvs::kNoCell, 1, 2};
  L.cell_leaf = {1, 3, 4};
  L.boxes = {
      {{-10, -10, -10}, {0, 10, 10}}, {{0, -10, -10}, {10, 10, 2}}, {{0, -10, 2}, {10, 5, 10}}};
  L.neighbours = {{1, 2}, {0, 2}, {0, 1}};
  return L;
}

struct Sample {
  pvs::FileInfo info;
  std::vector<pvs::CellSet> cells;
};

Sample bsp_sample() {
  Sample s;
  s.info.scene_fingerprint = 0x1122334455667788ull;
  s.info.universe = 300;
  s.info.layout = small_tree();
  s.info.metadata = "{\"note\":\"golden file of PVS format version 2\"}";
  std::vector<uint32_t> a, b;
  for (uint32_t i = 0; i < 200; ++i) a.push_back(i);
  b = a;
  b.push_back(250);
  s.cells = {a, b, std::vector<uint32_t>{7, 42, 299}};
  return s;
}

std::string golden_path() {
  return source_dir() + "/tests/golden/pvs_v2_bsp_tree.pvs";
}

// Offsets in the sample's file (docs/pvs-format.md, BSP tree): the section starts at 64 with 16
// bytes of counts and root, then 3 planes of 32 bytes, 3 nodes of 12, 5 leaves of 4, 3 cells of 52,
// then the neighbour lists.
constexpr size_t kPlanesAt = 64 + 16, kNodesAt = kPlanesAt + 3 * 32, kLeavesAt = kNodesAt + 3 * 12,
                 kCellsAt = kLeavesAt + 5 * 4, kNeighboursAt = kCellsAt + 3 * 52;

std::optional<uint32_t> cell_at(const pvs::CellLayout& L, double x, double y, double z) {
  const double p[3] = {x, y, z};
  return L.find_cell(p);
}

// The FormatError of reading `f` after its CRCs are fixed.
pvs::FormatError rejection(std::string f) {
  fix_crcs(f);
  try {
    pvs::Reader::from_memory(f);
  } catch (const pvs::FormatError& e) {
    return e;
  }
  ADD_FAILURE() << "the edited file was accepted";
  return pvs::FormatError(0, "accepted");
}

void put32(std::string& f, size_t at, uint32_t v) {
  std::memcpy(&f[at], &v, 4);
}

}  // namespace

TEST(PvsBspLayout, RoundTripKeepsTreeCellsNeighboursAndSets) {
  Sample s = bsp_sample();
  std::string f = pvs::write_pvs(s.info, s.cells);
  pvs::Reader r = pvs::Reader::from_memory(f);
  EXPECT_EQ(r.info().version, 2u);
  EXPECT_TRUE(r.info().layout == s.info.layout);
  EXPECT_EQ(r.info().metadata, s.info.metadata);
  ASSERT_EQ(r.cell_count(), 3u);
  for (uint32_t c = 0; c < 3; ++c) EXPECT_EQ(r.read_cell(c), *s.cells[c]) << c;
  r.verify();
}

TEST(PvsBspLayout, FindCellWalksThePlanesAndSendsPointsOnAPlaneBack) {
  const pvs::CellLayout L = small_tree();
  EXPECT_EQ(cell_at(L, -1, 0, 0), 0u);           // back of x = 0
  EXPECT_EQ(cell_at(L, 1, 0, 0), 1u);            // front of x = 0, back of z = 2
  EXPECT_EQ(cell_at(L, 1, 0, 3), 2u);            // front of z = 2, back of y = 5
  EXPECT_EQ(cell_at(L, 1, 6, 3), std::nullopt);  // front of y = 5: the sky leaf, no cell
  // Exactly on a plane: d = 0 is not > 0, so the back child (the Quake engine's rule).
  EXPECT_EQ(cell_at(L, 0, 0, 0), 0u);
  EXPECT_EQ(cell_at(L, 1, 0, 2), 1u);
  EXPECT_EQ(cell_at(L, 1, 5, 3), 2u);
  // Just off a plane, either way.
  const double tiny = std::numeric_limits<double>::denorm_min();
  EXPECT_EQ(cell_at(L, tiny, 0, 0), 1u);
  EXPECT_EQ(cell_at(L, -tiny, 0, 0), 0u);
  EXPECT_EQ(cell_at(L, 1, 5 + 1e-12, 3), std::nullopt);
  const double p[3] = {1, 6, 3};
  EXPECT_EQ(L.find_leaf(p), 2u);
}

TEST(PvsBspLayout, BadTreesAreRejectedNamingTheOffset) {
  Sample s = bsp_sample();
  const std::string good = pvs::write_pvs(s.info, s.cells);
  auto expect = [&](std::string f, uint64_t offset, const std::string& words) {
    pvs::FormatError e = rejection(std::move(f));
    EXPECT_EQ(e.offset(), offset) << e.what();
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
  };
  {  // A cycle: node 2's front child is node 0.
    std::string f = good;
    put32(f, kNodesAt + 2 * 12 + 4, 0);
    expect(f, kNodesAt + 2 * 12, "reached twice");
  }
  {  // A node index out of range.
    std::string f = good;
    put32(f, kNodesAt + 1 * 12 + 4, 9);
    expect(f, kNodesAt + 1 * 12, "node 9 out of range");
  }
  {  // A leaf out of range.
    std::string f = good;
    put32(f, kNodesAt + 0 * 12 + 8, uint32_t(leaf_ref(99)));
    expect(f, kNodesAt, "leaf 99 out of range");
  }
  {  // A plane index out of range.
    std::string f = good;
    put32(f, kNodesAt + 2 * 12, 3);
    expect(f, kNodesAt + 2 * 12, "plane 3 out of range");
  }
  {  // The root out of range.
    std::string f = good;
    put32(f, 64 + 12, 3);
    expect(f, 64 + 12, "root");
  }
  {  // A node nobody reaches: the root is node 1.
    std::string f = good;
    put32(f, 64 + 12, 1);
    expect(f, kNodesAt, "not reachable");
  }
  for (double bad : {std::nan(""), std::numeric_limits<double>::infinity()}) {
    std::string f = good;  // plane 1's distance
    std::memcpy(&f[kPlanesAt + 32 + 24], &bad, 8);
    expect(f, kPlanesAt + 32, "not finite");
  }
  {  // A zero normal.
    std::string f = good;
    std::memset(&f[kPlanesAt + 2 * 32], 0, 24);
    expect(f, kPlanesAt + 2 * 32, "nonzero normal");
  }
  {  // Leaf 2 (sky) claims cell 0, whose leaf is 1.
    std::string f = good;
    put32(f, kLeavesAt + 2 * 4, 0);
    expect(f, kLeavesAt + 2 * 4, "not a cell of that leaf");
  }
  {  // Cell 1 claims leaf 4, which belongs to cell 2.
    std::string f = good;
    put32(f, kCellsAt + 1 * 52, 4);
    expect(f, kLeavesAt + 3 * 4, "not a cell of that leaf");  // leaf 3 -> cell 1 -> leaf 4
  }
  {  // Cell 0's first neighbour 1 becomes 2 (then 2, 2: not increasing).
    std::string f = good;
    put32(f, kNeighboursAt + 4, 2);
    expect(f, kNeighboursAt, "cell 0");
  }
  {  // Cell 2's neighbours {0, 1} become {0, 2}: cell 1 lists 2, which no longer lists it back.
    std::string f = good;
    put32(f, kNeighboursAt + 2 * 12 + 8, 2);
    expect(f, kNeighboursAt + 12, "does not list this cell back");
  }
  {  // A neighbour count running past the section.
    std::string f = good;
    put32(f, kNeighboursAt, 1000000);
    expect(f, kNeighboursAt, "do not fit");
  }
  {  // A plane count running past the section.
    std::string f = good;
    put32(f, 64, 0x7FFFFFFF);
    expect(f, 64, "do not fit");
  }
}

TEST(PvsBspLayout, WriterRefusesTheSameBadTrees) {
  Sample s = bsp_sample();
  s.info.layout.nodes[2].children[0] = 0;
  EXPECT_THROW(pvs::write_pvs(s.info, s.cells), std::invalid_argument);
  s = bsp_sample();
  s.info.layout.neighbours[0] = {1};  // 2 lists 0, 0 does not list 2
  EXPECT_THROW(pvs::write_pvs(s.info, s.cells), std::invalid_argument);
  s = bsp_sample();
  s.info.layout.neighbours[0] = {0, 1, 2};  // itself
  EXPECT_THROW(pvs::write_pvs(s.info, s.cells), std::invalid_argument);
  s = bsp_sample();
  s.info.layout.planes[0].normal[1] = std::nan("");
  EXPECT_THROW(pvs::write_pvs(s.info, s.cells), std::invalid_argument);
}

TEST(PvsBspLayout, Version1FileWithTheBspLayoutIsRejected) {
  Sample s = bsp_sample();
  std::string f = pvs::write_pvs(s.info, s.cells);
  put32(f, 8, 1);
  pvs::FormatError e = rejection(f);
  EXPECT_EQ(e.offset(), 41u);
  EXPECT_NE(std::string(e.what()).find("needs format version 2"), std::string::npos) << e.what();
}

TEST(PvsBspLayout, GridAndBoxListFilesAreStillWrittenAndReadAsVersion1) {
  for (const char* name : {"pvs_v1_grid.pvs", "pvs_v1_boxes_partial.pvs"}) {
    std::string f = vislib::read_file(source_dir() + "/tests/golden/" + name);
    pvs::Reader r = pvs::Reader::from_memory(f);
    EXPECT_EQ(r.info().version, 1u) << name;
    r.verify();
    std::vector<pvs::CellSet> cells;
    for (uint32_t c = 0; c < r.cell_count(); ++c)
      cells.push_back(r.is_absent(c) ? pvs::CellSet{} : pvs::CellSet{r.read_cell(c)});
    EXPECT_EQ(pvs::write_pvs(r.info(), cells), f) << name;  // version 1, byte for byte
  }
}

TEST(PvsBspLayout, GoldenFileOfVersion2IsReproducedAndReadBack) {
  Sample s = bsp_sample();
  const std::string bytes = pvs::write_pvs(s.info, s.cells);
  const char* env = std::getenv("VISLIB_UPDATE_GOLDEN");
  if (env && std::string(env) == "1") vislib::write_file_atomic(golden_path(), bytes);
  EXPECT_EQ(bytes, vislib::read_file(golden_path()));
  pvs::Reader r = pvs::Reader::from_file(golden_path());
  EXPECT_EQ(r.info().version, 2u);
  EXPECT_EQ(r.info().scene_fingerprint, s.info.scene_fingerprint);
  EXPECT_EQ(r.info().universe, s.info.universe);
  EXPECT_TRUE(r.info().layout == s.info.layout);
  for (uint32_t c = 0; c < r.cell_count(); ++c) EXPECT_EQ(r.read_cell(c), *s.cells[c]) << c;
}

TEST(PvsBspLayout, RuntimeFindsCellsByTheTreeAndPrefetchesPortalNeighbours) {
  Sample s = bsp_sample();
  const std::string path = temp_dir("pvs_bsp_runtime") + "/tree.pvs";
  vislib::write_file_atomic(path, pvs::write_pvs(s.info, s.cells));
  pvs_runtime::Pvs p = pvs_runtime::Pvs::open(path);
  const double a[3] = {1, 0, 3}, sky[3] = {1, 6, 3}, on[3] = {0, 0, 0};
  const double nan[3] = {std::nan(""), 0, 0};
  EXPECT_EQ(p.find_cell(a), 2u);
  EXPECT_EQ(p.find_cell(sky), std::nullopt);
  EXPECT_EQ(p.find_cell(on), 0u);
  EXPECT_EQ(p.find_cell(nan), std::nullopt);
  EXPECT_EQ(p.neighbours(0), (std::vector<uint32_t>{1, 2}));
  EXPECT_EQ(p.neighbours(2, std::numeric_limits<double>::infinity()),
            (std::vector<uint32_t>{0, 1}));
  EXPECT_EQ(p.visible_ids(2), (std::vector<uint32_t>{7, 42, 299}));
}

// lqdm1's tree as the layout (bsp_leaf_layout, the bake's side), through a file: random points of
// each cell's leaf volume walk down the stored planes to that cell; each cell's neighbours (leaves
// whose volumes share a face) are leaves the map's own vis marks visible from it (a portal
// neighbour is always visible); every cell has one. Budget: about a second (Release).
TEST(PvsBspLayoutLibreQuake, Lqdm1PointsOfEachLeafVolumeFindThatLeafsCellThroughTheFile) {
  VISLIB_REQUIRE_SHARED(shared);
  const std::string path = shared + "/scenes/librequake/lqdm1.bsp";
  const vislib::QuakeBsp bsp = vislib::read_quake_bsp(path);
  const std::vector<uint32_t> leaves = vislib::bsp_cell_leaves(bsp);
  // Leaf 0 is the only solid leaf and lqdm1 has no sky or liquids: every vis leaf is a cell.
  EXPECT_EQ(leaves.size(), bsp.visleaf_count());
  pvs::FileInfo info;
  info.universe = 1;
  info.layout = vislib::bsp_leaf_layout(bsp, leaves);
  std::vector<pvs::CellSet> cells(leaves.size(), std::vector<uint32_t>{});
  pvs::Reader r = pvs::Reader::from_memory(pvs::write_pvs(info, cells));
  const pvs::CellLayout& L = r.info().layout;
  ASSERT_EQ(L.cell_count(), leaves.size());

  std::mt19937_64 rng(36);
  size_t points = 0;
  for (const vislib::BspLeafPiece& piece : vislib::bsp_leaf_pieces(bsp)) {
    if (piece.leaf == 0 || piece.volume.empty()) continue;
    const uint32_t cell = L.leaf_cell.at(piece.leaf);
    ASSERT_NE(cell, pvs::kNoCell) << "leaf " << piece.leaf;
    const vislib::Box3 b = piece.volume.bounds();
    int found = 0;
    for (int tries = 0; tries < 2000 && found < 20; ++tries) {
      vislib::Vec3 q;
      for (int k = 0; k < 3; ++k)
        q[k] = std::uniform_real_distribution<double>(b.min[k], b.max[k])(rng);
      bool inside = true;  // strictly inside, 1e-6 units from every plane
      for (const vislib::HalfSpace& h : piece.volume.halfspaces)
        inside = inside && vislib::dot(h.normal, q) < h.offset - 1e-6 * vislib::length(h.normal);
      if (!inside) continue;
      ++found;
      const vislib::Vec3 sp = vislib::quake_to_scene(q);
      const double p[3] = {sp.x, sp.y, sp.z};
      ASSERT_EQ(L.find_cell(p), cell) << "leaf " << piece.leaf;
      ASSERT_EQ(vislib::bsp_point_leaf(bsp, q), piece.leaf);  // the oracle agrees
    }
    EXPECT_GT(found, 0) << "no point sampled in leaf " << piece.leaf;
    points += size_t(found);
  }
  size_t pairs = 0;
  for (uint32_t c = 0; c < L.cell_count(); ++c) {
    EXPECT_FALSE(L.neighbours[c].empty()) << "cell " << c;
    const std::vector<uint32_t> sees = vislib::bsp_leaf_sees(bsp, L.cell_leaf[c]);
    for (uint32_t o : L.neighbours[c]) {
      EXPECT_TRUE(std::binary_search(sees.begin(), sees.end(), L.cell_leaf[o]))
          << "leaf " << L.cell_leaf[c] << " does not see its neighbour leaf " << L.cell_leaf[o];
      ++pairs;
    }
  }
  std::printf("lqdm1: %zu cells, %zu points walked to their leaf's cell, %zu neighbour pairs\n",
              leaves.size(), points, pairs / 2);
}
