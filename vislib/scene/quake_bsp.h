// quake_bsp.h: a compiled Quake map (.bsp) as plain data, read and validated, with the map's own
// visibility data (the compiler's `vis` stage: one compressed leaf bitset per leaf). Shared by the
// scene importer (import_bsp.cpp) and whatever holds our visible sets against the map's.
//
// Formats: BSP version 29 (the id format: 16-bit node children, face and marksurface indices,
// 16-bit integer bounds), "BSP2" (every index 32-bit, float bounds) and "2PSB" (32-bit indices,
// 16-bit integer bounds). The lumps, in header order: entities, planes, textures (miptex),
// vertexes, visibility, nodes, texinfo, faces, lighting, clipnodes, leafs, marksurfaces, edges,
// surfedges, models. Lighting, clipnodes and the miptex pixels are not read (only names are).
//
// Coordinates here are Quake's (z up, 1 unit about 2.5 cm). The scene is y-up:
// quake_to_scene((x, y, z)) = (x, z, -y), a rotation of -90 degrees about x (determinant +1, so
// handedness and every triangle's winding are kept); units are kept.
//
// Visibility (the engine's rules): leaf 0 is the shared solid leaf and has no row; leaves
// 1..visleafs (visleafs = model 0's count) have a row of (visleafs + 7) / 8 bytes at `visofs` in
// the visibility lump, in which bit k (byte k / 8, bit k % 8) stands for leaf k + 1; a zero byte is
// followed by a count byte and stands for that many zero bytes. A leaf with visofs < 0 has no row:
// the engine then draws everything (bsp_leaf_sees reports every vis leaf).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "vislib/base/vec.h"
#include "vislib/scene/import.h"

namespace vislib {

enum class BspFormat { bsp29, bsp2, bsp2rmq /* "2PSB" */ };

// Leaf contents (the `contents` field of a leaf).
constexpr int32_t kBspContentsEmpty = -1;
constexpr int32_t kBspContentsSolid = -2;
constexpr int32_t kBspContentsWater = -3;
constexpr int32_t kBspContentsSlime = -4;
constexpr int32_t kBspContentsLava = -5;
constexpr int32_t kBspContentsSky = -6;
// True for water, slime and lava.
inline bool bsp_contents_liquid(int32_t c) {
  return c == kBspContentsWater || c == kBspContentsSlime || c == kBspContentsLava;
}

struct BspPlane {
  std::array<float, 3> normal{};
  float dist = 0;
  int32_t type = 0;
};

// A child reference of a node: >= 0 a node index, < 0 the leaf -(child + 1).
struct BspNode {
  uint32_t plane = 0;
  std::array<int32_t, 2> children{};  // [0]: front (dot(normal, p) - dist > 0), [1]: back
  std::array<float, 3> mins{}, maxs{};
  uint32_t first_face = 0, face_count = 0;
};

struct BspLeaf {
  int32_t contents = 0;
  int32_t visofs = -1;  // byte offset of the row in the visibility lump, < 0: none
  std::array<float, 3> mins{}, maxs{};
  uint32_t first_marksurface = 0, marksurface_count = 0;
};

struct BspTexinfo {
  std::array<std::array<float, 4>, 2> vecs{};
  uint32_t miptex = 0;  // index into QuakeBsp::texture_names
  int32_t flags = 0;
};

struct BspFace {
  uint32_t plane = 0;
  int32_t side = 0;
  uint32_t first_edge = 0, edge_count = 0;  // a range of QuakeBsp::surfedges
  uint32_t texinfo = 0;
};

struct BspModel {
  std::array<float, 3> mins{}, maxs{}, origin{};
  std::array<int32_t, 4> headnode{};  // [0]: the BSP tree of nodes (a child reference as above)
  int32_t visleafs = 0;
  uint32_t first_face = 0, face_count = 0;
};

// A map after read_quake_bsp: every index in range (faces -> planes, texinfo, surfedges; surfedges
// -> edges -> vertices; texinfo -> texture_names; nodes -> planes, children, faces; leaves ->
// marksurfaces -> faces; models -> faces, head node), the node tree of every model acyclic, every
// vertex, plane and bound finite, model 0's visleafs < leaves.size(), and every leaf's row
// decoding within the visibility lump. Functions below rely on this and do not check again.
struct QuakeBsp {
  BspFormat format = BspFormat::bsp29;
  std::string entities;
  std::vector<BspPlane> planes;
  std::vector<std::string> texture_names;  // per miptex slot; "" for a missing one (offset -1)
  std::vector<std::array<float, 3>> vertices;
  std::vector<uint8_t> visibility;
  std::vector<BspNode> nodes;
  std::vector<BspTexinfo> texinfo;
  std::vector<BspFace> faces;
  std::vector<BspLeaf> leaves;
  std::vector<uint32_t> marksurfaces;          // face indices
  std::vector<std::array<uint32_t, 2>> edges;  // vertex indices
  std::vector<int32_t> surfedges;              // >= 0: edge e forward, < 0: edge -e backward
  std::vector<BspModel> models;                // at least one (model 0, the world)

  // Model 0's visleafs: the leaves 1..visleaf_count() have visibility rows.
  uint32_t visleaf_count() const { return uint32_t(models[0].visleafs); }
  // The texture name of face f.
  const std::string& face_texture(uint32_t f) const {
    return texture_names[texinfo[faces[f].texinfo].miptex];
  }
  // The vertex indices of face f in its edge order (the winding as stored).
  std::vector<uint32_t> face_vertices(uint32_t f) const;
};

// Reads and validates `bytes`, the contents of `path` (for messages). Throws InputError(path, ...)
// naming the lump and the byte offset in the file of what is wrong: a truncated header or lump, a
// lump length that is not a whole number of records, an index out of range, a cyclic node tree, a
// non-finite value, a visibility row running past its lump or its length. "2PSB" and "BSP2" are
// read; other versions are refused with the version found. Never reads out of bounds; allocates at
// most a small multiple of the file size. Deterministic.
QuakeBsp parse_quake_bsp(const std::string& path, const std::string& bytes);
// read_file(path) then parse_quake_bsp.
QuakeBsp read_quake_bsp(const std::string& path);
// The map at `path` (a .bsp) read once for two uses: returns the scene load_scene(path, options,
// warnings) returns (the same triangles, warnings and errors) and leaves in `map` what
// read_quake_bsp(path) returns, the map it was imported from (import.cpp).
Scene load_bsp_scene(const std::string& path, const LoadOptions& options, QuakeBsp& map,
                     std::vector<std::string>* warnings = nullptr);

// Quake (z up) to scene (y up) coordinates and back: (x, y, z) -> (x, z, -y).
inline Vec3 quake_to_scene(Vec3 q) {
  return {q.x, q.z, -q.y};
}
inline Vec3 scene_to_quake(Vec3 s) {
  return {s.x, -s.z, s.y};
}

// The faces the importer turns into triangles (LoadOptions::bsp_models, bsp_liquids), and the
// triangle ids of each map face: face f (in map face order) gives its edge_count - 2 fan
// triangles (v0, vi, vi+1) with consecutive ids starting at first_triangle, in face order; faces
// left out (other models, omitted liquids) and faces of fewer than 3 edges have triangle_count 0.
struct BspFaceTriangles {
  bool imported = false;  // the face is one object of the scene
  uint32_t first_triangle = 0, triangle_count = 0;
};
// True for a texture the engine draws as a liquid or teleporter surface (name starts with '*').
inline bool bsp_texture_liquid(const std::string& name) {
  return !name.empty() && name[0] == '*';
}
// True for a sky texture (name starts with "sky", case-insensitive).
bool bsp_texture_sky(const std::string& name);
// One entry per map face. Liquid faces are kept for BspLiquids::opaque and see_through (the
// importer marks the latter's objects see-through) and left out for omit.
std::vector<BspFaceTriangles> bsp_face_triangles(const QuakeBsp& bsp, const LoadOptions& options);

// Leaf `leaf`'s visibility row decoded: the leaves (1..visleafs, increasing) it sees. Leaf 0 and
// leaves beyond visleafs have no row: empty. visofs < 0: every vis leaf. `leaf` must be <
// bsp.leaves.size().
std::vector<uint32_t> bsp_leaf_sees(const QuakeBsp& bsp, uint32_t leaf);
// The faces the engine draws from inside `leaf`: those in the marksurfaces of every leaf it sees
// (itself included when its row says so), sorted, unique.
std::vector<uint32_t> bsp_leaf_drawn_faces(const QuakeBsp& bsp, uint32_t leaf);
// The same as triangle ids of the scene imported with `faces` (bsp_face_triangles), sorted.
std::vector<uint32_t> bsp_leaf_drawn_triangles(const QuakeBsp& bsp,
                                               const std::vector<BspFaceTriangles>& faces,
                                               uint32_t leaf);
// A point entity of the map's entities lump: its classname and origin (scene coordinates).
struct BspEntityPoint {
  std::string classname;
  Vec3 origin;
};
// The player starts the entities lump names, in lump order: the entities whose classname is
// info_player_start, info_player_start2, info_player_deathmatch or info_player_coop and whose
// "origin" is three finite numbers (Quake coordinates, turned into the scene's by
// quake_to_scene). The origin is the player's centre, 24 units above the floor it stands on. The
// lump is read as the engine reads it ({ "key" "value" ... } blocks); an entity with no or a
// malformed origin is left out, and reading stops at the first malformed block (the starts
// before it are kept). Deterministic.
std::vector<BspEntityPoint> bsp_player_starts(const QuakeBsp& bsp);

// Quake's player (the engine's player hull, -16..16 x -16..16 x -24..32, and its STEPSIZE), in
// Quake units: the agent of walkable cells on a Quake map.
constexpr double kQuakePlayerHeight = 56, kQuakePlayerRadius = 16, kQuakeStepHeight = 18;

// The leaf of model 0 holding the Quake-space point `p`: walks the node tree from model 0's head
// node, taking the front child where dot(normal, p) - dist > 0 and the back child otherwise (the
// engine's Mod_PointInLeaf).
uint32_t bsp_point_leaf(const QuakeBsp& bsp, Vec3 p);

}  // namespace vislib
