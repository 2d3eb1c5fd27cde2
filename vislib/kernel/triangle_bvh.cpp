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

// Splits on the triangles' centroids only (12 bytes a triangle while building); a leaf's bounds
// come from its corners, an inner node's from its children's (the same floats as the union of
// per-triangle bounds rounded outward: rounding outward is monotone).
struct Builder {
  const Scene& scene;
  size_t state;
  std::vector<float> mid;  // per triangle: centre of its box, 3 each
  TriangleBvh& bvh;

  void build(uint32_t node, uint32_t begin, uint32_t end) {
    TriangleBvh::Node n;
    if (end - begin <= kBvhLeafSize) {
      double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
      for (uint32_t i = begin; i < end; ++i)
        for (const Vec3& c : scene.corners(bvh.order[i], state))
          for (int a = 0; a < 3; ++a) {
            lo[a] = std::min(lo[a], c[a]);
            hi[a] = std::max(hi[a], c[a]);
          }
      for (int a = 0; a < 3; ++a) {
        n.lo[a] = down(lo[a]);
        n.hi[a] = up(hi[a]);
      }
      n.first = begin;
      n.count = end - begin;
      bvh.nodes[node] = n;
      return;
    }
    float cmin[3] = {INFINITY, INFINITY, INFINITY}, cmax[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = begin; i < end; ++i) {
      const uint32_t t = bvh.order[i];
      for (int a = 0; a < 3; ++a) {
        cmin[a] = std::min(cmin[a], mid[t * 3 + a]);
        cmax[a] = std::max(cmax[a], mid[t * 3 + a]);
      }
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
    const uint32_t left = uint32_t(bvh.nodes.size());
    bvh.nodes.resize(bvh.nodes.size() + 2);
    build(left, begin, m);
    build(left + 1, m, end);
    const TriangleBvh::Node &l = bvh.nodes[left], &r = bvh.nodes[left + 1];
    for (int a = 0; a < 3; ++a) {
      n.lo[a] = std::min(l.lo[a], r.lo[a]);
      n.hi[a] = std::max(l.hi[a], r.hi[a]);
    }
    n.first = left;
    n.count = 0;
    bvh.nodes[node] = n;
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
  Builder b{scene, state, std::vector<float>(n * 3), bvh};
  for (size_t t = 0; t < n; ++t) {
    const auto c = scene.corners(uint32_t(t), state);
    for (int a = 0; a < 3; ++a) {
      const double l = std::min({c[0][a], c[1][a], c[2][a]});
      const double h = std::max({c[0][a], c[1][a], c[2][a]});
      b.mid[t * 3 + a] = float(0.5 * (l + h));
    }
  }
  bvh.order.resize(n);
  for (size_t t = 0; t < n; ++t) bvh.order[t] = uint32_t(t);
  bvh.nodes.reserve(n +
                    2);  // leaves hold at least 2 triangles (or the one), so at most n + 2 nodes
  bvh.nodes.resize(1);
  b.build(0, 0, uint32_t(n));
  return bvh;
}

}  // namespace vislib
