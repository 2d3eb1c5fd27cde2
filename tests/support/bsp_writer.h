// bsp_writer.h: encodes a vislib::QuakeBsp as a .bsp file (BSP29, BSP2 or 2PSB), for the tests
// and the fuzz seeds: small generated maps, and real maps re-encoded in another format. The record
// layouts are those read by vislib/scene/quake_bsp.cpp. Lighting and clipnodes are written empty,
// miptex headers carry the name only (no pixels). Writes what it is given, valid or not (the tests
// break maps on purpose), except that values are truncated to the field width of the format.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>

#include "vislib/scene/quake_bsp.h"

namespace vislib_test {

class BspBytes {
 public:
  void u8(uint32_t v) { s_.push_back(char(v & 0xff)); }
  void u16(uint32_t v) { u8(v), u8(v >> 8); }
  void u32(uint32_t v) { u16(v & 0xffff), u16(v >> 16); }
  void i32(int32_t v) { u32(uint32_t(v)); }
  void f32(float f) {
    uint32_t u;
    std::memcpy(&u, &f, 4);
    u32(u);
  }
  void bytes(const std::string& b) { s_ += b; }
  std::string& str() { return s_; }

 private:
  std::string s_;
};

// The file bytes of `m` in `m.format`. Node children are written as the reader decodes them
// (BSP29: a leaf l as 0xffff - l).
inline std::string encode_bsp(const vislib::QuakeBsp& m) {
  using vislib::BspFormat;
  const bool wide = m.format != BspFormat::bsp29;
  const bool float_bounds = m.format == BspFormat::bsp2;
  std::string lumps[15];
  auto bounds = [&](BspBytes& o, const std::array<float, 3>& mins,
                    const std::array<float, 3>& maxs) {
    for (const auto* b : {&mins, &maxs})
      for (float v : *b) {
        if (float_bounds)
          o.f32(v);
        else
          o.u16(uint32_t(int32_t(std::lround(v))) & 0xffff);
      }
  };
  auto index = [&](BspBytes& o, uint32_t v) { wide ? o.u32(v) : o.u16(v & 0xffff); };
  {  // entities
    lumps[0] = m.entities + std::string(1, '\0');
  }
  {
    BspBytes o;
    for (const auto& p : m.planes)
      o.f32(p.normal[0]), o.f32(p.normal[1]), o.f32(p.normal[2]), o.f32(p.dist), o.i32(p.type);
    lumps[1] = o.str();
  }
  {  // textures: count, offsets, 40-byte headers
    BspBytes o;
    const size_t n = m.texture_names.size();
    o.i32(int32_t(n));
    for (size_t i = 0; i < n; ++i) o.i32(int32_t(4 + 4 * n + 40 * i));
    for (const auto& name : m.texture_names) {
      std::string field = name.substr(0, 16);
      field.resize(16, '\0');
      o.bytes(field);
      for (int k = 0; k < 6; ++k) o.u32(0);
    }
    lumps[2] = o.str();
  }
  {
    BspBytes o;
    for (const auto& v : m.vertices) o.f32(v[0]), o.f32(v[1]), o.f32(v[2]);
    lumps[3] = o.str();
  }
  lumps[4].assign(m.visibility.begin(), m.visibility.end());
  {
    BspBytes o;
    for (const auto& n : m.nodes) {
      o.i32(int32_t(n.plane));
      for (int32_t c : n.children) {
        if (wide)
          o.i32(c);
        else
          o.u16(c >= 0 ? uint32_t(c) : (0xffffu - uint32_t(-(int64_t(c) + 1))) & 0xffff);
      }
      bounds(o, n.mins, n.maxs);
      index(o, n.first_face), index(o, n.face_count);
    }
    lumps[5] = o.str();
  }
  {
    BspBytes o;
    for (const auto& t : m.texinfo) {
      for (const auto& row : t.vecs)
        for (float v : row) o.f32(v);
      o.i32(int32_t(t.miptex)), o.i32(t.flags);
    }
    lumps[6] = o.str();
  }
  {
    BspBytes o;
    for (const auto& f : m.faces) {
      if (wide) {
        o.i32(int32_t(f.plane)), o.i32(f.side), o.i32(int32_t(f.first_edge)),
            o.i32(int32_t(f.edge_count)), o.i32(int32_t(f.texinfo));
      } else {
        o.u16(f.plane), o.u16(uint32_t(f.side)), o.i32(int32_t(f.first_edge)), o.u16(f.edge_count),
            o.u16(f.texinfo);
      }
      o.u32(0xffffffffu);  // styles: none
      o.i32(-1);           // lightofs: none
    }
    lumps[7] = o.str();
  }
  {
    BspBytes o;
    for (const auto& l : m.leaves) {
      o.i32(l.contents), o.i32(l.visofs);
      bounds(o, l.mins, l.maxs);
      index(o, l.first_marksurface), index(o, l.marksurface_count);
      o.u32(0);  // ambient levels
    }
    lumps[10] = o.str();
  }
  {
    BspBytes o;
    for (uint32_t f : m.marksurfaces) index(o, f);
    lumps[11] = o.str();
  }
  {
    BspBytes o;
    for (const auto& e : m.edges) index(o, e[0]), index(o, e[1]);
    lumps[12] = o.str();
  }
  {
    BspBytes o;
    for (int32_t se : m.surfedges) o.i32(se);
    lumps[13] = o.str();
  }
  {
    BspBytes o;
    for (const auto& md : m.models) {
      for (const auto* v : {&md.mins, &md.maxs, &md.origin})
        for (float x : *v) o.f32(x);
      for (int32_t h : md.headnode) o.i32(h);
      o.i32(md.visleafs), o.i32(int32_t(md.first_face)), o.i32(int32_t(md.face_count));
    }
    lumps[14] = o.str();
  }
  BspBytes out;
  if (m.format == BspFormat::bsp29)
    out.i32(29);
  else
    out.bytes(m.format == BspFormat::bsp2 ? "BSP2" : "2PSB");
  uint32_t at = 4 + 15 * 8;
  for (const auto& l : lumps) {  // each lump starts 4-byte aligned, as compilers write them
    out.u32(at), out.u32(uint32_t(l.size()));
    at += uint32_t((l.size() + 3) / 4 * 4);
  }
  for (const auto& l : lumps) out.bytes(l + std::string((4 - l.size() % 4) % 4, '\0'));
  return out.str();
}

}  // namespace vislib_test
