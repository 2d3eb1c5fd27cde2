// kernel_compare.h: bit-for-bit comparison of kernel results, for the tests that check that a
// speed-up (vectorised coverage, culling, the BVH walk) changes no result.
#pragma once

#include <cstring>
#include <vector>

#include "vislib/kernel/interval_list.h"
#include "vislib/kernel/witness.h"

namespace vislib_test {

// Every byte of every piece (t0, t1, id, depth) equal: bit-identical, -0.0 != +0.0.
inline bool identical_lists(const std::vector<vislib::PieceList>& a,
                            const std::vector<vislib::PieceList>& b) {
  if (a.size() != b.size()) return false;
  for (size_t k = 0; k < a.size(); ++k) {
    if (a[k].size() != b[k].size()) return false;
    for (size_t i = 0; i < a[k].size(); ++i) {
      const vislib::Piece &p = a[k][i], &q = b[k][i];
      if (std::memcmp(&p.t0, &q.t0, 8) || std::memcmp(&p.t1, &q.t1, 8) || p.id != q.id ||
          std::memcmp(&p.depth, &q.depth, sizeof(vislib::LinearDepth)))
        return false;
    }
  }
  return true;
}

// The same witness (triangle, face, pixel, t bit for bit) for every visible triangle.
inline bool same_witnesses(const std::vector<vislib::Witness>& a,
                           const std::vector<vislib::Witness>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (a[i].tri != b[i].tri || a[i].face != b[i].face || a[i].x != b[i].x || a[i].y != b[i].y ||
        std::memcmp(&a[i].t, &b[i].t, 8))
      return false;
  return true;
}

}  // namespace vislib_test
