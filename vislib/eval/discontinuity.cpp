// discontinuity.cpp: the near-far paper's discontinuity metric delta (§5, Eqs. 7-8). See
// discontinuity.h.
#include "vislib/eval/discontinuity.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cassert>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>

namespace vislib {

std::optional<std::array<double, 2>> project_to_pixel(const Camera& c, Vec3 point) {
  const std::optional<PixelPosition> p = camera_project(c, point);
  if (!p || !std::isfinite(p->view_depth)) return std::nullopt;
  if (!std::isfinite(p->x) || !std::isfinite(p->y)) return std::nullopt;
  return std::array<double, 2>{p->x, p->y};
}

Discontinuity discontinuity(int width, int height, const std::vector<double>& truth_xy,
                            double radius) {
  assert(width >= 1 && height >= 1 && radius > 0);
  const size_t n = size_t(width) * size_t(height);
  assert(truth_xy.size() == 2 * n);
  // Buckets of side `radius` over the truth positions: the neighbours of p are in the 3 x 3
  // buckets around t(p). Positions beyond +-2^30 buckets have no delta (no real frame has them).
  const double limit = std::ldexp(radius, 30);
  auto has = [&](size_t p) {
    const double x = truth_xy[2 * p], y = truth_xy[2 * p + 1];
    return std::isfinite(x) && std::isfinite(y) && std::fabs(x) < limit && std::fabs(y) < limit;
  };
  auto key = [](int64_t bx, int64_t by) {
    return uint64_t(bx + (int64_t(1) << 31)) << 32 | uint64_t(by + (int64_t(1) << 31));
  };
  std::unordered_map<uint64_t, std::vector<uint32_t>> buckets;
  for (size_t p = 0; p < n; ++p)
    if (has(p))
      buckets[key(int64_t(std::floor(truth_xy[2 * p] / radius)),
                  int64_t(std::floor(truth_xy[2 * p + 1] / radius)))]
          .push_back(uint32_t(p));

  Discontinuity d;
  d.delta.assign(n, std::numeric_limits<double>::quiet_NaN());
  std::vector<size_t> coincident(n, 0);
  const double r2 = radius * radius;
  tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y != rows.end(); ++y)
      for (int x = 0; x < width; ++x) {
        const size_t p = size_t(y) * size_t(width) + size_t(x);
        if (!has(p)) continue;
        const double tx = truth_xy[2 * p], ty = truth_xy[2 * p + 1];
        const int64_t bx = int64_t(std::floor(tx / radius)), by = int64_t(std::floor(ty / radius));
        double sum = 0;
        size_t count = 0;
        // Buckets in a fixed order and their pixels in id order: the sum is deterministic.
        for (int64_t i = bx - 1; i <= bx + 1; ++i)
          for (int64_t j = by - 1; j <= by + 1; ++j) {
            auto it = buckets.find(key(i, j));
            if (it == buckets.end()) continue;
            for (uint32_t q : it->second) {
              if (q == p) continue;
              const double dx = truth_xy[2 * size_t(q)] - tx, dy = truth_xy[2 * size_t(q) + 1] - ty;
              const double t2 = dx * dx + dy * dy;
              if (!(t2 < r2)) continue;
              if (t2 == 0) {
                ++coincident[p];
                continue;
              }
              const double qx = double(q % uint32_t(width)), qy = double(q / uint32_t(width));
              sum += std::hypot(qx - x, qy - y) / std::sqrt(t2);
              ++count;
            }
          }
        if (count > 0) d.delta[p] = sum / double(count) - 1.0;
      }
  });
  size_t above = 0;
  double total = 0, total_abs = 0;
  for (size_t p = 0; p < n; ++p) {
    d.coincident_pairs += coincident[p];
    if (std::isnan(d.delta[p])) continue;
    ++d.pixels;
    total += d.delta[p];
    total_abs += std::fabs(d.delta[p]);
    if (d.delta[p] > d.max) d.max = d.delta[p];
    above += d.delta[p] > 0.5;
  }
  if (d.pixels > 0) {
    d.mean = total / double(d.pixels);
    d.mean_abs = total_abs / double(d.pixels);
    d.share_above_half = double(above) / double(d.pixels);
  }
  return d;
}

Discontinuity frame_discontinuity(const Camera& truth_camera, const std::vector<Vec3>& points,
                                  double radius) {
  assert(points.size() == size_t(truth_camera.width) * size_t(truth_camera.height));
  std::vector<double> xy(2 * points.size(), std::numeric_limits<double>::quiet_NaN());
  for (size_t p = 0; p < points.size(); ++p)
    if (auto t = project_to_pixel(truth_camera, points[p])) {
      xy[2 * p] = (*t)[0];
      xy[2 * p + 1] = (*t)[1];
    }
  return discontinuity(truth_camera.width, truth_camera.height, xy, radius);
}

}  // namespace vislib
