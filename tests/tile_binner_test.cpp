// The tile binner shared by the static and dynamic kernels (kernel_support.h): every primitive is
// listed in exactly the tiles its pixel box touches, in primitive order within a tile; empty boxes
// are listed nowhere.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "vislib/base/random.h"
#include "vislib/kernel/kernel_support.h"

using namespace vislib;

TEST(TileBinner, EveryPrimitiveIsInExactlyTheTilesItsBoxTouchesInPrimitiveOrder) {
  const int n = 100, ts = 16, tiles_x = (n + ts - 1) / ts;
  Rng rng(3);
  const size_t count = 500;
  std::vector<int> bbox(count * 4);
  for (size_t p = 0; p < count; ++p) {
    int x0 = int(rng.below(n)), x1 = int(rng.below(n)), y0 = int(rng.below(n)),
        y1 = int(rng.below(n));
    if (p % 7 == 0) std::swap(x0, x1);  // some boxes empty (x0 > x1) or single columns
    if (y0 > y1) std::swap(y0, y1);
    if (p % 7 != 0 && x0 > x1) std::swap(x0, x1);
    bbox[p * 4 + 0] = x0;
    bbox[p * 4 + 1] = x1;
    bbox[p * 4 + 2] = y0;
    bbox[p * 4 + 3] = y1;
  }
  std::vector<uint32_t> start;
  std::vector<uint32_t> items;
  bin_by_tile(bbox, count, ts, tiles_x, start, items, [](size_t p) { return uint32_t(p); });
  ASSERT_EQ(start.size(), size_t(tiles_x * tiles_x) + 1);
  ASSERT_EQ(start.back(), items.size());
  size_t expected_total = 0;
  for (int ty = 0; ty < tiles_x; ++ty)
    for (int tx = 0; tx < tiles_x; ++tx) {
      const int tile = ty * tiles_x + tx;
      std::vector<uint32_t> want;
      for (size_t p = 0; p < count; ++p) {
        const int* b = &bbox[p * 4];
        if (b[0] > b[1]) continue;
        if (b[0] <= (tx + 1) * ts - 1 && b[1] >= tx * ts && b[2] <= (ty + 1) * ts - 1 &&
            b[3] >= ty * ts)
          want.push_back(uint32_t(p));
      }
      expected_total += want.size();
      std::vector<uint32_t> got(items.begin() + start[tile], items.begin() + start[tile + 1]);
      EXPECT_EQ(got, want) << "tile " << tx << "," << ty;
    }
  EXPECT_EQ(items.size(), expected_total);
  EXPECT_GT(expected_total, count);  // boxes spanning several tiles are listed in each
}
