// import_ply.cpp: the project's own PLY reader. OpenMesh's PLY reader crashed (signal
// 11) on a misspelt header, grew to 3.5 GB on a 75-byte file and threw std::bad_alloc on a header
// claiming 2*10^9 vertices; this one checks every header count against the bytes left in the file
// before it allocates, and reports the byte offset or line of what is wrong.
//
// Supported: `format ascii 1.0`, `binary_little_endian 1.0`, `binary_big_endian 1.0`; any elements
// in any order; scalar types char/int8 uchar/uint8 short/int16 ushort/uint16 int/int32 uint/uint32
// float/float32 double/float64; list properties. The `vertex` element must have scalar properties
// x, y, z (any type; other properties are skipped). The `face` element's list `vertex_indices` (or
// `vertex_index`) gives the polygons, fan-triangulated (v0,v1,v2), (v0,v2,v3), ... in file order,
// degenerate ones kept (counts match the file); faces with fewer than 3 vertices are skipped with a
// warning. Other elements (edges, materials, ...) are parsed and skipped. One object named after
// the file stem. `comment` and `obj_info` header lines are ignored.
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>

#include "vislib/base/error.h"
#include "vislib/base/file_util.h"
#include "vislib/scene/import_formats.h"
#include "vislib/scene/mesh_reader_support.h"

namespace vislib {

namespace {

enum class Type { I8, U8, I16, U16, I32, U32, F32, F64 };

bool type_of(const std::string& s, Type& t) {
  static const struct {
    const char* name;
    Type type;
  } names[] = {
      {"char", Type::I8},   {"int8", Type::I8},     {"uchar", Type::U8},   {"uint8", Type::U8},
      {"short", Type::I16}, {"int16", Type::I16},   {"ushort", Type::U16}, {"uint16", Type::U16},
      {"int", Type::I32},   {"int32", Type::I32},   {"uint", Type::U32},   {"uint32", Type::U32},
      {"float", Type::F32}, {"float32", Type::F32}, {"double", Type::F64}, {"float64", Type::F64}};
  for (const auto& n : names)
    if (s == n.name) {
      t = n.type;
      return true;
    }
  return false;
}

size_t size_of(Type t) {
  switch (t) {
    case Type::I8:
    case Type::U8:
      return 1;
    case Type::I16:
    case Type::U16:
      return 2;
    case Type::I32:
    case Type::U32:
    case Type::F32:
      return 4;
    case Type::F64:
      return 8;
  }
  return 1;
}

bool is_integer(Type t) {
  return t != Type::F32 && t != Type::F64;
}

struct Property {
  std::string name;
  bool list = false;
  Type count_type = Type::U8;  // list only
  Type type = Type::F32;       // scalar type, or the list's item type
};

struct Element {
  std::string name;
  uint64_t count = 0;
  std::vector<Property> props;
  size_t header_line = 0;
};

enum class Format { Ascii, BinaryLE, BinaryBE };

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    size_t j = i;
    while (j < line.size() && line[j] != ' ' && line[j] != '\t' && line[j] != '\r') ++j;
    if (j > i) out.push_back(line.substr(i, j - i));
    i = j;
  }
  return out;
}

// Strict unsigned decimal (digits only, no sign, fits 64 bits).
bool parse_count(const std::string& s, uint64_t& v) {
  if (s.empty() || s.size() > 19) return false;
  v = 0;
  for (char c : s) {
    if (c < '0' || c > '9') return false;
    v = v * 10 + uint64_t(c - '0');
  }
  return true;
}

// Reads the element data in one of the three encodings; positions and bounds checks in one place.
class Body {
 public:
  Body(const std::string& path, const std::string& bytes, size_t at, Format format, size_t line)
      : path_(path), b_(bytes), at_(at), format_(format), line_(line) {}

  size_t remaining() const { return b_.size() - at_; }

  // One value of type t, as double (integers exactly up to 2^53, which covers all PLY ints).
  double value(Type t, const std::string& what) {
    if (format_ == Format::Ascii) return ascii_value(t, what);
    size_t n = size_of(t);
    if (remaining() < n)
      fail_at(b_.size(),
              "truncated: " + what + " needs " + std::to_string(n) + " bytes, the file ends");
    unsigned char raw[8];
    std::memcpy(raw, b_.data() + at_, n);
    if (format_ == Format::BinaryBE)
      for (size_t i = 0; i < n / 2; ++i) std::swap(raw[i], raw[n - 1 - i]);
    at_ += n;
    switch (t) {
      case Type::I8:
        return double(int8_t(raw[0]));
      case Type::U8:
        return double(raw[0]);
      case Type::I16: {
        int16_t v;
        std::memcpy(&v, raw, 2);
        return v;
      }
      case Type::U16: {
        uint16_t v;
        std::memcpy(&v, raw, 2);
        return v;
      }
      case Type::I32: {
        int32_t v;
        std::memcpy(&v, raw, 4);
        return v;
      }
      case Type::U32: {
        uint32_t v;
        std::memcpy(&v, raw, 4);
        return v;
      }
      case Type::F32: {
        float v;
        std::memcpy(&v, raw, 4);
        return double(v);
      }
      case Type::F64: {
        double v;
        std::memcpy(&v, raw, 8);
        return v;
      }
    }
    return 0;
  }

  // Where the next value starts, for messages: "byte N" (binary) or "line N" (ascii).
  std::string where() const {
    return format_ == Format::Ascii ? "line " + std::to_string(line_)
                                    : "byte " + std::to_string(at_);
  }

  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(path_, where() + ": " + what);
  }

  // For ascii files: anything but whitespace after the last element is an error.
  void expect_end() {
    if (format_ == Format::Ascii) {
      skip_space();
      if (at_ < b_.size()) fail("unexpected data after the last element");
    } else if (at_ != b_.size()) {
      fail("unexpected " + std::to_string(b_.size() - at_) + " bytes after the last element");
    }
  }

 private:
  [[noreturn]] void fail_at(size_t byte, const std::string& what) const {
    throw InputError(path_, "byte " + std::to_string(byte) + ": " + what);
  }

  void skip_space() {
    while (at_ < b_.size()) {
      char c = b_[at_];
      if (c == '\n') {
        ++line_;
      } else if (c != ' ' && c != '\t' && c != '\r') {
        break;
      }
      ++at_;
    }
  }

  double ascii_value(Type t, const std::string& what) {
    skip_space();
    if (at_ >= b_.size()) fail("truncated: expected " + what + ", the file ends");
    size_t end = at_;
    while (end < b_.size() && !std::isspace(static_cast<unsigned char>(b_[end]))) ++end;
    std::string tok = b_.substr(at_, std::min<size_t>(end - at_, 64));
    if (end - at_ > 64) fail("'" + tok + "...' is not a number (" + what + ")");
    char* stop = nullptr;
    errno = 0;
    double v;
    if (is_integer(t)) {
      long long i = std::strtoll(tok.c_str(), &stop, 10);
      if (errno == ERANGE) fail("'" + tok + "' is out of range (" + what + ")");
      v = double(i);
    } else {
      v = std::strtod(tok.c_str(), &stop);
    }
    if (tok.empty() || stop != tok.c_str() + tok.size())
      fail("'" + tok + "' is not a number (" + what + ")");
    at_ = end;
    return v;
  }

  const std::string& path_;
  const std::string& b_;
  size_t at_;
  Format format_;
  size_t line_;
};

// The header of a PLY file: its format, its elements, where the body starts (byte and line).
struct Header {
  Format format = Format::Ascii;
  std::vector<Element> elements;
  size_t body_at = 0, lines = 0;
};

Header read_header(const std::string& path, const std::string& bytes) {
  // --- Header: lines up to "end_header". ---
  size_t at = 0, line_no = 0;
  auto next_line = [&](std::string& line) {
    if (at >= bytes.size()) return false;
    size_t end = bytes.find('\n', at);
    if (end == std::string::npos) end = bytes.size();
    line = bytes.substr(at, end - at);
    at = std::min(bytes.size(), end + 1);
    ++line_no;
    return true;
  };
  auto fail = [&](const std::string& what) {
    throw InputError(path, "line " + std::to_string(line_no) + ": " + what);
  };
  std::string line;
  if (!next_line(line) || split(line) != std::vector<std::string>{"ply"})
    throw InputError(path, "not a PLY file (the first line must be 'ply')");
  bool have_format = false, ended = false;
  Header h;
  Format& format = h.format;
  std::vector<Element>& elements = h.elements;
  while (next_line(line)) {
    std::vector<std::string> tok = split(line);
    if (tok.empty()) continue;
    const std::string& key = tok[0];
    if (key == "comment" || key == "obj_info") continue;
    if (key == "end_header") {
      ended = true;
      break;
    }
    if (key == "format") {
      if (have_format) fail("second 'format' line");
      if (tok.size() != 3)
        fail("expected 'format ascii|binary_little_endian|binary_big_endian 1.0'");
      if (tok[1] == "ascii")
        format = Format::Ascii;
      else if (tok[1] == "binary_little_endian")
        format = Format::BinaryLE;
      else if (tok[1] == "binary_big_endian")
        format = Format::BinaryBE;
      else
        fail("unknown format '" + tok[1] + "' (ascii, binary_little_endian or binary_big_endian)");
      if (tok[2] != "1.0") fail("unsupported PLY version '" + tok[2] + "' (this reader knows 1.0)");
      have_format = true;
    } else if (key == "element") {
      if (!have_format) fail("'element' before the 'format' line");
      uint64_t count = 0;
      if (tok.size() != 3 || !parse_count(tok[2], count))
        fail("expected 'element NAME COUNT' with a non-negative integer COUNT");
      if (elements.size() >= 1024) fail("more than 1024 elements");
      elements.push_back({tok[1], count, {}, line_no});
    } else if (key == "property") {
      if (elements.empty()) fail("'property' before any 'element'");
      Property p;
      if (tok.size() == 5 && tok[1] == "list") {
        p.list = true;
        if (!type_of(tok[2], p.count_type) || !is_integer(p.count_type))
          fail("list count type '" + tok[2] + "' is not an integer type");
        if (!type_of(tok[3], p.type)) fail("unknown property type '" + tok[3] + "'");
        p.name = tok[4];
      } else if (tok.size() == 3) {
        if (!type_of(tok[1], p.type)) fail("unknown property type '" + tok[1] + "'");
        p.name = tok[2];
      } else {
        fail("expected 'property TYPE NAME' or 'property list COUNT_TYPE TYPE NAME'");
      }
      if (elements.back().props.size() >= 1024) fail("more than 1024 properties in one element");
      elements.back().props.push_back(p);
    } else {
      fail("unknown header keyword '" + key.substr(0, 64) + "'");
    }
  }
  if (!have_format) throw InputError(path, "no 'format' line in the header");
  if (!ended) throw InputError(path, "the header has no 'end_header' line");
  h.body_at = at;
  h.lines = line_no;
  return h;
}

// Which element holds the vertices (with the property index of x, y, z) and which the faces
// (with the index of its vertex list); none when absent.
struct Roles {
  const Element* vertex_el = nullptr;
  const Element* face_el = nullptr;
  int xyz[3] = {-1, -1, -1};
  int face_list = -1;
};

Roles element_roles(const std::string& path, const Header& h, uint64_t body_bytes) {
  const Format format = h.format;
  const std::vector<Element>& elements = h.elements;
  Roles r;
  const Element*& vertex_el = r.vertex_el;
  const Element*& face_el = r.face_el;
  int(&xyz)[3] = r.xyz;
  int& face_list = r.face_list;
  // --- Which element is what, and whether the declared counts can fit in the file. ---
  uint64_t min_total = 0;
  for (const Element& e : elements) {
    for (size_t i = 0; i < e.props.size(); ++i)
      for (size_t j = 0; j < i; ++j)
        if (e.props[i].name == e.props[j].name)
          throw InputError(path, "line " + std::to_string(e.header_line) + ": element '" + e.name +
                                     "' has two properties named '" + e.props[i].name + "'");
    // Smallest encoding of one instance: binary, its scalar sizes and list counts; ascii, one
    // character and one separator per value.
    uint64_t min_bytes = 0;
    for (const Property& p : e.props)
      min_bytes += format == Format::Ascii ? 2 : size_of(p.list ? p.count_type : p.type);
    if (e.props.empty() && e.count > 0)
      throw InputError(path, "line " + std::to_string(e.header_line) + ": element '" + e.name +
                                 "' has " + std::to_string(e.count) +
                                 " instances but no properties");
    mesh_reader::check_count_fits(path, "element '" + e.name + "' count", e.count,
                                  std::max<uint64_t>(1, min_bytes), body_bytes);
    if (e.count > 0) {
      uint64_t need = e.count * min_bytes;
      if (need > body_bytes - std::min(min_total, body_bytes))
        throw InputError(path, "the elements declared in the header need at least " +
                                   std::to_string(min_total + need) + " bytes, but the file has " +
                                   std::to_string(body_bytes) + " after the header");
      min_total += need;
    }
    if (e.name == "vertex") {
      if (vertex_el) throw InputError(path, "two 'vertex' elements");
      vertex_el = &e;
      for (size_t i = 0; i < e.props.size(); ++i)
        for (int k = 0; k < 3; ++k)
          if (e.props[i].name == std::string(1, char('x' + k))) {
            if (e.props[i].list)
              throw InputError(
                  path, "vertex property '" + e.props[i].name + "' is a list, expected a number");
            xyz[k] = int(i);
          }
      for (int k = 0; k < 3; ++k)
        if (xyz[k] < 0 && e.count > 0)
          throw InputError(
              path, "the vertex element has no property '" + std::string(1, char('x' + k)) + "'");
    } else if (e.name == "face") {
      if (face_el) throw InputError(path, "two 'face' elements");
      face_el = &e;
      for (size_t i = 0; i < e.props.size(); ++i)
        if (e.props[i].list &&
            (e.props[i].name == "vertex_indices" || e.props[i].name == "vertex_index")) {
          if (!is_integer(e.props[i].type))
            throw InputError(path, "face list '" + e.props[i].name + "' has a non-integer type");
          face_list = int(i);
        }
      if (face_list < 0 && e.count > 0)
        throw InputError(path, "the face element has no list property 'vertex_indices'");
    }
  }
  return r;
}

}  // namespace

Scene load_ply(const std::string& path, std::vector<std::string>& warnings) {
  const std::string bytes = read_file(path);
  const Header header = read_header(path, bytes);
  const Format format = header.format;
  const std::vector<Element>& elements = header.elements;
  const size_t at = header.body_at, line_no = header.lines;
  const Roles roles = element_roles(path, header, bytes.size() - at);
  const Element* vertex_el = roles.vertex_el;
  const Element* face_el = roles.face_el;
  const int* xyz = roles.xyz;
  const int face_list = roles.face_list;
  uint64_t nv = vertex_el ? vertex_el->count : 0;
  if (nv >= UINT32_MAX) throw InputError(path, "more than 2^32-2 vertices");

  // --- Body. ---
  Scene scene = mesh_reader::one_object_scene(path);
  auto& pos = scene.positions[0];
  pos.reserve(size_t(nv));
  if (face_el) {
    scene.triangles.reserve(size_t(face_el->count));
    scene.triangle_object.reserve(size_t(face_el->count));
  }
  Body body(path, bytes, at, format, line_no + 1);
  std::vector<uint32_t> face;
  size_t short_faces = 0;
  for (const Element& e : elements) {
    const bool is_vertex = &e == vertex_el, is_face = &e == face_el;
    for (uint64_t i = 0; i < e.count; ++i) {
      Vec3 v{0, 0, 0};
      for (size_t pi = 0; pi < e.props.size(); ++pi) {
        const Property& p = e.props[pi];
        if (!p.list) {
          double x =
              body.value(p.type, e.name + " " + std::to_string(i) + " property '" + p.name + "'");
          if (is_vertex)
            for (int k = 0; k < 3; ++k)
              if (int(pi) == xyz[k]) v[k] = x;
          continue;
        }
        std::string who = e.name + " " + std::to_string(i) + " list '" + p.name + "'";
        double n = body.value(p.count_type, who + " count");
        // Each item takes at least 2 characters (ascii) or its size (binary).
        uint64_t item_min = format == Format::Ascii ? 2 : size_of(p.type);
        if (n < 0 || n > double(body.remaining() / item_min + 1))
          body.fail(who + ": count " + std::to_string((long long)n) + " does not fit in the " +
                    std::to_string(body.remaining()) + " bytes left");
        const bool indices = is_face && int(pi) == face_list;
        if (indices) face.clear();
        for (uint64_t k = 0; k < uint64_t(n); ++k) {
          double x = body.value(p.type, who + " item " + std::to_string(k));
          if (!indices) continue;
          if (x < 0 || x >= double(nv))
            body.fail("face " + std::to_string(i) + " has vertex index " +
                      std::to_string((long long)x) + " out of range (" + std::to_string(nv) +
                      " vertices)");
          face.push_back(uint32_t(x));
        }
        if (indices) {
          if (face.size() < 3)
            ++short_faces;
          else
            mesh_reader::add_fan(scene, face);
        }
      }
      if (is_vertex) {
        if (!is_finite(v))
          throw InputError(path, "vertex " + std::to_string(i) + " has a non-finite coordinate");
        pos.push_back(v);
      }
    }
  }
  body.expect_end();
  mesh_reader::warn_faces(path, short_faces, scene, warnings);
  return scene;
}

}  // namespace vislib
