// gltf_reader.h: the parts of the glTF importer (import_gltf.cpp, the top of which says what is
// imported and how): the file (import_gltf_file.cpp), buffers, accessors and meshes
// (import_gltf_mesh.cpp), animation channels (import_gltf_animation.cpp). Internal to vislib.
#pragma once

#include <tiny_gltf.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "vislib/base/error.h"
#include "vislib/base/vec.h"

namespace vislib {
namespace gltf_reader {

using json = nlohmann::json;

struct Bytes {
  const unsigned char* data = nullptr;
  size_t size = 0;
};

struct Channel {
  int node = -1;
  int path = 0;      // 0 translation, 1 rotation, 2 scale, 3 morph weights
  int interp = 0;    // 0 LINEAR, 1 STEP, 2 CUBICSPLINE
  size_t ncomp = 3;  // values per key element: 3, 4 (rotation) or the morph target count (weights)
  std::vector<double> times;
  std::vector<double>
      values;  // per key: ncomp values (CUBICSPLINE: in-tangent, value, out-tangent)
};

// One primitive of a mesh, decoded once and shared by all instances of the mesh.
struct Prim {
  std::vector<Vec3> local;
  std::vector<std::array<uint32_t, 3>> tris;
  std::vector<std::array<uint32_t, 4>> joints;  // empty unless skinned
  std::vector<std::array<double, 4>> weights;
  // POSITION displacement of each vertex per morph target; a target without POSITION is empty.
  std::vector<std::vector<Vec3>> targets;  // With the appearance only: NORMAL and TEXCOORD_0 per
                                           // vertex (empty when absent), material.
  std::vector<Vec3> normals;
  std::vector<std::array<double, 2>> uvs;
  int material = -1;
};

struct Ctx {
  std::string path;
  tinygltf::Model model;
  json doc;
  std::vector<std::vector<unsigned char>> decoded;  // meshopt-decoded bufferViews
  std::vector<char> is_decoded;
  std::vector<std::string>* warnings;

  [[noreturn]] void fail(const std::string& what) const { throw InputError(path, what); }
};

// Parses the container, rewrites meshopt fallback buffers and hands the file to tinygltf.
void parse_file(Ctx& ctx);
// Checks the required extensions (see the top of import_gltf.cpp).
void check_extensions(const Ctx& ctx);

// The bytes of a bufferView, range-checked (meshopt-compressed views are decoded first).
Bytes view_bytes(Ctx& ctx, int view, const std::string& who);
// All values of an accessor as doubles (count * ncomp), every range checked. `who` says what the
// accessor is for; `want` lists the allowed component counts (empty = any).
std::vector<double> read_accessor(Ctx& ctx, int index, const std::string& what, int& ncomp,
                                  std::initializer_list<int> want = {});
// The primitives of mesh `mesh_index` (joints and weights when `skinned`; normals, UVs and
// materials when `appearance`).
std::vector<Prim> decode_mesh(Ctx& ctx, int mesh_index, bool skinned, bool appearance);

// Reads the animation channels of the selected animations. `node_targets[n]` is the morph target
// count of node n's mesh (0 without a mesh), the number of weights a "weights" channel animates.
std::vector<Channel> read_channels(Ctx& ctx, int which, const std::vector<size_t>& node_targets);
// Value of channel `c` at time t (c.ncomp components).
void sample(const Channel& c, double t, double* v);

}  // namespace gltf_reader
}  // namespace vislib
