// pvs_format.h: writing and reading PVS files (potentially visible sets per view cell), format
// versions 1 and 2, specified byte for byte in docs/pvs-format.md.
//
// This library depends on the C++ standard library only (house style, "Which way the arrows
// point"): an engine embeds it to load a PVS without vislib or its dependencies. It knows nothing
// of scenes: it stores a 64-bit scene fingerprint computed by the caller (vislib's is
// scene_fingerprint() in vislib/scene/scene_fingerprint.h, its byte stream is in the format
// document).
//
// Errors: a malformed, truncated, corrupted or too new file throws pvs::FormatError carrying the
// byte offset where the problem was found and what is wrong. The reader never crashes or reads
// out of bounds on any input (a libFuzzer target checks this: fuzz/pvs_reader_fuzz.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <fstream>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace pvs {

// The newest version this library reads. It writes version 1 for grid and box-list layouts (so
// their files stay byte-identical to what version-1 writers wrote) and version 2 for the BSP-tree
// layout, which version 1 does not have (format_version_for).
constexpr uint32_t kFormatVersion = 2;
// The eight magic bytes that open every PVS file ("\x89PVS\r\n\x1a\n", PNG-style: a text-mode
// transfer or a 7-bit channel damages them visibly).
constexpr char kMagic[8] = {'\x89', 'P', 'V', 'S', '\r', '\n', '\x1a', '\n'};
constexpr size_t kHeaderSize = 64;
constexpr size_t kIndexEntrySize = 16;

// A malformed file. `offset` is the byte offset (from the start of the file) where the reader
// found the problem; `what()` is "byte <offset>: <problem>".
class FormatError : public std::runtime_error {
 public:
  FormatError(uint64_t offset, const std::string& problem);
  uint64_t offset() const { return offset_; }
  const std::string& problem() const { return problem_; }

 private:
  uint64_t offset_;
  std::string problem_;
};

enum class Granularity : uint8_t { Triangle = 0, Object = 1 };
enum class LayoutKind : uint8_t { Grid = 0, Boxes = 1, BspTree = 2 };
// The version a file with this layout is written as: 1 for Grid and Boxes, 2 for BspTree.
uint32_t format_version_for(LayoutKind kind);

// How one cell's block is encoded (the first byte of the block).
enum class Encoding : uint8_t {
  SortedDelta = 0,  // count, first id, gaps - 1 as LEB128 varints
  RunLength = 1,    // runs of consecutive ids: (zeros before, length - 1) varint pairs
  Delta = 2,        // symmetric difference with an earlier cell, itself SortedDelta or RunLength
  Absent = 3,       // no data: the cell belongs to another shard (partial files only)
};
const char* encoding_name(Encoding e);

// Axis-aligned box; y is up (the glTF convention of vislib scenes).
struct Box {
  double min[3] = {0, 0, 0};
  double max[3] = {0, 0, 0};
};
bool operator==(const Box& a, const Box& b);

// One plane of a BSP-tree layout: the points p with dot(normal, p) - dist = 0 (scene units, y up).
struct BspPlane {
  double normal[3] = {0, 0, 0};
  double dist = 0;
};
// A child reference of a BSP node (as in a Quake map): >= 0 the node of that index, < 0 the leaf
// number -(child + 1).
constexpr uint32_t kNoCell = 0xFFFFFFFFu;  // BSP leaf without a cell (solid, sky, not baked)
struct BspNode {
  uint32_t plane = 0;
  int32_t children[2] = {0, 0};  // [0] front: d > 0; [1] back: d <= 0 (CellLayout::find_cell)
};
bool operator==(const BspPlane& a, const BspPlane& b);
bool operator==(const BspNode& a, const BspNode& b);

// Where the cells are. Grid: the box split into nx * ny * nz equal cells, cell id
// x + nx * (y + ny * z); a cell's view region spans its x and z range and the eye band
// [bottom + eye_lo, bottom + eye_hi] above the cell's bottom face. Boxes: one box per cell, which
// is both the cell and its view region (vislib's walkable cells: the eye band above a floor).
// BspTree: a BSP tree (planes, nodes, a root) whose leaves are numbered as in the map it comes
// from; each cell is one leaf (cell_leaf), each leaf is one cell or none (leaf_cell, kNoCell for
// solid, sky or leaves not baked); `boxes` holds the bounding box of each cell's volume, and
// `neighbours` each cell's neighbour cells (leaves sharing a portal: computed by the writer's
// caller, stored as given: sorted, unique, symmetric, without the cell itself). Preconditions of
// the BSP fields (checked by the writer, enforced by the reader): plane indices and child
// references in range, finite planes with a nonzero normal, every node reached exactly once from
// the root (a tree: no cycle, no shared or unreachable node), cell_leaf and leaf_cell inverse to
// each other, every cell's leaf reached by the tree.
struct CellLayout {
  LayoutKind kind = LayoutKind::Grid;
  Box grid_box;
  uint32_t nx = 1, ny = 1, nz = 1;
  double eye_lo = 0, eye_hi = 0;
  std::vector<Box> boxes;  // Boxes: the cells; BspTree: each cell's bounding box
  // BspTree only.
  std::vector<BspPlane> planes;
  std::vector<BspNode> nodes;
  int32_t root = -1;                // a child reference (a node, or a leaf for a one-leaf tree)
  std::vector<uint32_t> leaf_cell;  // per leaf number: its cell or kNoCell
  std::vector<uint32_t> cell_leaf;  // per cell: its leaf number
  std::vector<std::vector<uint32_t>> neighbours;  // per cell

  uint32_t cell_count() const;  // nx * ny * nz (grid, must fit 32 bits) or boxes.size()
  // The lookup box of cell `cell` (< cell_count()): grid cell (i, j, k) spans
  // [min + (max - min) * i / n, min + (max - min) * (i + 1) / n] on each axis, in double, in that
  // order of operations (the last cell ends exactly at max).
  Box cell_box(uint32_t cell) const;
  // The view region of cell `cell`: for a grid, the cell box with y replaced by the eye band;
  // for a box list, the box itself; for a BSP tree, the bounding box of the cell's volume (the
  // region itself is the leaf's convex volume, which this box only bounds).
  Box view_region(uint32_t cell) const;
  // Grid and box list: the first cell (in id order) whose lookup box contains p (boundaries
  // inclusive), if any; grid O(1), box list a linear scan. BSP tree: walks from the root, at each
  // node computing d = n[0]*p[0] + n[1]*p[1] + n[2]*p[2] - dist in binary64 in that order and going
  // to the front child when d > 0, to the back child otherwise (a point on a plane goes back, as in
  // the Quake engine's Mod_PointInLeaf), until a leaf; then that leaf's cell, nullopt for a leaf
  // without one. O(depth). A NaN coordinate goes back at every node.
  std::optional<uint32_t> find_cell(const double p[3]) const;
  // BSP tree: the leaf number `p` falls in (the walk of find_cell). nullopt for other layouts, or
  // if the walk exceeds nodes.size() steps (a cyclic tree the reader would have rejected).
  std::optional<uint32_t> find_leaf(const double p[3]) const;
};
bool operator==(const CellLayout& a, const CellLayout& b);

// Everything of a file except the visible sets.
struct FileInfo {
  uint32_t version = 1;  // as read; the writer writes format_version_for(layout.kind)
  bool partial = false;  // some cells are Absent (a shard of a bake)
  uint64_t scene_fingerprint = 0;
  uint32_t universe = 0;  // number of ids at this granularity (scene triangles or objects)
  Granularity granularity = Granularity::Triangle;
  uint8_t max_delta_depth = 8;  // longest chain of Delta references a cell may need
  CellLayout layout;
  std::string metadata;  // free text, by convention JSON with the bake settings
};

// ---- Writing --------------------------------------------------------------------------------

// One cell's visible ids (sorted, unique, each < universe), or nullopt for an absent cell.
using CellSet = std::optional<std::vector<uint32_t>>;

struct WriteStats {
  uint64_t file_bytes = 0, header_bytes = 0, layout_bytes = 0, index_bytes = 0, block_bytes = 0;
};

// Returns the bytes of a PVS file. Each present cell is encoded with the smallest of: sorted-delta
// varints, run-length runs, or a Delta against one candidate earlier cell (grid: the previous cell
// along x, y and z; box list: the previous cell and the earlier cell whose box centre is nearest,
// searched among the 4096 previous cells), with the difference itself sorted-delta or run-length,
// never making a chain longer than info.max_delta_depth. Ties go to the first of that order.
// Deterministic: same arguments, same bytes.
// Preconditions: cells.size() == info.layout.cell_count(); every set sorted, unique, ids <
// info.universe; some cell absent only if info.partial; layout boxes finite with min <= max;
// grid nx, ny, nz >= 1; eye_lo <= eye_hi; a BSP tree as CellLayout says. Violations throw
// std::invalid_argument. A BSP-tree layout is delta-encoded as a box list over its bounding boxes.
std::string write_pvs(const FileInfo& info, const std::vector<CellSet>& cells,
                      WriteStats* stats = nullptr);

// write_pvs one cell at a time, in cell order, for files larger than memory (pvs bake streams its
// output): the same bytes as write_pvs(info, all cells). `sink(offset, bytes)` stores bytes at a
// file offset: the header and layout at construction, each block as it is added (appended in
// order), the index and the header (which hold the sizes and offsets) again at finish(). Holds
// O(cell count) small state (16 index bytes, a depth byte and a bit per cell) plus the sets a
// later cell may reference as a Delta (grid: the previous nx*ny cells; box list: the previous
// 4096), kept sorted-delta encoded. Throws std::invalid_argument on the preconditions of
// write_pvs (a bad layout at construction, a bad set in add(), a missing cell in finish()).
// Not thread-safe.
class StreamWriter {
 public:
  using Sink = std::function<void(uint64_t offset, std::string_view bytes)>;
  StreamWriter(FileInfo info, Sink sink);
  ~StreamWriter();
  StreamWriter(StreamWriter&&) noexcept;
  // Adds the next cell (next_cell()): its set, or nullopt for an absent cell (info.partial only).
  void add(const CellSet& set);
  uint32_t next_cell() const;
  // Writes the index and the header once every cell was added. Returns the sizes.
  WriteStats finish();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// ---- Reading --------------------------------------------------------------------------------

struct IndexEntry {
  uint64_t offset = 0;  // of the block, from the start of the file
  uint32_t size = 0;    // bytes of the block, encoding byte and checksum included
  uint32_t count = 0;   // number of visible ids of the cell (0 when absent)
};

struct ReadOptions {
  // If set, a file whose scene fingerprint differs is rejected (FormatError at byte 24).
  std::optional<uint64_t> expected_fingerprint;
  // Files claiming more ids than this are rejected, so that no input can make the reader allocate
  // more than 4 bytes x this per decoded set. 2^27 ids = 512 MiB.
  uint32_t max_universe = 1u << 27;
  // False skips the CRC32C comparisons (everything else is still checked). Only for the fuzzer,
  // which could otherwise never get past a checksum to the parsing behind it.
  bool verify_checksums = true;
};

// Details of one block, for inspection.
struct BlockInfo {
  Encoding encoding = Encoding::SortedDelta;
  Encoding inner = Encoding::SortedDelta;  // Delta only: how the difference is encoded
  uint32_t reference = 0;                  // Delta only: the cell the difference is against
  uint32_t size = 0;                       // bytes, as in the index
};

// Reads a PVS file from a memory buffer or from a file on disk. Opening reads and checks the
// header, the layout section and the index (O(cells) bytes); a cell's block is read and checked
// (CRC32C) only when asked for, by seeking, plus the blocks of the earlier cells a Delta chain
// refers to (at most max_delta_depth more). verify() reads and checks every block.
// Not thread-safe: use one Reader per thread.
class Reader {
 public:
  // `bytes` is copied.
  static Reader from_memory(std::string_view bytes, const ReadOptions& options = {});
  // `bytes` is not copied: it must stay valid and unchanged for the life of the Reader (a
  // memory-mapped file, as the runtime loader uses). Blocks are read from it on demand.
  static Reader from_view(std::string_view bytes, const ReadOptions& options = {});
  // Throws FormatError(0, "cannot open ...") if the file cannot be opened.
  static Reader from_file(const std::string& path, const ReadOptions& options = {});
  // Reads a file of `size` bytes that the caller serves by byte range (a file fetched over HTTP
  // with range requests, a packed archive): `read(offset, n, out)` stores exactly the n bytes at
  // `offset` in out[0..n) (offset + n <= size, n > 0), or throws (the exception reaches the
  // caller of the Reader function that asked). Opening asks for the header, the layout section
  // and the index; read_cell asks for the cell's block and those of its Delta chain, and nothing
  // is cached: each call asks again.
  using RangeRead = std::function<void(uint64_t offset, size_t n, char* out)>;
  static Reader from_ranges(uint64_t size, RangeRead read, const ReadOptions& options = {});

  Reader(Reader&&) noexcept;
  Reader& operator=(Reader&&) noexcept;
  ~Reader();

  const FileInfo& info() const { return info_; }
  uint32_t cell_count() const { return uint32_t(index_.size()); }
  uint64_t file_size() const { return file_size_; }
  const IndexEntry& entry(uint32_t cell) const { return index_.at(cell); }
  // Offsets of the sections: the layout section starts at kHeaderSize, the index at
  // index_offset(), the first block at blocks_offset().
  uint64_t index_offset() const { return index_offset_; }
  uint64_t blocks_offset() const { return blocks_offset_; }

  bool is_absent(uint32_t cell);
  // The visible ids of cell `cell` (< cell_count()), sorted. Throws FormatError on a corrupt
  // block (or one of its references) and if the cell is absent.
  std::vector<uint32_t> read_cell(uint32_t cell);
  // The encoding of the cell's block (reads and checks that block only).
  BlockInfo block_info(uint32_t cell);
  // Reads and checks every block.
  void verify();

  struct Source;  // implementation detail: the memory buffer or the open file

 private:
  Reader() = default;
  void open(const ReadOptions& options);
  std::string read_block(uint32_t cell);
  std::vector<uint32_t> decode_cell(uint32_t cell, int depth);

  std::unique_ptr<Source> source_;
  FileInfo info_;
  std::vector<IndexEntry> index_;
  bool verify_checksums_ = true;
  uint64_t file_size_ = 0, index_offset_ = 0, blocks_offset_ = 0;
};

// Joins partial files (shards of one bake) into one complete file: every other header field,
// the layout and the metadata must be equal in all of them, and every cell must be present in at
// least one (a cell present in several must have the same ids everywhere). The result is what
// write_pvs gives for the full set of cells, so byte-identical to an unsharded bake. Throws
// FormatError (offset 0 when the problem is a mismatch between files) naming the shard by its
// position in `shards`.
std::string merge_pvs(std::vector<Reader>& shards);

// ---- Building blocks (also used by vislib's checkpoint file) --------------------------------

// CRC32C (Castagnoli, reflected polynomial 0x82F63B78, initial value and final xor 0xFFFFFFFF).
// crc32c("123456789") == 0xE3069283. Chain by passing the previous result as `crc`.
uint32_t crc32c(const void* data, size_t size, uint32_t crc = 0);

// FNV-1a 64-bit over bytes (offset basis 0xcbf29ce484222325, prime 0x100000001b3); chain by
// passing the previous result as `hash`. Used by vislib for the scene fingerprint.
constexpr uint64_t kFnvOffsetBasis = 0xcbf29ce484222325ull;
uint64_t fnv1a64(const void* data, size_t size, uint64_t hash = kFnvOffsetBasis);

// Little-endian appenders of the format's byte streams (the file, vislib's checkpoint and the
// scene fingerprint below).
void put_u32(std::string& out, uint32_t v);
void put_u64(std::string& out, uint64_t v);
void put_f64(std::string& out, double v);  // the IEEE 754 bits, as put_u64

// The scene fingerprint (docs/pvs-format.md, "The scene fingerprint"): FNV-1a 64 of the byte
// stream "vislib-scene-fingerprint-1", the state, vertex, triangle and object counts (u64 each),
// every vertex position (3 f64) of state 0 in vertex order, then of state 1, ..., then every
// triangle in id order as its 3 vertex indices and its object id (u32 each). The one
// implementation of that stream: vislib::scene_fingerprint (from a Scene) and the runtime's
// pvs_rt_scene_fingerprint (from an engine's buffers) both feed it.
// Usage: construct with the counts, call add_position for every position and then add_triangle
// for every triangle, in the order above, then value(). The caller must feed exactly the counts it
// declared (states = 0 for a scene without vertices); nothing checks it. O(1) memory.
class SceneFingerprint {
 public:
  SceneFingerprint(uint64_t states, uint64_t vertices, uint64_t triangles, uint64_t objects);
  void add_position(double x, double y, double z);
  void add_triangle(uint32_t a, uint32_t b, uint32_t c, uint32_t object);
  uint64_t value() const { return hash_; }

 private:
  uint64_t hash_;
};

// Appends `ids` (sorted, unique) as SortedDelta payload (count, first, gaps - 1).
void append_sorted_delta(std::string& out, const std::vector<uint32_t>& ids);
// Appends `ids` (sorted, unique) as RunLength payload (run count, then per run: zeros before it
// (minus one after the first run), length - 1).
void append_run_length(std::string& out, const std::vector<uint32_t>& ids);
// Decodes a whole SortedDelta payload (no bytes may remain); ids must stay < universe.
// Throws FormatError with offsets relative to `base_offset`.
std::vector<uint32_t> decode_sorted_delta(std::string_view payload, uint32_t universe,
                                          uint64_t base_offset = 0);

}  // namespace pvs
