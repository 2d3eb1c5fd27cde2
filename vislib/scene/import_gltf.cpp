// import_gltf.cpp: glTF 2.0 (.gltf, .glb) through tinygltf (Debian's shared library).
//
// What is imported: the default scene (scene 0 if none is set; all root nodes if the file has no
// scenes), nodes depth-first with children in order, TRS or matrix transforms composed in double;
// every node with a mesh becomes one Object (node name, else mesh name, else "node<i>") with its
// own copy of the vertices (instancing flattened); it is see-through (Object::see_through) when
// one of its triangle primitives uses a material with alphaMode BLEND or MASK. TRIANGLES,
// TRIANGLE_STRIP and TRIANGLE_FAN primitives in order (points and lines are skipped with a
// warning); indexed or not.
//
// Robustness: tinygltf parses the JSON and loads buffers, but every bufferView and accessor range
// is checked here before a byte is read, so a bad file gives InputError, never a crash. Images
// are never decoded (a no-op image loader). tinygltf 2.7 ignores extensionsRequired; we check it:
// extensions that only concern appearance (materials, textures, lights) are ignored, geometry
// extensions other than EXT_meshopt_compression and KHR_mesh_quantization are rejected.
//
// EXT_meshopt_compression: tinygltf does not decode it, and it rejects the GLB "fallback" buffer
// (no uri, larger than the BIN chunk). We rewrite such fallback buffers in the JSON into 1-byte
// data URIs before tinygltf sees the file, and decode compressed bufferViews with meshoptimizer
// into our own byte buffers (filters NONE/OCTAHEDRAL/QUATERNION/EXPONENTIAL).
//
// Animation (LoadOptions::states K > 1): translation/rotation/scale and morph "weights" channels
// (LINEAR, with slerp for rotations; STEP; CUBICSPLINE as cubic Hermite splines through the value
// element of each in-tangent/value/out-tangent triple, the tangents giving the slopes) are sampled
// at K evenly spaced times over [0, latest key time] of the selected animations. Channels of
// other paths (e.g. KHR_animation_pointer) are skipped with a warning.
//
// Morph targets (glTF 2.0 §3.7.2.2): the POSITION displacements of the targets (sparse accessors
// included) are applied first, p = base + sum_i w_i * target_i in double, then skinning, then the
// node transform. Weights: the mesh's `weights`, overridden by the node's `weights` (zeros if
// neither is given), overridden in each state by a sampled "weights" channel. K = 1 is the rest
// pose: default weights, the animation is not sampled. NORMAL/TANGENT targets do not move
// geometry and are not read.
//
// Skinned meshes are deformed by linear-blend skinning (JOINTS_0/WEIGHTS_0, inverse bind
// matrices) with the sampled joint transforms, also for K = 1 (the rest pose of the joints).
#include <meshoptimizer.h>
#include <tiny_gltf.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "vislib/base/error.h"
#include "vislib/base/file_util.h"
#include "vislib/scene/appearance.h"
#include "vislib/scene/import_formats.h"

namespace vislib {

namespace {

using json = nlohmann::json;

// Column-major 4x4 matrix, as in glTF.
struct Mat4 {
  double m[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
};

Mat4 operator*(const Mat4& a, const Mat4& b) {
  Mat4 r;
  for (int c = 0; c < 4; ++c)
    for (int i = 0; i < 4; ++i) {
      double s = 0;
      for (int k = 0; k < 4; ++k) s += a.m[k * 4 + i] * b.m[c * 4 + k];
      r.m[c * 4 + i] = s;
    }
  return r;
}

Vec3 transform(const Mat4& a, Vec3 p) {
  return {a.m[0] * p.x + a.m[4] * p.y + a.m[8] * p.z + a.m[12],
          a.m[1] * p.x + a.m[5] * p.y + a.m[9] * p.z + a.m[13],
          a.m[2] * p.x + a.m[6] * p.y + a.m[10] * p.z + a.m[14]};
}

struct Trs {
  double t[3] = {0, 0, 0};
  double r[4] = {0, 0, 0, 1};  // quaternion x, y, z, w
  double s[3] = {1, 1, 1};
  bool has_matrix = false;
  Mat4 matrix;
};

Mat4 to_matrix(const Trs& x) {
  if (x.has_matrix) return x.matrix;
  double qx = x.r[0], qy = x.r[1], qz = x.r[2], qw = x.r[3];
  double n = std::sqrt(qx * qx + qy * qy + qz * qz + qw * qw);
  if (n > 0) qx /= n, qy /= n, qz /= n, qw /= n;
  double R[3][3] = {
      {1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)},
      {2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)},
      {2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)}};
  Mat4 m;
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) m.m[c * 4 + r] = R[r][c] * x.s[c];
  for (int r = 0; r < 3; ++r) m.m[12 + r] = x.t[r];
  return m;
}

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

// True when a triangle primitive of mesh `m` uses a material whose alphaMode is BLEND or MASK:
// its node's object is see-through (docs/scene-model.md "See-through objects"). One such
// primitive makes the whole object see-through, the direction that never hides what is behind
// it.
bool see_through_mesh(const tinygltf::Model& model, int m) {
  for (const auto& prim : model.meshes[size_t(m)].primitives) {
    const bool triangles = prim.mode == 4 || prim.mode == 5 || prim.mode == 6 || prim.mode == -1;
    if (!triangles || prim.material < 0 || size_t(prim.material) >= model.materials.size())
      continue;
    const std::string& mode = model.materials[size_t(prim.material)].alphaMode;
    if (mode == "BLEND" || mode == "MASK") return true;
  }
  return false;
}

struct Ctx {
  std::string path;
  tinygltf::Model model;
  json doc;
  std::vector<std::vector<unsigned char>> decoded;  // meshopt-decoded bufferViews
  std::vector<char> is_decoded;
  std::vector<std::string>* warnings;

  [[noreturn]] void fail(const std::string& what) const { throw InputError(path, what); }
};

bool image_loader_noop(tinygltf::Image*, const int, std::string*, std::string*, int, int,
                       const unsigned char*, int, void*) {
  return true;
}

uint32_t rd32(const std::string& b, size_t at) {
  uint32_t v;
  std::memcpy(&v, b.data() + at, 4);
  return v;
}

// Decodes an EXT_meshopt_compression bufferView into ctx.decoded[view].
void decode_meshopt(Ctx& ctx, int view, const json& ext) {
  std::string who = "bufferView " + std::to_string(view) + " (EXT_meshopt_compression): ";
  auto num = [&](const char* key, bool required) -> uint64_t {
    if (!ext.contains(key)) {
      if (required) ctx.fail(who + "missing '" + key + "'");
      return 0;
    }
    const json& v = ext[key];
    if (!v.is_number_unsigned()) ctx.fail(who + "'" + key + "' must be a non-negative integer");
    return v.get<uint64_t>();
  };
  uint64_t buffer = num("buffer", true), offset = num("byteOffset", false),
           length = num("byteLength", true), stride = num("byteStride", true),
           count = num("count", true);
  std::string mode = ext.value("mode", std::string());
  std::string filter = ext.value("filter", std::string("NONE"));
  if (buffer >= ctx.model.buffers.size())
    ctx.fail(who + "buffer " + std::to_string(buffer) + " does not exist");
  const auto& data = ctx.model.buffers[buffer].data;
  if (offset > data.size() || length > data.size() - offset)
    ctx.fail(who + "source bytes [" + std::to_string(offset) + ", " +
             std::to_string(offset + length) + ") exceed buffer " + std::to_string(buffer) +
             " of " + std::to_string(data.size()) + " bytes");
  if (stride == 0 || stride > 256 || count > (uint64_t(1) << 31) / stride)
    ctx.fail(who + "bad byteStride " + std::to_string(stride) + " or count " +
             std::to_string(count));
  // meshoptimizer's codecs compress at most 64:1 (2 header bits per 16 bytes of zero deltas):
  // a larger claim is rejected before the output is allocated (issue 18: memory amplification).
  if (count * stride > 128 * length + 4096)
    ctx.fail(who + std::to_string(count) + " elements of " + std::to_string(stride) +
             " bytes cannot come from " + std::to_string(length) + " compressed bytes");
  auto& out = ctx.decoded[view];
  out.assign(size_t(count * stride), 0);
  const unsigned char* src = data.data() + offset;
  int rc;
  if (mode == "ATTRIBUTES") {
    if (stride % 4) ctx.fail(who + "ATTRIBUTES need a byteStride multiple of 4");
    rc = meshopt_decodeVertexBuffer(out.data(), count, stride, src, length);
  } else if (mode == "TRIANGLES" || mode == "INDICES") {
    if (stride != 2 && stride != 4) ctx.fail(who + "indices need byteStride 2 or 4");
    if (mode == "TRIANGLES" && count % 3) ctx.fail(who + "TRIANGLES count is not a multiple of 3");
    rc = mode == "TRIANGLES" ? meshopt_decodeIndexBuffer(out.data(), count, stride, src, length)
                             : meshopt_decodeIndexSequence(out.data(), count, stride, src, length);
  } else {
    ctx.fail(who + "unknown mode '" + mode + "'");
  }
  if (rc != 0)
    ctx.fail(who + "meshoptimizer could not decode the data (error " + std::to_string(rc) + ")");
  if (filter == "NONE") {
  } else if (mode != "ATTRIBUTES") {
    ctx.fail(who + "filter " + filter + " is only allowed with ATTRIBUTES");
  } else if (filter == "OCTAHEDRAL" && (stride == 4 || stride == 8)) {
    meshopt_decodeFilterOct(out.data(), count, stride);
  } else if (filter == "QUATERNION" && stride == 8) {
    meshopt_decodeFilterQuat(out.data(), count, stride);
  } else if (filter == "EXPONENTIAL") {
    meshopt_decodeFilterExp(out.data(), count, stride);
  } else {
    ctx.fail(who + "filter '" + filter + "' is unknown or does not fit byteStride " +
             std::to_string(stride));
  }
}

// The bytes of a bufferView, range-checked (meshopt-compressed views are decoded first).
Bytes view_bytes(Ctx& ctx, int view, const std::string& who) {
  const auto& views = ctx.model.bufferViews;
  if (view < 0 || size_t(view) >= views.size())
    ctx.fail(who + ": bufferView " + std::to_string(view) + " does not exist (the file has " +
             std::to_string(views.size()) + ")");
  const json* ext = nullptr;
  const json& jv = ctx.doc["bufferViews"][size_t(view)];
  if (jv.contains("extensions") && jv["extensions"].contains("EXT_meshopt_compression"))
    ext = &jv["extensions"]["EXT_meshopt_compression"];
  if (ext) {
    if (!ctx.is_decoded[view]) {
      decode_meshopt(ctx, view, *ext);
      ctx.is_decoded[view] = 1;
    }
    return {ctx.decoded[view].data(), ctx.decoded[view].size()};
  }
  const auto& bv = views[view];
  if (bv.buffer < 0 || size_t(bv.buffer) >= ctx.model.buffers.size())
    ctx.fail("bufferView " + std::to_string(view) + ": buffer " + std::to_string(bv.buffer) +
             " does not exist");
  const auto& data = ctx.model.buffers[bv.buffer].data;
  if (bv.byteOffset > data.size() || bv.byteLength > data.size() - bv.byteOffset)
    ctx.fail("bufferView " + std::to_string(view) + ": bytes [" + std::to_string(bv.byteOffset) +
             ", " + std::to_string(bv.byteOffset + bv.byteLength) +
             ") are out of range of buffer " + std::to_string(bv.buffer) + " (" +
             std::to_string(data.size()) + " bytes)");
  return {data.data() + bv.byteOffset, bv.byteLength};
}

double read_component(const unsigned char* p, int type, bool normalized) {
  switch (type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      int8_t v;
      std::memcpy(&v, p, 1);
      return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return normalized ? p[0] / 255.0 : p[0];
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      int16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      uint32_t v;
      std::memcpy(&v, p, 4);
      return v;
    }
    default: {
      float v;
      std::memcpy(&v, p, 4);
      return v;
    }
  }
}

int component_size(int type) {
  switch (type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return 4;
    default:
      return 0;
  }
}

// Reads `count` elements of `ncomp` components each from a (view, offset, stride) region after
// checking the range.
void read_elements(Ctx& ctx, const std::string& who, int view, size_t offset, size_t stride,
                   size_t count, int ncomp, int ctype, bool normalized, double* out,
                   const std::vector<size_t>* targets = nullptr) {
  Bytes b = view_bytes(ctx, view, who);
  size_t csize = size_t(component_size(ctype)), esize = csize * size_t(ncomp);
  if (stride == 0) stride = esize;
  if (stride < esize)
    ctx.fail(who + ": byteStride " + std::to_string(stride) + " is smaller than the element (" +
             std::to_string(esize) + " bytes)");
  if (count == 0) return;
  if (offset > b.size || esize > b.size - offset ||
      (count - 1) > (b.size - offset - esize) / stride)
    ctx.fail(who + ": " + std::to_string(count) + " elements of " + std::to_string(esize) +
             " bytes (stride " + std::to_string(stride) + ") from byte " + std::to_string(offset) +
             " do not fit in bufferView " + std::to_string(view) + " (" + std::to_string(b.size) +
             " bytes)");
  for (size_t i = 0; i < count; ++i) {
    const unsigned char* p = b.data + offset + i * stride;
    double* dst = out + (targets ? (*targets)[i] : i) * size_t(ncomp);
    for (int c = 0; c < ncomp; ++c)
      dst[c] = read_component(p + size_t(c) * csize, ctype, normalized);
  }
}

// All values of an accessor as doubles (count * ncomp), every range checked. `who` says what the
// accessor is for; `want` lists the allowed component counts (empty = any).
std::vector<double> read_accessor(Ctx& ctx, int index, const std::string& what, int& ncomp,
                                  std::initializer_list<int> want = {}) {
  const auto& accs = ctx.model.accessors;
  std::string who = "accessor " + std::to_string(index) + " (" + what + ")";
  if (index < 0 || size_t(index) >= accs.size())
    ctx.fail(who + " does not exist (the file has " + std::to_string(accs.size()) + " accessors)");
  const auto& a = accs[index];
  if (!component_size(a.componentType))
    ctx.fail(who + ": bad componentType " + std::to_string(a.componentType));
  ncomp = tinygltf::GetNumComponentsInType(uint32_t(a.type));
  if (ncomp <= 0) ctx.fail(who + ": bad type " + std::to_string(a.type));
  if (want.size() && std::find(want.begin(), want.end(), ncomp) == want.end())
    ctx.fail(who + ": unexpected type with " + std::to_string(ncomp) + " components");
  if (a.count > (size_t(1) << 28))
    ctx.fail(who + ": count " + std::to_string(a.count) + " is too large");
  // Bound the count by the data before allocating (issue 18): with a bufferView, the elements must
  // fit in it (checked exactly by read_elements); without one (zeros, maybe sparse), at most 2^24
  // values, so that a small file cannot ask for gigabytes.
  if (a.bufferView >= 0 && a.count > 0) {
    Bytes b = view_bytes(ctx, a.bufferView, who);
    size_t esize = size_t(component_size(a.componentType)) * size_t(ncomp);
    size_t stride = size_t(a.bufferView) < ctx.model.bufferViews.size()
                        ? ctx.model.bufferViews[a.bufferView].byteStride
                        : 0;
    if (stride < esize) stride = esize;
    if (a.byteOffset > b.size || b.size - a.byteOffset < esize ||
        a.count - 1 > (b.size - a.byteOffset - esize) / stride)
      ctx.fail(who + ": " + std::to_string(a.count) + " elements of " + std::to_string(esize) +
               " bytes (stride " + std::to_string(stride) + ") from byte " +
               std::to_string(a.byteOffset) + " do not fit in bufferView " +
               std::to_string(a.bufferView) + " (" + std::to_string(b.size) + " bytes)");
  } else if (a.bufferView < 0 && a.count * size_t(ncomp) > (size_t(1) << 24)) {
    ctx.fail(who + ": " + std::to_string(a.count) +
             " elements without a bufferView (more than 2^24 values)");
  }
  std::vector<double> out(a.count * size_t(ncomp), 0.0);
  if (a.bufferView >= 0) {
    size_t stride = ctx.model.bufferViews.size() > size_t(a.bufferView)
                        ? ctx.model.bufferViews[a.bufferView].byteStride
                        : 0;
    read_elements(ctx, who, a.bufferView, a.byteOffset, stride, a.count, ncomp, a.componentType,
                  a.normalized, out.data());
  }
  if (a.sparse.isSparse) {
    size_t n = size_t(std::max(a.sparse.count, 0));
    if (n > a.count) ctx.fail(who + ": sparse count exceeds the accessor count");
    int itype = a.sparse.indices.componentType;
    if (itype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
        itype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        itype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
      ctx.fail(who + ": bad sparse index componentType");
    std::vector<double> idx(n);
    read_elements(ctx, who + " sparse indices", a.sparse.indices.bufferView,
                  size_t(std::max(a.sparse.indices.byteOffset, 0)), 0, n, 1, itype, false,
                  idx.data());
    std::vector<size_t> targets(n);
    for (size_t i = 0; i < n; ++i) {
      if (idx[i] >= double(a.count)) ctx.fail(who + ": sparse index out of range");
      targets[i] = size_t(idx[i]);
    }
    read_elements(ctx, who + " sparse values", a.sparse.values.bufferView,
                  size_t(std::max(a.sparse.values.byteOffset, 0)), 0, n, ncomp, a.componentType,
                  a.normalized, out.data(), &targets);
  }
  return out;
}

std::vector<Prim> decode_mesh(Ctx& ctx, int mesh_index, bool skinned, bool appearance) {
  const auto& mesh = ctx.model.meshes[mesh_index];
  std::vector<Prim> prims;
  for (size_t pi = 0; pi < mesh.primitives.size(); ++pi) {
    const auto& prim = mesh.primitives[pi];
    std::string where = "mesh " + std::to_string(mesh_index) + " primitive " + std::to_string(pi);
    int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
        mode != TINYGLTF_MODE_TRIANGLE_FAN) {
      ctx.warnings->push_back(ctx.path + ": " + where + ": mode " + std::to_string(mode) +
                              " (points/lines) skipped");
      continue;
    }
    auto pos_it = prim.attributes.find("POSITION");
    if (pos_it == prim.attributes.end()) {
      ctx.warnings->push_back(ctx.path + ": " + where + ": no POSITION, skipped");
      continue;
    }
    Prim out;
    int nc;
    auto pos = read_accessor(ctx, pos_it->second, "POSITION of " + where, nc, {3});
    size_t nv = pos.size() / 3;
    out.local.resize(nv);
    for (size_t v = 0; v < nv; ++v) {
      out.local[v] = {pos[3 * v], pos[3 * v + 1], pos[3 * v + 2]};
      if (!is_finite(out.local[v]))
        ctx.fail("accessor " + std::to_string(pos_it->second) + " (POSITION of " + where +
                 "): vertex " + std::to_string(v) + " is not finite (NaN or inf)");
    }
    std::vector<uint32_t> idx;
    if (prim.indices >= 0) {
      const auto& accs = ctx.model.accessors;
      if (size_t(prim.indices) < accs.size()) {
        int ct = accs[prim.indices].componentType;
        if (ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
            ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
            ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
          ctx.fail("accessor " + std::to_string(prim.indices) + " (indices of " + where +
                   "): componentType " + std::to_string(ct) + " is not an unsigned integer type");
      }
      auto raw = read_accessor(ctx, prim.indices, "indices of " + where, nc, {1});
      size_t bad = 0;
      double worst = 0;
      idx.resize(raw.size());
      for (size_t i = 0; i < raw.size(); ++i) {
        if (raw[i] >= double(nv)) ++bad, worst = std::max(worst, raw[i]);
        idx[i] = uint32_t(raw[i]);
      }
      if (bad)
        ctx.fail("accessor " + std::to_string(prim.indices) + " (indices of " + where +
                 "): " + std::to_string(bad) + " indices out of range (largest " +
                 std::to_string(uint64_t(worst)) + ", POSITION has " + std::to_string(nv) +
                 " vertices)");
    } else {
      idx.resize(nv);
      for (size_t i = 0; i < nv; ++i) idx[i] = uint32_t(i);
    }
    size_t n = idx.size();
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      for (size_t i = 0; i + 2 < n; i += 3) out.tris.push_back({idx[i], idx[i + 1], idx[i + 2]});
      if (n % 3)
        ctx.warnings->push_back(ctx.path + ": " + where + ": " + std::to_string(n % 3) +
                                " trailing indices ignored");
    } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {  // p_i = {v_i, v_{i+1+i%2}, v_{i+2-i%2}}
      for (size_t i = 0; i + 2 < n; ++i)
        out.tris.push_back({idx[i], idx[i + 1 + i % 2], idx[i + 2 - i % 2]});
    } else {  // fan: p_i = {v_{i+1}, v_{i+2}, v_0}
      for (size_t i = 0; i + 2 < n; ++i) out.tris.push_back({idx[i + 1], idx[i + 2], idx[0]});
    }
    auto j_it = prim.attributes.find("JOINTS_0"), w_it = prim.attributes.find("WEIGHTS_0");
    if (skinned && j_it != prim.attributes.end() && w_it != prim.attributes.end()) {
      auto j = read_accessor(ctx, j_it->second, "JOINTS_0 of " + where, nc, {4});
      auto w = read_accessor(ctx, w_it->second, "WEIGHTS_0 of " + where, nc, {4});
      if (j.size() != 4 * nv || w.size() != 4 * nv)
        ctx.fail(where + ": JOINTS_0/WEIGHTS_0 counts differ from POSITION");
      out.joints.resize(nv);
      out.weights.resize(nv);
      for (size_t v = 0; v < nv; ++v)
        for (int c = 0; c < 4; ++c) {
          out.joints[v][c] = uint32_t(j[4 * v + c]);
          out.weights[v][c] = w[4 * v + c];
        }
    }
    for (size_t ti = 0; ti < prim.targets.size(); ++ti) {
      auto t_it = prim.targets[ti].find("POSITION");
      if (t_it == prim.targets[ti].end()) {
        out.targets.emplace_back();
        continue;
      }
      std::string what = "POSITION of morph target " + std::to_string(ti) + " of " + where;
      auto d = read_accessor(ctx, t_it->second, what, nc, {3});
      if (d.size() != 3 * nv)
        ctx.fail("accessor " + std::to_string(t_it->second) + " (" + what +
                 "): " + std::to_string(d.size() / 3) + " elements, but POSITION has " +
                 std::to_string(nv));
      std::vector<Vec3> disp(nv);
      for (size_t v = 0; v < nv; ++v) {
        disp[v] = {d[3 * v], d[3 * v + 1], d[3 * v + 2]};
        if (!is_finite(disp[v]))
          ctx.fail("accessor " + std::to_string(t_it->second) + " (" + what + "): vertex " +
                   std::to_string(v) + " is not finite (NaN or inf)");
      }
      out.targets.push_back(std::move(disp));
    }
    if (appearance) {
      out.material = prim.material;
      if (prim.material >= int(ctx.model.materials.size())) out.material = -1;
      auto n_it = prim.attributes.find("NORMAL");
      if (n_it != prim.attributes.end()) {
        auto nv3 = read_accessor(ctx, n_it->second, "NORMAL of " + where, nc, {3});
        if (nv3.size() == 3 * nv) {
          out.normals.resize(nv);
          for (size_t v = 0; v < nv; ++v)
            out.normals[v] = {nv3[3 * v], nv3[3 * v + 1], nv3[3 * v + 2]};
        } else {
          ctx.warnings->push_back(ctx.path + ": " + where +
                                  ": NORMAL count differs from POSITION; normals dropped");
        }
      }
      auto t_it = prim.attributes.find("TEXCOORD_0");
      if (t_it != prim.attributes.end()) {
        auto uv = read_accessor(ctx, t_it->second, "TEXCOORD_0 of " + where, nc, {2});
        if (uv.size() == 2 * nv) {
          out.uvs.resize(nv);
          for (size_t v = 0; v < nv; ++v) out.uvs[v] = {uv[2 * v], uv[2 * v + 1]};
        } else {
          ctx.warnings->push_back(ctx.path + ": " + where +
                                  ": TEXCOORD_0 count differs from POSITION; UVs dropped");
        }
      }
    }
    prims.push_back(std::move(out));
  }
  return prims;
}

// Reads the animation channels of the selected animations. `node_targets[n]` is the morph target
// count of node n's mesh (0 without a mesh), the number of weights a "weights" channel animates.
std::vector<Channel> read_channels(Ctx& ctx, int which, const std::vector<size_t>& node_targets) {
  std::vector<Channel> out;
  const auto& anims = ctx.model.animations;
  if (which >= int(anims.size()))
    ctx.fail("animation " + std::to_string(which) + " does not exist (the file has " +
             std::to_string(anims.size()) + ")");
  for (size_t ai = 0; ai < anims.size(); ++ai) {
    if (which >= 0 && size_t(which) != ai) continue;
    const auto& an = anims[ai];
    for (size_t ci = 0; ci < an.channels.size(); ++ci) {
      const auto& ch = an.channels[ci];
      std::string where = "animation " + std::to_string(ai) + " channel " + std::to_string(ci);
      Channel c;
      if (ch.target_path == "translation")
        c.path = 0;
      else if (ch.target_path == "rotation")
        c.path = 1;
      else if (ch.target_path == "scale")
        c.path = 2;
      else if (ch.target_path == "weights")
        c.path = 3;
      else {
        ctx.warnings->push_back(ctx.path + ": " + where + ": target path '" + ch.target_path +
                                "' is not supported; channel ignored");
        continue;
      }
      if (ch.target_node < 0 || size_t(ch.target_node) >= ctx.model.nodes.size())
        ctx.fail(where + ": target node " + std::to_string(ch.target_node) + " does not exist");
      if (c.path == 3) {
        c.ncomp = node_targets[size_t(ch.target_node)];
        if (c.ncomp == 0)
          ctx.fail(where + ": animates the morph weights of node " +
                   std::to_string(ch.target_node) + ", which has no mesh with morph targets");
      } else {
        c.ncomp = c.path == 1 ? 4 : 3;
      }
      if (ch.sampler < 0 || size_t(ch.sampler) >= an.samplers.size())
        ctx.fail(where + ": sampler " + std::to_string(ch.sampler) + " does not exist");
      const auto& s = an.samplers[ch.sampler];
      c.node = ch.target_node;
      c.interp = s.interpolation == "STEP" ? 1 : s.interpolation == "CUBICSPLINE" ? 2 : 0;
      int nc;
      c.times = read_accessor(ctx, s.input, "input of " + where, nc, {1});
      c.values =
          read_accessor(ctx, s.output, "output of " + where, nc, {c.path == 3 ? 1 : int(c.ncomp)});
      size_t per_key = c.ncomp * (c.interp == 2 ? 3 : 1);
      if (c.times.empty() || c.values.size() != c.times.size() * per_key)
        ctx.fail("accessor " + std::to_string(s.output) + " (output of " + where +
                 "): " + std::to_string(c.values.size()) + " values, but " +
                 std::to_string(c.times.size()) + " keys (accessor " + std::to_string(s.input) +
                 ") need " + std::to_string(c.times.size() * per_key) +
                 (c.path == 3 ? " (" + std::to_string(c.ncomp) + " morph weights per key" +
                                    (c.interp == 2 ? ", times 3 for CUBICSPLINE)" : ")")
                              : std::string()));
      for (double t : c.times)
        if (!std::isfinite(t)) ctx.fail(where + ": non-finite key time");
      c.node = ch.target_node;
      out.push_back(std::move(c));
    }
  }
  return out;
}

// Value of channel `c` at time t (c.ncomp components).
void sample(const Channel& c, double t, double* v) {
  const size_t n = c.ncomp;
  size_t keys = c.times.size();
  size_t stride = n * (c.interp == 2 ? 3 : 1), voff = c.interp == 2 ? n : 0;
  auto val = [&](size_t k, size_t i) { return c.values[k * stride + voff + i]; };
  size_t k = size_t(std::upper_bound(c.times.begin(), c.times.end(), t) - c.times.begin());
  if (k == 0 || k == keys) {
    size_t at = k == 0 ? 0 : keys - 1;
    for (size_t i = 0; i < n; ++i) v[i] = val(at, i);
    return;
  }
  size_t k0 = k - 1;
  double t0 = c.times[k0], t1 = c.times[k], dt = t1 - t0;
  double s = dt > 0 ? (t - t0) / dt : 0;
  if (c.interp == 1) {
    for (size_t i = 0; i < n; ++i) v[i] = val(k0, i);
  } else if (c.interp == 2) {
    double s2 = s * s, s3 = s2 * s;
    for (size_t i = 0; i < n; ++i) {
      double p0 = val(k0, i), p1 = val(k, i);
      double m0 = dt * c.values[k0 * stride + 2 * n + i];  // out-tangent of k0
      double m1 = dt * c.values[k * stride + i];           // in-tangent of k
      v[i] = (2 * s3 - 3 * s2 + 1) * p0 + (s3 - 2 * s2 + s) * m0 + (-2 * s3 + 3 * s2) * p1 +
             (s3 - s2) * m1;
    }
  } else if (c.path == 1) {  // slerp
    double a[4], b[4], d = 0;
    for (size_t i = 0; i < 4; ++i) a[i] = val(k0, i), b[i] = val(k, i), d += a[i] * b[i];
    if (d < 0) {
      d = -d;
      for (double& x : b) x = -x;
    }
    double wa = 1 - s, wb = s;
    if (d < 0.9995) {
      double th = std::acos(std::min(d, 1.0)), sn = std::sin(th);
      wa = std::sin((1 - s) * th) / sn;
      wb = std::sin(s * th) / sn;
    }
    for (size_t i = 0; i < 4; ++i) v[i] = wa * a[i] + wb * b[i];
  } else {
    for (size_t i = 0; i < n; ++i) v[i] = val(k0, i) + (val(k, i) - val(k0, i)) * s;
  }
}

// Checks the required extensions (see the top of this file).
void check_extensions(const Ctx& ctx) {
  for (const auto& e : ctx.model.extensionsRequired) {
    bool appearance = e.rfind("KHR_materials_", 0) == 0 || e.rfind("KHR_texture_", 0) == 0 ||
                      e.rfind("EXT_texture_", 0) == 0 || e == "KHR_lights_punctual" ||
                      e.rfind("MSFT_texture_", 0) == 0;
    if (appearance) {
      ctx.warnings->push_back(ctx.path + ": required extension " + e +
                              " concerns appearance only; ignored");
    } else if (e != "EXT_meshopt_compression" && e != "KHR_mesh_quantization") {
      ctx.fail("requires extension " + e + ", which vislib does not support");
    }
  }
  for (const auto& e : ctx.model.extensionsUsed)
    if (e == "EXT_mesh_gpu_instancing" || e == "KHR_draco_mesh_compression")
      ctx.warnings->push_back(ctx.path + ": extension " + e +
                              " is used but not supported; "
                              "geometry that relies on it is missing");
}

// --- External resources stay inside the asset's folder (issue 18) -------------------------------
// A buffer or image `uri` that is not a data URI names a file relative to the folder of the .gltf
// or .glb. tinygltf would open whatever it names ("../../../../etc/hostname", "/etc/passwd", a
// symbolic link to anywhere) and its error would echo the size of that file. We reject, before
// tinygltf sees the document, a uri that is absolute, has a `..` component (after tinygltf's own
// %-decoding, '+' as a space), or resolves through a symbolic link to a file outside the folder;
// the message names the uri only. tinygltf's file callbacks enforce the same containment again on
// the path it actually opens.

// tinygltf 2.7's URI decoding (dlib::urldecode): '+' is a space, %XX a byte.
std::string decode_uri(const std::string& s) {
  auto hex = [](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return 0;
  };
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '+') {
      out += ' ';
    } else if (s[i] == '%' && s.size() > i + 2) {
      out += char((hex(s[i + 1]) << 4) | hex(s[i + 2]));
      i += 2;
    } else {
      out += s[i];
    }
  }
  return out;
}

// The canonical asset folder (symbolic links resolved), or "" if it cannot be resolved.
std::filesystem::path asset_folder(const std::string& path) {
  std::filesystem::path dir = std::filesystem::path(path).parent_path();
  if (dir.empty()) dir = ".";
  std::error_code ec;
  std::filesystem::path real = std::filesystem::canonical(dir, ec);
  return ec ? std::filesystem::path() : real;
}

// True if `p` (an existing file or not) resolves to a path inside `root` (canonical).
bool resolves_inside(const std::filesystem::path& root, const std::filesystem::path& p) {
  std::error_code ec;
  std::filesystem::path real = std::filesystem::weakly_canonical(p, ec);
  if (ec || root.empty()) return false;
  std::filesystem::path rel = real.lexically_relative(root);
  return !rel.empty() && *rel.begin() != ".." && !rel.is_absolute();
}

void check_external_uris(const Ctx& ctx) {
  const std::filesystem::path root = asset_folder(ctx.path);
  for (const char* kind : {"buffers", "images"}) {
    if (!ctx.doc.contains(kind) || !ctx.doc[kind].is_array()) continue;
    const json& list = ctx.doc[kind];
    for (size_t i = 0; i < list.size(); ++i) {
      if (!list[i].is_object() || !list[i].contains("uri") || !list[i]["uri"].is_string()) continue;
      const std::string uri = list[i]["uri"].get<std::string>();
      if (uri.rfind("data:", 0) == 0) continue;
      std::string who = std::string(kind).substr(0, std::strlen(kind) - 1) + " " +
                        std::to_string(i) + ": uri '" + uri.substr(0, 200) + "'";
      const std::string decoded = decode_uri(uri);
      std::filesystem::path rel(decoded);
      if (decoded.empty()) ctx.fail(who + " is empty");
      if (decoded.find('\0') != std::string::npos) ctx.fail(who + " contains a NUL byte");
      if (rel.is_absolute() || rel.has_root_name() || rel.has_root_directory())
        ctx.fail(who + " is an absolute path: external files must lie in the asset's folder");
      for (const auto& part : rel)
        if (part == "..") ctx.fail(who + " leaves the asset's folder ('..' is not allowed)");
      if (!resolves_inside(root, root / rel))
        ctx.fail(who + " resolves (through a symbolic link) outside the asset's folder");
    }
  }
}

// tinygltf file callbacks: only files that resolve inside the asset folder (user data) are seen.
bool fs_file_exists(const std::string& abs, void* root) {
  const auto& r = *static_cast<const std::filesystem::path*>(root);
  std::error_code ec;
  return resolves_inside(r, abs) && std::filesystem::is_regular_file(abs, ec);
}

std::string fs_expand(const std::string& p, void*) {
  return p;
}

bool fs_read(std::vector<unsigned char>* out, std::string* err, const std::string& abs,
             void* root) {
  const auto& r = *static_cast<const std::filesystem::path*>(root);
  std::error_code ec;
  std::filesystem::path real = std::filesystem::canonical(abs, ec);
  if (ec || !resolves_inside(r, real) || !std::filesystem::is_regular_file(real, ec)) {
    if (err) *err += "external file outside the asset's folder or not a regular file\n";
    return false;
  }
  try {
    std::string bytes = read_file(real.string());
    out->assign(bytes.begin(), bytes.end());
  } catch (const std::exception&) {
    if (err) *err += "cannot read an external file\n";
    return false;
  }
  return true;
}

bool fs_write(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err += "writing is not allowed\n";
  return false;
}

// Parses the container, rewrites meshopt fallback buffers and hands the file to tinygltf.
void parse_file(Ctx& ctx) {
  // Memory (issue 18: a 200 MB .glb peaked at 1.29 GB): the file is read once and the GLB handed to
  // tinygltf is rebuilt inside the same string (the BIN chunk is never copied); tinygltf's own copy
  // of the BIN chunk is the only other one.
  std::string bytes = read_file(ctx.path);
  bool glb = bytes.size() >= 4 && bytes.compare(0, 4, "glTF") == 0;
  std::string json_text;
  bool has_bin = false;
  size_t bin_at = 0, bin_len = 0;  // the BIN chunk's payload in `bytes`
  if (glb) {
    if (bytes.size() < 20)
      ctx.fail("truncated .glb: " + std::to_string(bytes.size()) +
               " bytes, less than a GLB header");
    uint32_t version = rd32(bytes, 4), length = rd32(bytes, 8);
    if (version != 2) ctx.fail("unsupported GLB version " + std::to_string(version));
    if (length > bytes.size())
      ctx.fail("truncated .glb: the header declares " + std::to_string(length) +
               " bytes but the file has " + std::to_string(bytes.size()));
    size_t at = 12;
    for (int chunk = 0; at + 8 <= length; ++chunk) {
      uint32_t clen = rd32(bytes, at), ctype = rd32(bytes, at + 4);
      if (clen > length - at - 8)
        ctx.fail("truncated .glb: chunk " + std::to_string(chunk) + " at byte " +
                 std::to_string(at) + " declares " + std::to_string(clen) +
                 " bytes, past the end of the file");
      if (chunk == 0 && ctype != 0x4E4F534Au)
        ctx.fail("malformed .glb: the first chunk is not JSON");
      if (chunk == 0) json_text = bytes.substr(at + 8, clen);
      if (chunk == 1 && ctype == 0x004E4942u) bin_at = at + 8, bin_len = clen, has_bin = true;
      at += 8 + size_t(clen);
      at = (at + 3) & ~size_t(3);
    }
    if (at == 12) ctx.fail("malformed .glb: no JSON chunk");
  } else {
    json_text.swap(bytes);
  }
  try {
    ctx.doc = json::parse(json_text);
    json_text.clear();
    json_text.shrink_to_fit();
  } catch (const json::exception& e) {
    ctx.fail(std::string("invalid JSON: ") + e.what());
  }
  if (!ctx.doc.is_object()) ctx.fail("invalid glTF: the JSON is not an object");
  // EXT_meshopt_compression fallback buffers: replace by a 1-byte data URI (see top of file).
  if (ctx.doc.contains("buffers") && ctx.doc["buffers"].is_array())
    for (auto& b : ctx.doc["buffers"])
      if (b.is_object() && b.contains("extensions") && b["extensions"].is_object() &&
          b["extensions"].contains("EXT_meshopt_compression") &&
          b["extensions"]["EXT_meshopt_compression"].value("fallback", false)) {
        b["uri"] = "data:application/octet-stream;base64,AA==";
        b["byteLength"] = 1;
      }
  if (!ctx.doc.contains("bufferViews") || !ctx.doc["bufferViews"].is_array())
    ctx.doc["bufferViews"] = json::array();
  for (const auto& v : ctx.doc["bufferViews"])
    if (!v.is_object()) ctx.fail("invalid glTF: a bufferView is not an object");

  check_external_uris(ctx);
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(image_loader_noop, nullptr);
  const std::filesystem::path root = asset_folder(ctx.path);
  loader.SetFsCallbacks({&fs_file_exists, &fs_expand, &fs_read, &fs_write,
                         const_cast<std::filesystem::path*>(&root)});
  std::string err, warn, text = ctx.doc.dump();
  std::string base = std::filesystem::path(ctx.path).parent_path().string();
  bool ok;
  try {
    if (glb) {
      // [header 12][JSON chunk header 8][text][BIN chunk header 8][BIN], built in `bytes`: the
      // part before the BIN payload is replaced, what follows the BIN chunk is cut.
      while (text.size() % 4) text += ' ';
      std::string head(12, '\0');
      auto put = [](std::string& o, uint32_t v) { o.append(reinterpret_cast<const char*>(&v), 4); };
      put(head, uint32_t(text.size()));
      put(head, 0x4E4F534Au);
      head += text;
      if (has_bin) {
        size_t padded = (bin_len + 3) & ~size_t(3);
        put(head, uint32_t(padded));
        put(head, 0x004E4942u);
        bytes.resize(bin_at + bin_len);
        bytes.replace(0, bin_at, head);
        bytes.resize(head.size() + padded, '\0');
      } else {
        bytes.swap(head);
      }
      text.clear();
      text.shrink_to_fit();
      if (bytes.size() > 0xFFFFFFFFu) ctx.fail(".glb larger than 4 GiB");
      uint32_t header[3] = {0x46546C67u, 2u, uint32_t(bytes.size())};
      std::memcpy(&bytes[0], header, 12);
      ok = loader.LoadBinaryFromMemory(&ctx.model, &err, &warn,
                                       reinterpret_cast<const unsigned char*>(bytes.data()),
                                       unsigned(bytes.size()), base);
    } else {
      ok = loader.LoadASCIIFromString(&ctx.model, &err, &warn, text.c_str(), unsigned(text.size()),
                                      base);
    }
  } catch (const std::exception& e) {
    ok = false;
    err += e.what();
  }
  if (!ok) {
    while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
    ctx.fail("invalid glTF (tinygltf: " + err + ")");
  }
  if (ctx.model.bufferViews.size() != ctx.doc["bufferViews"].size())
    ctx.fail("invalid glTF: bufferViews could not be parsed");
  ctx.decoded.resize(ctx.model.bufferViews.size());
  ctx.is_decoded.assign(ctx.model.bufferViews.size(), 0);
}

// The inverse transpose of the linear part of `a` applied to `n` (a normal), not normalised.
Vec3 transform_normal(const Mat4& a, Vec3 n) {
  // cofactor(A) = det(A) * A^-T: the cofactor times sign(det) has the direction of A^-T n.
  const double* m = a.m;  // column-major: A(r, c) = m[c * 4 + r]
  auto A = [&](int r, int c) { return m[c * 4 + r]; };
  double C[3][3];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      int r1 = (r + 1) % 3, r2 = (r + 2) % 3, c1 = (c + 1) % 3, c2 = (c + 2) % 3;
      C[r][c] = A(r1, c1) * A(r2, c2) - A(r1, c2) * A(r2, c1);
    }
  double det = A(0, 0) * C[0][0] + A(0, 1) * C[0][1] + A(0, 2) * C[0][2];
  double s = det < 0 ? -1 : 1;
  return {s * (C[0][0] * n.x + C[0][1] * n.y + C[0][2] * n.z),
          s * (C[1][0] * n.x + C[1][1] * n.y + C[1][2] * n.z),
          s * (C[2][0] * n.x + C[2][1] * n.y + C[2][2] * n.z)};
}

Vec3 unit_or_nan(Vec3 v) {
  double l = length(v);
  if (!(l > 0) || !std::isfinite(l)) return {NAN, NAN, NAN};
  return v * (1 / l);
}

std::string image_mime(const tinygltf::Image& im) {
  if (!im.mimeType.empty()) return im.mimeType;
  std::string u = im.uri;
  for (auto& c : u) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (u.size() >= 4 && u.compare(u.size() - 4, 4, ".png") == 0) return "image/png";
  if ((u.size() >= 4 && u.compare(u.size() - 4, 4, ".jpg") == 0) ||
      (u.size() >= 5 && u.compare(u.size() - 5, 5, ".jpeg") == 0))
    return "image/jpeg";
  return "";
}

// "a%20b.png" -> "a b.png" (glTF URIs are percent-encoded).
std::string percent_decode(const std::string& u) {
  std::string out;
  for (size_t i = 0; i < u.size(); ++i) {
    if (u[i] == '%' && i + 2 < u.size() && std::isxdigit(static_cast<unsigned char>(u[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(u[i + 2]))) {
      out += char(std::stoi(u.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      out += u[i];
    }
  }
  return out;
}

void read_materials(Ctx& ctx, SceneAppearance& app) {
  const auto& model = ctx.model;
  app.copyright = model.asset.copyright;
  for (size_t i = 0; i < model.images.size(); ++i) {
    const auto& im = model.images[i];
    AppearanceImage out;
    out.name = im.name;
    out.mime_type = image_mime(im);
    if (im.bufferView >= 0) {
      Bytes b = view_bytes(ctx, im.bufferView, "image " + std::to_string(i));
      out.bytes.assign(reinterpret_cast<const char*>(b.data), b.size);
    } else if (im.uri.rfind("data:", 0) == 0) {
      std::vector<unsigned char> data;
      std::string mime;
      if (tinygltf::DecodeDataURI(&data, mime, im.uri, 0, false))
        out.bytes.assign(data.begin(), data.end());
      if (out.mime_type.empty()) out.mime_type = mime;
    } else if (!im.uri.empty()) {
      out.uri = im.uri;
      std::filesystem::path f =
          std::filesystem::path(ctx.path).parent_path() / percent_decode(im.uri);
      try {
        out.bytes = read_file(f.string());
      } catch (const std::exception&) {
        ctx.warnings->push_back(ctx.path + ": image " + std::to_string(i) + ": cannot read " +
                                f.string());
      }
    }
    app.images.push_back(std::move(out));
  }
  for (const auto& m : model.materials) {
    AppearanceMaterial out;
    out.name = m.name;
    const auto& pbr = m.pbrMetallicRoughness;
    for (int c = 0; c < 4 && c < int(pbr.baseColorFactor.size()); ++c)
      out.base_color[c] = pbr.baseColorFactor[c];
    int tex = pbr.baseColorTexture.index;
    if (tex >= 0 && size_t(tex) < model.textures.size()) {
      int src = model.textures[size_t(tex)].source;
      if (src >= 0 && size_t(src) < model.images.size()) out.base_color_image = src;
    }
    out.base_color_texcoord = uint32_t(std::max(0, pbr.baseColorTexture.texCoord));
    if (out.base_color_texcoord != 0) out.base_color_image = -1;  // only TEXCOORD_0 is kept
    out.metallic = pbr.metallicFactor;
    out.roughness = pbr.roughnessFactor;
    for (int c = 0; c < 3 && c < int(m.emissiveFactor.size()); ++c)
      out.emissive[c] = m.emissiveFactor[c];
    if (!m.alphaMode.empty()) out.alpha_mode = m.alphaMode;
    out.alpha_cutoff = m.alphaCutoff;
    out.double_sided = m.doubleSided;
    app.materials.push_back(std::move(out));
  }
}

}  // namespace

SceneAppearance load_appearance(const std::string& path, const LoadOptions& options,
                                std::vector<std::string>* warnings) {
  std::vector<std::string> local;
  SceneAppearance app;
  std::string ext = file_extension(path);
  if (ext == ".gltf" || ext == ".glb") load_gltf(path, options, warnings ? *warnings : local, &app);
  return app;
}

Scene load_gltf(const std::string& path, const LoadOptions& options,
                std::vector<std::string>& warnings, SceneAppearance* appearance) {
  Ctx ctx;
  ctx.path = path;
  ctx.warnings = &warnings;
  parse_file(ctx);
  check_extensions(ctx);
  const auto& model = ctx.model;
  const size_t N = model.nodes.size();

  // Rest-pose TRS of every node, and the hierarchy (validated: indices, single parent, no cycle).
  std::vector<Trs> rest(N);
  std::vector<int> parent(N, -1);
  for (size_t n = 0; n < N; ++n) {
    const auto& nd = model.nodes[n];
    std::string who = "node " + std::to_string(n);
    if (nd.matrix.size() == 16) {
      rest[n].has_matrix = true;
      std::copy(nd.matrix.begin(), nd.matrix.end(), rest[n].matrix.m);
    } else if (!nd.matrix.empty()) {
      ctx.fail(who + ": matrix must have 16 numbers");
    }
    if (!nd.translation.empty() && nd.translation.size() != 3) ctx.fail(who + ": bad translation");
    if (!nd.rotation.empty() && nd.rotation.size() != 4) ctx.fail(who + ": bad rotation");
    if (!nd.scale.empty() && nd.scale.size() != 3) ctx.fail(who + ": bad scale");
    std::copy(nd.translation.begin(), nd.translation.end(), rest[n].t);
    std::copy(nd.rotation.begin(), nd.rotation.end(), rest[n].r);
    std::copy(nd.scale.begin(), nd.scale.end(), rest[n].s);
    if (nd.mesh >= int(model.meshes.size()))
      ctx.fail(who + ": mesh " + std::to_string(nd.mesh) + " does not exist");
    if (nd.skin >= int(model.skins.size()))
      ctx.fail(who + ": skin " + std::to_string(nd.skin) + " does not exist");
    for (int c : nd.children) {
      if (c < 0 || size_t(c) >= N)
        ctx.fail(who + ": child " + std::to_string(c) + " does not exist");
      if (parent[c] != -1 || size_t(c) == n)
        ctx.fail("node " + std::to_string(c) + " has more than one parent (or is its own child)");
      parent[c] = int(n);
    }
  }
  // Morph target count of each mesh (every primitive must have the same, glTF 2.0 §3.7.2.2) and
  // the default weights of each node: node `weights`, else mesh `weights`, else zeros.
  std::vector<size_t> mesh_targets(model.meshes.size(), 0);
  for (size_t m = 0; m < model.meshes.size(); ++m) {
    const auto& mesh = model.meshes[m];
    if (!mesh.primitives.empty()) mesh_targets[m] = mesh.primitives[0].targets.size();
    for (size_t pi = 1; pi < mesh.primitives.size(); ++pi)
      if (mesh.primitives[pi].targets.size() != mesh_targets[m])
        ctx.fail("mesh " + std::to_string(m) + ": primitive " + std::to_string(pi) + " has " +
                 std::to_string(mesh.primitives[pi].targets.size()) +
                 " morph targets, primitive 0 has " + std::to_string(mesh_targets[m]));
    if (!mesh.weights.empty() && mesh.weights.size() != mesh_targets[m])
      ctx.fail("mesh " + std::to_string(m) + ": weights has " +
               std::to_string(mesh.weights.size()) + " numbers, but the mesh has " +
               std::to_string(mesh_targets[m]) + " morph targets");
  }
  std::vector<size_t> node_targets(N, 0);
  std::vector<std::vector<double>> rest_weights(N);
  for (size_t n = 0; n < N; ++n) {
    const auto& nd = model.nodes[n];
    if (nd.mesh >= 0) node_targets[n] = mesh_targets[size_t(nd.mesh)];
    if (!nd.weights.empty() && nd.weights.size() != node_targets[n])
      ctx.fail("node " + std::to_string(n) + ": weights has " + std::to_string(nd.weights.size()) +
               " numbers, but its mesh has " + std::to_string(node_targets[n]) + " morph targets");
    if (!nd.weights.empty())
      rest_weights[n] = nd.weights;
    else if (nd.mesh >= 0 && !model.meshes[size_t(nd.mesh)].weights.empty())
      rest_weights[n] = model.meshes[size_t(nd.mesh)].weights;
    else
      rest_weights[n].assign(node_targets[n], 0.0);
    for (double w : rest_weights[n])
      if (!std::isfinite(w)) ctx.fail("node " + std::to_string(n) + ": non-finite morph weight");
  }
  for (size_t n = 0; n < N; ++n) {  // cycle check: walking up must end within N steps
    size_t steps = 0;
    for (int p = parent[n]; p != -1; p = parent[p])
      if (++steps > N) ctx.fail("node hierarchy has a cycle through node " + std::to_string(n));
  }
  std::vector<int> roots;
  if (!model.scenes.empty()) {
    int si = model.defaultScene >= 0 ? model.defaultScene : 0;
    if (size_t(si) >= model.scenes.size())
      ctx.fail("default scene " + std::to_string(si) + " does not exist");
    for (int r : model.scenes[si].nodes) {
      if (r < 0 || size_t(r) >= N)
        ctx.fail("scene " + std::to_string(si) + ": node " + std::to_string(r) + " does not exist");
      roots.push_back(r);
    }
  } else {
    for (size_t n = 0; n < N; ++n)
      if (parent[n] == -1) roots.push_back(int(n));
  }
  // Mesh instances in depth-first order.
  std::vector<int> instances;
  {
    std::vector<int> stack(roots.rbegin(), roots.rend());
    while (!stack.empty()) {
      int n = stack.back();
      stack.pop_back();
      if (model.nodes[n].mesh >= 0) instances.push_back(n);
      const auto& ch = model.nodes[n].children;
      for (auto it = ch.rbegin(); it != ch.rend(); ++it) stack.push_back(*it);
    }
  }

  // Animation channels and sample times.
  std::vector<Channel> channels;
  if (options.states > 1 || options.animation >= 0)
    channels = read_channels(ctx, options.animation, node_targets);
  double t_end = 0;
  for (const auto& c : channels)
    t_end = std::max(t_end, *std::max_element(c.times.begin(), c.times.end()));
  size_t K = options.states > 1 && !channels.empty() ? size_t(options.states) : 1;
  if (options.states <= 1 && !model.animations.empty())
    ctx.warnings->push_back(
        ctx.path + ": " + std::to_string(model.animations.size()) +
        " animation(s) ignored: loaded static, in the rest pose; sample them into key "
        "states with --states K (e.g. --states 9)");

  // World matrices and morph weights of all nodes in each state.
  std::vector<std::vector<Mat4>> world(K, std::vector<Mat4>(N));
  std::vector<std::vector<std::vector<double>>> morph_weights(K, rest_weights);
  for (size_t k = 0; k < K; ++k) {
    std::vector<Trs> local = rest;
    if (K > 1) {
      double t = t_end * double(k) / double(K - 1);
      for (const auto& c : channels) {
        if (c.path == 3) {
          sample(c, t, morph_weights[k][size_t(c.node)].data());
          continue;
        }
        if (local[c.node].has_matrix) continue;  // animated nodes must use TRS (glTF 2.0 §5.25)
        sample(c, t,
               c.path == 0   ? local[c.node].t
               : c.path == 1 ? local[c.node].r
                             : local[c.node].s);
      }
    }
    std::vector<char> done(N, 0);
    for (size_t n = 0; n < N; ++n) {
      std::vector<int> chain;
      for (int p = int(n); p != -1 && !done[p]; p = parent[p]) chain.push_back(p);
      for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
        int p = parent[*it];
        world[k][*it] = p == -1 ? to_matrix(local[*it]) : world[k][p] * to_matrix(local[*it]);
        done[*it] = 1;
      }
    }
  }

  if (appearance) {
    *appearance = SceneAppearance{};
    read_materials(ctx, *appearance);
  }
  Scene scene;
  scene.positions.resize(K);
  // Memory: the scene's arrays are reserved from the accessor counts (an upper bound: skipped
  // primitives are counted too), so they never grow by doubling; a decoded mesh is released after
  // its last instance.
  std::vector<size_t> uses(model.meshes.size(), 0);
  size_t vertex_bound = 0, triangle_bound = 0;
  for (int n : instances) {
    const auto& mesh = model.meshes[size_t(model.nodes[n].mesh)];
    ++uses[size_t(model.nodes[n].mesh)];
    for (const auto& prim : mesh.primitives) {
      auto count = [&](int acc) {
        return acc >= 0 && size_t(acc) < model.accessors.size() ? model.accessors[size_t(acc)].count
                                                                : size_t(0);
      };
      auto pos = prim.attributes.find("POSITION");
      size_t nv = pos == prim.attributes.end() ? 0 : count(pos->second);
      size_t ni = prim.indices >= 0 ? count(prim.indices) : nv;
      vertex_bound += nv;
      triangle_bound += prim.mode == 4 || prim.mode == -1  ? ni / 3
                        : prim.mode == 5 || prim.mode == 6 ? ni
                                                           : 0;
    }
  }
  if (vertex_bound < (size_t(1) << 32) && triangle_bound < (size_t(1) << 32)) {
    for (auto& state : scene.positions) state.reserve(vertex_bound);
    scene.triangles.reserve(triangle_bound);
    scene.triangle_object.reserve(triangle_bound);
  }
  std::vector<std::vector<Prim>> mesh_cache(model.meshes.size());
  std::vector<char> mesh_cached(model.meshes.size(), 0);
  for (int n : instances) {
    const auto& nd = model.nodes[n];
    bool skinned = nd.skin >= 0;
    if (!mesh_cached[nd.mesh]) {
      mesh_cache[nd.mesh] = decode_mesh(ctx, nd.mesh, skinned, appearance != nullptr);
      mesh_cached[nd.mesh] = 1;
    }
    // Released at the end of this iteration if this is the mesh's last instance.
    struct Release {
      std::vector<Prim>& prims;
      bool last;
      ~Release() {
        if (last) std::vector<Prim>().swap(prims);
      }
    } release{mesh_cache[nd.mesh], --uses[size_t(nd.mesh)] == 0};
    std::string name = !nd.name.empty()                      ? nd.name
                       : !model.meshes[nd.mesh].name.empty() ? model.meshes[nd.mesh].name
                                                             : "node" + std::to_string(n);
    uint32_t obj = uint32_t(scene.objects.size());
    scene.objects.push_back({name});
    scene.objects.back().see_through = see_through_mesh(model, nd.mesh);
    // Joint matrices per state (skinned nodes): world(joint) * inverseBind.
    std::vector<std::vector<Mat4>> joint_m;
    if (skinned) {
      const auto& skin = model.skins[nd.skin];
      std::vector<double> ibm;
      int nc;
      if (skin.inverseBindMatrices >= 0)
        ibm = read_accessor(ctx, skin.inverseBindMatrices,
                            "inverseBindMatrices of skin " + std::to_string(nd.skin), nc, {16});
      if (!ibm.empty() && ibm.size() < 16 * skin.joints.size())
        ctx.fail("skin " + std::to_string(nd.skin) + ": fewer inverse bind matrices than joints");
      joint_m.assign(K, std::vector<Mat4>(skin.joints.size()));
      for (size_t j = 0; j < skin.joints.size(); ++j) {
        int jn = skin.joints[j];
        if (jn < 0 || size_t(jn) >= N)
          ctx.fail("skin " + std::to_string(nd.skin) + ": joint node " + std::to_string(jn) +
                   " does not exist");
        Mat4 inv;
        if (!ibm.empty()) std::copy(ibm.begin() + 16 * j, ibm.begin() + 16 * (j + 1), inv.m);
        for (size_t k = 0; k < K; ++k) joint_m[k][j] = world[k][jn] * inv;
      }
    }
    std::vector<Vec3> morphed;
    for (const Prim& p : mesh_cache[nd.mesh]) {
      size_t base = scene.positions[0].size();
      if (base + p.local.size() >= UINT32_MAX) ctx.fail("too many vertices for 32-bit indices");
      for (size_t k = 0; k < K; ++k) {
        auto& out = scene.positions[k];
        // Morph first (base + sum_i w_i * target_i), then skin, then the node transform.
        const std::vector<Vec3>* local = &p.local;
        if (!p.targets.empty()) {
          const auto& w = morph_weights[k][size_t(n)];
          morphed = p.local;
          for (size_t ti = 0; ti < p.targets.size(); ++ti) {
            if (w[ti] == 0 || p.targets[ti].empty()) continue;
            for (size_t v = 0; v < morphed.size(); ++v)
              morphed[v] = morphed[v] + p.targets[ti][v] * w[ti];
          }
          local = &morphed;
        }
        for (size_t v = 0; v < p.local.size(); ++v) {
          const Vec3 lv = (*local)[v];
          if (!skinned || p.joints.empty()) {
            out.push_back(transform(world[k][n], lv));
            continue;
          }
          Vec3 acc{0, 0, 0};
          double wsum = 0;
          for (int c = 0; c < 4; ++c) {
            double w = p.weights[v][c];
            if (w == 0) continue;
            uint32_t j = p.joints[v][c];
            if (j >= joint_m[k].size())
              ctx.fail("mesh " + std::to_string(nd.mesh) + ": joint index " + std::to_string(j) +
                       " out of range of skin " + std::to_string(nd.skin));
            acc = acc + transform(joint_m[k][j], lv) * w;
            wsum += w;
          }
          out.push_back(wsum > 0 ? acc * (1.0 / wsum) : transform(world[k][n], lv));
        }
      }
      for (auto t : p.tris) {
        scene.triangles.push_back(
            {uint32_t(t[0] + base), uint32_t(t[1] + base), uint32_t(t[2] + base)});
        scene.triangle_object.push_back(obj);
      }
      if (appearance) {
        SceneAppearance& app = *appearance;
        for (size_t v = 0; v < p.local.size(); ++v) {
          Vec3 nrm{NAN, NAN, NAN};
          if (!p.normals.empty()) {
            if (!skinned || p.joints.empty()) {
              nrm = unit_or_nan(transform_normal(world[0][n], p.normals[v]));
            } else {
              // The weight blend of the joints' normal transforms; joints whose matrix is
              // singular (scaled to 0) are skipped, and the node transform is the fallback.
              Vec3 acc{0, 0, 0};
              for (int c = 0; c < 4; ++c) {
                if (p.weights[v][c] == 0 || p.joints[v][c] >= joint_m[0].size()) continue;
                Vec3 t = unit_or_nan(transform_normal(joint_m[0][p.joints[v][c]], p.normals[v]));
                if (is_finite(t)) acc = acc + t * p.weights[v][c];
              }
              nrm = unit_or_nan(acc);
              if (!is_finite(nrm)) nrm = unit_or_nan(transform_normal(world[0][n], p.normals[v]));
            }
          }
          app.normals.push_back(nrm);
          app.uvs.push_back(p.uvs.empty() ? std::array<double, 2>{NAN, NAN} : p.uvs[v]);
        }
        app.triangle_material.insert(app.triangle_material.end(), p.tris.size(), p.material);
      }
    }
  }
  return scene;
}

}  // namespace vislib
