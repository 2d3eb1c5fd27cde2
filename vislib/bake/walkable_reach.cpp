// walkable_reach.cpp: reachable floor for an agent, over Recast's compact heightfield
// (recastnavigation: rcRasterizeTriangles, rcFilterLowHangingWalkableObstacles,
// rcFilterWalkableLowHeightSpans, rcBuildCompactHeightfield, rcErodeWalkableArea), with a flood
// fill of our own over its connections and over drops (Recast's navigation mesh stages after the
// compact heightfield are not needed: reachability is a question about spans).
#include "vislib/bake/walkable_reach.h"

#include <recastnavigation/Recast.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <deque>
#include <stdexcept>

namespace vislib {

bool floor_triangle(const std::array<Vec3, 3>& c, double max_slope_degrees, bool clockwise_front) {
  const Vec3 n = cross(c[1] - c[0], c[2] - c[0]) * (clockwise_front ? -1.0 : 1.0);
  const double len = length(n);
  return len > 0 && n.y > 0 && n.y >= std::cos(max_slope_degrees * M_PI / 180.0) * len;
}

bool ReachableFloor::any_in(double x0, double x1, double z0, double z1, double y0,
                            double y1) const {
  if (width == 0 || depth == 0) return false;
  // Columns whose centre min + (i + 0.5) * voxel lies in [x0, x1).
  auto first = [&](double lo, double v0) {
    return std::max(0.0, std::ceil((v0 - lo) / voxel - 0.5));
  };
  const double i0 = first(min_x, x0), i1 = std::min(double(width), first(min_x, x1));
  const double k0 = first(min_z, z0), k1 = std::min(double(depth), first(min_z, z1));
  for (double k = k0; k < k1; ++k)
    for (double i = i0; i < i1; ++i)
      for (double y : columns[size_t(k) * size_t(width) + size_t(i)])
        if (y >= y0 && y <= y1) return true;
  return false;
}

size_t ReachableFloor::floor_count() const {
  size_t n = 0;
  for (const auto& c : columns) n += c.size();
  return n;
}

namespace {

// Owns Recast's heightfields.
struct Heightfields {
  rcHeightfield* solid = rcAllocHeightfield();
  rcCompactHeightfield* open = rcAllocCompactHeightfield();
  ~Heightfields() {
    rcFreeHeightField(solid);
    rcFreeCompactHeightfield(open);
  }
};

[[noreturn]] void recast_failed(const char* stage) {
  throw std::runtime_error(std::string("walkable reachability: Recast failed in ") + stage +
                           " (out of memory?)");
}

}  // namespace

ReachableFloor reachable_floor(const Scene& scene, const ReachOptions& o) {
  assert(!o.starts.empty() && scene.triangle_count() > 0);
  assert(o.agent.height > 0 && o.agent.radius >= 0 && o.agent.step >= 0 && o.voxel > 0);
  const Box3 b = scene.bounds();
  ReachableFloor out;
  // Voxel side: at most kMaxReachColumns columns over the bounds.
  const double ex = b.max.x - b.min.x, ez = b.max.z - b.min.z, ey = b.max.y - b.min.y;
  double cs =
      std::max(o.voxel, std::sqrt(std::max(ex, 0.0) * std::max(ez, 0.0) / kMaxReachColumns));
  // Voxel height: an eighth of the agent's height and at most half its step, raised so that the
  // agent's height is at most 250 voxels (Recast stores a span's clearance in 8 bits) and the
  // scene's height at most 8,000 (its spans' heights in 13 bits).
  double ch = o.agent.height / 8;
  if (o.agent.step > 0) ch = std::min(ch, o.agent.step / 2);
  ch = std::max({ch, o.agent.height / 250, ey / 8000});
  out.voxel = cs;
  out.voxel_height = ch;
  // One voxel of margin all round (and the agent's height above the top).
  const float bmin[3] = {float(b.min.x - cs), float(b.min.y - ch), float(b.min.z - cs)};
  const float bmax[3] = {float(b.max.x + cs), float(b.max.y + o.agent.height + ch),
                         float(b.max.z + cs)};
  out.min_x = bmin[0];
  out.min_z = bmin[2];
  rcCalcGridSize(bmin, bmax, float(cs), &out.width, &out.depth);
  const int walk_height = std::max(3, int(std::floor(o.agent.height / ch)));  // errs: lower passes
  const int walk_climb = int(std::ceil(o.agent.step / ch));  // errs: higher steps climbed
  const int walk_radius = int(std::floor(o.agent.radius / cs));

  rcContext ctx(false);
  Heightfields hf;
  if (!hf.solid || !hf.open) recast_failed("allocation");
  if (!rcCreateHeightfield(&ctx, *hf.solid, out.width, out.depth, bmin, bmax, float(cs), float(ch)))
    recast_failed("rcCreateHeightfield");
  // Every triangle is solid; floor triangles are walkable. Degenerate ones are left out.
  std::vector<float> verts;
  std::vector<unsigned char> areas;
  verts.reserve(scene.triangle_count() * 9);
  areas.reserve(scene.triangle_count());
  for (uint32_t t = 0; t < scene.triangle_count(); ++t) {
    const auto c = scene.corners(t, o.state);
    if (!(length(cross(c[1] - c[0], c[2] - c[0])) > 0)) continue;
    for (const Vec3& v : c) verts.insert(verts.end(), {float(v.x), float(v.y), float(v.z)});
    areas.push_back(floor_triangle(c, o.max_slope_degrees, o.clockwise_front) ? RC_WALKABLE_AREA
                                                                              : RC_NULL_AREA);
  }
  if (!rcRasterizeTriangles(&ctx, verts.data(), areas.data(), int(areas.size()), *hf.solid,
                            walk_climb))
    recast_failed("rcRasterizeTriangles");
  rcFilterLowHangingWalkableObstacles(&ctx, walk_climb, *hf.solid);
  rcFilterWalkableLowHeightSpans(&ctx, walk_height, *hf.solid);
  if (!rcBuildCompactHeightfield(&ctx, walk_height, walk_climb, *hf.solid, *hf.open))
    recast_failed("rcBuildCompactHeightfield");
  const rcCompactHeightfield& chf = *hf.open;
  const std::vector<unsigned char> walkable(chf.areas, chf.areas + chf.spanCount);
  if (walk_radius > 0 && !rcErodeWalkableArea(&ctx, walk_radius, *hf.open))
    recast_failed("rcErodeWalkableArea");

  const auto floor_y = [&](const rcCompactSpan& s) { return double(chf.bmin[1]) + s.y * ch; };
  const auto cell = [&](int x, int z) -> const rcCompactCell& {
    return chf.cells[size_t(x) + size_t(z) * size_t(chf.width)];
  };
  std::vector<uint8_t> reached(size_t(chf.spanCount), 0);
  std::deque<int> queue;  // span indices; their columns in `where`
  std::vector<std::array<int, 2>> where(size_t(chf.spanCount));
  for (int z = 0; z < chf.height; ++z)
    for (int x = 0; x < chf.width; ++x)
      for (unsigned i = cell(x, z).index, e = i + cell(x, z).count; i < e; ++i) where[i] = {x, z};
  const auto reach = [&](int i) {
    if (reached[size_t(i)] || walkable[size_t(i)] == RC_NULL_AREA) return;
    reached[size_t(i)] = 1;
    queue.push_back(i);
  };

  // The starts: the highest walkable floor at or below the point + the step, in the point's
  // column or the nearest one within the radius + 1 voxel (nearest ring, then nearest column,
  // then highest floor).
  const int ring = walk_radius + 1;
  for (const WalkStart& st : o.starts) {
    const int sx = int(std::floor((st.point.x - chf.bmin[0]) / cs));
    const int sz = int(std::floor((st.point.z - chf.bmin[2]) / cs));
    int best = -1;
    double best_d2 = INFINITY, best_y = -INFINITY;
    for (int r = 0; r <= ring && best < 0; ++r)
      for (int z = sz - r; z <= sz + r; ++z)
        for (int x = sx - r; x <= sx + r; ++x) {
          if (std::max(std::abs(x - sx), std::abs(z - sz)) != r) continue;
          if (x < 0 || z < 0 || x >= chf.width || z >= chf.height) continue;
          const double d2 = double(x - sx) * (x - sx) + double(z - sz) * (z - sz);
          for (unsigned i = cell(x, z).index, e = i + cell(x, z).count; i < e; ++i) {
            const double y = floor_y(chf.spans[i]);
            if (walkable[i] == RC_NULL_AREA || y > st.point.y + o.agent.step + ch) continue;
            if (d2 < best_d2 || (d2 == best_d2 && y > best_y)) {
              best = int(i);
              best_d2 = d2;
              best_y = y;
            }
          }
        }
    out.start_floors.push_back(best < 0 ? std::nullopt : std::optional<double>(best_y));
    if (best >= 0) reach(best);
  }

  // Flood fill: Recast's connections (a step of at most the climb, with headroom), and drops.
  while (!queue.empty()) {
    const int i = queue.front();
    queue.pop_front();
    const rcCompactSpan& s = chf.spans[i];
    const auto [x, z] = where[size_t(i)];
    for (int dir = 0; dir < 4; ++dir) {
      const int nx = x + rcGetDirOffsetX(dir), nz = z + rcGetDirOffsetY(dir);
      if (nx < 0 || nz < 0 || nx >= chf.width || nz >= chf.height) continue;
      const rcCompactCell& nc = cell(nx, nz);
      if (rcGetCon(s, dir) != RC_NOT_CONNECTED) {
        reach(int(nc.index) + rcGetCon(s, dir));
        continue;
      }
      // A drop: the open space of the next column that holds this floor's height, if its floor
      // is more than a step lower and it reaches the agent's head (a clearance of 255 voxels is
      // Recast's "255 or more").
      for (unsigned j = nc.index + nc.count; j-- > nc.index;) {
        const rcCompactSpan& t = chf.spans[j];
        if (t.y > s.y) continue;
        if (int(s.y) - int(t.y) > walk_climb &&
            (t.h >= 255 || int(t.y) + int(t.h) >= int(s.y) + walk_height))
          reach(int(j));
        break;
      }
    }
  }

  out.columns.assign(size_t(out.width) * size_t(out.depth), {});
  for (int z = 0; z < chf.height; ++z)
    for (int x = 0; x < chf.width; ++x)
      for (unsigned i = cell(x, z).index, e = i + cell(x, z).count; i < e; ++i)
        if (reached[i] && chf.areas[i] != RC_NULL_AREA)
          out.columns[size_t(z) * size_t(out.width) + size_t(x)].push_back(floor_y(chf.spans[i]));
  return out;
}

}  // namespace vislib
