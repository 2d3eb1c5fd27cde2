// pvs_format.cpp: the PVS file format, versions 1 and 2 (docs/pvs-format.md). Standard library
// only.
#include "pvs_format/pvs_format.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <limits>

namespace pvs {

FormatError::FormatError(uint64_t offset, const std::string& problem)
    : std::runtime_error("byte " + std::to_string(offset) + ": " + problem),
      offset_(offset),
      problem_(problem) {}

const char* encoding_name(Encoding e) {
  switch (e) {
    case Encoding::SortedDelta:
      return "sorted-delta";
    case Encoding::RunLength:
      return "run-length";
    case Encoding::Delta:
      return "delta";
    case Encoding::Absent:
      return "absent";
  }
  return "unknown";
}

bool operator==(const Box& a, const Box& b) {
  for (int i = 0; i < 3; ++i)
    if (a.min[i] != b.min[i] || a.max[i] != b.max[i]) return false;
  return true;
}

bool operator==(const BspPlane& a, const BspPlane& b) {
  return a.normal[0] == b.normal[0] && a.normal[1] == b.normal[1] && a.normal[2] == b.normal[2] &&
         a.dist == b.dist;
}

bool operator==(const BspNode& a, const BspNode& b) {
  return a.plane == b.plane && a.children[0] == b.children[0] && a.children[1] == b.children[1];
}

bool operator==(const CellLayout& a, const CellLayout& b) {
  if (a.kind != b.kind) return false;
  if (a.kind == LayoutKind::Grid)
    return a.grid_box == b.grid_box && a.nx == b.nx && a.ny == b.ny && a.nz == b.nz &&
           a.eye_lo == b.eye_lo && a.eye_hi == b.eye_hi;
  if (a.kind == LayoutKind::BspTree)
    return a.boxes == b.boxes && a.planes == b.planes && a.nodes == b.nodes && a.root == b.root &&
           a.leaf_cell == b.leaf_cell && a.cell_leaf == b.cell_leaf && a.neighbours == b.neighbours;
  return a.boxes == b.boxes;
}

uint32_t format_version_for(LayoutKind kind) {
  return kind == LayoutKind::BspTree ? 2 : 1;
}

// ---- Checksums and hashes --------------------------------------------------------------------

namespace {

std::array<uint32_t, 256> make_crc_table() {
  std::array<uint32_t, 256> table{};
  for (uint32_t i = 0; i < 256; ++i) {
    uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1) ? (c >> 1) ^ 0x82F63B78u : c >> 1;
    table[i] = c;
  }
  return table;
}

}  // namespace

uint32_t crc32c(const void* data, size_t size, uint32_t crc) {
  static const std::array<uint32_t, 256> table = make_crc_table();
  const auto* p = static_cast<const unsigned char*>(data);
  crc = ~crc;
  for (size_t i = 0; i < size; ++i) crc = table[(crc ^ p[i]) & 0xFF] ^ (crc >> 8);
  return ~crc;
}

uint64_t fnv1a64(const void* data, size_t size, uint64_t hash) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < size; ++i) {
    hash ^= p[i];
    hash *= 0x100000001b3ull;
  }
  return hash;
}

// ---- Little-endian writing and bounds-checked reading -------------------------------------------

void put_u32(std::string& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(char((v >> (8 * i)) & 0xFF));
}
void put_u64(std::string& out, uint64_t v) {
  for (int i = 0; i < 8; ++i) out.push_back(char((v >> (8 * i)) & 0xFF));
}
void put_f64(std::string& out, double v) {
  uint64_t bits;
  std::memcpy(&bits, &v, 8);
  put_u64(out, bits);
}

// ---- The scene fingerprint --------------------------------------------------------------------

SceneFingerprint::SceneFingerprint(uint64_t states, uint64_t vertices, uint64_t triangles,
                                   uint64_t objects) {
  static const char kTag[] = "vislib-scene-fingerprint-1";
  std::string head(kTag, sizeof kTag - 1);
  put_u64(head, states);
  put_u64(head, vertices);
  put_u64(head, triangles);
  put_u64(head, objects);
  hash_ = fnv1a64(head.data(), head.size());
}

void SceneFingerprint::add_position(double x, double y, double z) {
  unsigned char b[24];
  const double v[3] = {x, y, z};
  for (int k = 0; k < 3; ++k) {
    uint64_t bits;
    std::memcpy(&bits, &v[k], 8);
    for (int i = 0; i < 8; ++i) b[8 * k + i] = (unsigned char)((bits >> (8 * i)) & 0xFF);
  }
  hash_ = fnv1a64(b, sizeof b, hash_);
}

void SceneFingerprint::add_triangle(uint32_t a, uint32_t b, uint32_t c, uint32_t object) {
  unsigned char bytes[16];
  const uint32_t v[4] = {a, b, c, object};
  for (int k = 0; k < 4; ++k)
    for (int i = 0; i < 4; ++i) bytes[4 * k + i] = (unsigned char)((v[k] >> (8 * i)) & 0xFF);
  hash_ = fnv1a64(bytes, sizeof bytes, hash_);
}

namespace {

void put_u8(std::string& out, uint8_t v) {
  out.push_back(char(v));
}
void put_varint(std::string& out, uint32_t v) {
  while (v >= 0x80) {
    out.push_back(char((v & 0x7F) | 0x80));
    v >>= 7;
  }
  out.push_back(char(v));
}
// Reads little-endian values from a byte range whose first byte is at file offset `base`; every
// read is bounds-checked and failures name the absolute offset.
class Cursor {
 public:
  Cursor(std::string_view bytes, uint64_t base, const char* what)
      : bytes_(bytes), base_(base), what_(what) {}
  uint64_t offset() const { return base_ + pos_; }
  size_t remaining() const { return bytes_.size() - pos_; }
  bool done() const { return pos_ == bytes_.size(); }
  [[noreturn]] void fail(const std::string& problem) const { throw FormatError(offset(), problem); }
  void need(size_t n) const {
    if (remaining() < n)
      fail(std::string(what_) + " ends early: need " + std::to_string(n) + " more bytes, " +
           std::to_string(remaining()) + " left");
  }
  uint8_t u8() {
    need(1);
    return uint8_t(bytes_[pos_++]);
  }
  uint32_t u32() {
    need(4);
    uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v |= uint32_t(uint8_t(bytes_[pos_ + i])) << (8 * i);
    pos_ += 4;
    return v;
  }
  uint64_t u64() {
    need(8);
    uint64_t v = 0;
    for (int i = 0; i < 8; ++i) v |= uint64_t(uint8_t(bytes_[pos_ + i])) << (8 * i);
    pos_ += 8;
    return v;
  }
  double f64() {
    uint64_t bits = u64();
    double v;
    std::memcpy(&v, &bits, 8);
    return v;
  }
  // Unsigned LEB128, at most 5 bytes, value < 2^32, canonical (no superfluous zero groups).
  uint32_t varint() {
    uint64_t start = offset();
    uint64_t v = 0;
    for (int i = 0; i < 5; ++i) {
      if (remaining() < 1) throw FormatError(start, std::string(what_) + " ends inside a varint");
      uint8_t b = uint8_t(bytes_[pos_++]);
      v |= uint64_t(b & 0x7F) << (7 * i);
      if (!(b & 0x80)) {
        if (i > 0 && b == 0) throw FormatError(start, "non-canonical varint (trailing zero group)");
        if (v > 0xFFFFFFFFull) throw FormatError(start, "varint exceeds 32 bits");
        return uint32_t(v);
      }
    }
    throw FormatError(start, "varint longer than 5 bytes");
  }
  std::string_view bytes(size_t n) {
    need(n);
    std::string_view v = bytes_.substr(pos_, n);
    pos_ += n;
    return v;
  }

 private:
  std::string_view bytes_;
  uint64_t base_;
  size_t pos_ = 0;
  const char* what_;
};

std::string hex64(uint64_t v) {
  char buf[19];
  std::snprintf(buf, sizeof buf, "0x%016llx", static_cast<unsigned long long>(v));
  return buf;
}

// ---- Set codecs -------------------------------------------------------------------------------

// Decodes a SortedDelta or RunLength payload from `c`, consuming exactly what it needs. At most
// `limit` ids are produced (more is an error) and all are < universe.
std::vector<uint32_t> decode_set(Cursor& c, Encoding e, uint32_t universe, uint64_t limit) {
  std::vector<uint32_t> ids;
  if (e == Encoding::SortedDelta) {
    uint64_t start = c.offset();
    uint32_t n = c.varint();
    if (n > limit)
      throw FormatError(start, "set of " + std::to_string(n) + " ids, at most " +
                                   std::to_string(limit) + " allowed here");
    // Each id takes at least one byte: a count larger than the bytes left is corrupt (and must not
    // drive an allocation).
    if (n > c.remaining())
      throw FormatError(start, "set of " + std::to_string(n) + " ids in " +
                                   std::to_string(c.remaining()) + " bytes");
    ids.reserve(n);
    uint64_t next = 0;
    for (uint32_t i = 0; i < n; ++i) {
      uint64_t at = c.offset();
      uint64_t id = next + c.varint();
      if (id >= universe)
        throw FormatError(at, "id " + std::to_string(id) + " is not below the universe " +
                                  std::to_string(universe));
      ids.push_back(uint32_t(id));
      next = id + 1;
    }
  } else {
    uint64_t start = c.offset();
    uint32_t m = c.varint();
    if (m > c.remaining() / 2)
      throw FormatError(start,
                        std::to_string(m) + " runs in " + std::to_string(c.remaining()) + " bytes");
    uint64_t next = 0;
    for (uint32_t r = 0; r < m; ++r) {
      uint64_t at = c.offset();
      uint64_t first = next + c.varint() + (r > 0 ? 1 : 0);
      uint64_t length = uint64_t(c.varint()) + 1;
      if (first + length > universe)
        throw FormatError(at, "run [" + std::to_string(first) + ", " +
                                  std::to_string(first + length) + ") goes past the universe " +
                                  std::to_string(universe));
      if (ids.size() + length > limit)
        throw FormatError(at, "runs hold more than " + std::to_string(limit) + " ids");
      for (uint64_t id = first; id < first + length; ++id) ids.push_back(uint32_t(id));
      next = first + length;
    }
  }
  return ids;
}

std::vector<uint32_t> symmetric_difference(const std::vector<uint32_t>& a,
                                           const std::vector<uint32_t>& b) {
  std::vector<uint32_t> out;
  out.reserve(a.size() + b.size());
  std::set_symmetric_difference(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(out));
  return out;
}

}  // namespace

void append_sorted_delta(std::string& out, const std::vector<uint32_t>& ids) {
  put_varint(out, uint32_t(ids.size()));
  uint64_t next = 0;
  for (uint32_t id : ids) {
    put_varint(out, uint32_t(id - next));
    next = uint64_t(id) + 1;
  }
}

void append_run_length(std::string& out, const std::vector<uint32_t>& ids) {
  // Runs of consecutive ids: (zeros before the run, run length - 1); zeros before a run that is
  // not the first are counted minus one (there is at least one).
  std::vector<std::pair<uint32_t, uint32_t>> runs;
  size_t i = 0;
  uint64_t prev_end = 0;  // one past the previous run
  while (i < ids.size()) {
    size_t j = i;
    while (j + 1 < ids.size() && ids[j + 1] == ids[j] + 1) ++j;
    uint32_t zeros = uint32_t(ids[i] - prev_end - (runs.empty() ? 0 : 1));
    runs.push_back({zeros, uint32_t(j - i)});
    prev_end = uint64_t(ids[j]) + 1;
    i = j + 1;
  }
  put_varint(out, uint32_t(runs.size()));
  for (auto [z, l] : runs) {
    put_varint(out, z);
    put_varint(out, l);
  }
}

std::vector<uint32_t> decode_sorted_delta(std::string_view payload, uint32_t universe,
                                          uint64_t base_offset) {
  Cursor c(payload, base_offset, "sorted-delta set");
  std::vector<uint32_t> ids = decode_set(c, Encoding::SortedDelta, universe, universe);
  if (!c.done()) c.fail(std::to_string(c.remaining()) + " bytes after the set");
  return ids;
}

// ---- Layout ---------------------------------------------------------------------------------

uint32_t CellLayout::cell_count() const {
  if (kind != LayoutKind::Grid) return uint32_t(boxes.size());
  return nx * ny * nz;
}

Box CellLayout::cell_box(uint32_t cell) const {
  if (kind != LayoutKind::Grid) return boxes.at(cell);
  uint32_t n[3] = {nx, ny, nz};
  uint32_t i[3] = {cell % nx, (cell / nx) % ny, cell / nx / ny};
  Box b;
  for (int a = 0; a < 3; ++a) {
    double lo = grid_box.min[a], ext = grid_box.max[a] - grid_box.min[a];
    b.min[a] = lo + ext * double(i[a]) / double(n[a]);
    b.max[a] = i[a] + 1 == n[a] ? grid_box.max[a] : lo + ext * double(i[a] + 1) / double(n[a]);
  }
  return b;
}

Box CellLayout::view_region(uint32_t cell) const {
  Box b = cell_box(cell);
  if (kind == LayoutKind::Grid) {
    double bottom = b.min[1];
    b.min[1] = bottom + eye_lo;
    b.max[1] = bottom + eye_hi;
  }
  return b;
}

std::optional<uint32_t> CellLayout::find_leaf(const double p[3]) const {
  if (kind != LayoutKind::BspTree) return std::nullopt;
  int32_t at = root;
  for (size_t steps = 0; at >= 0; ++steps) {
    if (steps >= nodes.size() || size_t(at) >= nodes.size()) return std::nullopt;
    const BspNode& node = nodes[size_t(at)];
    if (node.plane >= planes.size()) return std::nullopt;
    const BspPlane& pl = planes[node.plane];
    double d = pl.normal[0] * p[0] + pl.normal[1] * p[1] + pl.normal[2] * p[2] - pl.dist;
    at = node.children[d > 0 ? 0 : 1];
  }
  return uint32_t(-(int64_t(at) + 1));
}

std::optional<uint32_t> CellLayout::find_cell(const double p[3]) const {
  if (kind == LayoutKind::BspTree) {
    std::optional<uint32_t> leaf = find_leaf(p);
    if (!leaf || *leaf >= leaf_cell.size() || leaf_cell[*leaf] == kNoCell) return std::nullopt;
    return leaf_cell[*leaf];
  }
  auto inside = [&](const Box& b) {
    for (int a = 0; a < 3; ++a)
      if (!(p[a] >= b.min[a] && p[a] <= b.max[a])) return false;
    return true;
  };
  if (kind == LayoutKind::Boxes) {
    for (uint32_t c = 0; c < boxes.size(); ++c)
      if (inside(boxes[c])) return c;
    return std::nullopt;
  }
  if (!inside(grid_box)) return std::nullopt;
  uint32_t n[3] = {nx, ny, nz};
  uint32_t idx[3];
  for (int a = 0; a < 3; ++a) {
    double ext = grid_box.max[a] - grid_box.min[a];
    double f = ext > 0 ? (p[a] - grid_box.min[a]) / ext * double(n[a]) : 0.0;
    uint32_t i = f >= double(n[a]) ? n[a] - 1 : uint32_t(f);
    // The division above may round across a boundary: settle on the cell whose box (as
    // cell_box computes it) contains p, preferring the lower one on a shared boundary.
    idx[a] = i;
  }
  for (int a = 0; a < 3; ++a) {
    auto lo = [&](uint32_t i) {
      return grid_box.min[a] + (grid_box.max[a] - grid_box.min[a]) * double(i) / double(n[a]);
    };
    while (idx[a] > 0 && p[a] <= lo(idx[a])) --idx[a];
    while (idx[a] + 1 < n[a] && p[a] > lo(idx[a] + 1)) ++idx[a];
  }
  return idx[0] + nx * (idx[1] + ny * idx[2]);
}

// ---- BSP-tree layouts ---------------------------------------------------------------------------

namespace {

// What is wrong with a BSP-tree layout: the part of the layout section and the index in it (the
// reader turns these into a file offset, the writer into its message).
struct BspProblem {
  enum Part { Plane, Node, Root, LeafCell, CellLeaf, Neighbours } part;
  uint32_t index;
  std::string what;
};

// The one check of the BSP fields (CellLayout's preconditions), shared by writer and reader.
std::optional<BspProblem> check_bsp(const CellLayout& L) {
  const uint64_t P = L.planes.size(), N = L.nodes.size(), NL = L.leaf_cell.size(),
                 C = L.boxes.size();
  if (N > 0x7FFFFFFFull || NL > 0x80000000ull)
    return BspProblem{BspProblem::Root, 0, "more nodes or leaves than child references reach"};
  if (L.cell_leaf.size() != C || L.neighbours.size() != C)
    return BspProblem{BspProblem::CellLeaf, 0, "cell_leaf, neighbours and boxes differ in size"};
  for (uint32_t i = 0; i < P; ++i) {
    const BspPlane& p = L.planes[i];
    bool finite = std::isfinite(p.dist), nonzero = false;
    for (double v : p.normal) {
      finite = finite && std::isfinite(v);
      nonzero = nonzero || v != 0;
    }
    if (!finite || !nonzero)
      return BspProblem{BspProblem::Plane, i,
                        "plane " + std::to_string(i) + " is not finite with a nonzero normal"};
  }
  // A child reference: "" when in range.
  auto bad_ref = [&](int32_t ref) -> std::string {
    if (ref >= 0) {
      if (uint64_t(ref) >= N)
        return "node " + std::to_string(ref) + " out of range (" + std::to_string(N) + " nodes)";
    } else if (uint64_t(-(int64_t(ref) + 1)) >= NL) {
      return "leaf " + std::to_string(-(int64_t(ref) + 1)) + " out of range (" +
             std::to_string(NL) + " leaves)";
    }
    return "";
  };
  for (uint32_t i = 0; i < N; ++i) {
    const BspNode& n = L.nodes[i];
    if (n.plane >= P)
      return BspProblem{BspProblem::Node, i,
                        "node " + std::to_string(i) + ": plane " + std::to_string(n.plane) +
                            " out of range (" + std::to_string(P) + " planes)"};
    for (int32_t ref : n.children)
      if (std::string e = bad_ref(ref); !e.empty())
        return BspProblem{BspProblem::Node, i, "node " + std::to_string(i) + ": child " + e};
  }
  if (std::string e = bad_ref(L.root); !e.empty())
    return BspProblem{BspProblem::Root, 0, "root: " + e};
  // Every node reached exactly once from the root: a tree, so every walk ends in a leaf within
  // N steps.
  std::vector<uint8_t> seen(N, 0);
  std::vector<uint8_t> leaf_reached(NL, 0);
  std::vector<int32_t> stack = {L.root};
  if (L.root >= 0) seen[size_t(L.root)] = 1;
  while (!stack.empty()) {
    int32_t ref = stack.back();
    stack.pop_back();
    if (ref < 0) {
      leaf_reached[size_t(-(int64_t(ref) + 1))] = 1;
      continue;
    }
    for (int32_t child : L.nodes[size_t(ref)].children) {
      if (child >= 0) {
        if (seen[size_t(child)])
          return BspProblem{BspProblem::Node, uint32_t(ref),
                            "node " + std::to_string(ref) + ": child node " +
                                std::to_string(child) +
                                " is reached twice (a cycle or a shared subtree)"};
        seen[size_t(child)] = 1;
      }
      stack.push_back(child);
    }
  }
  for (uint32_t i = 0; i < N; ++i)
    if (!seen[i])
      return BspProblem{BspProblem::Node, i,
                        "node " + std::to_string(i) + " is not reachable from the root"};
  for (uint32_t l = 0; l < NL; ++l) {
    uint32_t c = L.leaf_cell[l];
    if (c != kNoCell && (c >= C || L.cell_leaf[c] != l))
      return BspProblem{BspProblem::LeafCell, l,
                        "leaf " + std::to_string(l) + " names cell " + std::to_string(c) +
                            ", which is not a cell of that leaf"};
  }
  for (uint32_t c = 0; c < C; ++c) {
    uint32_t l = L.cell_leaf[c];
    if (l >= NL || L.leaf_cell[l] != c)
      return BspProblem{BspProblem::CellLeaf, c,
                        "cell " + std::to_string(c) + " names leaf " + std::to_string(l) +
                            ", which is not the leaf of that cell"};
    if (!leaf_reached[l])
      return BspProblem{BspProblem::CellLeaf, c,
                        "cell " + std::to_string(c) + ": leaf " + std::to_string(l) +
                            " is not reached by the tree"};
  }
  for (uint32_t c = 0; c < C; ++c) {
    const std::vector<uint32_t>& nb = L.neighbours[c];
    for (size_t i = 0; i < nb.size(); ++i) {
      uint32_t o = nb[i];
      std::string e;
      if (o >= C)
        e = "neighbour " + std::to_string(o) + " out of range";
      else if (o == c)
        e = "the cell is its own neighbour";
      else if (i > 0 && o <= nb[i - 1])
        e = "neighbours not strictly increasing";
      else if (!std::binary_search(L.neighbours[o].begin(), L.neighbours[o].end(), c))
        e = "neighbour " + std::to_string(o) + " does not list this cell back";
      if (!e.empty())
        return BspProblem{BspProblem::Neighbours, c, "cell " + std::to_string(c) + ": " + e};
    }
  }
  return std::nullopt;
}

void put_bsp_layout(std::string& out, const CellLayout& L) {
  put_u32(out, uint32_t(L.planes.size()));
  put_u32(out, uint32_t(L.nodes.size()));
  put_u32(out, uint32_t(L.leaf_cell.size()));
  put_u32(out, uint32_t(L.root));
  for (const BspPlane& p : L.planes) {
    for (double v : p.normal) put_f64(out, v);
    put_f64(out, p.dist);
  }
  for (const BspNode& n : L.nodes) {
    put_u32(out, n.plane);
    put_u32(out, uint32_t(n.children[0]));
    put_u32(out, uint32_t(n.children[1]));
  }
  for (uint32_t c : L.leaf_cell) put_u32(out, c);
  for (size_t c = 0; c < L.boxes.size(); ++c) {
    put_u32(out, L.cell_leaf[c]);
    for (double v : L.boxes[c].min) put_f64(out, v);
    for (double v : L.boxes[c].max) put_f64(out, v);
  }
  for (const std::vector<uint32_t>& nb : L.neighbours) {
    put_u32(out, uint32_t(nb.size()));
    for (uint32_t o : nb) put_u32(out, o);
  }
}

}  // namespace

// ---- Writer ---------------------------------------------------------------------------------

namespace {

void check_box(const Box& b, const char* what) {
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(b.min[a]) || !std::isfinite(b.max[a]) || !(b.min[a] <= b.max[a]))
      throw std::invalid_argument(std::string("write_pvs: ") + what +
                                  " is not finite with min <= max");
}

void put_box(std::string& out, const Box& b) {
  for (double v : b.min) put_f64(out, v);
  for (double v : b.max) put_f64(out, v);
}

// Box-list layouts: how far back (in cells) a Delta reference may be (write_pvs).
constexpr uint32_t kBoxDeltaWindow = 4096;

// Smallest encoding of one cell's set. `candidates` are earlier present cells allowed as Delta
// references, in preference order.
struct Choice {
  std::string block;  // encoding byte + payload (no checksum yet)
  int depth = 0;
};

// `set_of(ref)` gives the ids of an earlier present cell.
template <class SetOf>
Choice encode_cell(const std::vector<uint32_t>& ids, uint32_t cell,
                   const std::vector<uint32_t>& candidates, const SetOf& set_of,
                   const std::vector<uint8_t>& depth) {
  Choice best;
  best.block.push_back(char(Encoding::SortedDelta));
  append_sorted_delta(best.block, ids);
  std::string rle(1, char(Encoding::RunLength));
  append_run_length(rle, ids);
  if (rle.size() < best.block.size()) best.block = rle;
  for (uint32_t ref : candidates) {
    std::vector<uint32_t> diff = symmetric_difference(ids, set_of(ref));
    for (Encoding inner : {Encoding::SortedDelta, Encoding::RunLength}) {
      std::string b(1, char(Encoding::Delta));
      put_varint(b, cell - ref);
      b.push_back(char(inner));
      if (inner == Encoding::SortedDelta)
        append_sorted_delta(b, diff);
      else
        append_run_length(b, diff);
      if (b.size() < best.block.size()) {
        best.block = std::move(b);
        best.depth = depth[ref] + 1;
      }
    }
  }
  return best;
}

// Delta reference candidates of `cell` among earlier cells, in preference order (write_pvs).
// present[r]: cell r has a set; depth[r]: its delta chain length.
std::vector<uint32_t> delta_candidates(const FileInfo& info, const std::vector<bool>& present,
                                       const std::vector<uint8_t>& depth, uint32_t cell) {
  std::vector<uint32_t> out;
  auto consider = [&](uint32_t ref) {
    if (!present[ref] || depth[ref] + 1 > int(info.max_delta_depth)) return;
    if (std::find(out.begin(), out.end(), ref) == out.end()) out.push_back(ref);
  };
  const CellLayout& L = info.layout;
  if (L.kind == LayoutKind::Grid) {
    uint32_t i = cell % L.nx, j = (cell / L.nx) % L.ny, k = cell / L.nx / L.ny;
    if (i > 0) consider(cell - 1);
    if (j > 0) consider(cell - L.nx);
    if (k > 0) consider(cell - L.nx * L.ny);
  } else if (cell > 0) {
    consider(cell - 1);
    auto centre = [&](uint32_t c, int a) { return 0.5 * (L.boxes[c].min[a] + L.boxes[c].max[a]); };
    double best = std::numeric_limits<double>::infinity();
    uint32_t best_ref = cell;
    uint32_t lo = cell > kBoxDeltaWindow ? cell - kBoxDeltaWindow : 0;
    for (uint32_t r = cell; r-- > lo;) {
      if (!present[r] || depth[r] + 1 > int(info.max_delta_depth)) continue;
      double d2 = 0;
      for (int a = 0; a < 3; ++a) {
        double d = centre(r, a) - centre(cell, a);
        d2 += d * d;
      }
      if (d2 < best) {
        best = d2;
        best_ref = r;
      }
    }
    if (best_ref != cell) consider(best_ref);
  }
  return out;
}

}  // namespace

struct StreamWriter::Impl {
  FileInfo info;
  Sink sink;
  uint32_t n = 0, next = 0;
  uint64_t index_offset = 0, blocks_offset = 0, at = 0;
  size_t layout_size = 0;
  std::string index;           // n entries of 16 bytes, written at finish()
  std::vector<bool> present;   // per cell
  std::vector<uint8_t> depth;  // per cell: delta chain length
  // The sets a later cell may reference (grid: the previous nx*ny cells; box list: the previous
  // kBoxDeltaWindow), sorted-delta encoded to keep them small, in a ring indexed by cell % window.
  uint64_t window = 1;
  std::vector<std::string> recent;
  bool finished = false;
};

StreamWriter::StreamWriter(FileInfo info, Sink sink) : impl_(std::make_unique<Impl>()) {
  const CellLayout& L = info.layout;
  if (L.kind == LayoutKind::Grid) {
    if (L.nx == 0 || L.ny == 0 || L.nz == 0)
      throw std::invalid_argument("write_pvs: grid dimensions must be >= 1");
    if (uint64_t(L.nx) * L.ny * L.nz > 0xFFFFFFFFull)
      throw std::invalid_argument("write_pvs: grid has more than 2^32-1 cells");
    check_box(L.grid_box, "grid box");
    const uint32_t dims[3] = {L.nx, L.ny, L.nz};
    for (int a = 0; a < 3; ++a)
      if (!std::isfinite((L.grid_box.max[a] - L.grid_box.min[a]) * double(dims[a])))
        throw std::invalid_argument(
            "write_pvs: grid box extent times the cell count overflows a double");
    if (!std::isfinite(L.eye_lo) || !std::isfinite(L.eye_hi) || !(L.eye_lo <= L.eye_hi))
      throw std::invalid_argument("write_pvs: eye band must be finite with eye_lo <= eye_hi");
  } else {
    if (L.boxes.size() > 0xFFFFFFFFull) throw std::invalid_argument("write_pvs: too many cells");
    for (const Box& b : L.boxes) check_box(b, "cell box");
    if (L.kind == LayoutKind::BspTree) {
      if (std::optional<BspProblem> p = check_bsp(L))
        throw std::invalid_argument("write_pvs: BSP tree: " + p->what);
    }
  }
  if (info.metadata.size() > 0xFFFFFFFFull)
    throw std::invalid_argument("write_pvs: metadata too long");
  Impl& w = *impl_;
  w.n = L.cell_count();
  w.window =
      std::max<uint64_t>(1, L.kind == LayoutKind::Grid ? uint64_t(L.nx) * L.ny : kBoxDeltaWindow);
  w.window = std::min<uint64_t>(w.window, std::max<uint32_t>(1, w.n));
  w.recent.resize(size_t(w.window));
  w.present.assign(w.n, false);
  w.depth.assign(w.n, 0);
  // Header (zeros until finish()), layout section, index (zeros until finish()).
  std::string out(kHeaderSize, '\0');
  if (L.kind == LayoutKind::Grid) {
    put_box(out, L.grid_box);
    put_u32(out, L.nx);
    put_u32(out, L.ny);
    put_u32(out, L.nz);
    put_f64(out, L.eye_lo);
    put_f64(out, L.eye_hi);
  } else if (L.kind == LayoutKind::BspTree) {
    put_bsp_layout(out, L);
  } else {
    for (const Box& b : L.boxes) put_box(out, b);
  }
  put_u32(out, uint32_t(info.metadata.size()));
  out += info.metadata;
  put_u32(out, crc32c(out.data() + kHeaderSize, out.size() - kHeaderSize));
  w.layout_size = out.size() - kHeaderSize;
  w.index_offset = out.size();
  w.blocks_offset = w.index_offset + uint64_t(w.n) * kIndexEntrySize + 4;
  w.at = w.blocks_offset;
  w.info = std::move(info);
  w.sink = std::move(sink);
  w.sink(0, out);
  w.index.reserve(size_t(w.n) * kIndexEntrySize + 4);
}

StreamWriter::~StreamWriter() = default;
StreamWriter::StreamWriter(StreamWriter&&) noexcept = default;

uint32_t StreamWriter::next_cell() const {
  return impl_->next;
}

void StreamWriter::add(const CellSet& s) {
  Impl& w = *impl_;
  if (w.finished || w.next >= w.n)
    throw std::invalid_argument("write_pvs: more cells than the layout has");
  const uint32_t c = w.next;
  if (!s) {
    if (!w.info.partial)
      throw std::invalid_argument("write_pvs: absent cell in a file not marked partial");
  } else {
    for (size_t i = 0; i < s->size(); ++i)
      if ((*s)[i] >= w.info.universe || (i > 0 && (*s)[i] <= (*s)[i - 1]))
        throw std::invalid_argument(
            "write_pvs: a cell's ids are not sorted, unique and below the universe");
  }
  std::string b;
  if (!s) {
    b.push_back(char(Encoding::Absent));
  } else {
    auto set_of = [&](uint32_t ref) {
      const std::string& enc = w.recent[size_t(ref % w.window)];
      return decode_sorted_delta(enc, w.info.universe, 0);
    };
    Choice ch =
        encode_cell(*s, c, delta_candidates(w.info, w.present, w.depth, c), set_of, w.depth);
    w.depth[c] = uint8_t(ch.depth);
    b = std::move(ch.block);
    w.present[c] = true;
    std::string& slot = w.recent[size_t(c % w.window)];
    slot.clear();
    append_sorted_delta(slot, *s);
    slot.shrink_to_fit();
  }
  put_u32(b, crc32c(b.data(), b.size()));
  if (b.size() > 0xFFFFFFFFull) throw std::invalid_argument("write_pvs: block larger than 4 GiB");
  put_u64(w.index, w.at);
  put_u32(w.index, uint32_t(b.size()));
  put_u32(w.index, s ? uint32_t(s->size()) : 0);
  w.sink(w.at, b);
  w.at += b.size();
  ++w.next;
}

WriteStats StreamWriter::finish() {
  Impl& w = *impl_;
  if (w.finished) throw std::invalid_argument("write_pvs: finish() twice");
  if (w.next != w.n)
    throw std::invalid_argument("write_pvs: cells.size() differs from the layout's cell count");
  w.finished = true;
  put_u32(w.index, crc32c(w.index.data(), w.index.size()));
  w.sink(w.index_offset, w.index);
  // Header last: it holds the total size.
  const CellLayout& L = w.info.layout;
  std::string h;
  h.append(kMagic, 8);
  put_u32(h, format_version_for(L.kind));
  put_u32(h, w.info.partial ? 1u : 0u);
  put_u64(h, w.at);
  put_u64(h, w.info.scene_fingerprint);
  put_u32(h, w.info.universe);
  put_u32(h, w.n);
  put_u8(h, uint8_t(w.info.granularity));
  put_u8(h, uint8_t(L.kind));
  put_u8(h, w.info.max_delta_depth);
  put_u8(h, 0);
  put_u32(h, uint32_t(w.layout_size));
  h.append(12, '\0');
  put_u32(h, crc32c(h.data(), h.size()));
  w.sink(0, h);
  WriteStats stats;
  stats.file_bytes = w.at;
  stats.header_bytes = kHeaderSize;
  stats.layout_bytes = w.layout_size;
  stats.index_bytes = w.blocks_offset - w.index_offset;
  stats.block_bytes = w.at - w.blocks_offset;
  return stats;
}

std::string write_pvs(const FileInfo& info, const std::vector<CellSet>& cells, WriteStats* stats) {
  if (cells.size() != info.layout.cell_count())
    throw std::invalid_argument("write_pvs: cells.size() differs from the layout's cell count");
  // Every set is checked before anything is encoded (as the contract says).
  for (const CellSet& s : cells) {
    if (!s) {
      if (!info.partial)
        throw std::invalid_argument("write_pvs: absent cell in a file not marked partial");
      continue;
    }
    for (size_t i = 0; i < s->size(); ++i)
      if ((*s)[i] >= info.universe || (i > 0 && (*s)[i] <= (*s)[i - 1]))
        throw std::invalid_argument(
            "write_pvs: a cell's ids are not sorted, unique and below the universe");
  }
  std::string out;
  StreamWriter w(info, [&out](uint64_t offset, std::string_view bytes) {
    if (out.size() < offset + bytes.size()) out.resize(size_t(offset + bytes.size()));
    std::memcpy(&out[size_t(offset)], bytes.data(), bytes.size());
  });
  for (const CellSet& s : cells) w.add(s);
  WriteStats st = w.finish();
  if (stats) *stats = st;
  return out;
}

// ---- Reader ---------------------------------------------------------------------------------

namespace {

// Reads a BSP-tree layout (docs/pvs-format.md, "BSP tree") of `n` cells from `l`, up to the
// metadata, then checks it (check_bsp). Every count is held against the bytes left before
// anything is allocated for it.
void read_bsp_layout(Cursor& l, uint32_t n, CellLayout& L) {
  const uint64_t counts_at = l.offset();
  const uint32_t P = l.u32(), N = l.u32(), NL = l.u32();
  const uint64_t root_at = l.offset();
  L.root = int32_t(l.u32());
  // `at`: the offset of the count.
  auto room = [&](uint64_t count, uint64_t each, uint64_t at, const char* what) {
    if (count * each > l.remaining())
      throw FormatError(at, std::to_string(count) + " " + what + " of " + std::to_string(each) +
                                " bytes do not fit in the " + std::to_string(l.remaining()) +
                                " bytes left of the layout section");
  };
  room(P, 32, counts_at, "planes");
  const uint64_t planes_at = l.offset();
  L.planes.resize(P);
  for (BspPlane& p : L.planes) {
    for (double& v : p.normal) v = l.f64();
    p.dist = l.f64();
  }
  room(N, 12, counts_at + 4, "nodes");
  const uint64_t nodes_at = l.offset();
  L.nodes.resize(N);
  for (BspNode& node : L.nodes) {
    node.plane = l.u32();
    node.children[0] = int32_t(l.u32());
    node.children[1] = int32_t(l.u32());
  }
  room(NL, 4, counts_at + 8, "leaves");
  const uint64_t leaves_at = l.offset();
  L.leaf_cell.resize(NL);
  for (uint32_t& c : L.leaf_cell) c = l.u32();
  room(n, 56, 36,
       "cells");  // the header's cell_count: 52 bytes of leaf and box, 4 or more of neighbours
  const uint64_t cells_at = l.offset();
  L.cell_leaf.resize(n);
  L.boxes.resize(n);
  for (uint32_t c = 0; c < n; ++c) {
    L.cell_leaf[c] = l.u32();
    uint64_t at = l.offset();
    Box& b = L.boxes[c];
    for (double& v : b.min) v = l.f64();
    for (double& v : b.max) v = l.f64();
    for (int a = 0; a < 3; ++a)
      if (!std::isfinite(b.min[a]) || !std::isfinite(b.max[a]) || !(b.min[a] <= b.max[a]))
        throw FormatError(at, "box is not finite with min <= max");
  }
  std::vector<uint64_t> neighbours_at(n);
  L.neighbours.resize(n);
  for (uint32_t c = 0; c < n; ++c) {
    neighbours_at[c] = l.offset();
    uint32_t k = l.u32();
    if (uint64_t(k) * 4 > l.remaining())
      throw FormatError(neighbours_at[c], "cell " + std::to_string(c) + ": " + std::to_string(k) +
                                              " neighbours do not fit in the layout section");
    L.neighbours[c].resize(k);
    for (uint32_t& o : L.neighbours[c]) o = l.u32();
  }
  if (std::optional<BspProblem> p = check_bsp(L)) {
    uint64_t at = counts_at;
    switch (p->part) {
      case BspProblem::Plane:
        at = planes_at + 32 * uint64_t(p->index);
        break;
      case BspProblem::Node:
        at = nodes_at + 12 * uint64_t(p->index);
        break;
      case BspProblem::Root:
        at = root_at;
        break;
      case BspProblem::LeafCell:
        at = leaves_at + 4 * uint64_t(p->index);
        break;
      case BspProblem::CellLeaf:
        at = cells_at + 52 * uint64_t(p->index);
        break;
      case BspProblem::Neighbours:
        at = neighbours_at[p->index];
        break;
    }
    throw FormatError(at, "BSP tree: " + p->what);
  }
}

}  // namespace

struct Reader::Source {
  virtual ~Source() = default;
  virtual uint64_t size() const = 0;
  // Exactly `n` bytes at `offset`; the caller has checked offset + n <= size().
  virtual std::string read(uint64_t offset, size_t n) = 0;
};

namespace {

struct MemorySource : Reader::Source {
  std::string bytes;
  uint64_t size() const override { return bytes.size(); }
  std::string read(uint64_t offset, size_t n) override { return bytes.substr(size_t(offset), n); }
};

struct ViewSource : Reader::Source {
  std::string_view bytes;
  uint64_t size() const override { return bytes.size(); }
  std::string read(uint64_t offset, size_t n) override {
    return std::string(bytes.substr(size_t(offset), n));
  }
};

struct FileSource : Reader::Source {
  std::ifstream in;
  uint64_t bytes = 0;
  uint64_t size() const override { return bytes; }
  std::string read(uint64_t offset, size_t n) override {
    std::string out(n, '\0');
    in.clear();
    in.seekg(std::streamoff(offset));
    in.read(out.data(), std::streamsize(n));
    if (size_t(in.gcount()) != n)
      throw FormatError(offset + uint64_t(in.gcount()), "read error (file changed or unreadable)");
    return out;
  }
};

struct RangeSource : Reader::Source {
  uint64_t bytes = 0;
  Reader::RangeRead fn;
  uint64_t size() const override { return bytes; }
  std::string read(uint64_t offset, size_t n) override {
    std::string out(n, '\0');
    if (n > 0) fn(offset, n, out.data());
    return out;
  }
};

}  // namespace

Reader::Reader(Reader&&) noexcept = default;
Reader& Reader::operator=(Reader&&) noexcept = default;
Reader::~Reader() = default;

Reader Reader::from_memory(std::string_view bytes, const ReadOptions& options) {
  auto src = std::make_unique<MemorySource>();
  src->bytes.assign(bytes.data(), bytes.size());
  Reader r;
  r.source_ = std::move(src);
  r.open(options);
  return r;
}

Reader Reader::from_view(std::string_view bytes, const ReadOptions& options) {
  auto src = std::make_unique<ViewSource>();
  src->bytes = bytes;
  Reader r;
  r.source_ = std::move(src);
  r.open(options);
  return r;
}

Reader Reader::from_file(const std::string& path, const ReadOptions& options) {
  auto src = std::make_unique<FileSource>();
  src->in.open(path, std::ios::binary);
  if (!src->in) throw FormatError(0, "cannot open " + path);
  src->in.seekg(0, std::ios::end);
  std::streamoff end = src->in.tellg();
  if (end < 0) throw FormatError(0, "cannot determine the size of " + path);
  src->bytes = uint64_t(end);
  Reader r;
  r.source_ = std::move(src);
  r.open(options);
  return r;
}

Reader Reader::from_ranges(uint64_t size, RangeRead read, const ReadOptions& options) {
  if (!read) throw std::invalid_argument("pvs::Reader::from_ranges: no read function");
  auto src = std::make_unique<RangeSource>();
  src->bytes = size;
  src->fn = std::move(read);
  Reader r;
  r.source_ = std::move(src);
  r.open(options);
  return r;
}

void Reader::open(const ReadOptions& options) {
  const uint64_t size = source_->size();
  file_size_ = size;
  // Magic first, on whatever is there, so that a non-PVS file is named as such.
  std::string head = source_->read(0, size_t(std::min<uint64_t>(size, kHeaderSize)));
  size_t m = std::min<size_t>(head.size(), 8);
  for (size_t i = 0; i < m; ++i)
    if (head[i] != kMagic[i]) throw FormatError(i, "not a PVS file (bad magic bytes)");
  if (size < kHeaderSize)
    throw FormatError(size, "truncated: the file has " + std::to_string(size) +
                                " bytes, the header alone needs 64");
  Cursor h(head, 0, "header");
  h.bytes(8);
  uint32_t version = h.u32();
  if (version == 0) throw FormatError(8, "invalid format version 0");
  if (version > kFormatVersion)
    throw FormatError(8, "format version " + std::to_string(version) +
                             " is newer than this reader (reads up to " +
                             std::to_string(kFormatVersion) + ")");
  verify_checksums_ = options.verify_checksums;
  uint32_t stored_crc = 0;
  {
    Cursor t(std::string_view(head).substr(60, 4), 60, "header");
    stored_crc = t.u32();
  }
  uint32_t crc = crc32c(head.data(), 60);
  if (verify_checksums_ && crc != stored_crc)
    throw FormatError(60, "header checksum mismatch (stored " + std::to_string(stored_crc) +
                              ", computed " + std::to_string(crc) + ")");
  info_.version = version;
  uint32_t flags = h.u32();
  if (flags & ~1u) throw FormatError(12, "unknown flags " + std::to_string(flags));
  info_.partial = flags & 1u;
  uint64_t declared_size = h.u64();
  if (declared_size > size)
    throw FormatError(size, "truncated: the header says " + std::to_string(declared_size) +
                                " bytes, the file has " + std::to_string(size));
  if (declared_size < size)
    throw FormatError(declared_size, "trailing bytes: the header says " +
                                         std::to_string(declared_size) + " bytes, the file has " +
                                         std::to_string(size));
  info_.scene_fingerprint = h.u64();
  if (options.expected_fingerprint && *options.expected_fingerprint != info_.scene_fingerprint)
    throw FormatError(
        24, "scene fingerprint " + hex64(info_.scene_fingerprint) + " does not match the scene's " +
                hex64(*options.expected_fingerprint) + " (this PVS was baked for another scene)");
  info_.universe = h.u32();
  if (info_.universe > options.max_universe)
    throw FormatError(32, "universe of " + std::to_string(info_.universe) +
                              " ids exceeds the reader's limit " +
                              std::to_string(options.max_universe));
  uint32_t n = h.u32();
  uint8_t gran = h.u8();
  if (gran > 1) throw FormatError(40, "unknown granularity " + std::to_string(gran));
  info_.granularity = Granularity(gran);
  uint8_t kind = h.u8();
  if (kind > 2) throw FormatError(41, "unknown cell layout " + std::to_string(kind));
  if (version < format_version_for(LayoutKind(kind)))
    throw FormatError(41, "cell layout " + std::to_string(kind) + " needs format version " +
                              std::to_string(format_version_for(LayoutKind(kind))) +
                              ", the file is version " + std::to_string(version));
  info_.layout.kind = LayoutKind(kind);
  info_.max_delta_depth = h.u8();
  if (h.u8() != 0) throw FormatError(43, "reserved byte is not zero");
  uint32_t layout_size = h.u32();
  for (int i = 0; i < 12; ++i)
    if (h.u8() != 0) throw FormatError(48 + i, "reserved byte is not zero");

  // Layout section.
  // (A BSP tree's section is at least its 16 count bytes and 56 bytes per cell.)
  const uint64_t layout_fixed = kind == 0   ? 76
                                : kind == 1 ? uint64_t(n) * 48
                                            : 16 + uint64_t(n) * 56;
  if (uint64_t(layout_size) < layout_fixed + 8)
    throw FormatError(44, "layout section of " + std::to_string(layout_size) +
                              " bytes is too small for " + std::to_string(n) + " cells");
  if (kHeaderSize + uint64_t(layout_size) > size)
    throw FormatError(44, "layout section of " + std::to_string(layout_size) +
                              " bytes runs past the end of the file");
  std::string layout = source_->read(kHeaderSize, layout_size);
  {
    Cursor t(std::string_view(layout).substr(layout_size - 4), kHeaderSize + layout_size - 4,
             "layout section");
    uint32_t stored = t.u32();
    uint32_t computed = crc32c(layout.data(), layout_size - 4);
    if (verify_checksums_ && stored != computed)
      throw FormatError(kHeaderSize + layout_size - 4, "layout section checksum mismatch");
  }
  Cursor l(std::string_view(layout).substr(0, layout_size - 4), kHeaderSize, "layout section");
  auto read_box = [&](Box& b) {
    uint64_t at = l.offset();
    for (double& v : b.min) v = l.f64();
    for (double& v : b.max) v = l.f64();
    for (int a = 0; a < 3; ++a)
      if (!std::isfinite(b.min[a]) || !std::isfinite(b.max[a]) || !(b.min[a] <= b.max[a]))
        throw FormatError(at, "box is not finite with min <= max");
  };
  CellLayout& L = info_.layout;
  if (L.kind == LayoutKind::Grid) {
    read_box(L.grid_box);
    for (int a = 0; a < 3; ++a)
      if (!std::isfinite(L.grid_box.max[a] - L.grid_box.min[a]))
        throw FormatError(kHeaderSize, "grid box extent overflows a double");
    uint64_t at = l.offset();
    L.nx = l.u32();
    L.ny = l.u32();
    L.nz = l.u32();
    if (L.nx == 0 || L.ny == 0 || L.nz == 0) throw FormatError(at, "grid dimension 0");
    // cell_box computes min + (max - min) * i / n: the product must not overflow for i <= n.
    const uint32_t dims[3] = {L.nx, L.ny, L.nz};
    for (int a = 0; a < 3; ++a)
      if (!std::isfinite((L.grid_box.max[a] - L.grid_box.min[a]) * double(dims[a])))
        throw FormatError(at, "grid box extent times the cell count overflows a double");
    if (uint64_t(L.nx) * L.ny * L.nz != n)
      throw FormatError(at, "grid " + std::to_string(L.nx) + "x" + std::to_string(L.ny) + "x" +
                                std::to_string(L.nz) + " does not have the header's " +
                                std::to_string(n) + " cells");
    at = l.offset();
    L.eye_lo = l.f64();
    L.eye_hi = l.f64();
    if (!std::isfinite(L.eye_lo) || !std::isfinite(L.eye_hi) || !(L.eye_lo <= L.eye_hi))
      throw FormatError(at, "eye band is not finite with eye_lo <= eye_hi");
  } else if (L.kind == LayoutKind::BspTree) {
    read_bsp_layout(l, n, L);
  } else {
    L.boxes.resize(n);
    for (Box& b : L.boxes) read_box(b);
  }
  uint64_t md_at = l.offset();
  uint32_t md_size = l.u32();
  if (l.remaining() != md_size)
    throw FormatError(md_at, "metadata of " + std::to_string(md_size) +
                                 " bytes does not fill the layout section (" +
                                 std::to_string(l.remaining()) + " bytes left)");
  info_.metadata = std::string(l.bytes(md_size));

  // Index.
  index_offset_ = kHeaderSize + uint64_t(layout_size);
  const uint64_t index_size = uint64_t(n) * kIndexEntrySize + 4;
  if (index_size > size - index_offset_)
    throw FormatError(size, "truncated: the index of " + std::to_string(n) + " cells needs " +
                                std::to_string(index_size) + " bytes, " +
                                std::to_string(size - index_offset_) + " left");
  std::string index = source_->read(index_offset_, size_t(index_size));
  blocks_offset_ = index_offset_ + index_size;
  {
    Cursor t(std::string_view(index).substr(index.size() - 4), blocks_offset_ - 4, "index");
    if (t.u32() != crc32c(index.data(), index.size() - 4) && verify_checksums_)
      throw FormatError(blocks_offset_ - 4, "index checksum mismatch");
  }
  Cursor x(std::string_view(index).substr(0, index.size() - 4), index_offset_, "index");
  index_.resize(n);
  uint64_t expect = blocks_offset_;
  for (uint32_t c = 0; c < n; ++c) {
    uint64_t at = x.offset();
    IndexEntry& e = index_[c];
    e.offset = x.u64();
    e.size = x.u32();
    e.count = x.u32();
    if (e.offset != expect)
      throw FormatError(at, "cell " + std::to_string(c) + ": block offset " +
                                std::to_string(e.offset) + ", expected " + std::to_string(expect) +
                                " (blocks are contiguous in cell order)");
    if (e.size < 5)
      throw FormatError(at + 8, "cell " + std::to_string(c) + ": block of " +
                                    std::to_string(e.size) + " bytes is smaller than 5");
    if (e.size > size - e.offset)
      throw FormatError(size, "truncated: cell " + std::to_string(c) + "'s block ends at " +
                                  std::to_string(e.offset + e.size) + ", past the end of the file");
    if (e.count > info_.universe)
      throw FormatError(at + 12, "cell " + std::to_string(c) + ": count " +
                                     std::to_string(e.count) + " exceeds the universe " +
                                     std::to_string(info_.universe));
    expect = e.offset + e.size;
  }
  if (expect != size)
    throw FormatError(expect, "trailing bytes: the last block ends at " + std::to_string(expect) +
                                  ", the file has " + std::to_string(size) + " bytes");
}

std::string Reader::read_block(uint32_t cell) {
  if (cell >= index_.size())
    throw std::out_of_range("pvs::Reader: cell " + std::to_string(cell) + " out of range");
  const IndexEntry& e = index_[cell];
  std::string b = source_->read(e.offset, e.size);
  Cursor t(std::string_view(b).substr(b.size() - 4), e.offset + e.size - 4, "block");
  if (t.u32() != crc32c(b.data(), b.size() - 4) && verify_checksums_)
    throw FormatError(e.offset + e.size - 4,
                      "cell " + std::to_string(cell) + ": block checksum mismatch");
  b.resize(b.size() - 4);
  uint8_t enc = uint8_t(b[0]);
  if (enc > 3)
    throw FormatError(e.offset,
                      "cell " + std::to_string(cell) + ": unknown encoding " + std::to_string(enc));
  if (Encoding(enc) == Encoding::Absent) {
    if (!info_.partial)
      throw FormatError(e.offset,
                        "cell " + std::to_string(cell) + " is absent in a file not marked partial");
    if (b.size() != 1)
      throw FormatError(e.offset + 1,
                        "cell " + std::to_string(cell) + ": absent block with a payload");
    if (e.count != 0)
      throw FormatError(e.offset, "cell " + std::to_string(cell) + ": absent block with count " +
                                      std::to_string(e.count));
  }
  return b;
}

bool Reader::is_absent(uint32_t cell) {
  return Encoding(uint8_t(read_block(cell)[0])) == Encoding::Absent;
}

BlockInfo Reader::block_info(uint32_t cell) {
  std::string b = read_block(cell);
  const IndexEntry& e = index_[cell];
  BlockInfo bi;
  bi.size = e.size;
  bi.encoding = Encoding(uint8_t(b[0]));
  if (bi.encoding == Encoding::Delta) {
    Cursor c(std::string_view(b).substr(1), e.offset + 1, "block");
    uint64_t at = c.offset();
    uint32_t d = c.varint();
    if (d == 0 || d > cell)
      throw FormatError(at, "cell " + std::to_string(cell) + ": delta reference distance " +
                                std::to_string(d) + " is not in [1, " + std::to_string(cell) + "]");
    bi.reference = cell - d;
    uint8_t inner = c.u8();
    if (inner > 1)
      throw FormatError(c.offset() - 1, "cell " + std::to_string(cell) +
                                            ": delta with inner encoding " + std::to_string(inner));
    bi.inner = Encoding(inner);
  }
  return bi;
}

std::vector<uint32_t> Reader::decode_cell(uint32_t cell, int depth) {
  std::string b = read_block(cell);
  const IndexEntry& e = index_[cell];
  const std::string name = "cell " + std::to_string(cell) + ": ";
  Encoding enc = Encoding(uint8_t(b[0]));
  if (enc == Encoding::Absent)
    throw FormatError(e.offset, name + "absent (this is a shard; merge the shards first)");
  Cursor c(std::string_view(b).substr(1), e.offset + 1, "block");
  std::vector<uint32_t> ids;
  if (enc == Encoding::Delta) {
    uint64_t at = c.offset();
    uint32_t d = c.varint();
    if (d == 0 || d > cell)
      throw FormatError(at, name + "delta reference distance " + std::to_string(d) +
                                " is not in [1, " + std::to_string(cell) + "]");
    if (depth + 1 > int(info_.max_delta_depth))
      throw FormatError(at, name + "delta chain longer than the header's limit " +
                                std::to_string(info_.max_delta_depth));
    uint8_t inner = c.u8();
    if (inner > 1)
      throw FormatError(c.offset() - 1,
                        name + "delta with inner encoding " + std::to_string(inner));
    std::vector<uint32_t> diff = decode_set(c, Encoding(inner), info_.universe, info_.universe);
    std::vector<uint32_t> ref = decode_cell(cell - d, depth + 1);
    ids = symmetric_difference(ref, diff);
  } else {
    ids = decode_set(c, enc, info_.universe, e.count);
  }
  if (!c.done()) c.fail(name + std::to_string(c.remaining()) + " bytes after the set");
  if (ids.size() != e.count)
    throw FormatError(e.offset, name + "decodes to " + std::to_string(ids.size()) +
                                    " ids, the index says " + std::to_string(e.count));
  return ids;
}

std::vector<uint32_t> Reader::read_cell(uint32_t cell) {
  return decode_cell(cell, 0);
}

void Reader::verify() {
  for (uint32_t c = 0; c < cell_count(); ++c)
    if (!is_absent(c)) read_cell(c);
}

// ---- Merge ----------------------------------------------------------------------------------

std::string merge_pvs(std::vector<Reader>& shards) {
  if (shards.empty()) throw FormatError(0, "no shards to merge");
  const FileInfo& first = shards[0].info();
  for (size_t s = 1; s < shards.size(); ++s) {
    const FileInfo& o = shards[s].info();
    auto bad = [&](const char* what) {
      throw FormatError(0, "shard " + std::to_string(s + 1) + " differs from shard 1 in its " +
                               what + ": not shards of the same bake");
    };
    if (o.scene_fingerprint != first.scene_fingerprint) bad("scene fingerprint");
    if (o.universe != first.universe) bad("universe");
    if (o.granularity != first.granularity) bad("granularity");
    if (o.max_delta_depth != first.max_delta_depth) bad("delta depth limit");
    if (!(o.layout == first.layout)) bad("cell layout");
    if (o.metadata != first.metadata) bad("metadata (bake settings)");
  }
  const uint32_t n = shards[0].cell_count();
  std::vector<CellSet> cells(n);
  for (size_t s = 0; s < shards.size(); ++s) {
    for (uint32_t c = 0; c < n; ++c) {
      if (shards[s].is_absent(c)) continue;
      std::vector<uint32_t> ids = shards[s].read_cell(c);
      if (cells[c] && *cells[c] != ids)
        throw FormatError(shards[s].entry(c).offset,
                          "shard " + std::to_string(s + 1) + ": cell " + std::to_string(c) +
                              " differs from the same cell in an earlier shard");
      cells[c] = std::move(ids);
    }
  }
  for (uint32_t c = 0; c < n; ++c)
    if (!cells[c])
      throw FormatError(
          0, "cell " + std::to_string(c) + " is absent from every shard (a shard is missing)");
  FileInfo info = first;
  info.partial = false;
  return write_pvs(info, cells);
}

}  // namespace pvs
