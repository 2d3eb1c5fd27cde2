// import_gltf_mesh.cpp: a glTF file's buffer views (EXT_meshopt_compression decoded), accessors
// (every range checked, sparse ones included) and meshes (gltf_reader.h).
#include <meshoptimizer.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "vislib/scene/appearance.h"
#include "vislib/scene/gltf_reader.h"

namespace vislib {
namespace gltf_reader {

namespace {

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
  // a larger claim is rejected before the output is allocated (a small file must not claim a huge
  // one).
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

}  // namespace

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

namespace {

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

}  // namespace

// All values of an accessor as doubles (count * ncomp), every range checked. `who` says what the
// accessor is for; `want` lists the allowed component counts (empty = any).
std::vector<double> read_accessor(Ctx& ctx, int index, const std::string& what, int& ncomp,
                                  std::initializer_list<int> want) {
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
  // Bound the count by the data before allocating: with a bufferView, the elements must
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

}  // namespace gltf_reader
}  // namespace vislib
