// tile_bins.h: counting-sort binning of primitives into the square pixel tiles of a cube face,
// shared by the static and the dynamic from-segment kernels.
#pragma once

#include <cstdint>
#include <vector>

namespace vislib {

// bbox holds 4 ints per primitive: x0, x1, y0, y1 (inclusive pixel bounds; x0 > x1 = empty).
// Fills `start` (tile_count + 1 offsets) and `items` (make(p) for each primitive p in each tile
// its box touches, in primitive order within a tile). tile = ty * tiles_x + tx, tiles of side ts.
template <class Item, class Make>
void bin_by_tile(const std::vector<int>& bbox, size_t count, int ts, int tiles_x, std::vector<uint32_t>& start,
                 std::vector<Item>& items, Make make) {
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
  for (size_t p = 0; p < count; ++p) for_tiles(p, [&](int tile) { items[fill[size_t(tile)]++] = make(p); });
}

}  // namespace vislib
