// edge_lines.cpp: runs of collinear edges joined through shared endpoints (edge_lines.h).
#include "vislib/kernel/edge_lines.h"

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <string>

namespace vislib {

bool EdgeLines::line_of(uint32_t tri, int e, Vec3& P, Vec3& Q) const {
  if (mask.empty() || !(mask[tri] >> e & 1)) return false;
  const uint32_t k = tri * 3 + uint32_t(e);
  const size_t i = size_t(std::lower_bound(keys.begin(), keys.end(), k) - keys.begin());
  const std::array<Vec3, 2>& l = lines[line_index[i]];
  P = l[0];
  Q = l[1];
  return true;
}

namespace {

// Union-find over edge ids; the root of a set is its smallest id (deterministic).
struct Sets {
  std::vector<uint32_t> parent;
  explicit Sets(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  uint32_t find(uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void unite(uint32_t a, uint32_t b) {
    a = find(a);
    b = find(b);
    if (a == b) return;
    if (b < a) std::swap(a, b);
    parent[b] = a;
  }
};

// The direction of `d` up to sign and length, for ordering the edges around a point: unit length,
// first non-zero coordinate positive.
Vec3 direction_key(Vec3 d) {
  const double len = length(d);
  d = d * (1.0 / len);
  if (d.x < 0 || (d.x == 0 && (d.y < 0 || (d.y == 0 && d.z < 0)))) d = d * -1.0;
  return d;
}

}  // namespace

EdgeLines build_edge_lines(const Scene& scene, size_t state) {
  EdgeLines el;
  el.scene = &scene;
  el.state = state;
  const size_t n = scene.triangle_count();
  el.triangle_count = n;
  if (n == 0) return el;
  if (state >= scene.positions.size())
    throw std::invalid_argument("edge lines: key state " + std::to_string(state) + " out of range");
  if (n > (size_t(1) << 30)) throw std::invalid_argument("too many triangles for the edge lines");
  const std::vector<Vec3>& pos = scene.positions[state];
  for (const Vec3& p : pos)
    if (!is_finite(p)) return el;  // no order to build on; the kernel refuses such scenes anyway

  // Points: distinct positions, numbered in lexicographic order (so the smaller id of an edge's
  // endpoints is its canonical P, and the extreme ids of a run are its line's ends).
  const size_t V = pos.size();
  std::vector<uint32_t> by_pos(V);
  std::iota(by_pos.begin(), by_pos.end(), 0u);
  std::sort(by_pos.begin(), by_pos.end(), [&](uint32_t a, uint32_t b) {
    if (pos[a] != pos[b]) return lex_less(pos[a], pos[b]);
    return a < b;
  });
  std::vector<uint32_t> point(V);
  std::vector<Vec3> point_pos;
  for (size_t i = 0; i < V; ++i) {
    if (i == 0 || pos[by_pos[i]] != pos[by_pos[i - 1]]) point_pos.push_back(pos[by_pos[i]]);
    point[by_pos[i]] = uint32_t(point_pos.size() - 1);
  }
  const size_t np = point_pos.size();

  // Edges 3t + e (corner e to corner e + 1) as point pairs a < b; a degenerate edge (a == b) joins
  // nothing. Incidence lists per point (CSR).
  const size_t ne = 3 * n;
  std::vector<uint32_t> ea(ne), eb(ne);
  std::vector<uint32_t> start(np + 1, 0);
  for (size_t t = 0; t < n; ++t)
    for (int e = 0; e < 3; ++e) {
      uint32_t a = point[scene.triangles[t][size_t(e)]],
               b = point[scene.triangles[t][size_t((e + 1) % 3)]];
      if (b < a) std::swap(a, b);
      ea[3 * t + size_t(e)] = a;
      eb[3 * t + size_t(e)] = b;
      if (a != b) ++start[a + 1], ++start[b + 1];
    }
  for (size_t p = 0; p < np; ++p) start[p + 1] += start[p];
  std::vector<uint32_t> incident(start[np]);
  {
    std::vector<uint32_t> fill(start.begin(), start.end() - 1);
    for (uint32_t id = 0; id < uint32_t(ne); ++id)
      if (ea[id] != eb[id]) incident[fill[ea[id]]++] = id, incident[fill[eb[id]]++] = id;
  }

  // Join collinear edges around each point: every pair while few, else neighbours in direction
  // order (runs through a point with more edges than the cap can then be missed, never invented).
  Sets sets(ne);
  std::vector<std::pair<Vec3, uint32_t>> around;
  for (size_t p = 0; p < np; ++p) {
    const uint32_t* first = incident.data() + start[p];
    const size_t k = start[p + 1] - start[p];
    if (k < 2) continue;
    const Vec3 X = point_pos[p];
    auto away = [&](uint32_t id) { return point_pos[ea[id] == p ? eb[id] : ea[id]] - X; };
    auto collinear = [](Vec3 d1, Vec3 d2) { return cross(d1, d2) == Vec3{0, 0, 0}; };
    if (k <= kEdgeLinesPairCap) {
      for (size_t i = 0; i < k; ++i)
        for (size_t j = i + 1; j < k; ++j)
          if (collinear(away(first[i]), away(first[j]))) sets.unite(first[i], first[j]);
      continue;
    }
    around.clear();
    for (size_t i = 0; i < k; ++i) around.push_back({direction_key(away(first[i])), first[i]});
    std::sort(around.begin(), around.end(), [](const auto& x, const auto& y) {
      if (x.first != y.first) return lex_less(x.first, y.first);
      return x.second < y.second;
    });
    for (size_t i = 1; i < k; ++i)
      if (collinear(away(around[i - 1].second), away(around[i].second)))
        sets.unite(around[i - 1].second, around[i].second);
  }
  std::vector<uint32_t>().swap(incident);  // freed before the runs' summaries
  std::vector<uint32_t>().swap(start);

  // Per run: its extreme points, and whether it holds two distinct edges (a run of one edge, or of
  // copies of one shared edge, computes its coefficients from its own points already).
  std::vector<uint32_t> lo(ne, UINT32_MAX), hi(ne, 0);
  std::vector<uint8_t> distinct(ne, 0);
  for (uint32_t id = 0; id < uint32_t(ne); ++id) {
    if (ea[id] == eb[id]) continue;
    const uint32_t r = sets.find(id);
    if (lo[r] != UINT32_MAX && (ea[id] != ea[r] || eb[id] != eb[r])) distinct[r] = 1;
    lo[r] = std::min(lo[r], ea[id]);
    hi[r] = std::max(hi[r], eb[id]);
  }
  std::vector<uint32_t> line_of_root(ne, UINT32_MAX);
  for (uint32_t id = 0; id < uint32_t(ne); ++id) {
    if (ea[id] == eb[id]) continue;
    const uint32_t r = sets.find(id);
    if (!distinct[r]) continue;
    if (el.mask.empty()) el.mask.assign(n, 0);
    el.mask[id / 3] |= uint8_t(1u << (id % 3));
    if (line_of_root[r] == UINT32_MAX) {
      line_of_root[r] = uint32_t(el.lines.size());
      el.lines.push_back({point_pos[lo[r]], point_pos[hi[r]]});
    }
    el.keys.push_back(id);
    el.line_index.push_back(line_of_root[r]);
  }
  return el;
}

}  // namespace vislib
