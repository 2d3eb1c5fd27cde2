// quake_bsp.cpp: the Quake map reader of quake_bsp.h. The record layouts follow the engines that
// load these files (id's Quake, QuakeSpasm for BSP2 and 2PSB): little-endian throughout.
//
//   record        BSP29                          BSP2                     2PSB
//   node          i32 plane, u16 children[2],    i32, i32[2], f32[6],     i32, i32[2], i16[6],
//                 i16 bounds[6], u16 face range  u32 range      (44 B)    u32 range     (32 B)
//                                     (24 B)
//   leaf          i32 contents, i32 visofs,      i32, i32, f32[6],        i32, i32, i16[6],
//                 i16 bounds[6], u16 mark range, u32 range, u8[4] (44 B)  u32 range, u8[4] (32 B)
//                 u8 ambient[4]       (28 B)
//   face          u16 plane, i16 side, i32 edge, i32 plane, i32 side, i32 edge, i32 count,
//                 u16 count, u16 texinfo, u8[4], i32 texinfo, u8[4], i32 lightofs (28 B, both)
//                 i32 lightofs        (20 B)
//   marksurface   u16                            u32                      u32
//   edge          u16[2]                         u32[2]                   u32[2]
// Common to all: plane f32 normal[3], f32 dist, i32 type (20 B); vertex f32[3] (12 B); texinfo
// f32 vecs[8], i32 miptex, i32 flags (40 B); surfedge i32 (4 B); model f32 mins[3], maxs[3],
// origin[3], i32 headnode[4], i32 visleafs, i32 firstface, i32 numfaces (64 B); the textures lump
// i32 count, i32 offsets[count] (from the lump's start, -1 = missing), each miptex a 16-byte name
// then u32 width, height, offsets[4] (40 B header).
// BSP29 node children are read as QuakeSpasm does: a value below the node count is a node, any
// other value v is the leaf 0xffff - v (the same as id's signed reading for maps under 32768
// nodes).
#include "vislib/scene/quake_bsp.h"

#include <algorithm>
#include <cassert>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <optional>

#include "vislib/base/error.h"
#include "vislib/base/file_util.h"

namespace vislib {

namespace {

enum Lump {
  kEntities,
  kPlanes,
  kTextures,
  kVertexes,
  kVisibility,
  kNodes,
  kTexinfo,
  kFaces,
  kLighting,
  kClipnodes,
  kLeafs,
  kMarksurfaces,
  kEdges,
  kSurfedges,
  kModels,
  kLumpCount
};
const char* const kLumpNames[kLumpCount] = {"entities",   "planes",    "textures", "vertexes",
                                            "visibility", "nodes",     "texinfo",  "faces",
                                            "lighting",   "clipnodes", "leafs",    "marksurfaces",
                                            "edges",      "surfedges", "models"};
constexpr size_t kHeaderBytes = 4 + kLumpCount * 8;

class Reader {
 public:
  Reader(const std::string& path, const std::string& b) : path_(path), b_(b) {}

  [[noreturn]] void fail_header(const std::string& what) const {
    throw InputError(path_, "header: " + what);
  }
  // `at` is a byte offset in the file.
  [[noreturn]] void fail(int lump, uint64_t at, const std::string& what) const {
    throw InputError(path_, std::string(kLumpNames[lump]) + " lump (at byte " +
                                std::to_string(off_[lump]) + ", " + std::to_string(len_[lump]) +
                                " bytes): " + what + " (byte " + std::to_string(at) + ")");
  }

  void read_header() {
    if (b_.size() < kHeaderBytes)
      fail_header("truncated: " + std::to_string(kHeaderBytes) + " bytes needed, the file has " +
                  std::to_string(b_.size()));
    for (int l = 0; l < kLumpCount; ++l) {
      size_t at = 4 + size_t(l) * 8;
      int32_t off = i32(at), len = i32(at + 4);
      if (off < 0 || len < 0 || uint64_t(off) + uint64_t(len) > b_.size())
        fail_header(std::string(kLumpNames[l]) + " lump (directory entry at byte " +
                    std::to_string(at) + "): offset " + std::to_string(off) + " and length " +
                    std::to_string(len) + " do not lie within the file (" +
                    std::to_string(b_.size()) + " bytes)");
      off_[l] = uint32_t(off);
      len_[l] = uint32_t(len);
    }
  }

  // The number of `size`-byte records in `lump`; its length must be a whole number of them.
  size_t count(int lump, size_t size) const {
    if (len_[lump] % size != 0)
      fail(lump, off_[lump],
           "length " + std::to_string(len_[lump]) + " is not a whole number of " +
               std::to_string(size) + "-byte records");
    return len_[lump] / size;
  }
  size_t at(int lump, size_t index, size_t size) const { return off_[lump] + index * size; }
  uint32_t offset(int lump) const { return off_[lump]; }
  uint32_t length(int lump) const { return len_[lump]; }

  uint8_t u8(size_t p) const { return uint8_t(b_[p]); }
  uint16_t u16(size_t p) const { return uint16_t(u8(p) | u8(p + 1) << 8); }
  int16_t i16(size_t p) const { return int16_t(u16(p)); }
  uint32_t u32(size_t p) const {
    return uint32_t(u8(p)) | uint32_t(u8(p + 1)) << 8 | uint32_t(u8(p + 2)) << 16 |
           uint32_t(u8(p + 3)) << 24;
  }
  int32_t i32(size_t p) const { return int32_t(u32(p)); }
  float f32(size_t p) const {
    uint32_t u = u32(p);
    float f;
    std::memcpy(&f, &u, 4);
    return f;
  }
  // Reads `n` floats at p, failing in `lump` on a non-finite one.
  template <size_t N>
  std::array<float, N> floats(int lump, size_t p, const std::string& what) const {
    std::array<float, N> v{};
    for (size_t k = 0; k < N; ++k) {
      v[k] = f32(p + 4 * k);
      if (!std::isfinite(v[k])) fail(lump, p + 4 * k, what + " has a non-finite value");
    }
    return v;
  }
  std::array<float, 3> shorts3(size_t p) const {
    return {float(i16(p)), float(i16(p + 2)), float(i16(p + 4))};
  }

 private:
  const std::string& path_;
  const std::string& b_;
  uint32_t off_[kLumpCount] = {}, len_[kLumpCount] = {};
};

std::string rec(const char* what, size_t i) {
  return std::string(what) + " " + std::to_string(i);
}

// Checks first + count <= size (no overflow).
bool range_ok(uint64_t first, uint64_t count, uint64_t size) {
  return first <= size && count <= size - first;
}

// Decodes the visibility row at `ofs` of `row_bytes` bytes into `out` (if not null); returns an
// empty string on success, else what is wrong and sets `bad_at` to the lump-relative offset.
std::string decode_row(const std::vector<uint8_t>& vis, size_t ofs, size_t row_bytes,
                       std::vector<uint8_t>* out, size_t& bad_at) {
  size_t done = 0, p = ofs;
  while (done < row_bytes) {
    if (p >= vis.size()) {
      bad_at = p;
      return "runs past the end of the lump after " + std::to_string(done) + " of " +
             std::to_string(row_bytes) + " bytes";
    }
    uint8_t c = vis[p++];
    if (c != 0) {
      if (out) (*out)[done] = c;
      ++done;
      continue;
    }
    if (p >= vis.size()) {
      bad_at = p - 1;
      return "a zero byte without its count at the end of the lump";
    }
    size_t run = vis[p++];
    if (run > row_bytes - done) {
      bad_at = p - 2;
      return "a run of " + std::to_string(run) + " zero bytes passes the row's end (" +
             std::to_string(row_bytes - done) + " bytes left of " + std::to_string(row_bytes) + ")";
    }
    if (out) std::fill(out->begin() + long(done), out->begin() + long(done + run), uint8_t(0));
    done += run;
  }
  return {};
}

}  // namespace

std::vector<uint32_t> QuakeBsp::face_vertices(uint32_t f) const {
  const BspFace& face = faces[f];
  std::vector<uint32_t> v(face.edge_count);
  for (uint32_t k = 0; k < face.edge_count; ++k) {
    int32_t se = surfedges[face.first_edge + k];
    v[k] = se >= 0 ? edges[uint32_t(se)][0] : edges[uint32_t(-int64_t(se))][1];
  }
  return v;
}

namespace {

// The record layout of a format (the table at the top of this file).
struct Layout {
  BspFormat format = BspFormat::bsp29;
  bool wide = false;          // 32-bit indices (BSP2, 2PSB)
  bool float_bounds = false;  // float node and leaf bounds (BSP2)
  size_t leaf_size = 28, node_size = 24;
};

// The format named by the file's first 4 bytes: "BSP2", "2PSB" or the version 29 (fails in the
// header on anything else, naming the version found).
Layout read_layout(const Reader& r, const std::string& b) {
  Layout lay;
  if (b.size() < 4) r.fail_header("truncated: the file has " + std::to_string(b.size()) + " bytes");
  if (b.compare(0, 4, "BSP2") == 0) {
    lay.format = BspFormat::bsp2;
  } else if (b.compare(0, 4, "2PSB") == 0) {
    lay.format = BspFormat::bsp2rmq;
  } else {
    int32_t version = r.i32(0);
    if (version != 29)
      r.fail_header("BSP version " + std::to_string(version) +
                    (version == 30 ? " (Half-Life)" : "") +
                    " is not supported (supported: 29, \"BSP2\", \"2PSB\")");
  }
  lay.wide = lay.format != BspFormat::bsp29;
  lay.float_bounds = lay.format == BspFormat::bsp2;
  lay.leaf_size = lay.float_bounds ? 44 : lay.wide ? 32 : 28;
  lay.node_size = lay.float_bounds ? 44 : lay.wide ? 32 : 24;
  return lay;
}

// A node's or leaf's bounds at byte q of `lump` (6 floats in BSP2, failing on a non-finite one
// named by `what`; 6 int16 otherwise). Returns the byte after them.
size_t read_bounds(const Reader& r, const Layout& lay, int lump, size_t q, const std::string& what,
                   std::array<float, 3>& mins, std::array<float, 3>& maxs) {
  if (lay.float_bounds) {
    auto v = r.floats<6>(lump, q, what);
    mins = {v[0], v[1], v[2]};
    maxs = {v[3], v[4], v[5]};
    return q + 24;
  }
  mins = r.shorts3(q);
  maxs = r.shorts3(q + 6);
  return q + 12;
}

// The entities lump, up to its first NUL.
void read_entities(const Reader& r, const std::string& b, QuakeBsp& m) {
  m.entities.assign(b, r.offset(kEntities), r.length(kEntities));
  if (size_t nul = m.entities.find('\0'); nul != std::string::npos) m.entities.resize(nul);
}

// Planes: finite normals and distances.
void read_planes(const Reader& r, QuakeBsp& m) {
  size_t n = r.count(kPlanes, 20);
  m.planes.resize(n);
  for (size_t i = 0; i < n; ++i) {
    size_t p = r.at(kPlanes, i, 20);
    auto v = r.floats<4>(kPlanes, p, rec("plane", i));
    m.planes[i] = {{v[0], v[1], v[2]}, v[3], r.i32(p + 16)};
  }
}

// The textures lump, names only: a count that fits the lump, and each present miptex's 40-byte
// header within it (offset -1: a missing texture, name "").
void read_texture_names(const Reader& r, const std::string& b, QuakeBsp& m) {
  if (r.length(kTextures) == 0) return;
  size_t base = r.offset(kTextures), len = r.length(kTextures);
  if (len < 4) r.fail(kTextures, base, "too short for the texture count");
  int32_t n = r.i32(base);
  if (n < 0 || uint64_t(n) > (len - 4) / 4)
    r.fail(kTextures, base,
           "texture count " + std::to_string(n) + " does not fit the lump's " +
               std::to_string(len) + " bytes");
  m.texture_names.resize(size_t(n));
  for (size_t i = 0; i < size_t(n); ++i) {
    int32_t ofs = r.i32(base + 4 + 4 * i);
    if (ofs == -1) continue;
    if (ofs < 0 || !range_ok(uint64_t(ofs), 40, len))
      r.fail(kTextures, base + 4 + 4 * i,
             "texture " + std::to_string(i) + ": offset " + std::to_string(ofs) +
                 " leaves no room for its 40-byte header in the lump");
    const char* name = b.data() + base + size_t(ofs);
    m.texture_names[i].assign(name, strnlen(name, 16));
  }
}

// Vertices: finite coordinates.
void read_vertices(const Reader& r, QuakeBsp& m) {
  size_t n = r.count(kVertexes, 12);
  m.vertices.resize(n);
  for (size_t i = 0; i < n; ++i)
    m.vertices[i] = r.floats<3>(kVertexes, r.at(kVertexes, i, 12), rec("vertex", i));
}

// The visibility lump's bytes, as stored (its rows are checked by check_visibility_rows).
void read_visibility(const Reader& r, const std::string& b, QuakeBsp& m) {
  m.visibility.assign(b.begin() + long(r.offset(kVisibility)),
                      b.begin() + long(r.offset(kVisibility) + r.length(kVisibility)));
}

// Leaves (read before the nodes, whose children refer to them): finite bounds, a visibility
// offset inside the visibility lump or < 0. Their marksurface ranges are checked by
// check_leaf_marksurfaces, once the marksurfaces are read.
void read_leaves(const Reader& r, const Layout& lay, QuakeBsp& m) {
  size_t n = r.count(kLeafs, lay.leaf_size);
  m.leaves.resize(n);
  for (size_t i = 0; i < n; ++i) {
    size_t p = r.at(kLeafs, i, lay.leaf_size);
    BspLeaf& l = m.leaves[i];
    l.contents = r.i32(p);
    l.visofs = r.i32(p + 4);
    size_t q = read_bounds(r, lay, kLeafs, p + 8, rec("leaf", i), l.mins, l.maxs);
    l.first_marksurface = lay.wide ? r.u32(q) : r.u16(q);
    l.marksurface_count = lay.wide ? r.u32(q + 4) : r.u16(q + 2);
    if (l.visofs >= 0 && uint64_t(l.visofs) >= r.length(kVisibility))
      r.fail(kLeafs, p + 4,
             rec("leaf", i) + ": visibility offset " + std::to_string(l.visofs) +
                 " is outside the visibility lump (" + std::to_string(r.length(kVisibility)) +
                 " bytes)");
  }
}

// Texinfo: each names a texture of m.texture_names (read before).
void read_texinfo(const Reader& r, QuakeBsp& m) {
  size_t n = r.count(kTexinfo, 40);
  m.texinfo.resize(n);
  for (size_t i = 0; i < n; ++i) {
    size_t p = r.at(kTexinfo, i, 40);
    BspTexinfo& t = m.texinfo[i];
    for (size_t k = 0; k < 8; ++k) t.vecs[k / 4][k % 4] = r.f32(p + 4 * k);
    int32_t mt = r.i32(p + 32);
    if (mt < 0 || size_t(mt) >= m.texture_names.size())
      r.fail(kTexinfo, p + 32,
             rec("texinfo", i) + ": texture " + std::to_string(mt) + " out of range (" +
                 std::to_string(m.texture_names.size()) + " textures)");
    t.miptex = uint32_t(mt);
    t.flags = r.i32(p + 36);
  }
}

// Edges: both ends index m.vertices (read before).
void read_edges(const Reader& r, const Layout& lay, QuakeBsp& m) {
  const size_t size = lay.wide ? 8 : 4;
  size_t n = r.count(kEdges, size);
  m.edges.resize(n);
  for (size_t i = 0; i < n; ++i) {
    size_t p = r.at(kEdges, i, size);
    for (int k = 0; k < 2; ++k) {
      uint32_t v = lay.wide ? r.u32(p + 4 * size_t(k)) : r.u16(p + 2 * size_t(k));
      if (v >= m.vertices.size())
        r.fail(kEdges, p,
               rec("edge", i) + ": vertex " + std::to_string(v) + " out of range (" +
                   std::to_string(m.vertices.size()) + " vertices)");
      m.edges[i][size_t(k)] = v;
    }
  }
}

// Surfedges: |value| indexes m.edges (read before); INT32_MIN has no magnitude and is refused.
void read_surfedges(const Reader& r, QuakeBsp& m) {
  size_t n = r.count(kSurfedges, 4);
  m.surfedges.resize(n);
  for (size_t i = 0; i < n; ++i) {
    size_t p = r.at(kSurfedges, i, 4);
    int32_t se = r.i32(p);
    if (se == INT32_MIN || uint64_t(se < 0 ? -int64_t(se) : se) >= m.edges.size())
      r.fail(kSurfedges, p,
             rec("surfedge", i) + ": edge " + std::to_string(se) + " out of range (" +
                 std::to_string(m.edges.size()) + " edges)");
    m.surfedges[i] = se;
  }
}

// Faces: plane, texinfo and surfedge range in range of what was read before, checked in that
// order.
void read_faces(const Reader& r, const Layout& lay, QuakeBsp& m) {
  const size_t size = lay.wide ? 28 : 20;
  size_t n = r.count(kFaces, size);
  m.faces.resize(n);
  for (size_t i = 0; i < n; ++i) {
    size_t p = r.at(kFaces, i, size);
    BspFace& f = m.faces[i];
    int64_t plane, side, first, count, ti;
    if (lay.wide) {
      plane = r.i32(p), side = r.i32(p + 4), first = r.i32(p + 8), count = r.i32(p + 12),
      ti = r.i32(p + 16);
    } else {
      plane = r.u16(p), side = r.i16(p + 2), first = r.i32(p + 4), count = r.u16(p + 8),
      ti = r.u16(p + 10);
    }
    if (plane < 0 || uint64_t(plane) >= m.planes.size())
      r.fail(kFaces, p,
             rec("face", i) + ": plane " + std::to_string(plane) + " out of range (" +
                 std::to_string(m.planes.size()) + " planes)");
    if (ti < 0 || uint64_t(ti) >= m.texinfo.size())
      r.fail(kFaces, p,
             rec("face", i) + ": texinfo " + std::to_string(ti) + " out of range (" +
                 std::to_string(m.texinfo.size()) + " texinfos)");
    if (first < 0 || count < 0 || !range_ok(uint64_t(first), uint64_t(count), m.surfedges.size()))
      r.fail(kFaces, p,
             rec("face", i) + ": edges " + std::to_string(first) + " + " + std::to_string(count) +
                 " out of range (" + std::to_string(m.surfedges.size()) + " surfedges)");
    f = {uint32_t(plane), int32_t(side), uint32_t(first), uint32_t(count), uint32_t(ti)};
  }
}

// Marksurfaces: each indexes m.faces (read before).
void read_marksurfaces(const Reader& r, const Layout& lay, QuakeBsp& m) {
  const size_t size = lay.wide ? 4 : 2;
  size_t n = r.count(kMarksurfaces, size);
  m.marksurfaces.resize(n);
  for (size_t i = 0; i < n; ++i) {
    size_t p = r.at(kMarksurfaces, i, size);
    uint32_t f = lay.wide ? r.u32(p) : r.u16(p);
    if (f >= m.faces.size())
      r.fail(kMarksurfaces, p,
             rec("marksurface", i) + ": face " + std::to_string(f) + " out of range (" +
                 std::to_string(m.faces.size()) + " faces)");
    m.marksurfaces[i] = f;
  }
}

// Every leaf's marksurface range lies within m.marksurfaces (fails in the leafs lump).
void check_leaf_marksurfaces(const Reader& r, const Layout& lay, const QuakeBsp& m) {
  for (size_t i = 0; i < m.leaves.size(); ++i) {
    const BspLeaf& l = m.leaves[i];
    if (!range_ok(l.first_marksurface, l.marksurface_count, m.marksurfaces.size()))
      r.fail(kLeafs, r.at(kLeafs, i, lay.leaf_size),
             rec("leaf", i) + ": marksurfaces " + std::to_string(l.first_marksurface) + " + " +
                 std::to_string(l.marksurface_count) + " out of range (" +
                 std::to_string(m.marksurfaces.size()) + " marksurfaces)");
  }
}

// Child k of node i (record at byte p of `n` nodes) as a child reference (>= 0 a node, < 0 the
// leaf -(child + 1)), in range of the nodes and m.leaves. BSP29: see the note at the top of this
// file.
int32_t read_node_child(const Reader& r, const Layout& lay, const QuakeBsp& m, size_t n, size_t i,
                        size_t p, size_t k) {
  if (lay.wide) {
    int32_t c = r.i32(p + 4 + 4 * k);
    if (c >= 0 && size_t(c) >= n)
      r.fail(kNodes, p,
             rec("node", i) + ": child node " + std::to_string(c) + " out of range (" +
                 std::to_string(n) + " nodes)");
    if (c < 0 && uint64_t(-(int64_t(c) + 1)) >= m.leaves.size())
      r.fail(kNodes, p,
             rec("node", i) + ": child leaf " + std::to_string(-(int64_t(c) + 1)) +
                 " out of range (" + std::to_string(m.leaves.size()) + " leaves)");
    return c;
  }
  uint32_t c = r.u16(p + 4 + 2 * k);
  if (c < n) return int32_t(c);
  uint32_t leaf = 0xffffu - c;
  if (leaf >= m.leaves.size())
    r.fail(kNodes, p,
           rec("node", i) + ": child " + std::to_string(c) + " is neither a node (" +
               std::to_string(n) + ") nor a leaf (" + std::to_string(m.leaves.size()) + ")");
  return int32_t(-int64_t(leaf) - 1);
}

// Nodes: plane, children, finite bounds and face range in range of what was read before, checked
// in that order. Whether the nodes form trees is check_node_trees.
void read_nodes(const Reader& r, const Layout& lay, QuakeBsp& m) {
  size_t n = r.count(kNodes, lay.node_size);
  m.nodes.resize(n);
  for (size_t i = 0; i < n; ++i) {
    size_t p = r.at(kNodes, i, lay.node_size);
    BspNode& node = m.nodes[i];
    int32_t plane = r.i32(p);
    if (plane < 0 || size_t(plane) >= m.planes.size())
      r.fail(kNodes, p,
             rec("node", i) + ": plane " + std::to_string(plane) + " out of range (" +
                 std::to_string(m.planes.size()) + " planes)");
    node.plane = uint32_t(plane);
    for (size_t k = 0; k < 2; ++k) node.children[k] = read_node_child(r, lay, m, n, i, p, k);
    size_t q =
        read_bounds(r, lay, kNodes, p + (lay.wide ? 12 : 8), rec("node", i), node.mins, node.maxs);
    node.first_face = lay.wide ? r.u32(q) : r.u16(q);
    node.face_count = lay.wide ? r.u32(q + 4) : r.u16(q + 2);
    if (!range_ok(node.first_face, node.face_count, m.faces.size()))
      r.fail(kNodes, q,
             rec("node", i) + ": faces " + std::to_string(node.first_face) + " + " +
                 std::to_string(node.face_count) + " out of range (" +
                 std::to_string(m.faces.size()) + " faces)");
  }
}

// Models: at least one (the world); finite bounds and origin, a face range and head node in
// range; model 0's visleafs in [0, leaves) (or 0 when there are no leaves).
void read_models(const Reader& r, QuakeBsp& m) {
  size_t n = r.count(kModels, 64);
  if (n == 0) r.fail(kModels, r.offset(kModels), "no models (model 0, the world, is required)");
  m.models.resize(n);
  for (size_t i = 0; i < n; ++i) {
    size_t p = r.at(kModels, i, 64);
    BspModel& md = m.models[i];
    auto v = r.floats<9>(kModels, p, rec("model", i));
    md.mins = {v[0], v[1], v[2]};
    md.maxs = {v[3], v[4], v[5]};
    md.origin = {v[6], v[7], v[8]};
    for (size_t k = 0; k < 4; ++k) md.headnode[k] = r.i32(p + 36 + 4 * k);
    md.visleafs = r.i32(p + 52);
    int32_t first = r.i32(p + 56), count = r.i32(p + 60);
    if (first < 0 || count < 0 || !range_ok(uint64_t(first), uint64_t(count), m.faces.size()))
      r.fail(kModels, p + 56,
             rec("model", i) + ": faces " + std::to_string(first) + " + " + std::to_string(count) +
                 " out of range (" + std::to_string(m.faces.size()) + " faces)");
    md.first_face = uint32_t(first);
    md.face_count = uint32_t(count);
    int32_t h = md.headnode[0];
    if (h >= 0 ? size_t(h) >= m.nodes.size() : uint64_t(-(int64_t(h) + 1)) >= m.leaves.size())
      r.fail(kModels, p + 36,
             rec("model", i) + ": head node " + std::to_string(h) + " out of range (" +
                 std::to_string(m.nodes.size()) + " nodes, " + std::to_string(m.leaves.size()) +
                 " leaves)");
  }
  int32_t vl = m.models[0].visleafs;
  if (vl < 0 || size_t(vl) >= std::max<size_t>(m.leaves.size(), 1))
    r.fail(kModels, r.offset(kModels) + 52,
           "model 0: visleafs " + std::to_string(vl) + " out of range (" +
               std::to_string(m.leaves.size()) + " leaves, leaf 0 included)");
}

// Every model's node tree is a tree: no node is reached twice from the models' head nodes (which
// also rules out cycles).
void check_node_trees(const Reader& r, const Layout& lay, const QuakeBsp& m) {
  std::vector<uint8_t> seen(m.nodes.size(), 0);
  std::vector<int32_t> stack;
  for (size_t i = 0; i < m.models.size(); ++i) {
    if (m.models[i].headnode[0] < 0) continue;
    stack.assign(1, m.models[i].headnode[0]);
    while (!stack.empty()) {
      int32_t node = stack.back();
      stack.pop_back();
      if (seen[size_t(node)])
        r.fail(kNodes, r.at(kNodes, size_t(node), lay.node_size),
               rec("node", size_t(node)) + " is reached twice from the models' head nodes (model " +
                   std::to_string(i) + ")");
      seen[size_t(node)] = 1;
      for (int32_t c : m.nodes[size_t(node)].children)
        if (c >= 0) stack.push_back(c);
    }
  }
}

// The visibility rows of leaves 1..visleafs decode within the visibility lump and their length.
void check_visibility_rows(const Reader& r, const QuakeBsp& m) {
  const size_t row = (m.visleaf_count() + 7) / 8;
  for (size_t i = 1; i <= m.visleaf_count(); ++i) {
    const BspLeaf& l = m.leaves[i];
    if (l.visofs < 0) continue;
    size_t bad = 0;
    std::string what = decode_row(m.visibility, size_t(l.visofs), row, nullptr, bad);
    if (!what.empty())
      r.fail(kVisibility, r.offset(kVisibility) + bad,
             "the row of leaf " + std::to_string(i) + " (at lump offset " +
                 std::to_string(l.visofs) + "): " + what);
  }
}

}  // namespace

// The lumps in dependency order (each checks its indices against those read before it), then
// the checks that need several lumps. The order fixes which error a file with several defects
// reports.
QuakeBsp parse_quake_bsp(const std::string& path, const std::string& b) {
  Reader r(path, b);
  QuakeBsp m;
  const Layout lay = read_layout(r, b);
  m.format = lay.format;
  r.read_header();
  read_entities(r, b, m);
  read_planes(r, m);
  read_texture_names(r, b, m);
  read_vertices(r, m);
  read_visibility(r, b, m);
  read_leaves(r, lay, m);
  read_texinfo(r, m);
  read_edges(r, lay, m);
  read_surfedges(r, m);
  read_faces(r, lay, m);
  read_marksurfaces(r, lay, m);
  check_leaf_marksurfaces(r, lay, m);
  read_nodes(r, lay, m);
  read_models(r, m);
  check_node_trees(r, lay, m);
  check_visibility_rows(r, m);
  return m;
}

QuakeBsp read_quake_bsp(const std::string& path) {
  return parse_quake_bsp(path, read_file(path));
}

bool bsp_texture_sky(const std::string& name) {
  if (name.size() < 3) return false;
  for (size_t i = 0; i < 3; ++i)
    if (std::tolower(static_cast<unsigned char>(name[i])) != "sky"[i]) return false;
  return true;
}

std::vector<BspFaceTriangles> bsp_face_triangles(const QuakeBsp& bsp, const LoadOptions& options) {
  std::vector<uint8_t> selected(bsp.faces.size(), 0);
  const size_t models = options.bsp_models == BspModels::all ? bsp.models.size() : 1;
  for (size_t i = 0; i < models; ++i)
    for (uint32_t k = 0; k < bsp.models[i].face_count; ++k)
      selected[bsp.models[i].first_face + k] = 1;
  std::vector<BspFaceTriangles> out(bsp.faces.size());
  uint32_t next = 0;
  for (uint32_t f = 0; f < bsp.faces.size(); ++f) {
    if (!selected[f] || bsp.faces[f].edge_count < 3) continue;
    if (options.bsp_liquids == BspLiquids::omit && bsp_texture_liquid(bsp.face_texture(f)))
      continue;
    out[f] = {true, next, bsp.faces[f].edge_count - 2};
    next += out[f].triangle_count;
  }
  return out;
}

std::vector<uint32_t> bsp_leaf_sees(const QuakeBsp& bsp, uint32_t leaf) {
  assert(leaf < bsp.leaves.size());
  std::vector<uint32_t> out;
  const uint32_t n = bsp.visleaf_count();
  if (leaf == 0 || leaf > n) return out;
  if (bsp.leaves[leaf].visofs < 0) {
    for (uint32_t k = 1; k <= n; ++k) out.push_back(k);
    return out;
  }
  std::vector<uint8_t> row((n + 7) / 8, 0);
  size_t bad = 0;
  std::string what =
      decode_row(bsp.visibility, size_t(bsp.leaves[leaf].visofs), row.size(), &row, bad);
  assert(what.empty());  // checked by parse_quake_bsp
  for (uint32_t k = 0; k < n; ++k)
    if (row[k / 8] >> (k % 8) & 1) out.push_back(k + 1);
  return out;
}

std::vector<uint32_t> bsp_leaf_drawn_faces(const QuakeBsp& bsp, uint32_t leaf) {
  std::vector<uint32_t> faces;
  for (uint32_t l : bsp_leaf_sees(bsp, leaf)) {
    const BspLeaf& seen = bsp.leaves[l];
    for (uint32_t k = 0; k < seen.marksurface_count; ++k)
      faces.push_back(bsp.marksurfaces[seen.first_marksurface + k]);
  }
  std::sort(faces.begin(), faces.end());
  faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
  return faces;
}

std::vector<uint32_t> bsp_leaf_drawn_triangles(const QuakeBsp& bsp,
                                               const std::vector<BspFaceTriangles>& faces,
                                               uint32_t leaf) {
  assert(faces.size() == bsp.faces.size());
  std::vector<uint32_t> tris;
  for (uint32_t f : bsp_leaf_drawn_faces(bsp, leaf))  // face order = triangle id order
    for (uint32_t k = 0; k < faces[f].triangle_count; ++k)
      tris.push_back(faces[f].first_triangle + k);
  return tris;
}

std::vector<BspEntityPoint> bsp_player_starts(const QuakeBsp& bsp) {
  const std::string& t = bsp.entities;
  size_t at = 0;
  const auto skip_space = [&] {
    while (at < t.size() && std::isspace(static_cast<unsigned char>(t[at]))) ++at;
  };
  // A quoted string at `at`, or none (malformed).
  const auto quoted = [&]() -> std::optional<std::string> {
    skip_space();
    if (at >= t.size() || t[at] != '"') return std::nullopt;
    const size_t end = t.find('"', at + 1);
    if (end == std::string::npos) return std::nullopt;
    std::string out = t.substr(at + 1, end - at - 1);
    at = end + 1;
    return out;
  };
  std::vector<BspEntityPoint> starts;
  for (;;) {
    skip_space();
    if (at >= t.size() || t[at] != '{') break;
    ++at;
    std::string classname, origin;
    bool closed = false;
    for (;;) {
      skip_space();
      if (at < t.size() && t[at] == '}') {
        ++at;
        closed = true;
        break;
      }
      const auto key = quoted();
      const auto value = key ? quoted() : std::nullopt;
      if (!value) break;
      if (*key == "classname") classname = *value;
      if (*key == "origin") origin = *value;
    }
    if (!closed) break;
    static const char* const kStarts[] = {"info_player_start", "info_player_start2",
                                          "info_player_deathmatch", "info_player_coop"};
    if (std::find(std::begin(kStarts), std::end(kStarts), classname) == std::end(kStarts)) continue;
    double q[3];
    char extra;
    if (std::sscanf(origin.c_str(), "%lf %lf %lf %c", &q[0], &q[1], &q[2], &extra) != 3 ||
        !std::isfinite(q[0]) || !std::isfinite(q[1]) || !std::isfinite(q[2]))
      continue;
    starts.push_back({classname, quake_to_scene({q[0], q[1], q[2]})});
  }
  return starts;
}

uint32_t bsp_point_leaf(const QuakeBsp& bsp, Vec3 p) {
  int32_t node = bsp.models[0].headnode[0];
  while (node >= 0) {
    const BspNode& n = bsp.nodes[size_t(node)];
    const BspPlane& pl = bsp.planes[n.plane];
    double d = double(pl.normal[0]) * p.x + double(pl.normal[1]) * p.y +
               double(pl.normal[2]) * p.z - double(pl.dist);
    node = n.children[d > 0 ? 0 : 1];
  }
  return uint32_t(-(int64_t(node) + 1));
}

}  // namespace vislib
