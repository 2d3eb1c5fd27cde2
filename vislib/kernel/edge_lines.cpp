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

EdgeLines build_edge_lines(const Scene& scene, size_t state, size_t incident_budget) {
  EdgeLines el;
  el.scene = &scene;
  el.state = state;
  const size_t n = scene.triangle_count();
  el.triangle_count = n;
  if (n == 0) return el;
  if (state >= scene.positions.size())
    throw std::invalid_argument("edge lines: key state " + std::to_string(state) + " out of range");
  // Edge ids (3 per triangle) stay below 2^31: the run marks take the top bit.
  if (3 * n >= (size_t(1) << 31))
    throw std::invalid_argument("too many triangles for the edge lines");
  const std::vector<Vec3>& pos = scene.positions[state];
  for (const Vec3& p : pos)
    if (!is_finite(p)) return el;  // no order to build on; the kernel refuses such scenes anyway

  // Points: distinct positions, numbered in lexicographic order (so the smaller id of an edge's
  // endpoints is its canonical P, and the extreme ids of a run are its line's ends), each kept as
  // one vertex of that position (4 bytes a point rather than its 24).
  const size_t V = pos.size();
  std::vector<uint32_t> point(V);
  std::vector<uint32_t> point_vertex;
  {
    std::vector<uint32_t> by_pos(V);
    std::iota(by_pos.begin(), by_pos.end(), 0u);
    // A strict total order (ties by index): the parallel sort's result is the only one.
    tbb::parallel_sort(by_pos.begin(), by_pos.end(), [&](uint32_t a, uint32_t b) {
      if (pos[a] != pos[b]) return lex_less(pos[a], pos[b]);
      return a < b;
    });
    for (size_t i = 0; i < V; ++i) {
      if (i == 0 || pos[by_pos[i]] != pos[by_pos[i - 1]]) point_vertex.push_back(by_pos[i]);
      point[by_pos[i]] = uint32_t(point_vertex.size() - 1);
    }
  }
  const size_t np = point_vertex.size();
  auto point_pos = [&](uint32_t p) { return pos[point_vertex[p]]; };

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
  // The points are taken in ranges whose incident lists hold at most `incident_budget`
  // entries (each range scans every edge once more), so that memory stays bounded.
  Sets sets(ne);
  {
    std::vector<uint32_t> degree(np, 0);
    uint32_t a, b;
    for (uint32_t id = 0; id < uint32_t(ne); ++id) {
      ends(id, a, b);
      if (a != b) ++degree[a], ++degree[b];
    }
    std::vector<uint32_t> start, incident;
    std::vector<std::pair<Vec3, uint32_t>> around;
    for (size_t p0 = 0; p0 < np;) {
      size_t p1 = p0, entries = 0;  // the range [p0, p1): at least one point
      while (p1 < np && (p1 == p0 || entries + degree[p1] <= incident_budget))
        entries += degree[p1++];
      start.assign(p1 - p0 + 1, 0);
      for (size_t p = p0; p < p1; ++p) start[p - p0 + 1] = start[p - p0] + degree[p];
      incident.resize(entries);
      std::vector<uint32_t> fill(start.begin(), start.end() - 1);
      for (uint32_t id = 0; id < uint32_t(ne); ++id) {
        ends(id, a, b);
        if (a == b) continue;
        if (a >= p0 && a < p1) incident[fill[a - p0]++] = id;
        if (b >= p0 && b < p1) incident[fill[b - p0]++] = id;
      }
      for (size_t p = p0; p < p1; ++p) {
        const uint32_t* first = incident.data() + start[p - p0];
        const size_t k = degree[p];
        if (k < 2) continue;
        const Vec3 X = point_pos(uint32_t(p));
        auto away = [&](uint32_t id) {
          uint32_t u, v;
          ends(id, u, v);
          return point_pos(u == p ? v : u) - X;
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
      p0 = p1;
    }
  }

  // Runs: the sets of two or more edges, numbered by their root (the set's smallest id), in place
  // in the parent array: a root with members gets kRunFlag | its run, a member its root. Per run
  // its extreme points, and whether it holds two distinct edges (a run of one edge, or of copies
  // of one shared edge, computes its coefficients from its own points already).
  constexpr uint32_t kRunFlag = 0x80000000u;  // edge ids stay below 2^31 (at most 3 * 2^30)
  std::vector<uint32_t>& parent = sets.parent;
  for (uint32_t id = 0; id < uint32_t(ne); ++id) parent[id] = sets.find(id);  // roots are smaller
  for (uint32_t id = 0; id < uint32_t(ne); ++id)
    if (parent[id] != id) parent[parent[id]] |= kRunFlag;  // marks a root with members
  struct Run {
    uint32_t lo = UINT32_MAX, hi = 0, a0 = 0, b0 = 0;
    bool distinct = false;
  };
  std::vector<Run> runs;
  size_t run_count = 0;  // vectors of the exact size: a doubling one would hold twice as much
  for (uint32_t id = 0; id < uint32_t(ne); ++id) run_count += parent[id] == (id | kRunFlag);
  runs.reserve(run_count);
  for (uint32_t id = 0; id < uint32_t(ne); ++id)
    if (parent[id] == (id | kRunFlag)) {
      parent[id] = kRunFlag | uint32_t(runs.size());
      runs.emplace_back();
    }
  auto run_of = [&](uint32_t id) {
    const uint32_t v = parent[id];
    return (v & kRunFlag) ? v & ~kRunFlag : parent[v] & ~kRunFlag;
  };
  if (runs.empty()) return el;
  for (uint32_t id = 0; id < uint32_t(ne); ++id) {
    const uint32_t v = parent[id];
    if (!(v & kRunFlag) && v == id) continue;  // an edge of no run
    Run& r = runs[run_of(id)];
    uint32_t a, b;
    ends(id, a, b);
    if (v & kRunFlag) {  // the root: the first edge of its run
      r.a0 = a;
      r.b0 = b;
    }
    r.distinct = r.distinct || a != r.a0 || b != r.b0;
    r.lo = std::min(r.lo, a);
    r.hi = std::max(r.hi, b);
  }
  // Lines for the runs of distinct edges, in root order; a run's lo becomes its line (or kNone).
  point = {};
  el.lines.reserve(
      size_t(std::count_if(runs.begin(), runs.end(), [](const Run& r) { return r.distinct; })));
  for (Run& r : runs) {
    if (r.distinct) {
      el.lines.push_back({point_pos(r.lo), point_pos(r.hi)});
      r.lo = uint32_t(el.lines.size() - 1);
    } else {
      r.lo = EdgeLines::kNone;
    }
  }
  if (el.lines.empty()) return el;
  point_vertex = {};
  // The parent array becomes edge_line: from the last id down, so that a member reads its root's
  // run before the root (its smaller id) is overwritten.
  for (uint32_t id = uint32_t(ne); id-- > 0;) {
    const uint32_t v = parent[id];
    parent[id] = (!(v & kRunFlag) && v == id) ? EdgeLines::kNone : runs[run_of(id)].lo;
  }
  el.edge_line = std::move(parent);
  return el;
}

}  // namespace vislib
