// write_gltf.cpp: GLB writer through tinygltf (glTF 2.0; section 4.4 "Binary glTF layout" is
// tinygltf's). Builds a tinygltf::Model: one node + mesh per object, a primitive per run of
// triangles of one material, positions (and morph targets), normals, UVs, materials with their
// base colour textures embedded in the BIN chunk, and the source's asset.copyright.
#include "vislib/scene/write_gltf.h"

#include <tiny_gltf.h>

#include <cassert>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace vislib {

namespace {

constexpr int kArrayBuffer = TINYGLTF_TARGET_ARRAY_BUFFER;
constexpr int kElementArrayBuffer = TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER;

// A run of triangles of one object with one material, re-indexed over the vertices it uses.
struct Primitive {
  std::vector<uint32_t> indices;   // local vertex ids, 3 per triangle
  std::vector<uint32_t> vertices;  // local -> scene vertex id
  int32_t material = -1;
  bool normals = false, uvs = false;
};

struct ObjectMesh {
  std::vector<Primitive> prims;
  bool dynamic = false;
};

struct Writer {
  tinygltf::Model model;
  std::vector<unsigned char>& bin;
  explicit Writer(std::vector<unsigned char>& b) : bin(b) {}

  int add_view(const void* data, size_t bytes, int target) {
    while (bin.size() % 4) bin.push_back(0);
    tinygltf::BufferView v;
    v.buffer = 0;
    v.byteOffset = bin.size();
    v.byteLength = bytes;
    if (target) v.target = target;
    const auto* p = static_cast<const unsigned char*>(data);
    bin.insert(bin.end(), p, p + bytes);
    model.bufferViews.push_back(v);
    return int(model.bufferViews.size() - 1);
  }
  int add_accessor(int view, int component, size_t count, int type) {
    tinygltf::Accessor a;
    a.bufferView = view;
    a.componentType = component;
    a.count = count;
    a.type = type;
    model.accessors.push_back(a);
    return int(model.accessors.size() - 1);
  }
  // Float VEC3/VEC2 data with min/max when `bounds`.
  int add_floats(const std::vector<float>& f, int ncomp, bool bounds) {
    int view = add_view(f.data(), 4 * f.size(), kArrayBuffer);
    int a = add_accessor(view, TINYGLTF_COMPONENT_TYPE_FLOAT, f.size() / ncomp,
                         ncomp == 3 ? TINYGLTF_TYPE_VEC3 : TINYGLTF_TYPE_VEC2);
    if (bounds) {
      std::vector<double> lo(ncomp, std::numeric_limits<float>::max()),
          hi(ncomp, -std::numeric_limits<float>::max());
      for (size_t i = 0; i < f.size(); ++i) {
        lo[i % ncomp] = std::min(lo[i % ncomp], double(f[i]));
        hi[i % ncomp] = std::max(hi[i % ncomp], double(f[i]));
      }
      model.accessors[a].minValues = lo;
      model.accessors[a].maxValues = hi;
    }
    return a;
  }
};

bool finite3(const Vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// The meshes of the objects of `scene` (see scene_to_glb).
std::vector<ObjectMesh> object_meshes(const Scene& scene, const SceneAppearance* app, size_t K) {
  const size_t nobj = scene.objects.size();
  const bool has_normals = app && app->normals.size() == scene.vertex_count();
  const bool has_uvs = app && app->uvs.size() == scene.vertex_count();
  const bool has_materials = app && app->triangle_material.size() == scene.triangle_count();
  // Bucket triangles by object (stable: id order within an object), split into runs of one
  // material, re-index each run over the vertices it uses (numbered by first use).
  std::vector<std::vector<uint32_t>> by_object(nobj);
  for (uint32_t t = 0; t < scene.triangle_count(); ++t) {
    assert(scene.triangle_object[t] < nobj);
    by_object[scene.triangle_object[t]].push_back(t);
  }
  std::vector<ObjectMesh> meshes(nobj);
  std::vector<uint32_t> local(scene.vertex_count(), UINT32_MAX);
  for (size_t o = 0; o < nobj; ++o) {
    ObjectMesh& m = meshes[o];
    for (uint32_t t : by_object[o]) {
      int32_t mat = has_materials ? app->triangle_material[t] : -1;
      if (mat >= int32_t(app ? app->materials.size() : 0)) mat = -1;
      if (m.prims.empty() || m.prims.back().material != mat) {
        for (uint32_t v : m.prims.empty() ? std::vector<uint32_t>{} : m.prims.back().vertices)
          local[v] = UINT32_MAX;
        m.prims.emplace_back();
        m.prims.back().material = mat;
      }
      Primitive& p = m.prims.back();
      for (uint32_t v : scene.triangles[t]) {
        assert(v < scene.vertex_count());
        if (local[v] == UINT32_MAX) {
          local[v] = uint32_t(p.vertices.size());
          p.vertices.push_back(v);
        }
        p.indices.push_back(local[v]);
      }
    }
    for (Primitive& p : m.prims) {
      for (uint32_t v : p.vertices) {
        local[v] = UINT32_MAX;
        for (size_t k = 1; k < K && !m.dynamic; ++k)
          if (scene.positions[k][v] != scene.positions[0][v]) m.dynamic = true;
      }
      p.normals = has_normals;
      p.uvs = has_uvs;
      for (uint32_t v : p.vertices) {
        p.normals = p.normals && finite3(app->normals[v]);
        p.uvs = p.uvs && std::isfinite(app->uvs[v][0]) && std::isfinite(app->uvs[v][1]);
      }
    }
  }
  return meshes;
}

// Writes the materials of `app` that `meshes` use; returns the glTF index of each (-1: unused).
std::vector<int> write_materials(Writer& w, const std::vector<ObjectMesh>& meshes,
                                 const SceneAppearance* app) {
  tinygltf::Model& model = w.model;
  // Materials and their images (embedded), only those some kept triangle uses, in index order.
  std::vector<int> material_id(app ? app->materials.size() : 0, -1);
  for (const auto& m : meshes)
    for (const auto& p : m.prims)
      if (p.material >= 0) material_id[size_t(p.material)] = 0;
  std::vector<int> texture_of_image(app ? app->images.size() : 0, -1);
  for (size_t i = 0; i < material_id.size(); ++i) {
    if (material_id[i] < 0) continue;
    const AppearanceMaterial& am = app->materials[i];
    tinygltf::Material mat;
    mat.name = am.name;
    mat.pbrMetallicRoughness.baseColorFactor.assign(am.base_color.begin(), am.base_color.end());
    mat.pbrMetallicRoughness.metallicFactor = am.metallic;
    mat.pbrMetallicRoughness.roughnessFactor = am.roughness;
    mat.emissiveFactor.assign(am.emissive.begin(), am.emissive.end());
    mat.alphaMode = am.alpha_mode;
    mat.alphaCutoff = am.alpha_cutoff;
    mat.doubleSided = am.double_sided;
    const int im = am.base_color_image;
    if (im >= 0 && size_t(im) < app->images.size()) {
      const AppearanceImage& ai = app->images[size_t(im)];
      const bool embed =
          !ai.bytes.empty() && (ai.mime_type == "image/png" || ai.mime_type == "image/jpeg");
      if (texture_of_image[size_t(im)] < 0 && (embed || !ai.uri.empty())) {
        tinygltf::Image img;
        img.name = ai.name;
        if (embed) {
          img.bufferView = w.add_view(ai.bytes.data(), ai.bytes.size(), 0);
          img.mimeType = ai.mime_type;
        } else {
          img.uri = ai.uri;  // a reference to the source's file, as written there
        }
        model.images.push_back(img);
        if (model.samplers.empty()) model.samplers.emplace_back();  // defaults: repeat, auto filter
        tinygltf::Texture tex;
        tex.source = int(model.images.size() - 1);
        tex.sampler = 0;
        model.textures.push_back(tex);
        texture_of_image[size_t(im)] = int(model.textures.size() - 1);
      }
      if (texture_of_image[size_t(im)] >= 0) {
        mat.pbrMetallicRoughness.baseColorTexture.index = texture_of_image[size_t(im)];
        mat.pbrMetallicRoughness.baseColorTexture.texCoord = 0;
      }
    }
    material_id[i] = int(model.materials.size());
    model.materials.push_back(mat);
  }
  return material_id;
}

// The key times and morph weights of the "states" animation (key state k at time k, its morph
// target k - 1 at weight 1): their accessors.
struct StateKeys {
  int time_accessor = -1, weight_accessor = -1;
};
StateKeys write_state_keys(Writer& w, size_t K) {
  tinygltf::Model& model = w.model;
  StateKeys keys;
  int& time_accessor = keys.time_accessor;
  int& weight_accessor = keys.weight_accessor;
  std::vector<float> times(K), weights(K * (K - 1), 0.0f);
  for (size_t k = 0; k < K; ++k) {
    times[k] = float(k);
    if (k > 0) weights[k * (K - 1) + (k - 1)] = 1.0f;
  }
  time_accessor = w.add_accessor(w.add_view(times.data(), 4 * K, 0), TINYGLTF_COMPONENT_TYPE_FLOAT,
                                 K, TINYGLTF_TYPE_SCALAR);
  model.accessors[time_accessor].minValues = {0.0};
  model.accessors[time_accessor].maxValues = {double(K - 1)};
  weight_accessor =
      w.add_accessor(w.add_view(weights.data(), 4 * weights.size(), 0),
                     TINYGLTF_COMPONENT_TYPE_FLOAT, weights.size(), TINYGLTF_TYPE_SCALAR);
  return keys;
}

// The primitive `p` of an object (morph targets when `dynamic`).
tinygltf::Primitive write_primitive(Writer& w, const Scene& scene, const SceneAppearance* app,
                                    const Primitive& p, bool dynamic, size_t K,
                                    const std::vector<int>& material_id) {
  tinygltf::Primitive prim;
  prim.mode = TINYGLTF_MODE_TRIANGLES;
  prim.indices =
      w.add_accessor(w.add_view(p.indices.data(), 4 * p.indices.size(), kElementArrayBuffer),
                     TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, p.indices.size(), TINYGLTF_TYPE_SCALAR);
  std::vector<float> f;
  f.reserve(3 * p.vertices.size());
  for (size_t k = 0; k < (dynamic ? K : 1); ++k) {
    f.clear();
    for (uint32_t v : p.vertices) {
      Vec3 q = k == 0 ? scene.positions[0][v] : scene.positions[k][v] - scene.positions[0][v];
      f.insert(f.end(), {float(q.x), float(q.y), float(q.z)});
    }
    int a = w.add_floats(f, 3, true);
    if (k == 0)
      prim.attributes["POSITION"] = a;
    else
      prim.targets.push_back({{"POSITION", a}});
  }
  if (p.normals) {
    f.clear();
    for (uint32_t v : p.vertices) {
      // Unit length in float too (the validator checks |n| = 1 within 5e-4).
      const Vec3& n = app->normals[v];
      f.insert(f.end(), {float(n.x), float(n.y), float(n.z)});
    }
    prim.attributes["NORMAL"] = w.add_floats(f, 3, false);
  }
  if (p.uvs) {
    f.clear();
    for (uint32_t v : p.vertices) f.insert(f.end(), {float(app->uvs[v][0]), float(app->uvs[v][1])});
    prim.attributes["TEXCOORD_0"] = w.add_floats(f, 2, false);
  }
  if (p.material >= 0) prim.material = material_id[size_t(p.material)];
  return prim;
}

// The GLB bytes of `model` with the binary chunk `bin`.
std::string glb_bytes(tinygltf::Model& model, std::vector<unsigned char>& bin) {
  while (bin.size() % 4) bin.push_back(0);
  if (!bin.empty()) {
    tinygltf::Buffer b;
    b.data = std::move(bin);
    model.buffers.push_back(std::move(b));
  }
  const uint64_t bin_size = model.buffers.empty() ? 0 : model.buffers[0].data.size();
  if (bin_size + (1u << 20) + 64 * model.accessors.size() > 0xFFFFFFFFull)
    throw std::runtime_error("scene too large for GLB: " + std::to_string(bin_size) +
                             " bytes of binary data come near the 4 GiB limit of the format");

  tinygltf::TinyGLTF writer;
  writer.SetImageWriter(nullptr,
                        nullptr);  // images are embedded bytes or kept URIs, never re-encoded
  std::ostringstream out;
  if (!writer.WriteGltfSceneToStream(&model, out, false, true))
    throw std::runtime_error("tinygltf could not write the GLB");
  return out.str();
}

}  // namespace

std::string scene_to_glb(const Scene& scene, const SceneAppearance* appearance) {
  const size_t K = scene.positions.size() ? scene.positions.size() : 1;
  const size_t nobj = scene.objects.size();
  assert(scene.triangle_object.size() == scene.triangles.size());
  const SceneAppearance* app = appearance;

  const std::vector<ObjectMesh> meshes = object_meshes(scene, app, K);

  std::vector<unsigned char> bin;
  Writer w(bin);
  tinygltf::Model& model = w.model;
  model.asset.version = "2.0";
  model.asset.generator = "vislib scene_to_glb";
  if (app) model.asset.copyright = app->copyright;

  // Materials and their images (embedded), only those some kept triangle uses, in index order.
  const std::vector<int> material_id = write_materials(w, meshes, app);

  bool animated = false;
  for (const auto& m : meshes) animated = animated || m.dynamic;
  tinygltf::Animation anim;
  anim.name = "states";
  StateKeys keys;
  if (animated) keys = write_state_keys(w, K);
  tinygltf::Scene root;
  for (size_t o = 0; o < nobj; ++o) {
    const ObjectMesh& m = meshes[o];
    tinygltf::Node node;
    node.name = scene.objects[o].name;
    if (!m.prims.empty()) {
      tinygltf::Mesh mesh;
      mesh.name = scene.objects[o].name;
      for (const Primitive& p : m.prims) {
        tinygltf::Primitive prim = write_primitive(w, scene, app, p, m.dynamic, K, material_id);
        mesh.primitives.push_back(prim);
      }
      if (m.dynamic) {
        mesh.weights.assign(K - 1, 0.0);
        tinygltf::AnimationSampler s;
        s.input = keys.time_accessor;
        s.output = keys.weight_accessor;
        s.interpolation = "LINEAR";
        anim.samplers.push_back(s);
        tinygltf::AnimationChannel c;
        c.sampler = int(anim.samplers.size() - 1);
        c.target_node = int(o);
        c.target_path = "weights";
        anim.channels.push_back(c);
      }
      node.mesh = int(model.meshes.size());
      model.meshes.push_back(mesh);
    }
    model.nodes.push_back(node);
    root.nodes.push_back(int(o));
  }
  model.scenes.push_back(root);
  model.defaultScene = 0;
  if (animated) model.animations.push_back(anim);
  return glb_bytes(model, bin);
}
}  // namespace vislib
