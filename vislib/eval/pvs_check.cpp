// pvs_check.cpp: the sampled ground truth of a bake (pvs_check.h): eyes drawn in view regions,
// Embree cubemaps from them, and every hit missing from a set re-cast in double by the
// brute-force reference (ray_reference.h) under the seeing rule of vis_compare.h.
#include "vislib/eval/pvs_check.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>

#include "vislib/eval/ray_reference.h"
#include "vislib/eval/seeing_rule.h"
#include "vislib/scene/quake_bsp.h"

namespace vislib {
namespace {

bool inside(const ConvexPolytope& p, Vec3 q) {
  for (const HalfSpace& h : p.halfspaces)
    if (dot(h.normal, q) > h.offset) return false;
  return true;
}

// A random point of a leaf region (Quake coordinates).
Vec3 random_leaf_point(const ConvexPolytope& p, const std::vector<Vec3>& c, Rng& rng) {
  const Box3 b = p.bounds();
  for (int i = 0; i < kEyeRejectionTries; ++i) {
    const Vec3 q{rng.uniform(b.min.x, b.max.x), rng.uniform(b.min.y, b.max.y),
                 rng.uniform(b.min.z, b.max.z)};
    if (inside(p, q)) return q;
  }
  Vec3 sum{0, 0, 0};
  double w = 0;
  for (const Vec3& q : c) {
    const double wi = -std::log(1.0 - rng.uniform());
    sum = sum + q * wi;
    w += wi;
  }
  return sum * (1.0 / w);
}

// One hit `x` of the ray (eye, dir): for each set missing it, the optional plane pre-filter,
// then one double-precision re-cast shared by the sets.
void check_hit(const Scene& scene, const EmbreeScene& embree, const SampleSettings& st, Vec3 eye,
               Vec3 dir, uint32_t x, std::vector<SampledSet>& sets, std::vector<uint8_t>& need,
               SampleTally& tally) {
  bool any = false;
  for (size_t i = 0; i < sets.size(); ++i) any |= (need[i] = !(*sets[i].in_set)[x]) != 0;
  if (!any) return;
  if (st.tri_plane && !scene.triangle_see_through(x)) {
    const std::vector<uint32_t>& plane = *st.tri_plane;
    const Hit g = embree.first_hit_excluding(eye, dir, st.z_near, x);
    if (g.tri != kNoHit && plane[g.tri] != kNoTrianglePlane && plane[g.tri] == plane[x]) {
      any = false;
      for (size_t i = 0; i < sets.size(); ++i) {
        if ((*sets[i].in_set)[g.tri]) need[i] = 0;
        any |= need[i] != 0;
      }
    }
    if (!any) return;
  }
  const std::vector<RayCrossing> cr =
      st.crossings ? st.crossings->crossings(eye, dir) : ray_crossings(scene, 0, eye, dir);
  const SeeingRule rule{scene, st.z_near, st.eps_z};
  const double lambda = rule.seen_depth(cr, x);
  if (lambda < 0) {
    ++tally.ambiguous;
    return;
  }
  for (size_t i = 0; i < sets.size(); ++i) {
    SampledSet& s = sets[i];
    if (!need[i] || rule.set_at_depth(cr, lambda, *s.in_set)) continue;
    if (s.excused && (*s.excused)[x]) {
      ++s.excused_misses;
    } else {
      ++s.misses;
      s.missed.push_back(x);
    }
  }
}

void sort_unique(std::vector<uint32_t>& v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
}

}  // namespace

std::vector<Vec3> polytope_corners(const ConvexPolytope& p) {
  std::vector<Vec3> v;
  for (const auto& f : p.faces)
    for (const Vec3& q : f)
      if (std::find(v.begin(), v.end(), q) == v.end()) v.push_back(q);
  return v;
}

EyeRegion box_eye_region(const Box3& box) {
  assert(box.min.x <= box.max.x && box.min.y <= box.max.y && box.min.z <= box.max.z);
  EyeRegion r;
  r.kind = EyeRegion::box_region;
  r.box = box;
  return r;
}

void for_cells_in_chunks(size_t n, const std::function<void(size_t)>& one_cell,
                         const std::function<void(size_t, size_t)>& progress) {
  constexpr size_t kChunk = 64;  // cells between two progress reports
  for (size_t first = 0; first < n; first += kChunk) {
    const size_t last = std::min(n, first + kChunk);
    tbb::parallel_for(first, last, one_cell);
    if (progress) progress(last, n);
  }
}

std::vector<EyeRegion> bsp_leaf_eye_regions(const QuakeBsp& bsp,
                                            const std::vector<uint32_t>& leaves, double near,
                                            std::vector<double>* insets) {
  std::vector<int64_t> piece_of(bsp.leaves.size(), -1);
  const std::vector<BspLeafPiece> pieces = bsp_leaf_pieces(bsp);
  for (size_t i = 0; i < pieces.size(); ++i)
    if (pieces[i].leaf != 0) piece_of[pieces[i].leaf] = int64_t(i);
  std::vector<EyeRegion> regions(leaves.size());
  if (insets) insets->assign(leaves.size(), 0.0);
  tbb::parallel_for(size_t(0), leaves.size(), [&](size_t c) {
    const uint32_t leaf = leaves[c];
    if (leaf >= piece_of.size() || piece_of[leaf] < 0) return;
    BspViewRegion v = bsp_leaf_view_region(pieces[size_t(piece_of[leaf])].volume, near);
    regions[c].near_limit = v.near_limit;
    regions[c].leaf = std::move(v.volume);
    regions[c].leaf_corners = polytope_corners(regions[c].leaf);
    if (!regions[c].leaf_corners.empty()) regions[c].kind = EyeRegion::leaf_region;
    if (insets) (*insets)[c] = v.inset;
  });
  return regions;
}

Vec3 random_eye(const EyeRegion& r, Rng& rng) {
  assert(r.kind != EyeRegion::none);
  if (r.kind == EyeRegion::leaf_region)
    return quake_to_scene(random_leaf_point(r.leaf, r.leaf_corners, rng));
  const double x = rng.uniform(r.box.min.x, r.box.max.x);
  const double y = rng.uniform(r.box.min.y, r.box.max.y);
  const double z = rng.uniform(r.box.min.z, r.box.max.z);
  return {x, y, z};
}

void sample_eye(const Scene& scene, const EmbreeScene& embree, const SampleSettings& st, Vec3 eye,
                std::vector<SampledSet>& sets, SampleTally& tally) {
  assert(st.resolution >= 1 && st.z_near > 0 && !sets.empty());
  const int n = st.resolution;
  std::vector<Vec3> dirs(static_cast<size_t>(n));
  std::vector<Hit> hits(static_cast<size_t>(n));
  std::vector<uint32_t> passed;
  std::vector<uint8_t> need(sets.size(), 0);
  const bool see_through = embree.has_see_through();
  auto in_every_set = [&](uint32_t t) {
    for (const SampledSet& s : sets)
      if (!(*s.in_set)[t]) return false;
    return true;
  };
  for (const Mat3& orientation : st.orientations) {
    FaceAxes axes[kCubeFaces];
    for (int k = 0; k < kCubeFaces; ++k) axes[k] = face_axes(k, orientation);
    for (int k = 0; k < kCubeFaces; ++k) {
      for (int y = 0; y < n; ++y) {
        for (int x = 0; x < n; ++x) dirs[size_t(x)] = pixel_direction(axes[k], x, y, n);
        bool redo = false;
        if (see_through) {
          passed.clear();
          embree.hits_through(eye, dirs.data(), size_t(n), st.z_near, hits.data(), passed);
          for (uint32_t p : passed)
            if (!in_every_set(p)) redo = true;
        } else {
          embree.first_hits(eye, dirs.data(), size_t(n), st.z_near, hits.data());
        }
        tally.rays += uint64_t(n);
        for (int x = 0; x < n; ++x) {
          const Vec3 d = dirs[size_t(x)];
          if (redo) {  // this row passed a see-through triangle missing from a set: ray by ray
            Hit h;
            passed.clear();
            embree.hits_through(eye, &d, 1, st.z_near, &h, passed);
            sort_unique(passed);
            for (uint32_t p : passed) check_hit(scene, embree, st, eye, d, p, sets, need, tally);
          }
          const uint32_t h = hits[size_t(x)].tri;
          if (h == kNoHit) {
            ++tally.no_hit;
            continue;
          }
          check_hit(scene, embree, st, eye, d, h, sets, need, tally);
        }
      }
    }
  }
}

PvsCheckResult pvs_check(const Scene& scene, const std::vector<EyeRegion>& regions,
                         const std::vector<std::vector<uint32_t>>& sets,
                         const PvsCheckOptions& options,
                         const std::function<void(size_t, size_t)>& progress) {
  assert(regions.size() == sets.size() && options.samples >= 1);
  const size_t tris = scene.triangle_count();
  const Box3 bounds = scene.bounds();
  const EmbreeScene embree(scene, 0, tris ? (bounds.min + bounds.max) * 0.5 : Vec3{0, 0, 0});
  const RayCrossingIndex crossings(scene, 0);
  SampleSettings settings = options.sample;
  settings.tri_plane = nullptr;
  settings.crossings = &crossings;
  PvsCheckResult result;
  result.cells.resize(regions.size());
  auto one_cell = [&](size_t c) {
    PvsCheckCell& row = result.cells[c];
    row.cell = uint32_t(c);
    row.set_size = sets[c].size();
    if (regions[c].kind == EyeRegion::none) return;
    std::vector<uint8_t> in_set(tris, 0);
    for (uint32_t t : sets[c]) in_set[t] = 1;
    std::vector<SampledSet> one(1);
    one[0].in_set = &in_set;
    Rng rng(Rng::derive(options.seed, c));
    SampleSettings cell_settings = settings;
    cell_settings.z_near = std::min(settings.z_near, regions[c].near_limit);
    const bool test_free = options.in_solid && regions[c].kind == EyeRegion::box_region;
    for (int s = 0; s < options.samples; ++s) {
      Vec3 eye;
      int rejected = 0;
      bool free = false;
      while (!free && rejected < kEyeRedraws) {
        eye = random_eye(regions[c], rng);
        free = !test_free || !options.in_solid(eye);
        rejected += !free;
      }
      row.eyes_redrawn += uint64_t(rejected);
      if (!free) {
        ++row.eyes_given_up;
        continue;
      }
      ++row.eyes;
      sample_eye(scene, embree, cell_settings, eye, one, row.tally);
    }
    row.miss_rays = one[0].misses;
    std::vector<uint32_t>& m = one[0].missed;
    std::sort(m.begin(), m.end());
    for (size_t i = 0; i < m.size();) {
      size_t j = i;
      while (j < m.size() && m[j] == m[i]) ++j;
      row.missed.emplace_back(m[i], uint64_t(j - i));
      i = j;
    }
  };
  for_cells_in_chunks(regions.size(), one_cell, progress);
  return result;
}

PvsCheckTotals pvs_check_totals(const PvsCheckResult& r) {
  PvsCheckTotals t;
  std::vector<uint32_t> tris;
  for (const PvsCheckCell& c : r.cells) {
    t.eyes += uint64_t(c.eyes), t.eyes_redrawn += c.eyes_redrawn;
    t.eyes_given_up += uint64_t(c.eyes_given_up);
    t.rays += c.tally.rays, t.no_hit += c.tally.no_hit, t.ambiguous += c.tally.ambiguous;
    t.miss_rays += c.miss_rays;
    t.cells_with_misses += !c.missed.empty();
    t.missed_pairs += c.missed.size();
    for (const auto& m : c.missed) tris.push_back(m.first);
  }
  sort_unique(tris);
  t.missed_triangles = tris.size();
  return t;
}

std::string pvs_check_json(const PvsCheckResult& r, const std::string& header_json) {
  using nlohmann::json;
  json j = json::parse(header_json);
  assert(j.is_object());
  const PvsCheckTotals t = pvs_check_totals(r);
  j["totals"] = {{"cells", r.cells.size()},
                 {"eyes", t.eyes},
                 {"eyes_redrawn", t.eyes_redrawn},
                 {"eyes_given_up", t.eyes_given_up},
                 {"sampled_rays", t.rays},
                 {"no_hit", t.no_hit},
                 {"ambiguous", t.ambiguous},
                 {"miss_rays", t.miss_rays},
                 {"cells_with_misses", t.cells_with_misses},
                 {"missed_pairs", t.missed_pairs},
                 {"missed_triangles", t.missed_triangles}};
  json rows = json::array();
  std::map<uint32_t, std::pair<std::vector<uint32_t>, uint64_t>> by_triangle;
  for (const PvsCheckCell& c : r.cells) {
    json missed = json::array();
    for (const auto& [tri, rays] : c.missed) {
      missed.push_back({{"triangle", tri}, {"miss_rays", rays}});
      auto& b = by_triangle[tri];
      b.first.push_back(c.cell);
      b.second += rays;
    }
    rows.push_back({{"cell", c.cell},
                    {"set_size", c.set_size},
                    {"eyes", c.eyes},
                    {"eyes_redrawn", c.eyes_redrawn},
                    {"eyes_given_up", c.eyes_given_up},
                    {"sampled_rays", c.tally.rays},
                    {"no_hit", c.tally.no_hit},
                    {"ambiguous", c.tally.ambiguous},
                    {"miss_rays", c.miss_rays},
                    {"missed", missed}});
  }
  j["per_cell"] = rows;
  json tri_rows = json::array();
  for (const auto& [tri, b] : by_triangle)
    tri_rows.push_back({{"triangle", tri}, {"cells", b.first}, {"miss_rays", b.second}});
  j["per_triangle"] = tri_rows;
  return j.dump(1);
}

}  // namespace vislib
