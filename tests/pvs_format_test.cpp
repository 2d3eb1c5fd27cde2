// Tests of pvs_format/: round trips through every encoding, rejection of every kind of damage
// (each single byte, truncation, trailing bytes, newer versions, another scene), the golden files
// of format version 1, and merging shards.
//
// The golden files are tests/golden/pvs_v1_*.pvs. They are never regenerated silently: run the
// test binary with VISLIB_UPDATE_GOLDEN=1 only when shipping a new version's golden file.
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>

#include "tests/pvs_file_edit.h"
#include "tests/pvs_stream_case.h"
#include "tests/test_support.h"
#include "vislib/base/file_util.h"

using namespace vislib_test;

namespace {

std::vector<uint32_t> range(uint32_t lo, uint32_t hi) {
  std::vector<uint32_t> v;
  for (uint32_t i = lo; i < hi; ++i) v.push_back(i);
  return v;
}

std::vector<uint32_t> unite(std::vector<uint32_t> a, const std::vector<uint32_t>& b) {
  a.insert(a.end(), b.begin(), b.end());
  std::sort(a.begin(), a.end());
  a.erase(std::unique(a.begin(), a.end()), a.end());
  return a;
}

// A 4 x 1 x 2 grid whose sets make the writer use every encoding.
struct Sample {
  pvs::FileInfo info;
  std::vector<pvs::CellSet> cells;
};

Sample grid_sample() {
  Sample s;
  s.info.scene_fingerprint = 0x0123456789abcdefull;
  s.info.universe = 1000;
  s.info.granularity = pvs::Granularity::Triangle;
  s.info.layout.kind = pvs::LayoutKind::Grid;
  s.info.layout.grid_box = {{-10, 0, -5}, {10, 4, 5}};
  s.info.layout.nx = 4;
  s.info.layout.ny = 1;
  s.info.layout.nz = 2;
  s.info.layout.eye_lo = 1.5;
  s.info.layout.eye_hi = 1.8;
  s.info.metadata = "{\"note\":\"golden file of PVS format version 1\"}";
  std::vector<uint32_t> sparse = {3, 100, 500, 999};
  std::vector<uint32_t> dense = range(0, 400);
  std::vector<uint32_t> dense2 = unite(dense, {450});
  std::vector<uint32_t> dense3 = unite(dense2, range(600, 900));
  s.cells = {sparse,
             dense,
             dense2,
             dense3,
             std::vector<uint32_t>{},
             range(0, 1000),
             dense2,
             unite(sparse, {7, 8, 64, 65, 700})};
  return s;
}

// A box list of 5 cells, two of them absent (a shard), object granularity.
Sample boxes_sample() {
  Sample s;
  s.info.scene_fingerprint = 0xfedcba9876543210ull;
  s.info.universe = 40;
  s.info.granularity = pvs::Granularity::Object;
  s.info.partial = true;
  s.info.max_delta_depth = 2;
  s.info.layout.kind = pvs::LayoutKind::Boxes;
  for (int i = 0; i < 5; ++i)
    s.info.layout.boxes.push_back({{double(i), 0.5, 0}, {double(i) + 1, 2.0, 1}});
  s.info.metadata = "{}";
  s.cells = {range(0, 20), std::nullopt, unite(range(0, 20), {30}), std::nullopt, {{1, 5, 9, 39}}};
  return s;
}

std::string golden_path(const std::string& name) {
  return source_dir() + "/tests/golden/" + name;
}

bool update_golden() {
  const char* env = std::getenv("VISLIB_UPDATE_GOLDEN");
  return env && std::string(env) == "1";
}

// Opens and reads every cell (the complete check a damaged file must fail).
void read_everything(const std::string& bytes, const pvs::ReadOptions& opt = {}) {
  pvs::Reader r = pvs::Reader::from_memory(bytes, opt);
  r.verify();
}

}  // namespace

TEST(PvsFormat, Crc32cMatchesTheStandardCheckValue) {
  EXPECT_EQ(pvs::crc32c("123456789", 9), 0xE3069283u);
  EXPECT_EQ(pvs::crc32c("6789", 4, pvs::crc32c("12345", 5)), 0xE3069283u);
  EXPECT_EQ(pvs::fnv1a64("a", 1), 0xaf63dc4c8601ec8cull);  // the FNV-1a 64 test vector
}

TEST(PvsFormat, RoundTripThroughEveryEncoding) {
  Sample s = grid_sample();
  std::string bytes = pvs::write_pvs(s.info, s.cells);
  std::string path = temp_dir("pvs_roundtrip") + "/grid.pvs";
  vislib::write_file_atomic(path, bytes);
  for (int from_file = 0; from_file < 2; ++from_file) {
    pvs::Reader r = from_file ? pvs::Reader::from_file(path) : pvs::Reader::from_memory(bytes);
    EXPECT_EQ(r.info().metadata, s.info.metadata);
    EXPECT_EQ(r.info().scene_fingerprint, s.info.scene_fingerprint);
    EXPECT_TRUE(r.info().layout == s.info.layout);
    ASSERT_EQ(r.cell_count(), s.cells.size());
    std::set<std::string> used;
    for (uint32_t c = 0; c < r.cell_count(); ++c) {
      EXPECT_EQ(r.read_cell(c), *s.cells[c]) << "cell " << c;
      pvs::BlockInfo b = r.block_info(c);
      std::string name = pvs::encoding_name(b.encoding);
      if (b.encoding == pvs::Encoding::Delta)
        name += std::string("/") + pvs::encoding_name(b.inner);
      used.insert(name);
    }
    EXPECT_EQ(used, (std::set<std::string>{"sorted-delta", "run-length", "delta/sorted-delta",
                                           "delta/run-length"}));
  }
}

TEST(PvsFormat, EachCellIsTheSmallestOfItsCandidates) {
  // A cell equal to its x-neighbour costs a handful of bytes whatever its size.
  Sample s = grid_sample();
  pvs::Reader r = pvs::Reader::from_memory(pvs::write_pvs(s.info, s.cells));
  pvs::BlockInfo b = r.block_info(6);  // == cell 2, its z-neighbour
  EXPECT_EQ(b.encoding, pvs::Encoding::Delta);
  EXPECT_EQ(b.reference, 2u);
  EXPECT_EQ(b.size, 1u + 1 + 1 + 1 + 4);
  // All ids: one run.
  EXPECT_EQ(r.block_info(5).encoding, pvs::Encoding::RunLength);
  EXPECT_LE(r.block_info(5).size, 1u + 1 + 1 + 2 + 4);
}

TEST(PvsFormat, DeltaChainsStayWithinTheDeclaredDepth) {
  pvs::FileInfo info;
  info.universe = 5000;
  info.max_delta_depth = 3;
  info.layout.nx = 40;
  info.layout.grid_box = {{0, 0, 0}, {40, 1, 1}};
  std::vector<pvs::CellSet> cells;
  std::vector<uint32_t> ids = range(0, 4000);
  for (uint32_t c = 0; c < 40; ++c) {
    ids.push_back(4000 + c);  // each cell one more id: a Delta of one id against the previous
    cells.push_back(ids);
  }
  pvs::Reader r = pvs::Reader::from_memory(pvs::write_pvs(info, cells));
  for (uint32_t c = 0; c < 40; ++c) {
    int depth = 0;
    for (uint32_t x = c; r.block_info(x).encoding == pvs::Encoding::Delta;
         x = r.block_info(x).reference)
      ++depth;
    EXPECT_LE(depth, 3) << "cell " << c;
    EXPECT_EQ(r.read_cell(c), *cells[c]);
  }
}

TEST(PvsFormat, EveryDamagedByteIsDetected) {
  for (const Sample& s : {grid_sample(), boxes_sample()}) {
    const std::string good = pvs::write_pvs(s.info, s.cells);
    ASSERT_NO_THROW(read_everything(good));
    for (size_t i = 0; i < good.size(); ++i) {
      for (uint8_t mask : {uint8_t(0x01), uint8_t(0x80), uint8_t(0xFF)}) {
        std::string bad = good;
        bad[i] = char(uint8_t(bad[i]) ^ mask);
        EXPECT_THROW(read_everything(bad), pvs::FormatError) << "byte " << i << " ^ " << int(mask);
      }
    }
  }
}

TEST(PvsFormat, TruncationAtAnyLengthIsRejected) {
  Sample s = grid_sample();
  const std::string good = pvs::write_pvs(s.info, s.cells);
  for (size_t n = 0; n < good.size(); ++n) {
    try {
      read_everything(good.substr(0, n));
      ADD_FAILURE() << "accepted a file truncated to " << n << " bytes";
    } catch (const pvs::FormatError& e) {
      EXPECT_LE(e.offset(), good.size());
      if (n >= 64) {
        EXPECT_NE(std::string(e.what()).find("truncated"), std::string::npos) << e.what();
      }
    }
  }
}

TEST(PvsFormat, TrailingBytesAreRejected) {
  Sample s = grid_sample();
  const std::string good = pvs::write_pvs(s.info, s.cells);
  try {
    read_everything(good + std::string("\0", 1));
    FAIL() << "accepted trailing bytes";
  } catch (const pvs::FormatError& e) {
    EXPECT_EQ(e.offset(), good.size());
    EXPECT_NE(std::string(e.what()).find("trailing bytes"), std::string::npos) << e.what();
  }
  // Also when the header's size field is patched to match: then the blocks end early.
  std::string longer = good + "xxxx";
  uint64_t size = longer.size();
  std::memcpy(&longer[16], &size, 8);
  fix_crcs(longer);
  try {
    read_everything(longer);
    FAIL() << "accepted trailing bytes behind the last block";
  } catch (const pvs::FormatError& e) {
    EXPECT_EQ(e.offset(), good.size());
    EXPECT_NE(std::string(e.what()).find("trailing bytes"), std::string::npos) << e.what();
  }
}

TEST(PvsFormat, NewerVersionIsRejectedWithItsNumber) {
  Sample s = grid_sample();
  std::string f = pvs::write_pvs(s.info, s.cells);
  uint32_t v = pvs::kFormatVersion + 1;
  std::memcpy(&f[8], &v, 4);
  fix_crcs(f);
  try {
    read_everything(f);
    FAIL() << "accepted version " << v;
  } catch (const pvs::FormatError& e) {
    EXPECT_EQ(e.offset(), 8u);
    EXPECT_NE(std::string(e.what()).find("format version " + std::to_string(v) + " is newer"),
              std::string::npos)
        << e.what();
  }
}

TEST(PvsFormat, WrongSceneFingerprintIsRejected) {
  Sample s = grid_sample();
  std::string f = pvs::write_pvs(s.info, s.cells);
  pvs::ReadOptions opt;
  opt.expected_fingerprint = s.info.scene_fingerprint;
  EXPECT_NO_THROW(read_everything(f, opt));
  opt.expected_fingerprint = s.info.scene_fingerprint ^ 1;
  try {
    read_everything(f, opt);
    FAIL() << "accepted another scene's PVS";
  } catch (const pvs::FormatError& e) {
    EXPECT_EQ(e.offset(), 24u);
    EXPECT_NE(std::string(e.what()).find("another scene"), std::string::npos) << e.what();
  }
}

TEST(PvsFormat, InconsistentFieldsBehindValidChecksumsAreRejected) {
  // Edits that keep every CRC valid (as a deliberate forgery would): the parser itself must catch
  // them, at the right offset.
  Sample s = grid_sample();
  const std::string good = pvs::write_pvs(s.info, s.cells);
  auto expect_rejected = [&](std::string f, const std::string& what) {
    fix_crcs(f);
    try {
      read_everything(f);
      ADD_FAILURE() << "accepted: " << what;
    } catch (const pvs::FormatError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  std::string f = good;
  f[40] = 7;
  expect_rejected(f, "unknown granularity 7");
  f = good;
  uint32_t nx = 3;
  std::memcpy(&f[64 + 48], &nx, 4);
  expect_rejected(f, "does not have the header's 8 cells");
  f = good;
  uint32_t universe = 10;
  std::memcpy(&f[32], &universe, 4);
  expect_rejected(f, "exceeds the universe");
  f = good;
  f[42] = 0;  // max_delta_depth 0, but the file has Delta blocks
  expect_rejected(f, "delta chain longer");
  f = good;
  uint32_t count;
  size_t index = 64 + 76 + 4 + s.info.metadata.size() + 4;
  std::memcpy(&count, &f[index + 12], 4);
  ++count;
  std::memcpy(&f[index + 12], &count, 4);
  expect_rejected(f, "the index says");
  // A grid box whose extent is finite but whose extent times the cell count is not: cell_box's
  // (max - min) * i would overflow to inf (found by pvs_reader_fuzz after 1M runs, 2026-11-23).
  f = good;
  const double lo = -5e307, hi = 5e307;  // extent 1e308 (finite); times nx = 4 overflows
  std::memcpy(&f[64 + 0], &lo, 8);
  std::memcpy(&f[64 + 24], &hi, 8);
  expect_rejected(f, "extent times the cell count overflows");
  // The writer refuses the same layout.
  Sample w = grid_sample();
  w.info.layout.grid_box.min[0] = lo;
  w.info.layout.grid_box.max[0] = hi;
  EXPECT_THROW(pvs::write_pvs(w.info, w.cells), std::invalid_argument);
}

TEST(PvsFormat, HugeClaimsAreRejectedBeforeAllocating) {
  Sample s = grid_sample();
  std::string f = pvs::write_pvs(s.info, s.cells);
  uint32_t universe = 0xFFFFFFFFu;
  std::memcpy(&f[32], &universe, 4);
  fix_crcs(f);
  EXPECT_THROW(read_everything(f), pvs::FormatError);
  pvs::ReadOptions opt;
  opt.max_universe = 999;
  EXPECT_THROW(read_everything(pvs::write_pvs(s.info, s.cells), opt), pvs::FormatError);
}

TEST(PvsFormat, GoldenFilesOfVersion1AreReadBack) {
  for (auto [name, s] : {std::pair{"pvs_v1_grid.pvs", grid_sample()},
                         std::pair{"pvs_v1_boxes_partial.pvs", boxes_sample()}}) {
    if (update_golden())
      vislib::write_file_atomic(golden_path(name), pvs::write_pvs(s.info, s.cells));
    pvs::Reader r = pvs::Reader::from_file(golden_path(name));
    EXPECT_EQ(r.info().version, 1u);
    EXPECT_EQ(r.info().partial, s.info.partial);
    EXPECT_EQ(r.info().granularity, s.info.granularity);
    EXPECT_EQ(r.info().universe, s.info.universe);
    EXPECT_EQ(r.info().metadata, s.info.metadata);
    EXPECT_TRUE(r.info().layout == s.info.layout);
    for (uint32_t c = 0; c < r.cell_count(); ++c) {
      if (!s.cells[c]) {
        EXPECT_TRUE(r.is_absent(c));
        EXPECT_THROW(r.read_cell(c), pvs::FormatError);
      } else {
        EXPECT_EQ(r.read_cell(c), *s.cells[c]) << name << " cell " << c;
      }
    }
  }
}

TEST(PvsFormat, WriterReproducesTheGoldenFilesByteForByte) {
  for (auto [name, s] : {std::pair{"pvs_v1_grid.pvs", grid_sample()},
                         std::pair{"pvs_v1_boxes_partial.pvs", boxes_sample()}}) {
    EXPECT_EQ(pvs::write_pvs(s.info, s.cells), vislib::read_file(golden_path(name))) << name;
  }
}

TEST(PvsFormat, ShardsMergeIntoTheCompleteFileByteForByte) {
  Sample s = grid_sample();
  const std::string whole = pvs::write_pvs(s.info, s.cells);
  for (int count : {2, 3}) {
    std::vector<pvs::Reader> shards;
    for (int i = 0; i < count; ++i) {
      pvs::FileInfo info = s.info;
      info.partial = true;
      std::vector<pvs::CellSet> part(s.cells.size());
      for (size_t c = 0; c < s.cells.size(); ++c)
        if (int(c % count) == i) part[c] = s.cells[c];
      shards.push_back(pvs::Reader::from_memory(pvs::write_pvs(info, part)));
    }
    EXPECT_EQ(pvs::merge_pvs(shards), whole) << count << " shards";
    shards.pop_back();
    EXPECT_THROW(pvs::merge_pvs(shards), pvs::FormatError) << "a missing shard must be named";
  }
}

TEST(PvsFormat, GridLookupAgreesWithCellBoxes) {
  pvs::CellLayout L;
  L.grid_box = {{-1, 0, 0.1}, {2, 3, 0.7}};
  L.nx = 3;
  L.ny = 7;
  L.nz = 5;
  for (uint32_t c = 0; c < L.cell_count(); ++c) {
    pvs::Box b = L.cell_box(c);
    double centre[3], corner[3];
    for (int a = 0; a < 3; ++a) {
      centre[a] = 0.5 * (b.min[a] + b.max[a]);
      corner[a] = b.max[a];
    }
    EXPECT_EQ(L.find_cell(centre), c);
    // A shared corner belongs to the cell with the lowest index on each axis: never a higher id.
    auto at_corner = L.find_cell(corner);
    ASSERT_TRUE(at_corner);
    pvs::Box cb = L.cell_box(*at_corner);
    for (int a = 0; a < 3; ++a) EXPECT_TRUE(corner[a] >= cb.min[a] && corner[a] <= cb.max[a]);
    EXPECT_LE(*at_corner, c);
  }
  double outside[3] = {2.0001, 1, 0.5};
  EXPECT_FALSE(L.find_cell(outside));
}

TEST(PvsFormat, SortedDeltaPayloadRejectsNonCanonicalVarints) {
  std::string p;
  pvs::append_sorted_delta(p, {1, 2, 300});
  EXPECT_EQ(pvs::decode_sorted_delta(p, 301), (std::vector<uint32_t>{1, 2, 300}));
  EXPECT_THROW(pvs::decode_sorted_delta(p, 300), pvs::FormatError);
  EXPECT_THROW(pvs::decode_sorted_delta(std::string("\x01\x80\x00", 3), 10), pvs::FormatError);
  EXPECT_THROW(pvs::decode_sorted_delta(std::string("\x01\xff\xff\xff\xff\x7f", 6), 10),
               pvs::FormatError);
  EXPECT_THROW(pvs::decode_sorted_delta(p + "x", 301), pvs::FormatError);
}

TEST(PvsFormat, FuzzCorpusIsReadOrRejectedCleanly) {
  // Every input the fuzzer kept (fuzz/corpus/pvs_reader) either reads completely or throws
  // FormatError: under the sanitizer build of CI this replays the corpus.
  size_t files = 0;
  for (const auto& entry :
       std::filesystem::directory_iterator(source_dir() + "/fuzz/corpus/pvs_reader")) {
    std::string bytes = vislib::read_file(entry.path().string());
    for (bool checksums : {true, false}) {
      pvs::ReadOptions opt;
      opt.verify_checksums = checksums;
      try {
        read_everything(bytes, opt);
      } catch (const pvs::FormatError&) {
      }
    }
    ++files;
  }
  EXPECT_GE(files, 2u);
}

// docs/pvs-format.md, RunLength: the worked byte example, both ways: the
// writer gives the doc's bytes, and the doc's decoder (pseudocode, transcribed) gives the ids back.
TEST(PvsFormat, RunLengthWorkedExampleOfTheSpecIsExact) {
  const std::vector<uint32_t> ids = {3, 4, 5, 9, 200, 201, 202};
  const std::string doc = std::string("\x03", 1) + std::string("\x03\x02", 2) +
                          std::string("\x02\x00", 2) + std::string("\xBD\x01\x02", 3);
  std::string payload;
  pvs::append_run_length(payload, ids);
  EXPECT_EQ(payload, doc);
  // The doc's decoder; all varints here but 0xBD 0x01 are one byte.
  std::vector<uint32_t> values;
  for (size_t i = 0; i < doc.size(); ++i) {
    uint32_t v = uint8_t(doc[i]) & 0x7F;
    if (uint8_t(doc[i]) & 0x80) v |= uint32_t(uint8_t(doc[++i])) << 7;
    values.push_back(v);
  }
  ASSERT_EQ(values.size(), 7u);
  std::vector<uint32_t> decoded;
  uint32_t next = 0;
  for (uint32_t r = 0; r < values[0]; ++r) {
    uint32_t first = next + values[1 + 2 * r] + (r > 0 ? 1 : 0);
    for (uint32_t id = first; id <= first + values[2 + 2 * r]; ++id) decoded.push_back(id);
    next = first + values[2 + 2 * r] + 1;
  }
  EXPECT_EQ(decoded, ids);
}

// The whole block of the worked example (docs/pvs-format.md, RunLength) as the writer writes it in
// a file: encoding byte, payload, and the CRC32C the doc gives (computed apart from pvs::crc32c).
TEST(PvsFormat, RunLengthWorkedExampleIsTheBlockTheWriterWrites) {
  pvs::FileInfo info;
  info.universe = 256;
  info.layout.kind = pvs::LayoutKind::Grid;
  info.layout.grid_box = {{0, 0, 0}, {1, 1, 1}};
  info.layout.nx = info.layout.ny = info.layout.nz = 1;
  const std::vector<uint32_t> ids = {3, 4, 5, 9, 200, 201, 202};
  const std::string file = pvs::write_pvs(info, {ids});
  const std::string doc("\x01\x03\x03\x02\x02\x00\xBD\x01\x02\xBD\x22\xA2\x6C", 13);
  ASSERT_GE(file.size(), doc.size());
  EXPECT_EQ(file.substr(file.size() - doc.size()), doc);  // the only block ends the file
  pvs::Reader r = pvs::Reader::from_memory(file);
  EXPECT_EQ(r.block_info(0).encoding, pvs::Encoding::RunLength);
  EXPECT_EQ(r.block_info(0).size, doc.size());
  EXPECT_EQ(r.read_cell(0), ids);
}

// pvs::StreamWriter (and write_pvs, built on it) gives the bytes of the writer released before
// streaming: the fnv1a64 of its output on two inputs that use every Delta reference (grid
// neighbours along x, y, z; box list nearest centres up to 4096 cells back) was computed with
// pvs_format.cpp of main at 7642afc (the hashes below); the file sink sees the blocks in order.
TEST(PvsWriter, StreamingWriterGivesTheBytesOfTheReleasedWriter) {
  const uint64_t expected[2] = {0x81f9c7a0d67e816aull, 0x1fa9870fb20f9807ull};
  const size_t sizes[2] = {133943, 527007};
  for (int kind = 0; kind < 2; ++kind) {
    vislib_test::StreamCase s = vislib_test::make_stream_case(kind);
    std::string whole = pvs::write_pvs(s.info, s.cells);
    EXPECT_EQ(whole.size(), sizes[kind]);
    EXPECT_EQ(pvs::fnv1a64(whole.data(), whole.size()), expected[kind]) << "kind " << kind;
    std::string dir = temp_dir("stream_writer");
    std::string path = dir + "/s.pvs";
    uint64_t last_block = 0;
    {
      vislib::AtomicFile out(path);
      pvs::StreamWriter w(s.info, [&](uint64_t offset, std::string_view bytes) {
        out.write_at(offset, bytes);
        if (offset > last_block) last_block = offset;
      });
      for (const pvs::CellSet& c : s.cells) w.add(c);
      pvs::WriteStats st = w.finish();
      EXPECT_EQ(st.file_bytes, whole.size());
      out.commit();
    }
    EXPECT_EQ(vislib::read_file(path), whole);
    EXPECT_LT(last_block, whole.size());
  }
}
