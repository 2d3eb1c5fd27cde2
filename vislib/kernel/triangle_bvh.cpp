// triangle_bvh.cpp: see triangle_bvh.h.
#include "vislib/kernel/triangle_bvh.h"

#include <tbb/parallel_for.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <cmath>
#include <map>
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
// Subtrees are built in parallel, into the slots a depth-first build would give them: a range's
// subtree takes a number of nodes that depends on its size alone (`below`), so the layout, and
// everything the kernel computes from it, is the same whatever the thread count.
struct Builder {
  const Scene& scene;
  size_t state;
  std::vector<float> mid;  // per primitive: centre of its box, 3 each
  TriangleBvh& bvh;
  std::map<uint32_t, uint32_t> below_size;  // filled by count_below before the build, then read

  // Ranges at least this large build their two halves as parallel tasks (triangles).
  static constexpr uint32_t kParallelRange = 1u << 14;

  // The nodes a range of `size` triangles allocates below its own node: two children and theirs.
  uint32_t count_below(uint32_t size) {
    if (size <= kBvhLeafSize) return 0;
    if (auto it = below_size.find(size); it != below_size.end()) return it->second;
    const uint32_t half = size / 2;
    const uint32_t k = 2 + count_below(half) + count_below(size - half);
    below_size.emplace(size, k);
    return k;
  }
  uint32_t below(uint32_t size) const { return size <= kBvhLeafSize ? 0 : below_size.at(size); }

  // Builds the range's subtree at `node`, its descendants in the slots from `next` on.
  void build(uint32_t node, uint32_t begin, uint32_t end, uint32_t next) {
    TriangleBvh::Node n;
    if (end - begin <= kBvhLeafSize) {
      double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
      for (uint32_t i = begin; i < end; ++i)
        for (uint32_t t = bvh.groups.begin(bvh.order[i]); t < bvh.groups.end(bvh.order[i]); ++t)
          for (const Vec3& c : scene.corners(t, state))
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
    const uint32_t left = next;
    const uint32_t right_next = next + 2 + below(m - begin);
    if (end - begin >= kParallelRange) {
      tbb::task_group halves;
      halves.run([&] { build(left, begin, m, next + 2); });
      build(left + 1, m, end, right_next);
      halves.wait();
    } else {
      build(left, begin, m, next + 2);
      build(left + 1, m, end, right_next);
    }
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

// The tree over the primitives `order` (distinct groups of `groups`, a group per triangle when
// it is empty).
TriangleBvh build_tree(const Scene& scene, size_t state, TriangleGroups groups,
                       std::vector<uint32_t> order) {
  TriangleBvh bvh;
  bvh.scene = &scene;
  bvh.state = state;
  const size_t n = scene.triangle_count();
  bvh.triangle_count = n;
  bvh.groups = std::move(groups);
  if (n >= (size_t(1) << 31)) throw std::invalid_argument("too many triangles for the BVH");
  if (order.empty()) return bvh;
  if (state >= scene.positions.size())
    throw std::invalid_argument("BVH: key state " + std::to_string(state) + " out of range");
  Builder b{scene, state, std::vector<float>(bvh.groups.count(n) * 3), bvh, {}};
  tbb::parallel_for(size_t(0), order.size(), [&](size_t i) {
    const uint32_t g = order[i];
    double l[3] = {INFINITY, INFINITY, INFINITY}, h[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t t = bvh.groups.begin(g); t < bvh.groups.end(g); ++t) {
      const auto c = scene.corners(t, state);
      for (int a = 0; a < 3; ++a) {
        l[a] = std::min({l[a], c[0][a], c[1][a], c[2][a]});
        h[a] = std::max({h[a], c[0][a], c[1][a], c[2][a]});
      }
    }
    for (int a = 0; a < 3; ++a) b.mid[size_t(g) * 3 + size_t(a)] = float(0.5 * (l[a] + h[a]));
  });
  const uint32_t m = uint32_t(order.size());
  bvh.order = std::move(order);
  bvh.nodes.resize(1 + size_t(b.count_below(m)));
  b.build(0, 0, m, 1);
  return bvh;
}

TriangleGroups groups_for(const Scene& scene, size_t state, BvhPrimitives primitives) {
  return primitives == BvhPrimitives::Groups ? build_triangle_groups(scene, state)
                                             : TriangleGroups{};
}

}  // namespace

TriangleBvh build_triangle_bvh(const Scene& scene, BvhPrimitives primitives, size_t state) {
  TriangleGroups groups = groups_for(scene, state, primitives);
  std::vector<uint32_t> order(groups.count(scene.triangle_count()));
  for (size_t g = 0; g < order.size(); ++g) order[g] = uint32_t(g);
  return build_tree(scene, state, std::move(groups), std::move(order));
}

TriangleBvh build_triangle_bvh(const Scene& scene, size_t state) {
  return build_triangle_bvh(scene, BvhPrimitives::Groups, state);
}

TriangleBvh build_triangle_bvh(const Scene& scene, size_t state,
                               const std::vector<uint32_t>& subset) {
  return build_triangle_bvh(scene, state, subset, groups_for(scene, state, BvhPrimitives::Groups));
}

TriangleBvh build_triangle_bvh(const Scene& scene, size_t state,
                               const std::vector<uint32_t>& subset, const TriangleGroups& groups) {
  for (size_t i = 0; i < subset.size(); ++i)
    if (subset[i] >= scene.triangle_count() || (i > 0 && subset[i] <= subset[i - 1]))
      throw std::invalid_argument("BVH: the subset is not increasing triangle ids of the scene");
  if (!groups.first.empty() && groups.first.back() != scene.triangle_count())
    throw std::invalid_argument("BVH: the groups were built for another scene");
  if (groups.first.empty()) return build_tree(scene, state, groups, subset);
  std::vector<uint32_t> order;  // the groups holding a triangle of the subset, increasing
  uint32_t g = 0;
  for (uint32_t t : subset) {
    while (groups.end(g) <= t) ++g;
    if (order.empty() || order.back() != g) order.push_back(g);
  }
  return build_tree(scene, state, groups, std::move(order));
}

}  // namespace vislib
