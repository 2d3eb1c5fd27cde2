// import_off.cpp: the project's own OFF reader. OpenMesh's OFF reader allocated what a
// 23-byte header asked for; this one checks the counts against the bytes left before allocating.
//
// Format (ASCII, line based): an optional first line `[ST][C][N]OFF` (the counts may follow on the
// same line); then `nv nf [ne]`; then nv vertex lines `x y z [extra values]` and nf face lines
// `n i0 ... i(n-1) [colour]`. `#` starts a comment; blank lines are skipped. Extra values after
// the coordinates and after a face's indices (normals, colours, texture coordinates) are ignored.
// Faces are fan-triangulated (v0,v1,v2), (v0,v2,v3), ... in file order, degenerate ones kept;
// faces with fewer than 3 vertices are skipped with a warning. One object named after the file
// stem. Not supported (rejected with a message): binary OFF, 4OFF (homogeneous) and nOFF
// (dimension other than 3).
#include <cerrno>
#include <cmath>
#include <cstdlib>

#include "vislib/base/error.h"
#include "vislib/base/file_util.h"
#include "vislib/scene/import_formats.h"
#include "vislib/scene/mesh_reader_support.h"

namespace vislib {

namespace {

class Lines {
 public:
  Lines(const std::string& path, const std::string& text) : path_(path), t_(text) {}

  // The next line that is not blank once its comment is removed; false at the end of the file.
  bool next(std::vector<std::string>& tok) {
    while (at_ < t_.size()) {
      size_t end = t_.find('\n', at_);
      if (end == std::string::npos) end = t_.size();
      ++line_;
      std::string line = t_.substr(at_, end - at_);
      at_ = end + 1;
      size_t hash = line.find('#');
      if (hash != std::string::npos) line.resize(hash);
      tok.clear();
      size_t i = 0;
      while (i < line.size()) {
        while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
        size_t j = i;
        while (j < line.size() && !std::isspace(static_cast<unsigned char>(line[j]))) ++j;
        if (j > i) tok.push_back(line.substr(i, j - i));
        i = j;
      }
      if (!tok.empty()) return true;
    }
    return false;
  }
  size_t remaining() const { return at_ >= t_.size() ? 0 : t_.size() - at_; }
  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(path_, "line " + std::to_string(line_) + ": " + what);
  }

  double number(const std::string& s, const std::string& what) const {
    char* end = nullptr;
    errno = 0;
    double v = std::strtod(s.c_str(), &end);
    if (s.empty() || end != s.c_str() + s.size())
      fail("'" + s.substr(0, 64) + "' is not a number (" + what + ")");
    return v;
  }
  uint64_t count(const std::string& s, const std::string& what) const {
    if (s.empty() || s.size() > 19 || s.find_first_not_of("0123456789") != std::string::npos)
      fail("'" + s.substr(0, 64) + "' is not a non-negative integer (" + what + ")");
    return std::strtoull(s.c_str(), nullptr, 10);
  }

 private:
  const std::string& path_;
  const std::string& t_;
  size_t at_ = 0, line_ = 0;
};

}  // namespace

Scene load_off(const std::string& path, std::vector<std::string>& warnings) {
  const std::string text = read_file(path);
  Lines in(path, text);
  std::vector<std::string> tok;
  if (!in.next(tok)) throw InputError(path, "empty file: expected 'OFF' and the counts");
  size_t first = 0;
  const std::string& kw = tok[0];
  if (kw.size() >= 3 && kw.compare(kw.size() - 3, 3, "OFF") == 0) {
    std::string prefix = kw.substr(0, kw.size() - 3);
    if (prefix.find('4') != std::string::npos || prefix.find('n') != std::string::npos)
      in.fail("'" + kw + "': 4OFF and nOFF (other than 3 dimensions) are not supported");
    if (prefix.find_first_not_of("STCN") != std::string::npos)
      in.fail("'" + kw.substr(0, 64) + "' is not an OFF header ([ST][C][N]OFF)");
    first = 1;
    if (tok.size() > 1 && tok[1] == "BINARY") in.fail("binary OFF is not supported");
  } else if (kw.find_first_not_of("0123456789") != std::string::npos) {
    in.fail("not an OFF file (expected 'OFF' or the counts 'nv nf ne', got '" + kw.substr(0, 64) +
            "')");
  }
  if (tok.size() == first) {  // the counts are on a line of their own
    if (!in.next(tok)) in.fail("missing the counts line 'nv nf ne'");
    first = 0;
  }
  if (tok.size() < first + 2 || tok.size() > first + 3) in.fail("expected the counts 'nv nf [ne]'");
  uint64_t nv = in.count(tok[first], "vertex count");
  uint64_t nf = in.count(tok[first + 1], "face count");
  // A vertex line holds at least "0 0 0" and a line break (6 bytes, 5 for the last line); a face
  // line at least "0" and a line break.
  mesh_reader::check_count_fits(path, "vertex count", nv, 6, in.remaining() + 1);
  mesh_reader::check_count_fits(path, "face count", nf, 2, in.remaining() + 1 - nv * 6);
  if (nv >= UINT32_MAX) in.fail("more than 2^32-2 vertices");

  Scene scene = mesh_reader::one_object_scene(path);
  auto& pos = scene.positions[0];
  pos.reserve(size_t(nv));
  for (uint64_t v = 0; v < nv; ++v) {
    if (!in.next(tok))
      in.fail("truncated: vertex " + std::to_string(v) + " of " + std::to_string(nv) +
              " is missing");
    if (tok.size() < 3) in.fail("vertex " + std::to_string(v) + " needs 3 coordinates");
    Vec3 p;
    for (int k = 0; k < 3; ++k) p[k] = in.number(tok[size_t(k)], "vertex " + std::to_string(v));
    if (!is_finite(p)) in.fail("vertex " + std::to_string(v) + " has a non-finite coordinate");
    pos.push_back(p);
  }
  scene.triangles.reserve(size_t(nf));
  scene.triangle_object.reserve(size_t(nf));
  std::vector<uint32_t> face;
  size_t short_faces = 0;
  for (uint64_t f = 0; f < nf; ++f) {
    if (!in.next(tok))
      in.fail("truncated: face " + std::to_string(f) + " of " + std::to_string(nf) + " is missing");
    uint64_t n = in.count(tok[0], "vertex count of face " + std::to_string(f));
    if (tok.size() < n + 1)
      in.fail("face " + std::to_string(f) + " declares " + std::to_string(n) +
              " vertices but the line has " + std::to_string(tok.size() - 1) + " numbers");
    face.clear();
    for (size_t k = 0; k < n; ++k) {
      uint64_t i = in.count(tok[k + 1], "vertex index of face " + std::to_string(f));
      if (i >= nv)
        in.fail("face " + std::to_string(f) + " has vertex index " + std::to_string(i) +
                " out of range (" + std::to_string(nv) + " vertices)");
      face.push_back(uint32_t(i));
    }
    if (face.size() < 3)
      ++short_faces;
    else
      mesh_reader::add_fan(scene, face);
  }
  // Edges (ne) are not listed in OFF files in practice; anything after the faces is ignored.
  mesh_reader::warn_faces(path, short_faces, scene, warnings);
  return scene;
}

}  // namespace vislib
