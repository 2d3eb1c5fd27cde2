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
#include "vislib/scene/gltf_reader.h"
#include "vislib/scene/import_formats.h"

namespace vislib {

namespace {

using namespace gltf_reader;

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

// True when every fragment of `prim` drawn with `mat` (alphaMode MASK) passes the alpha test, so
// the cutout has no hole: the alpha is the base colour factor's, with no base-colour texture and
// no vertex colour (COLOR_0) of four components to lower it, and it is at least alphaCutoff.
bool mask_never_cuts(const tinygltf::Model& model, const tinygltf::Primitive& prim,
                     const tinygltf::Material& mat) {
  const auto& pbr = mat.pbrMetallicRoughness;
  if (pbr.baseColorTexture.index >= 0) return false;
  auto color = prim.attributes.find("COLOR_0");
  if (color != prim.attributes.end() &&
      (color->second < 0 || size_t(color->second) >= model.accessors.size() ||
       model.accessors[size_t(color->second)].type != TINYGLTF_TYPE_VEC3))
    return false;
  const double alpha = pbr.baseColorFactor.size() == 4 ? pbr.baseColorFactor[3] : 1.0;
  return alpha >= mat.alphaCutoff;
}

// The materials of mesh `m`'s triangle primitives that make its node's object see-through
// (docs/scene-model.md "See-through objects"), by name ("material N" when unnamed), each once, in
// primitive order: alphaMode BLEND, and MASK unless mask_never_cuts. One such primitive makes the
// whole object see-through, the direction that never hides what is behind it.
std::vector<std::string> see_through_materials(const tinygltf::Model& model, int m) {
  std::vector<std::string> names;
  for (const auto& prim : model.meshes[size_t(m)].primitives) {
    const bool triangles = prim.mode == 4 || prim.mode == 5 || prim.mode == 6 || prim.mode == -1;
    if (!triangles || prim.material < 0 || size_t(prim.material) >= model.materials.size())
      continue;
    const tinygltf::Material& mat = model.materials[size_t(prim.material)];
    if (mat.alphaMode != "BLEND" && (mat.alphaMode != "MASK" || mask_never_cuts(model, prim, mat)))
      continue;
    std::string name = mat.name.empty() ? "material " + std::to_string(prim.material) : mat.name;
    if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
  }
  return names;
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
    // tinygltf passes a data: URI's bytes to the image loader and keeps no URI: read it from the
    // document.
    std::string data_uri;
    if (im.bufferView < 0 && im.uri.empty() && ctx.doc.contains("images") &&
        ctx.doc["images"].is_array() && i < ctx.doc["images"].size() &&
        ctx.doc["images"][i].is_object())
      data_uri = ctx.doc["images"][i].value("uri", "");
    if (im.bufferView >= 0) {
      Bytes b = view_bytes(ctx, im.bufferView, "image " + std::to_string(i));
      out.bytes.assign(reinterpret_cast<const char*>(b.data), b.size);
    } else if (data_uri.rfind("data:", 0) == 0) {
      std::vector<unsigned char> data;
      std::string mime;
      if (tinygltf::DecodeDataURI(&data, mime, data_uri, 0, false))
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

// The node graph: every node's rest-pose TRS and its parent (-1 for none).
struct NodeGraph {
  std::vector<Trs> rest;
  std::vector<int> parent;
};

NodeGraph read_nodes(Ctx& ctx) {
  const auto& model = ctx.model;
  const size_t N = model.nodes.size();
  // Rest-pose TRS of every node, and the hierarchy (validated: indices, single parent, no cycle).
  NodeGraph g;
  std::vector<Trs>& rest = g.rest;
  std::vector<int>& parent = g.parent;
  rest.resize(N);
  parent.assign(N, -1);
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
  return g;
}

// The morph target count of each node's mesh (0 without a mesh) and each node's default weights.
struct MorphDefaults {
  std::vector<size_t> node_targets;
  std::vector<std::vector<double>> rest_weights;
};

MorphDefaults read_morph_defaults(Ctx& ctx) {
  const auto& model = ctx.model;
  const size_t N = model.nodes.size();
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
  MorphDefaults d;
  std::vector<size_t>& node_targets = d.node_targets;
  std::vector<std::vector<double>>& rest_weights = d.rest_weights;
  node_targets.assign(N, 0);
  rest_weights.resize(N);
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
  return d;
}

// The nodes with a mesh, in depth-first order from the roots of the scene shown.
std::vector<int> mesh_instances(Ctx& ctx, const std::vector<int>& parent) {
  const auto& model = ctx.model;
  const size_t N = model.nodes.size();
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
  return instances;
}

// The K states of the scene: world matrices and morph weights of every node in each.
struct Poses {
  size_t K = 1;
  std::vector<std::vector<Mat4>> world;
  std::vector<std::vector<std::vector<double>>> morph_weights;
};

Poses pose_states(Ctx& ctx, const LoadOptions& options, const NodeGraph& nodes,
                  const MorphDefaults& morph) {
  const auto& model = ctx.model;
  const size_t N = model.nodes.size();
  const std::vector<Trs>& rest = nodes.rest;
  const std::vector<int>& parent = nodes.parent;
  const std::vector<size_t>& node_targets = morph.node_targets;
  const std::vector<std::vector<double>>& rest_weights = morph.rest_weights;
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

  return {K, std::move(world), std::move(morph_weights)};
}

// Reserves the scene's arrays for `instances` and counts the instances of each mesh in `uses`.
void reserve_scene(const Ctx& ctx, const std::vector<int>& instances, Scene& scene,
                   std::vector<size_t>& uses) {
  const auto& model = ctx.model;
  // Memory: the scene's arrays are reserved from the accessor counts (an upper bound: skipped
  // primitives are counted too), so they never grow by doubling; a decoded mesh is released after
  // its last instance.
  uses.assign(model.meshes.size(), 0);
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
}

// Joint matrices per state of node `n`'s skin (none when the node is not skinned).
std::vector<std::vector<Mat4>> joint_matrices(Ctx& ctx, int n, const Poses& poses) {
  const auto& model = ctx.model;
  const size_t N = model.nodes.size();
  const auto& nd = model.nodes[size_t(n)];
  const bool skinned = nd.skin >= 0;
  const size_t K = poses.K;
  const auto& world = poses.world;
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
  return joint_m;
}

// Appends the vertices of primitive `p` of node `n` in every state to `scene.positions`.
// `morphed`: scratch space.
void append_positions(Ctx& ctx, const Prim& p, int n, const Poses& poses,
                      const std::vector<std::vector<Mat4>>& joint_m, Scene& scene,
                      std::vector<Vec3>& morphed) {
  const auto& nd = ctx.model.nodes[size_t(n)];
  const bool skinned = nd.skin >= 0;
  const size_t K = poses.K;
  const auto& world = poses.world;
  const auto& morph_weights = poses.morph_weights;
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
}

// Appends the normals, texture coordinates and materials of primitive `p` of a node whose key
// state 0 world matrix is `node_world` to `app`.
void append_appearance(const Prim& p, bool skinned, const Mat4& node_world,
                       const std::vector<std::vector<Mat4>>& joint_m, SceneAppearance& app) {
  for (size_t v = 0; v < p.local.size(); ++v) {
    Vec3 nrm{NAN, NAN, NAN};
    if (!p.normals.empty()) {
      if (!skinned || p.joints.empty()) {
        nrm = unit_or_nan(transform_normal(node_world, p.normals[v]));
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
        if (!is_finite(nrm)) nrm = unit_or_nan(transform_normal(node_world, p.normals[v]));
      }
    }
    app.normals.push_back(nrm);
    app.uvs.push_back(p.uvs.empty() ? std::array<double, 2>{NAN, NAN} : p.uvs[v]);
  }
  app.triangle_material.insert(app.triangle_material.end(), p.tris.size(), p.material);
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

  const NodeGraph nodes = read_nodes(ctx);
  const MorphDefaults morph = read_morph_defaults(ctx);
  const std::vector<int> instances = mesh_instances(ctx, nodes.parent);
  const Poses poses = pose_states(ctx, options, nodes, morph);
  const size_t K = poses.K;

  if (appearance) {
    *appearance = SceneAppearance{};
    read_materials(ctx, *appearance);
  }
  Scene scene;
  scene.positions.resize(K);
  std::vector<size_t> uses;
  reserve_scene(ctx, instances, scene, uses);
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
    scene.objects.back().alpha_materials = see_through_materials(model, nd.mesh);
    scene.objects.back().see_through = !scene.objects.back().alpha_materials.empty();
    const std::vector<std::vector<Mat4>> joint_m = joint_matrices(ctx, n, poses);
    std::vector<Vec3> morphed;
    for (const Prim& p : mesh_cache[nd.mesh]) {
      size_t base = scene.positions[0].size();
      if (base + p.local.size() >= UINT32_MAX) ctx.fail("too many vertices for 32-bit indices");
      append_positions(ctx, p, n, poses, joint_m, scene, morphed);
      for (auto t : p.tris) {
        scene.triangles.push_back(
            {uint32_t(t[0] + base), uint32_t(t[1] + base), uint32_t(t[2] + base)});
        scene.triangle_object.push_back(obj);
      }
      if (appearance) {
        append_appearance(p, skinned, poses.world[0][size_t(n)], joint_m, *appearance);
      }
    }
  }
  return scene;
}

}  // namespace vislib
