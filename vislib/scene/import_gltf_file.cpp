// import_gltf_file.cpp: a glTF file handed to tinygltf: the GLB container, meshopt fallback
// buffers, external resources kept inside the asset's folder, required extensions
// (gltf_reader.h).
#include <algorithm>
#include <cctype>
#include <cstring>
#include <filesystem>

#include "vislib/base/file_util.h"
#include "vislib/scene/gltf_reader.h"

namespace vislib {
namespace gltf_reader {

namespace {

bool image_loader_noop(tinygltf::Image*, const int, std::string*, std::string*, int, int,
                       const unsigned char*, int, void*) {
  return true;
}

uint32_t rd32(const std::string& b, size_t at) {
  uint32_t v;
  std::memcpy(&v, b.data() + at, 4);
  return v;
}

}  // namespace

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

namespace {

// --- External resources stay inside the asset's folder ------------------------------------------
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

}  // namespace

// Parses the container, rewrites meshopt fallback buffers and hands the file to tinygltf.
void parse_file(Ctx& ctx) {
  // Memory (a 200 MB .glb once peaked at 1.29 GB): the file is read once and the GLB handed to
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

}  // namespace gltf_reader
}  // namespace vislib
