// Tests of the runtime loader (runtime/pvs_runtime.h) and its C API (runtime/pvs_runtime_c.h).
// This binary links vislib::runtime only (tests/CMakeLists.txt), not vislib.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "pvs_format/pvs_format.h"
#include "runtime/pvs_runtime.h"
#include "runtime/pvs_runtime_c.h"

namespace fs = std::filesystem;
using pvs_runtime::Pvs;

namespace {

constexpr uint64_t kScene = 0x1234abcd5678ef00ull;

std::string temp_dir(const std::string& name) {
  fs::path d =
      fs::temp_directory_path() / ("vislib_runtime_test_" + std::to_string(getpid())) / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d.string();
}

void write_file(const std::string& path, const std::string& bytes) {
  std::ofstream f(path, std::ios::binary);
  f.write(bytes.data(), std::streamsize(bytes.size()));
}

// A 4 x 2 x 3 grid over [0,8] x [0,4] x [0,6] (2-unit cells); cell c sees ids {c, c+1, ..., 2c}.
struct GridFile {
  pvs::FileInfo info;
  std::vector<pvs::CellSet> cells;
  std::string bytes;
};
GridFile make_grid_file() {
  GridFile g;
  g.info.scene_fingerprint = kScene;
  g.info.universe = 100;
  g.info.layout.kind = pvs::LayoutKind::Grid;
  g.info.layout.grid_box = {{0, 0, 0}, {8, 4, 6}};
  g.info.layout.nx = 4;
  g.info.layout.ny = 2;
  g.info.layout.nz = 3;
  g.info.layout.eye_lo = 0;
  g.info.layout.eye_hi = 2;
  for (uint32_t c = 0; c < 24; ++c) {
    std::vector<uint32_t> ids;
    for (uint32_t i = c; i <= 2 * c; ++i) ids.push_back(i);
    g.cells.push_back(ids);
  }
  g.bytes = pvs::write_pvs(g.info, g.cells);
  return g;
}

std::vector<uint32_t> brute_neighbours(const pvs::CellLayout& l, uint32_t cell, double margin) {
  pvs::Box me = l.cell_box(cell);
  std::vector<uint32_t> out;
  for (uint32_t c = 0; c < l.cell_count(); ++c) {
    if (c == cell) continue;
    pvs::Box b = l.cell_box(c);
    bool touch = true;
    for (int k = 0; k < 3; ++k)
      touch = touch && b.min[k] <= me.max[k] + margin && me.min[k] - margin <= b.max[k];
    if (touch) out.push_back(c);
  }
  return out;
}

}  // namespace

TEST(Runtime, ReturnsTheIdsWrittenForTheCellOfAPosition) {
  GridFile g = make_grid_file();
  std::string path = temp_dir("grid") + "/grid.pvs";
  write_file(path, g.bytes);
  pvs_runtime::OpenOptions opt;
  opt.expected_fingerprint = kScene;
  Pvs p = Pvs::open(path, opt);
  EXPECT_EQ(p.cell_count(), 24u);
  EXPECT_EQ(p.file_size(), g.bytes.size());
  // (5, 3, 1): i = 2, j = 1, k = 0 -> cell 2 + 4 * 1 = 6.
  double eye[3] = {5, 3, 1};
  ASSERT_EQ(p.find_cell(eye), std::optional<uint32_t>(6));
  EXPECT_EQ(p.visible_ids(6), *g.cells[6]);
  EXPECT_EQ(p.visible_count(6), 7u);
  double outside[3] = {-1, 1, 1};
  EXPECT_FALSE(p.find_cell(outside));
  for (uint32_t c = 0; c < 24; ++c) {
    p.prefetch(c);
    EXPECT_EQ(p.visible_ids(c), *g.cells[c]) << c;
  }
}

TEST(Runtime, GridNeighboursAreTheCellsThatTouchOrComeWithinTheMargin) {
  GridFile g = make_grid_file();
  std::string path = temp_dir("grid_nb") + "/grid.pvs";
  write_file(path, g.bytes);
  Pvs p = Pvs::open(path);
  // Corner cell 0: 3 neighbours along x/y/z, 3 across edges, 1 across the corner.
  EXPECT_EQ(p.neighbours(0), (std::vector<uint32_t>{1, 4, 5, 8, 9, 12, 13}));
  for (double margin : {0.0, 1.0, 2.5})
    for (uint32_t c = 0; c < 24; ++c)
      EXPECT_EQ(p.neighbours(c, margin), brute_neighbours(g.info.layout, c, margin)) << c;
}

TEST(Runtime, BoxListLookupAndNeighboursMatchALinearScan) {
  pvs::FileInfo info;
  info.scene_fingerprint = kScene;
  info.universe = 10;
  info.layout.kind = pvs::LayoutKind::Boxes;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> pos(-50, 50), side(0.5, 4);
  for (int i = 0; i < 500; ++i) {
    pvs::Box b;
    for (int k = 0; k < 3; ++k) {
      b.min[k] = k == 1 ? pos(rng) * 0.05 : pos(rng);
      b.max[k] = b.min[k] + side(rng);
    }
    info.layout.boxes.push_back(b);
  }
  std::vector<pvs::CellSet> cells(500, std::vector<uint32_t>{1, 3});
  std::string path = temp_dir("boxes") + "/boxes.pvs";
  write_file(path, pvs::write_pvs(info, cells));
  Pvs p = Pvs::open(path);
  std::uniform_real_distribution<double> q(-55, 55);
  int found = 0;
  for (int i = 0; i < 20000; ++i) {
    double pt[3] = {q(rng), q(rng) * 0.05, q(rng)};
    auto expect = info.layout.find_cell(pt);
    ASSERT_EQ(p.find_cell(pt), expect);
    found += bool(expect);
  }
  EXPECT_GT(found, 100);  // the sample does land in cells
  for (uint32_t c = 0; c < 500; ++c)
    ASSERT_EQ(p.neighbours(c, 1.0), brute_neighbours(info.layout, c, 1.0)) << c;
}

TEST(Runtime, RejectsAPvsOfAnotherScene) {
  std::string path = temp_dir("other_scene") + "/grid.pvs";
  write_file(path, make_grid_file().bytes);
  pvs_runtime::OpenOptions opt;
  opt.expected_fingerprint = kScene + 1;
  try {
    Pvs::open(path, opt);
    FAIL() << "opened a PVS of another scene";
  } catch (const pvs_runtime::FingerprintMismatch& e) {
    EXPECT_EQ(e.offset(), 24u);
    EXPECT_EQ(e.found(), kScene);
    EXPECT_NE(std::string(e.what()).find("baked for another scene"), std::string::npos) << e.what();
  }
}

TEST(Runtime, RejectsCorruptAndTruncatedFilesWithTheByteOffset) {
  const std::string dir = temp_dir("corrupt");
  const GridFile g = make_grid_file();
  pvs::Reader r = pvs::Reader::from_memory(g.bytes);

  // A damaged block: opening reads only header, layout and index, so the damage shows when the
  // cell is read, or at open with verify_all_blocks.
  std::string bad = g.bytes;
  const uint64_t block = r.entry(5).offset + 1;
  bad[block] = char(bad[block] ^ 0x40);
  write_file(dir + "/block.pvs", bad);
  Pvs p = Pvs::open(dir + "/block.pvs");
  EXPECT_EQ(p.visible_ids(4), *g.cells[4]);
  EXPECT_THROW(p.visible_ids(5), pvs::FormatError);
  pvs_runtime::OpenOptions all;
  all.verify_all_blocks = true;
  EXPECT_THROW(Pvs::open(dir + "/block.pvs", all), pvs::FormatError);

  // A damaged header byte, a truncated file, not a PVS file at all, an empty file.
  std::string hdr = g.bytes;
  hdr[33] = char(hdr[33] ^ 1);
  write_file(dir + "/header.pvs", hdr);
  write_file(dir + "/truncated.pvs", g.bytes.substr(0, g.bytes.size() - 3));
  write_file(dir + "/text.pvs",
             "hello, this is not a PVS file at all, just some text bytes for the test");
  write_file(dir + "/empty.pvs", "");
  struct Case {
    const char* file;
    const char* message;
  };
  for (Case c : {Case{"header.pvs", "header checksum mismatch"}, Case{"truncated.pvs", "truncated"},
                 Case{"text.pvs", "not a PVS file"}, Case{"empty.pvs", "truncated"}}) {
    try {
      Pvs::open(dir + "/" + c.file);
      FAIL() << c.file << " opened";
    } catch (const pvs::FormatError& e) {
      EXPECT_NE(std::string(e.what()).find(c.message), std::string::npos)
          << c.file << ": " << e.what();
    }
  }
}

TEST(Runtime, MissingFileIsAnOpenErrorNamingThePath) {
  try {
    Pvs::open("/nonexistent/dir/x.pvs");
    FAIL();
  } catch (const pvs_runtime::OpenError& e) {
    EXPECT_EQ(e.error_number(), ENOENT);
    EXPECT_NE(std::string(e.what()).find("/nonexistent/dir/x.pvs"), std::string::npos);
  }
}

TEST(RuntimeC, FingerprintMismatchAndCorruptFileReturnCodesAndMessages) {
  const std::string dir = temp_dir("c_api");
  const GridFile g = make_grid_file();
  write_file(dir + "/ok.pvs", g.bytes);
  pvs_rt* h = reinterpret_cast<pvs_rt*>(1);
  EXPECT_EQ(pvs_rt_open((dir + "/ok.pvs").c_str(), 1, kScene ^ 0xff, &h), PVS_RT_FINGERPRINT);
  EXPECT_EQ(h, nullptr);
  EXPECT_NE(std::string(pvs_rt_last_error()).find("baked for another scene"), std::string::npos)
      << pvs_rt_last_error();

  std::string bad = g.bytes;
  bad[70] = char(bad[70] ^ 0x10);  // inside the layout section
  write_file(dir + "/bad.pvs", bad);
  EXPECT_EQ(pvs_rt_open((dir + "/bad.pvs").c_str(), 1, kScene, &h), PVS_RT_FORMAT);
  EXPECT_NE(std::string(pvs_rt_last_error()).find("layout section checksum mismatch"),
            std::string::npos)
      << pvs_rt_last_error();

  EXPECT_EQ(pvs_rt_open((dir + "/missing.pvs").c_str(), 0, 0, &h), PVS_RT_IO);
  EXPECT_NE(std::string(pvs_rt_last_error()).find("missing.pvs"), std::string::npos);
  EXPECT_EQ(pvs_rt_open(nullptr, 0, 0, &h), PVS_RT_INVALID_ARGUMENT);
}

TEST(RuntimeC, EngineCallsReturnIdsNeighboursAndReportShortBuffers) {
  const std::string dir = temp_dir("c_api_loop");
  const GridFile g = make_grid_file();
  write_file(dir + "/ok.pvs", g.bytes);
  pvs_rt* h = nullptr;
  ASSERT_EQ(pvs_rt_open((dir + "/ok.pvs").c_str(), 1, kScene, &h), PVS_RT_OK)
      << pvs_rt_last_error();
  pvs_rt_info info;
  ASSERT_EQ(pvs_rt_get_info(h, &info), PVS_RT_OK);
  EXPECT_EQ(info.cell_count, 24u);
  EXPECT_EQ(info.scene_fingerprint, kScene);
  double eye[3] = {5, 3, 1};
  uint32_t cell = 0;
  ASSERT_EQ(pvs_rt_find_cell(h, eye, &cell), PVS_RT_OK);
  EXPECT_EQ(cell, 6u);
  double far_away[3] = {100, 0, 0};
  EXPECT_EQ(pvs_rt_find_cell(h, far_away, &cell), PVS_RT_NOT_FOUND);

  uint32_t n = 0;
  ASSERT_EQ(pvs_rt_visible_count(h, 6, &n), PVS_RT_OK);
  std::vector<uint32_t> ids(n);
  size_t count = 0;
  EXPECT_EQ(pvs_rt_visible_ids(h, 6, ids.data(), n - 1, &count), PVS_RT_BUFFER_TOO_SMALL);
  EXPECT_EQ(count, n);
  ASSERT_EQ(pvs_rt_visible_ids(h, 6, ids.data(), ids.size(), &count), PVS_RT_OK);
  EXPECT_EQ(ids, *g.cells[6]);

  uint32_t nb[27];
  ASSERT_EQ(pvs_rt_neighbours(h, 0, 0.0, nb, 27, &count), PVS_RT_OK);
  EXPECT_EQ(std::vector<uint32_t>(nb, nb + count), (std::vector<uint32_t>{1, 4, 5, 8, 9, 12, 13}));
  EXPECT_EQ(pvs_rt_neighbours(h, 0, 0.0, nb, 2, &count), PVS_RT_BUFFER_TOO_SMALL);
  EXPECT_EQ(count, 7u);
  EXPECT_EQ(pvs_rt_prefetch(h, 23), PVS_RT_OK);
  EXPECT_EQ(pvs_rt_visible_count(h, 24, &n), PVS_RT_INVALID_ARGUMENT);
  EXPECT_NE(std::string(pvs_rt_last_error()).find("out of range"), std::string::npos);
  pvs_rt_close(h);
}

// End to end: `pvs generate city --blocks 2,2`, `pvs bake` a 3 x 1 x 3 grid at --res 32, then the
// runtime finds every cell from its centre, returns the same ids as pvs_format's reader, refuses
// another fingerprint, and the C example program walks it.
TEST(Runtime, LooksUpCellsOfABakedCity) {
  const std::string dir = temp_dir("city");
  const std::string pvs_exe = VISLIB_PVS_EXE;
  auto run = [](const std::string& cmd) {
    return std::system((cmd + " > /dev/null 2>&1").c_str());
  };
  ASSERT_EQ(run(pvs_exe + " generate city --blocks 2,2 -o " + dir + "/city.glb"), 0);
  ASSERT_EQ(run(pvs_exe + " bake " + dir +
                "/city.glb --box 0,0,0,40,3,40 --grid 3,1,3 --eye-height 1.5,1.8" +
                " --res 32 --threads 1 -o " + dir + "/city.pvs"),
            0);
  pvs::Reader reader = pvs::Reader::from_file(dir + "/city.pvs");
  const uint64_t fp = reader.info().scene_fingerprint;
  pvs_runtime::OpenOptions opt;
  opt.expected_fingerprint = fp;
  opt.verify_all_blocks = true;
  Pvs p = Pvs::open(dir + "/city.pvs", opt);
  ASSERT_EQ(p.cell_count(), 9u);
  size_t total = 0;
  for (uint32_t c = 0; c < 9; ++c) {
    pvs::Box b = p.info().layout.cell_box(c);
    double centre[3] = {(b.min[0] + b.max[0]) / 2, (b.min[1] + b.max[1]) / 2,
                        (b.min[2] + b.max[2]) / 2};
    EXPECT_EQ(p.find_cell(centre), std::optional<uint32_t>(c));
    EXPECT_EQ(p.visible_ids(c), reader.read_cell(c));
    EXPECT_EQ(p.neighbours(c), brute_neighbours(p.info().layout, c, 0.0));
    total += p.visible_count(c);
  }
  EXPECT_GT(total, 0u);
  opt.expected_fingerprint = fp ^ 1;
  EXPECT_THROW(Pvs::open(dir + "/city.pvs", opt), pvs_runtime::FingerprintMismatch);

  char fp_hex[17];
  std::snprintf(fp_hex, sizeof fp_hex, "%016llx", static_cast<unsigned long long>(fp));
  EXPECT_EQ(
      run(std::string(VISLIB_ENGINE_LOOP_EXE) + " " + dir + "/city.pvs " + fp_hex + " --frames 50"),
      0);
  EXPECT_NE(run(std::string(VISLIB_ENGINE_LOOP_EXE) + " " + dir + "/city.pvs 0123 --frames 50"), 0);
}

namespace {

// A small box-list file: 40 random boxes (the layout whose lookup converts coordinates to bucket
// indices).
std::string box_list_file(const std::string& dir) {
  pvs::FileInfo info;
  info.scene_fingerprint = kScene;
  info.universe = 10;
  info.layout.kind = pvs::LayoutKind::Boxes;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> pos(-20, 20), side(0.5, 4);
  for (int i = 0; i < 40; ++i) {
    pvs::Box b;
    for (int k = 0; k < 3; ++k) {
      b.min[k] = pos(rng);
      b.max[k] = b.min[k] + side(rng);
    }
    info.layout.boxes.push_back(b);
  }
  std::string path = dir + "/boxes.pvs";
  write_file(path, pvs::write_pvs(info, std::vector<pvs::CellSet>(40, std::vector<uint32_t>{2})));
  return path;
}

}  // namespace

// NaN and infinite positions are rejected before any conversion (UBSan flagged the cast of NaN to
// int in the box-list bucket lookup); huge finite ones are simply outside every cell.
TEST(RuntimeC, FindCellRejectsNonFinitePositionsOnBothLayouts) {
  std::string dir = temp_dir("c_nonfinite");
  write_file(dir + "/grid.pvs", make_grid_file().bytes);
  for (std::string path : {dir + "/grid.pvs", box_list_file(dir)}) {
    pvs_rt* h = nullptr;
    ASSERT_EQ(pvs_rt_open(path.c_str(), 0, 0, &h), PVS_RT_OK) << pvs_rt_last_error();
    const double inf = std::numeric_limits<double>::infinity(), nan = std::nan("");
    uint32_t cell = 77;
    for (double bad : {nan, inf, -inf}) {
      for (int k = 0; k < 3; ++k) {
        double p[3] = {1, 1, 1};
        p[k] = bad;
        EXPECT_EQ(pvs_rt_find_cell(h, p, &cell), PVS_RT_INVALID_ARGUMENT) << path << " axis " << k;
        EXPECT_NE(std::string(pvs_rt_last_error()).find("not finite"), std::string::npos);
      }
    }
    for (double far : {1e300, -1e300, 3e9}) {
      double p[3] = {far, far, far};
      EXPECT_EQ(pvs_rt_find_cell(h, p, &cell), PVS_RT_NOT_FOUND) << path;
    }
    EXPECT_EQ(cell, 77u);
    pvs_rt_close(h);
  }
}

TEST(RuntimeC, InfiniteMarginMakesEveryOtherCellANeighbour) {
  std::string dir = temp_dir("c_inf_margin");
  write_file(dir + "/grid.pvs", make_grid_file().bytes);
  for (std::string path : {dir + "/grid.pvs", box_list_file(dir)}) {
    pvs_rt* h = nullptr;
    ASSERT_EQ(pvs_rt_open(path.c_str(), 0, 0, &h), PVS_RT_OK) << pvs_rt_last_error();
    pvs_rt_info info;
    ASSERT_EQ(pvs_rt_get_info(h, &info), PVS_RT_OK);
    std::vector<uint32_t> out(info.cell_count);
    for (uint32_t c : {0u, 5u, info.cell_count - 1}) {
      size_t count = 0;
      ASSERT_EQ(pvs_rt_neighbours(h, c, std::numeric_limits<double>::infinity(), out.data(),
                                  out.size(), &count),
                PVS_RT_OK)
          << pvs_rt_last_error();
      ASSERT_EQ(count, size_t(info.cell_count - 1)) << path << " cell " << c;
      for (uint32_t i = 0, k = 0; i < info.cell_count; ++i) {
        if (i != c) {
          EXPECT_EQ(out[k++], i);
        }
      }
      // A huge finite margin reaches every cell too; NaN is an invalid argument.
      ASSERT_EQ(pvs_rt_neighbours(h, c, 1e308, out.data(), out.size(), &count), PVS_RT_OK);
      EXPECT_EQ(count, size_t(info.cell_count - 1));
      EXPECT_EQ(pvs_rt_neighbours(h, c, std::nan(""), out.data(), out.size(), &count),
                PVS_RT_INVALID_ARGUMENT);
    }
    pvs_rt_close(h);
  }
}

TEST(RuntimeC, StatusNameOfAnUnknownValueIsUnknown) {
  EXPECT_STREQ(pvs_rt_status_name(PVS_RT_OK), "ok");
  EXPECT_STREQ(pvs_rt_status_name(PVS_RT_INTERNAL), "internal");
  for (int v : {-1, 10, 16, 1000, std::numeric_limits<int>::min(), std::numeric_limits<int>::max()})
    EXPECT_STREQ(pvs_rt_status_name(v), "unknown") << v;
}
