// wall_traces.cpp: the traces of walls across the middle of a box cell's eye band (wall_traces.h).
#include "vislib/bake/wall_traces.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <optional>

#include "vislib/bake/view_cells.h"

namespace vislib {

namespace {

// Relative tolerance (of the cell's longer side) within which two pieces' ends touch and two
// pieces are parallel.
constexpr double kJoinTolerance = 1e-9;

double cell_side(const Box3& r) {
  return std::max(r.max.x - r.min.x, r.max.z - r.min.z);
}

// The front normal of a triangle and whether the triangle is a wall (kWallTraceMinTiltDegrees).
Vec3 front_normal(const std::array<Vec3, 3>& c, const WallTraceOptions& o) {
  const Vec3 n = cross(c[1] - c[0], c[2] - c[0]);
  return o.clockwise_front ? -n : n;
}
bool is_wall(Vec3 n) {
  const double sin_tilt = std::sin(kWallTraceMinTiltDegrees * M_PI / 180.0);
  const double len = length(n);
  return len > 0 && std::hypot(n.x, n.z) >= len * sin_tilt;
}

// The trace of wall triangle `c` (is_wall) at height y = h (wall_traces.h), unclipped; none when
// it does not cross h along a segment.
std::optional<Segment> raw_trace(const std::array<Vec3, 3>& c, double h,
                                 const WallTraceOptions& o) {
  const Vec3 n = front_normal(c, o);
  const double len = length(n), horizontal = std::hypot(n.x, n.z);
  Vec3 p[3];
  int k = 0;
  for (int e = 0; e < 3 && k < 3; ++e) {
    const Vec3 a = c[size_t(e)], b = c[size_t((e + 1) % 3)];
    const double da = a.y - h, db = b.y - h;
    if (da == 0) {
      p[k++] = a;
    } else if ((da < 0 && db > 0) || (da > 0 && db < 0)) {
      Vec3 q = a + (b - a) * (da / (da - db));
      q.y = h;
      p[k++] = q;
    }
  }
  if (k < 2) return std::nullopt;
  const Vec3 q = k == 3 && p[0] == p[1] ? p[2] : p[1];  // a vertex at h counted twice
  if (p[0] == q) return std::nullopt;
  // Off the wall to its front: a horizontal move s along n's horizontal direction is s * horizontal
  // / len from the plane.
  const Vec3 shift = Vec3{n.x, 0, n.z} * (o.clearance * len / (horizontal * horizontal));
  return Segment{p[0] + shift, q + shift};
}

// `s` clipped to the x/z rectangle of `r` (Liang-Barsky); none when nothing is left.
std::optional<Segment> clip_to_rectangle(const Segment& s, const Box3& r) {
  double t0 = 0, t1 = 1;
  const Vec3 d = s.to - s.from;
  for (int axis : {0, 2}) {
    const double lo = r.min[axis] - s.from[axis], hi = r.max[axis] - s.from[axis];
    if (d[axis] == 0) {
      if (lo > 0 || hi < 0) return std::nullopt;
      continue;
    }
    double a = lo / d[axis], b = hi / d[axis];
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
  }
  if (!(t0 < t1)) return std::nullopt;
  Segment out = s;
  out.from = s.from + d * t0;
  out.to = s.from + d * t1;
  return out;
}

// Joins `b` into `a` when they are parallel and an end of one touches an end of the other, so that
// their union is one segment (lengths add up); returns whether it did.
bool join(Segment& a, const Segment& b, double tol) {
  const Vec3 u = a.to - a.from, w = b.to - b.from;
  const double lu = length(u), lw = length(w);
  if (length(cross(u, w)) > kJoinTolerance * lu * lw) return false;
  const Vec3 ends[4][2] = {{a.from, b.to}, {b.from, a.to}, {a.from, b.from}, {a.to, b.to}};
  const bool touch[4] = {length(a.to - b.from) <= tol, length(a.from - b.to) <= tol,
                         length(a.to - b.to) <= tol, length(a.from - b.from) <= tol};
  for (int k = 0; k < 4; ++k) {
    if (!touch[k]) continue;
    const Vec3 f = ends[k][0], t = ends[k][1];
    if (std::abs(length(t - f) - (lu + lw)) > tol) continue;  // overlapping, not continuing
    a.from = f;
    a.to = t;
    return true;
  }
  return false;
}

// The traces of `candidates` (increasing triangle ids) in `region` (wall_traces.h).
std::vector<Segment> traces_of(const Scene& scene, const Box3& region,
                               const std::vector<uint32_t>& candidates, const WallTraceOptions& o) {
  const double h = 0.5 * (region.min.y + region.max.y), side = cell_side(region);
  const double tol = kJoinTolerance * side, min_length = kWallTraceMinLengthFraction * side;
  std::vector<Segment> out;
  for (uint32_t t : candidates) {
    const std::array<Vec3, 3> c = scene.corners(t, o.state);
    if (std::min({c[0].y, c[1].y, c[2].y}) > h || std::max({c[0].y, c[1].y, c[2].y}) < h) continue;
    const std::optional<Segment> raw = raw_trace(c, h, o);
    if (!raw) continue;
    std::optional<Segment> s = clip_to_rectangle(*raw, region);
    if (!s || !(length(s->to - s->from) > tol)) continue;
    bool joined = false;
    for (Segment& e : out)
      if (join(e, *s, tol)) {
        joined = true;
        break;
      }
    if (!joined) out.push_back(*s);
  }
  // A join can make two earlier pieces touch: join until none does.
  for (bool again = true; again;) {
    again = false;
    for (size_t i = 0; i < out.size() && !again; ++i)
      for (size_t j = i + 1; j < out.size(); ++j)
        if (join(out[i], out[j], tol)) {
          out.erase(out.begin() + std::ptrdiff_t(j));
          again = true;
          break;
        }
  }
  out.erase(
      std::remove_if(out.begin(), out.end(),
                     [&](const Segment& s) { return !(length(s.to - s.from) >= min_length); }),
      out.end());
  return out;
}

}  // namespace

std::vector<Segment> wall_traces(const Scene& scene, const Box3& view_region,
                                 const WallTraceOptions& options) {
  assert(options.clearance > 0);
  std::vector<uint32_t> all;
  for (uint32_t t = 0; t < scene.triangle_count(); ++t)
    if (is_wall(front_normal(scene.corners(t, options.state), options))) all.push_back(t);
  return traces_of(scene, view_region, all, options);
}

std::vector<std::vector<Segment>> wall_traces(const Scene& scene, const pvs::CellLayout& layout,
                                              const WallTraceOptions& options) {
  assert(options.clearance > 0);
  const uint32_t n = layout.cell_count();
  std::vector<std::vector<Segment>> out(n);
  if (n == 0) return out;
  // Wall triangles binned over a grid in x and z whose bins are the largest cell's side, so that
  // a cell reads the few bins its rectangle overlaps, not the whole scene.
  Box3 all;
  double side = 0;
  for (uint32_t c = 0; c < n; ++c) {
    const Box3 r = to_box3(layout.view_region(c));
    all.extend(r.min);
    all.extend(r.max);
    side = std::max(side, cell_side(r));
  }
  constexpr double kMaxBins = double(1 << 22);
  const double ex = all.max.x - all.min.x, ez = all.max.z - all.min.z;
  if (!(side > 0)) side = std::max({ex, ez, 1.0});
  while ((std::floor(ex / side) + 1) * (std::floor(ez / side) + 1) > kMaxBins) side *= 2;
  const int bx = int(std::floor(ex / side)) + 1, bz = int(std::floor(ez / side)) + 1;
  const auto bin_of = [&](double v, double lo, int count) {
    return std::clamp(int(std::floor((v - lo) / side)), 0, count - 1);
  };
  std::vector<std::vector<uint32_t>> bins(size_t(bx) * size_t(bz));
  for (uint32_t t = 0; t < scene.triangle_count(); ++t) {
    const std::array<Vec3, 3> c = scene.corners(t, options.state);
    if (!is_wall(front_normal(c, options))) continue;
    Box3 b;
    for (const Vec3& p : c) b.extend(p);
    if (b.max.x < all.min.x || b.min.x > all.max.x || b.max.z < all.min.z || b.min.z > all.max.z ||
        b.max.y < all.min.y || b.min.y > all.max.y)
      continue;
    for (int z = bin_of(b.min.z, all.min.z, bz); z <= bin_of(b.max.z, all.min.z, bz); ++z)
      for (int x = bin_of(b.min.x, all.min.x, bx); x <= bin_of(b.max.x, all.min.x, bx); ++x)
        bins[size_t(z) * size_t(bx) + size_t(x)].push_back(t);
  }
  tbb::parallel_for(uint32_t(0), n, [&](uint32_t cell) {
    const Box3 r = to_box3(layout.view_region(cell));
    std::vector<uint32_t> candidates;
    for (int z = bin_of(r.min.z, all.min.z, bz); z <= bin_of(r.max.z, all.min.z, bz); ++z)
      for (int x = bin_of(r.min.x, all.min.x, bx); x <= bin_of(r.max.x, all.min.x, bx); ++x) {
        const std::vector<uint32_t>& b = bins[size_t(z) * size_t(bx) + size_t(x)];
        candidates.insert(candidates.end(), b.begin(), b.end());
      }
    std::sort(candidates.begin(), candidates.end());
    candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
    out[cell] = traces_of(scene, r, candidates, options);
  });
  return out;
}

}  // namespace vislib
