// kernel_support.h: pieces shared by the static and the dynamic from-segment kernels
// (segment_visibility.cpp, dynamic_visibility.cpp): binning primitives into pixel tiles, and the
// per-thread visibility marks and witnesses with their deterministic reduction.
#pragma once

#include <algorithm>
#include <cstdint>
#include <memory>
#include <vector>

#include "vislib/kernel/witness.h"

namespace vislib {

// bbox holds 4 ints per primitive: x0, x1, y0, y1 (inclusive pixel bounds; x0 > x1 = empty).
// Fills `start` (tile_count + 1 offsets) and `items` (make(p) for each primitive p in each tile
// its box touches, in primitive order within a tile). tile = ty * tiles_x + tx, tiles of side ts.
template <class Item, class Make>
void bin_by_tile(const std::vector<int>& bbox, size_t count, int ts, int tiles_x,
                 std::vector<uint32_t>& start, std::vector<Item>& items, Make make) {
  const int tile_count = tiles_x * tiles_x;
  start.assign(size_t(tile_count) + 1, 0);
  auto for_tiles = [&](size_t p, auto f) {
    const int* b = &bbox[p * 4];
    if (b[0] > b[1]) return;
    for (int ty = b[2] / ts; ty <= b[3] / ts; ++ty)
      for (int tx = b[0] / ts; tx <= b[1] / ts; ++tx) f(ty * tiles_x + tx);
  };
  for (size_t p = 0; p < count; ++p) for_tiles(p, [&](int tile) { ++start[size_t(tile) + 1]; });
  for (int i = 0; i < tile_count; ++i) start[size_t(i) + 1] += start[size_t(i)];
  items.resize(start[size_t(tile_count)]);
  std::vector<uint32_t> fill(start.begin(), start.end() - 1);
  for (size_t p = 0; p < count; ++p)
    for_tiles(p, [&](int tile) { items[fill[size_t(tile)]++] = make(p); });
}

// Witness order: longer piece first, then lower face, row, column, t, tau. A missing witness has
// length -1 and loses to any real one. A total order, so reductions do not depend on scheduling.
inline bool better_witness(double len_a, const Witness& a, double len_b, const Witness& b) {
  if (len_a != len_b) return len_a > len_b;
  if (a.face != b.face) return a.face < b.face;
  if (a.y != b.y) return a.y < b.y;
  if (a.x != b.x) return a.x < b.x;
  if (a.t != b.t) return a.t < b.t;
  return a.tau < b.tau;
}

// What one thread found in one run: a mark per visible primitive and, if wanted, its best witness
// so far. The marks are kept in pages of kMarkPageIds primitives, allocated on the first mark in
// them: a run sees a few thousand of a scene's triangles, lying in a few pages, so a thread's marks
// cost about the run's visible set, not 1 byte per primitive of the scene. A thread that helps J
// runs in flight holds J sets; dense marks made that J x J x (scene size) bytes over a bake.
// The witnesses, when wanted (never in a bake), stay dense: 8 bytes and a Witness per primitive.
struct FoundMarks {
  static constexpr unsigned kMarkPageShift = 10;
  static constexpr size_t kMarkPageIds = size_t(1) << kMarkPageShift;  // primitives a page

  std::vector<double> witness_len;  // per primitive: length of the witness piece (-1 = none)
  std::vector<Witness> witness;     // per primitive

  FoundMarks(size_t count, bool witnesses) : marks_(count), groups_(count) {
    if (witnesses) {
      witness_len.assign(count, -1.0);
      witness.resize(count);
    }
  }
  // Primitive p's mark: 0 (not seen), 1, or a bit per part of a split segment.
  uint8_t seen(uint32_t p) const { return marks_.get(p); }
  // Sets `bits` in primitive p's mark.
  void add(uint32_t p, uint8_t bits) { marks_.add(p, bits); }
  // Marks primitive p visible through a piece of length `len` (in t) with witness w.
  void mark(uint32_t p, double len, const Witness& w) {
    add(p, 1);
    if (!witness_len.empty() && better_witness(len, w, witness_len[p], witness[p])) {
      witness_len[p] = len;
      witness[p] = w;
    }
  }
  // A kernel's note on group g (< count) of primitives, such as the mark bits that every
  // primitive of a fan holds already (marks only grow in a run, so such a note stays true): 0
  // until noted. Not part of the result.
  uint8_t group_note(uint32_t g) const { return groups_.get(g); }
  void add_group_note(uint32_t g, uint8_t bits) { groups_.add(g, bits); }
  // ORs these marks into seen (size: the primitive count).
  void unite_into(std::vector<uint8_t>& seen) const { marks_.unite_into(seen); }
  // Bytes held by the marks and notes (the page tables and the pages in use).
  size_t mark_bytes() const { return marks_.bytes() + groups_.bytes(); }

 private:
  // A byte per id in [0, count), in pages allocated on their first non-zero byte.
  struct Pages {
    explicit Pages(size_t count) : pages((count + kMarkPageIds - 1) >> kMarkPageShift) {}
    uint8_t get(uint32_t p) const {
      const auto& page = pages[p >> kMarkPageShift];
      return page ? page[p & (kMarkPageIds - 1)] : uint8_t(0);
    }
    void add(uint32_t p, uint8_t bits) {
      auto& page = pages[p >> kMarkPageShift];
      if (!page) page.reset(new uint8_t[kMarkPageIds]());
      page[p & (kMarkPageIds - 1)] |= bits;
    }
    void unite_into(std::vector<uint8_t>& seen) const {
      for (size_t g = 0; g < pages.size(); ++g) {
        if (!pages[g]) continue;
        const size_t first = g << kMarkPageShift;
        const size_t n = std::min(kMarkPageIds, seen.size() - first);
        for (size_t i = 0; i < n; ++i) seen[first + i] |= pages[g][i];
      }
    }
    size_t bytes() const {
      size_t n = pages.size() * sizeof(pages[0]);
      for (const auto& page : pages) n += page ? kMarkPageIds : 0;
      return n;
    }
    std::vector<std::unique_ptr<uint8_t[]>> pages;
  };
  Pages marks_;
  Pages groups_;
};

// Marks primitive p visible from the parts of a split segment (SegmentOptions::splits) that the
// stretch [t0, t1) overlaps by more than eps_len times the part's length: bit i of seen[p] for
// part i. `bounds` holds 0, the splits, 1.
inline void mark_parts(FoundMarks& found, const std::vector<double>& bounds, double eps_len,
                       uint32_t p, double t0, double t1) {
  for (size_t i = 0; i + 1 < bounds.size(); ++i) {
    if (!(bounds[i] < t1)) break;
    const double a = t0 > bounds[i] ? t0 : bounds[i];
    const double b = t1 < bounds[i + 1] ? t1 : bounds[i + 1];
    if ((b - a) / (bounds[i + 1] - bounds[i]) > eps_len) found.add(p, uint8_t(1u << i));
  }
}

// Unites the marks of all threads (`found` iterates FoundMarks): seen[p] and the best witness of
// every primitive (empty `best` when no witnesses were kept).
template <class Range>
void reduce_found(const Range& found, size_t count, bool witnesses, std::vector<uint8_t>& seen,
                  std::vector<Witness>& best) {
  seen.assign(count, 0);
  std::vector<double> best_len(witnesses ? count : 0, -1.0);
  best.assign(witnesses ? count : 0, Witness{});
  for (const FoundMarks& f : found) {
    f.unite_into(seen);
    if (witnesses)
      for (size_t p = 0; p < count; ++p)
        if (f.witness_len[p] >= 0 &&
            better_witness(f.witness_len[p], f.witness[p], best_len[p], best[p])) {
          best_len[p] = f.witness_len[p];
          best[p] = f.witness[p];
        }
  }
}

}  // namespace vislib
