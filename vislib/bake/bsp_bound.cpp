// bsp_bound.cpp: conservative bounds of a Quake map's portal runs (bsp_bound.h).
#include "vislib/bake/bsp_bound.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cassert>

namespace vislib {

namespace {

// A portal crossed in one direction, into leaf `to`, its plane's normal pointing into `to`
// (dot(normal, x) = offset on the plane).
struct DirectedPortal {
  const std::vector<Vec3>* polygon = nullptr;
  Vec3 normal;
  double offset = 0;
  uint32_t to = 0;
};

// The largest and the smallest signed distance of `poly`'s vertices from the plane of `d`.
double max_distance(const std::vector<Vec3>& poly, const DirectedPortal& d) {
  double m = -INFINITY;
  for (const Vec3& v : poly) m = std::max(m, dot(d.normal, v) - d.offset);
  return m;
}
double min_distance(const std::vector<Vec3>& poly, const DirectedPortal& d) {
  double m = INFINITY;
  for (const Vec3& v : poly) m = std::min(m, dot(d.normal, v) - d.offset);
  return m;
}

// Whether a ray that crosses `first` can cross `later` after it (bsp_bound.h): `later` reaches in
// front of first's plane and `first` behind later's, within kBspBoundDistance.
bool may_follow(const DirectedPortal& first, const DirectedPortal& later) {
  if (first.polygon == later.polygon) return false;  // itself, or itself the other way
  return max_distance(*later.polygon, first) > -kBspBoundDistance &&
         min_distance(*first.polygon, later) < kBspBoundDistance;
}

}  // namespace

std::vector<std::vector<uint32_t>> bsp_leaf_triangles(const QuakeBsp& bsp, const Scene& scene) {
  std::vector<std::vector<uint32_t>> out(bsp.leaves.size());
  const int32_t head = bsp.models.at(0).headnode[0];
  std::vector<int32_t> stack;
  for (uint32_t t = 0; t < scene.triangle_count(); ++t) {
    std::array<Vec3, 3> q;
    const auto corners = scene.corners(t, 0);
    for (int k = 0; k < 3; ++k) q[size_t(k)] = scene_to_quake(corners[size_t(k)]);
    stack.assign(1, head);
    while (!stack.empty()) {
      const int32_t child = stack.back();
      stack.pop_back();
      if (child < 0) {
        const uint32_t leaf = uint32_t(-(child + 1));
        if (leaf < out.size()) out[leaf].push_back(t);
        continue;
      }
      const BspNode& node = bsp.nodes[size_t(child)];
      const BspPlane& plane = bsp.planes[node.plane];
      const Vec3 n{plane.normal[0], plane.normal[1], plane.normal[2]};
      double lo = INFINITY, hi = -INFINITY;
      for (const Vec3& c : q) {
        const double d = dot(n, c) - double(plane.dist);
        lo = std::min(lo, d);
        hi = std::max(hi, d);
      }
      if (hi > -kBspBoundDistance) stack.push_back(node.children[0]);
      if (lo < kBspBoundDistance) stack.push_back(node.children[1]);
    }
  }
  return out;  // triangles in increasing id per leaf: each triangle appended once per leaf
}

std::vector<std::vector<uint32_t>> bsp_portal_bound_leaves(const QuakeBsp& bsp,
                                                           const std::vector<BspPortal>& portals,
                                                           BspBound bound) {
  assert(bound != BspBound::None);
  std::vector<std::vector<uint32_t>> out(portals.size());
  if (bound == BspBound::MapVis) {
    for (size_t p = 0; p < portals.size(); ++p) {
      std::vector<uint32_t>& leaves = out[p];
      for (uint32_t l : portals[p].leaves) {
        leaves.push_back(l);
        const std::vector<uint32_t> seen = bsp_leaf_sees(bsp, l);
        leaves.insert(leaves.end(), seen.begin(), seen.end());
      }
      std::sort(leaves.begin(), leaves.end());
      leaves.erase(std::unique(leaves.begin(), leaves.end()), leaves.end());
    }
    return out;
  }
  // Directed portal 2 p + 0 goes from leaves[0] into leaves[1], 2 p + 1 back.
  const size_t n = 2 * portals.size();
  std::vector<DirectedPortal> directed(n);
  std::vector<std::vector<uint32_t>> leaving(bsp.leaves.size());
  for (size_t p = 0; p < portals.size(); ++p) {
    const BspPortal& portal = portals[p];
    const double offset = dot(portal.normal, portal.polygon.at(0));
    directed[2 * p] = {&portal.polygon, portal.normal, offset, portal.leaves[1]};
    directed[2 * p + 1] = {&portal.polygon, portal.normal * -1.0, -offset, portal.leaves[0]};
    leaving.at(portal.leaves[0]).push_back(uint32_t(2 * p));
    leaving.at(portal.leaves[1]).push_back(uint32_t(2 * p + 1));
  }
  // The leaves each directed portal's flood reaches (its far leaf first).
  std::vector<std::vector<uint32_t>> flood(n);
  tbb::parallel_for(size_t(0), n, [&](size_t d) {
    const DirectedPortal& first = directed[d];
    std::vector<uint8_t> reached(bsp.leaves.size(), 0);
    std::vector<uint32_t> stack{first.to};
    reached[first.to] = 1;
    while (!stack.empty()) {
      const uint32_t leaf = stack.back();
      stack.pop_back();
      flood[d].push_back(leaf);
      for (uint32_t e : leaving[leaf]) {
        const DirectedPortal& later = directed[e];
        if (reached[later.to] || !may_follow(first, later)) continue;
        reached[later.to] = 1;
        stack.push_back(later.to);
      }
    }
  });
  for (size_t p = 0; p < portals.size(); ++p) {
    std::vector<uint32_t>& leaves = out[p];
    leaves = flood[2 * p];
    leaves.insert(leaves.end(), flood[2 * p + 1].begin(), flood[2 * p + 1].end());
    std::sort(leaves.begin(), leaves.end());
    leaves.erase(std::unique(leaves.begin(), leaves.end()), leaves.end());
  }
  return out;
}

std::vector<uint32_t> bound_triangles(const std::vector<std::vector<uint32_t>>& leaf_triangles,
                                      const std::vector<uint32_t>& leaves) {
  std::vector<uint32_t> out;
  for (uint32_t l : leaves)
    if (l < leaf_triangles.size())
      out.insert(out.end(), leaf_triangles[l].begin(), leaf_triangles[l].end());
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

}  // namespace vislib
