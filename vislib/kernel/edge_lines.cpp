// edge_lines.cpp: runs of collinear edges joined through shared endpoints (edge_lines.h).
#include "vislib/kernel/edge_lines.h"

#include <tbb/parallel_sort.h>

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <string>

namespace vislib {

size_t EdgeLines::edge_count() const {
  return size_t(
      std::count_if(edge_line.begin(), edge_line.end(), [](uint32_t l) { return l != kNone; }));
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
  std::vector<uint32_t> point(V);
  std::vector<Vec3> point_pos;
  {
    std::vector<uint32_t> by_pos(V);
    std::iota(by_pos.begin(), by_pos.end(), 0u);
    // A strict total order (ties by index): the parallel sort's result is the only one.
    tbb::parallel_sort(by_pos.begin(), by_pos.end(), [&](uint32_t a, uint32_t b) {
      if (pos[a] != pos[b]) return lex_less(pos[a], pos[b]);
      return a < b;
    });
    for (size_t i = 0; i < V; ++i) {
      if (i == 0 || pos[by_pos[i]] != pos[by_pos[i - 1]]) point_pos.push_back(pos[by_pos[i]]);
      point[by_pos[i]] = uint32_t(point_pos.size() - 1);
    }
  }
  const size_t np = point_pos.size();

  // Edge 3t + e as its point pair a <= b (a == b: degenerate, joins nothing).
  const size_t ne = 3 * n;
  auto ends = [&](uint32_t id, uint32_t& a, uint32_t& b) {
    const auto& t = scene.triangles[id / 3];
    a = point[t[id % 3]];
    b = point[t[(id % 3 + 1) % 3]];
    if (b < a) std::swap(a, b);
  };

  // Join collinear edges around each point: every pair while few, else neighbours in direction
  // order (runs through a point with more edges than the cap can then be missed, never invented).
  Sets sets(ne);
  {
    std::vector<uint32_t> start(np + 1, 0);
    uint32_t a, b;
    for (uint32_t id = 0; id < uint32_t(ne); ++id) {
      ends(id, a, b);
      if (a != b) ++start[a + 1], ++start[b + 1];
    }
    for (size_t p = 0; p < np; ++p) start[p + 1] += start[p];
    std::vector<uint32_t> incident(start[np]);
    {
      std::vector<uint32_t> fill(start.begin(), start.end() - 1);
      for (uint32_t id = 0; id < uint32_t(ne); ++id) {
        ends(id, a, b);
        if (a != b) incident[fill[a]++] = id, incident[fill[b]++] = id;
      }
    }
    std::vector<std::pair<Vec3, uint32_t>> around;
    for (size_t p = 0; p < np; ++p) {
      const uint32_t* first = incident.data() + start[p];
      const size_t k = start[p + 1] - start[p];
      if (k < 2) continue;
      const Vec3 X = point_pos[p];
      auto away = [&](uint32_t id) {
        uint32_t u, v;
        ends(id, u, v);
        return point_pos[u == p ? v : u] - X;
      };
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
  }

  // The edges of sets of two or more, as (root, id), by root; per run its extreme points, and
  // whether it holds two distinct edges (a run of one edge, or of copies of one shared edge,
  // computes its coefficients from its own points already).
  size_t grouped = 0;
  for (uint32_t id = 0; id < uint32_t(ne); ++id) grouped += sets.find(id) != id;
  std::vector<uint64_t> members;
  members.reserve(2 * grouped);  // the members, then at most as many roots
  for (uint32_t id = 0; id < uint32_t(ne); ++id) {
    const uint32_t r = sets.find(id);
    if (r != id) members.push_back(uint64_t(r) << 32 | id);
  }
  if (members.empty()) return el;
  {
    const size_t k = members.size();  // the roots themselves (repeats removed below)
    for (size_t i = 0; i < k; ++i) {
      const uint64_t r = members[i] >> 32;
      if (i == 0 || (members[i - 1] >> 32) != r) members.push_back(r << 32 | r);
    }
  }
  tbb::parallel_sort(members.begin(), members.end());
  members.erase(std::unique(members.begin(), members.end()), members.end());
  for (size_t i = 0; i < members.size();) {
    const uint64_t r = members[i] >> 32;
    size_t j = i;
    uint32_t lo = UINT32_MAX, hi = 0, a0 = 0, b0 = 0;
    bool distinct = false;
    for (; j < members.size() && (members[j] >> 32) == r; ++j) {
      uint32_t a, b;
      ends(uint32_t(members[j]), a, b);
      if (j == i) a0 = a, b0 = b;
      distinct = distinct || a != a0 || b != b0;
      lo = std::min(lo, a);
      hi = std::max(hi, b);
    }
    if (distinct) {
      if (el.edge_line.empty()) el.edge_line.assign(ne, EdgeLines::kNone);
      const uint32_t l = uint32_t(el.lines.size());
      el.lines.push_back({point_pos[lo], point_pos[hi]});
      for (size_t m = i; m < j; ++m) el.edge_line[uint32_t(members[m])] = l;
    }
    i = j;
  }
  return el;
}

}  // namespace vislib
