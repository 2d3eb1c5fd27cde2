// import_test_files.h: tiny glTF/GLB/text files written on the fly for the import tests.
#pragma once

#include <cstdint>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

namespace vislib_test {

inline std::string write_text(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

inline std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

inline std::string base64(const std::string& in) {
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    uint32_t v =
        uint32_t(uint8_t(in[i])) << 16 | uint32_t(uint8_t(in[i + 1])) << 8 | uint8_t(in[i + 2]);
    for (int s = 18; s >= 0; s -= 6) out += t[(v >> s) & 63];
  }
  if (i < in.size()) {
    uint32_t v = uint32_t(uint8_t(in[i])) << 16 |
                 (i + 1 < in.size() ? uint32_t(uint8_t(in[i + 1])) << 8 : 0);
    out += t[(v >> 18) & 63];
    out += t[(v >> 12) & 63];
    out += i + 1 < in.size() ? t[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

// One mesh ("mesh0") with one primitive: POSITION = accessor 0 (float VEC3, bufferView 0),
// indices = accessor 1 (uint32, bufferView 1) unless `indices` is empty. The knobs after `glb`
// break the file on purpose.
struct GltfSpec {
  std::vector<float> positions;
  std::vector<uint32_t> indices;
  int mode = 4;
  nlohmann::json nodes = nlohmann::json::array({{{"mesh", 0}}});
  std::vector<int> scene_nodes = {0};
  std::vector<std::string> extensions_required;
  bool glb = false;
  int position_accessor = 0;
  size_t view_length_extra = 0;
  int position_component_type = 5126;
  size_t position_count_override = 0;
  std::string alpha_mode;           // non-empty: the primitive uses material 0 with this alphaMode
  bool base_color_texture = false;  // material 0 has a base-colour texture (an image not loaded)
};

inline std::string write_gltf(const std::string& path, const GltfSpec& g) {
  using json = nlohmann::json;
  std::string bin(reinterpret_cast<const char*>(g.positions.data()), g.positions.size() * 4);
  size_t pos_bytes = bin.size();
  bin.append(reinterpret_cast<const char*>(g.indices.data()), g.indices.size() * 4);
  json doc;
  doc["asset"] = {{"version", "2.0"}};
  json buffer = {{"byteLength", bin.size()}};
  if (!g.glb) buffer["uri"] = "data:application/octet-stream;base64," + base64(bin);
  doc["buffers"] = json::array({buffer});
  doc["bufferViews"] = json::array(
      {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", pos_bytes + g.view_length_extra}}});
  doc["accessors"] = json::array(
      {{{"bufferView", 0},
        {"componentType", g.position_component_type},
        {"count", g.position_count_override ? g.position_count_override : g.positions.size() / 3},
        {"type", "VEC3"}}});
  json prim = {{"attributes", {{"POSITION", g.position_accessor}}}, {"mode", g.mode}};
  if (!g.indices.empty()) {
    doc["bufferViews"].push_back(
        {{"buffer", 0}, {"byteOffset", pos_bytes}, {"byteLength", g.indices.size() * 4}});
    doc["accessors"].push_back({{"bufferView", 1},
                                {"componentType", 5125},
                                {"count", g.indices.size()},
                                {"type", "SCALAR"}});
    prim["indices"] = 1;
  }
  if (!g.alpha_mode.empty()) {
    doc["materials"] = json::array({{{"name", "mat0"}, {"alphaMode", g.alpha_mode}}});
    prim["material"] = 0;
    if (g.base_color_texture) {
      doc["materials"][0]["pbrMetallicRoughness"] = {{"baseColorTexture", {{"index", 0}}}};
      doc["textures"] = json::array({{{"source", 0}}});
      doc["images"] = json::array({{{"uri", "data:image/png;base64,AAAA"}}});
    }
  }
  doc["meshes"] = json::array({{{"name", "mesh0"}, {"primitives", json::array({prim})}}});
  doc["nodes"] = g.nodes;
  doc["scenes"] = json::array({{{"nodes", g.scene_nodes}}});
  doc["scene"] = 0;
  if (!g.extensions_required.empty()) {
    doc["extensionsRequired"] = g.extensions_required;
    doc["extensionsUsed"] = g.extensions_required;
  }
  std::string text = doc.dump();
  if (!g.glb) return write_text(path, text);
  while (text.size() % 4) text += ' ';
  while (bin.size() % 4) bin += '\0';
  std::string out;
  auto put = [&](uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
  put(0x46546C67u);
  put(2);
  put(uint32_t(12 + 8 + text.size() + 8 + bin.size()));
  put(uint32_t(text.size()));
  put(0x4E4F534Au);
  out += text;
  put(uint32_t(bin.size()));
  put(0x004E4942u);
  out += bin;
  return write_text(path, out);
}

}  // namespace vislib_test
