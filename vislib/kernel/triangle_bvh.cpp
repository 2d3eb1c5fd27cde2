// triangle_bvh.cpp: see triangle_bvh.h.
#include "vislib/kernel/triangle_bvh.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace vislib {
namespace {

float down(double x) {
  float f = float(x);
  if (double(f) > x) f = std::nextafter(f, -INFINITY);
  return f;
}
float up(double x) {
  float f = float(x);
  if (double(f) < x) f = std::nextafter(f, INFINITY);
  return f;
}

struct Builder {
  std::vector<float> lo, hi;  // per triangle, 3 each
  std::vector<float> mid;     // per triangle: centroid of its box, 3 each
  TriangleBvh& bvh;

  void build(uint32_t node, uint32_t begin, uint32_t end) {
    TriangleBvh::Node n;
    for (int a = 0; a < 3; ++a) {
      n.lo[a] = INFINITY;
      n.hi[a] = -INFINITY;
    }
    float cmin[3] = {INFINITY, INFINITY, INFINITY}, cmax[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = begin; i < end; ++i) {
      const uint32_t t = bvh.order[i];
      for (int a = 0; a < 3; ++a) {
        n.lo[a] = std::min(n.lo[a], lo[t * 3 + a]);
        n.hi[a] = std::max(n.hi[a], hi[t * 3 + a]);
        cmin[a] = std::min(cmin[a], mid[t * 3 + a]);
        cmax[a] = std::max(cmax[a], mid[t * 3 + a]);
      }
    }
    if (end - begin <= kBvhLeafSize) {
      n.first = begin;
      n.count = end - begin;
      bvh.nodes[node] = n;
      return;
    }
    int axis = 0;
    for (int a = 1; a < 3; ++a)
      if (cmax[a] - cmin[a] > cmax[axis] - cmin[axis]) axis = a;
    const uint32_t m = begin + (end - begin) / 2;
    std::nth_element(bvh.order.begin() + begin, bvh.order.begin() + m, bvh.order.begin() + end,
                     [&](uint32_t x, uint32_t y) {
                       const float cx = mid[x * 3 + axis], cy = mid[y * 3 + axis];
                       return cx < cy || (cx == cy && x < y);
                     });
    n.first = uint32_t(bvh.nodes.size());
    n.count = 0;
    bvh.nodes[node] = n;
    bvh.nodes.resize(bvh.nodes.size() + 2);
    const uint32_t left = n.first;
    build(left, begin, m);
    build(left + 1, m, end);
  }
};

}  // namespace

TriangleBvh build_triangle_bvh(const Scene& scene, size_t state) {
  TriangleBvh bvh;
  bvh.scene = &scene;
  bvh.state = state;
  const size_t n = scene.triangle_count();
  bvh.triangle_count = n;
  if (n == 0) return bvh;
  if (n >= (size_t(1) << 31)) throw std::invalid_argument("too many triangles for the BVH");
  if (state >= scene.positions.size())
    throw std::invalid_argument("BVH: key state " + std::to_string(state) + " out of range");
  Builder b{std::vector<float>(n * 3), std::vector<float>(n * 3), std::vector<float>(n * 3), bvh};
  for (size_t t = 0; t < n; ++t) {
    const auto c = scene.corners(uint32_t(t), state);
    for (int a = 0; a < 3; ++a) {
      const double l = std::min({c[0][a], c[1][a], c[2][a]});
      const double h = std::max({c[0][a], c[1][a], c[2][a]});
      b.lo[t * 3 + a] = down(l);
      b.hi[t * 3 + a] = up(h);
      b.mid[t * 3 + a] = float(0.5 * (l + h));
    }
  }
  bvh.order.resize(n);
  for (size_t t = 0; t < n; ++t) bvh.order[t] = uint32_t(t);
  bvh.nodes.reserve(2 * (n / kBvhLeafSize + 1));
  bvh.nodes.resize(1);
  b.build(0, 0, uint32_t(n));
  return bvh;
}

}  // namespace vislib
