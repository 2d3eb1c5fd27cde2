// pvs_stream_case.h: deterministic PVS inputs large enough to exercise every Delta reference of
// write_pvs (grid: x, y and z neighbours; box list: the nearest centre among the 4096 previous
// cells, so more than 4096 cells), for the streaming writer's byte-identity test. Uses only the
// raw output of std::mt19937 (portable), no distributions.
#pragma once

#include <random>

#include "pvs_format/pvs_format.h"

namespace vislib_test {

struct StreamCase {
  pvs::FileInfo info;
  std::vector<pvs::CellSet> cells;
};

// kind 0: a 30 x 2 x 30 grid, partial (every 7th cell absent); kind 1: 5000 boxes.
inline StreamCase make_stream_case(int kind) {
  StreamCase s;
  std::mt19937 rng(1234 + kind);
  auto uniform = [&](double lo, double hi) {
    return lo + (hi - lo) * double(rng()) / 4294967296.0;
  };
  s.info.scene_fingerprint = 0x5eed0000u + uint64_t(kind);
  s.info.universe = 5000;
  s.info.metadata = "{\"case\":" + std::to_string(kind) + "}";
  uint32_t n;
  if (kind == 0) {
    s.info.layout.kind = pvs::LayoutKind::Grid;
    s.info.layout.grid_box = {{-30, 0, -30}, {30, 4, 30}};
    s.info.layout.nx = 30;
    s.info.layout.ny = 2;
    s.info.layout.nz = 30;
    s.info.layout.eye_lo = 1.5;
    s.info.layout.eye_hi = 1.8;
    s.info.partial = true;
    n = 1800;
  } else {
    s.info.layout.kind = pvs::LayoutKind::Boxes;
    n = 5000;
    for (uint32_t c = 0; c < n; ++c) {
      pvs::Box b;
      for (int k = 0; k < 3; ++k) {
        b.min[k] = uniform(-100, 100);
        b.max[k] = b.min[k] + uniform(0.5, 3);
      }
      s.info.layout.boxes.push_back(b);
    }
  }
  // Sets drift: each cell takes the previous cell's set, drops and adds a few ids, so that
  // Delta encodings win often; now and then a fresh set or a long run.
  std::vector<uint32_t> cur;
  for (uint32_t c = 0; c < n; ++c) {
    if (kind == 0 && c % 7 == 3) {
      s.cells.emplace_back(std::nullopt);
      continue;
    }
    uint32_t r = rng() % 100;
    std::vector<bool> in(s.info.universe, false);
    for (uint32_t id : cur) in[id] = true;
    if (r < 5) {
      std::fill(in.begin(), in.end(), false);
    } else if (r < 8) {
      uint32_t a = rng() % 4000;
      for (uint32_t i = a; i < a + 600; ++i) in[i] = true;
    }
    for (int k = 0; k < 6; ++k) in[rng() % s.info.universe] = false;
    for (int k = 0; k < 8; ++k) in[rng() % s.info.universe] = true;
    cur.clear();
    for (uint32_t id = 0; id < s.info.universe; ++id)
      if (in[id]) cur.push_back(id);
    s.cells.emplace_back(cur);
  }
  return s;
}

}  // namespace vislib_test
