// vis_compare.cpp: our sets of a Quake map's leaves against the map's own vis (vis_compare.h):
// counts, the witness search for each extra and the sampled ground truth, re-cast in double by
// the brute-force reference (ray_reference.h).
#include "vislib/eval/vis_compare.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

#include "vislib/base/cubemap.h"
#include "vislib/base/random.h"
#include "vislib/eval/embree_scene.h"
#include "vislib/eval/pvs_check.h"
#include "vislib/eval/ray_reference.h"
#include "vislib/eval/seeing_rule.h"
#include "vislib/scene/quake_bsp_volumes.h"

namespace vislib {
namespace {

struct Context {
  const QuakeBsp& bsp;
  const Scene& scene;
  const EmbreeScene& embree;
  const VisCompareOptions& opt;             // z_near: the cell's (its leaf's near_limit applied)
  SeeingRule rule;                          // with the cell's z_near
  const std::vector<uint32_t>& tri_plane;   // map plane of each triangle's face (or none)
  const std::vector<uint8_t>& degenerate;   // per triangle
  const std::vector<uint8_t>& never_drawn;  // per triangle: its face is in no marksurfaces
  const RayCrossingIndex& crossings;        // the scene's, for every re-cast
};

Vec3 centroid(const std::vector<Vec3>& c) {
  Vec3 s{0, 0, 0};
  for (const Vec3& q : c) s = s + q;
  return s * (1.0 / double(c.size()));
}

// The witness search for extra `tri` of a cell whose eyes (scene coordinates) are `eyes`.
enum class Search { witness, coincident, none };
Search find_witness(const Context& ctx, uint32_t tri, const std::vector<Vec3>& eyes,
                    const std::vector<uint8_t>& in_theirs, Rng& rng, VisWitness& out) {
  bool coincident = false;
  const auto& t = ctx.scene.triangles[tri];
  const Vec3 a = ctx.scene.positions[0][t[0]], b = ctx.scene.positions[0][t[1]],
             c = ctx.scene.positions[0][t[2]];
  const Vec3 mid = (a + b + c) * (1.0 / 3.0);
  const bool see_through = ctx.scene.triangle_see_through(tri);
  std::vector<uint32_t> passed;
  for (const Vec3& eye : eyes) {
    for (int j = 0; j < ctx.opt.witness_targets; ++j) {
      Vec3 target = mid;
      if (j > 0) {  // uniform on the triangle, pulled 4% towards its centroid
        double r1 = std::sqrt(rng.uniform()), r2 = rng.uniform();
        const Vec3 q = a * (1 - r1) + b * (r1 * (1 - r2)) + c * (r1 * r2);
        target = mid + (q - mid) * 0.96;
      }
      Vec3 dir = target - eye;
      const double len = length(dir);
      if (!(len > 0)) continue;
      dir = dir * (1.0 / len);
      // Embree first: only a ray that reaches the triangle (or a face coincident with it) is
      // re-cast.
      bool candidate = false;
      if (ctx.embree.has_see_through()) {
        Hit h;
        passed.clear();
        ctx.embree.hits_through(eye, &dir, 1, ctx.opt.z_near, &h, passed);
        candidate = see_through ? std::find(passed.begin(), passed.end(), tri) != passed.end()
                                : h.tri != kNoHit &&
                                      (h.tri == tri || ctx.tri_plane[h.tri] == ctx.tri_plane[tri]);
      } else {
        const Hit h = ctx.embree.first_hit(eye, dir, ctx.opt.z_near);
        candidate = h.tri != kNoHit && (h.tri == tri || ctx.tri_plane[h.tri] == ctx.tri_plane[tri]);
      }
      if (!candidate) continue;
      const std::vector<RayCrossing> cr = ctx.crossings.crossings(eye, dir);
      const double lambda = ctx.rule.seen_depth(cr, tri);
      if (lambda < 0) continue;
      // Seen, but where a triangle of theirs lies at the same depth (a coincident face they
      // draw), the ray shows no miss of theirs: search on.
      if (ctx.rule.set_at_depth(cr, lambda, in_theirs)) {
        coincident = true;
        continue;
      }
      out = {tri, eye, dir};
      return Search::witness;
    }
  }
  return coincident ? Search::coincident : Search::none;
}

// Re-casts the kernel witnesses `kw` of some of row.unconfirmed: confirmed, coincident, tie or
// false witnesses (vis_compare.h); the extras without one stay unconfirmed. Keeps every list
// sorted.
void settle_with_kernel(const Context& ctx, VisCompareLeaf& row, std::vector<VisWitness> kw,
                        const std::vector<uint8_t>& in_theirs) {
  std::sort(kw.begin(), kw.end(),
            [](const VisWitness& a, const VisWitness& b) { return a.tri < b.tri; });
  std::vector<uint32_t> still;
  size_t k = 0;
  for (uint32_t t : row.unconfirmed) {
    while (k < kw.size() && kw[k].tri < t) ++k;
    if (k == kw.size() || kw[k].tri != t) {
      still.push_back(t);
      continue;
    }
    VisWitness w = kw[k];
    w.from_kernel = true;
    const std::vector<RayCrossing> cr = ctx.crossings.crossings(w.eye, w.dir);
    const double lambda = ctx.rule.seen_depth(cr, t);
    if (lambda < 0 && ctx.rule.seen_at_tie(cr, t))
      row.tie_witnesses.push_back(w);
    else if (lambda < 0)
      row.false_witnesses.push_back(w);
    else if (ctx.rule.set_at_depth(cr, lambda, in_theirs))
      row.coincident.push_back(t);
    else
      row.confirmed.push_back(w);
  }
  row.unconfirmed = std::move(still);
  std::sort(row.coincident.begin(), row.coincident.end());
  std::sort(row.confirmed.begin(), row.confirmed.end(),
            [](const VisWitness& a, const VisWitness& b) { return a.tri < b.tri; });
}

// The sampled ground truth of one leaf (pvs_check.h's sampler, against ours and theirs).
void sample_leaf(const Context& ctx, VisCompareLeaf& row, const EyeRegion& region,
                 const std::vector<uint8_t>& in_ours, const std::vector<uint8_t>& in_theirs,
                 Rng& rng) {
  SampleSettings st;
  st.resolution = ctx.opt.resolution;
  st.z_near = ctx.opt.z_near;
  st.eps_z = ctx.opt.eps_z;
  st.tri_plane = &ctx.tri_plane;
  st.crossings = &ctx.crossings;
  std::vector<SampledSet> sets(2);
  sets[0].in_set = &in_ours;
  sets[1].in_set = &in_theirs;
  sets[1].excused = &ctx.never_drawn;
  SampleTally tally;
  for (int s = 0; s < ctx.opt.samples; ++s)
    sample_eye(ctx.scene, ctx.embree, st, random_eye(region, rng), sets, tally);
  row.rays = tally.rays, row.no_hit = tally.no_hit, row.ambiguous = tally.ambiguous;
  row.our_misses = sets[0].misses, row.their_misses = sets[1].misses;
  row.their_never_drawn = sets[1].excused_misses;
  for (SampledSet& set : sets) {
    std::sort(set.missed.begin(), set.missed.end());
    set.missed.erase(std::unique(set.missed.begin(), set.missed.end()), set.missed.end());
  }
  row.our_missed = std::move(sets[0].missed);
  row.their_missed = std::move(sets[1].missed);
}

}  // namespace

double VisCompareLeaf::tightness() const {
  if (theirs == 0) return ours == 0 ? 1.0 : std::numeric_limits<double>::infinity();
  return double(ours) / double(theirs);
}

VisCompareResult vis_compare(const QuakeBsp& bsp, const Scene& scene,
                             const std::vector<BspFaceTriangles>& faces,
                             const std::vector<uint32_t>& cell_leaf,
                             const std::vector<std::vector<uint32_t>>& ours,
                             const VisCompareOptions& options,
                             const std::function<void(size_t, size_t)>& progress) {
  assert(ours.size() == cell_leaf.size());
  assert(options.witness_eyes >= 1 && options.witness_targets >= 1 && options.samples >= 0 &&
         options.resolution >= 1 && options.z_near > 0);
  const size_t tris = scene.triangle_count();
  VisCompareResult result;

  // Per triangle: its face's plane, degenerate, never drawn.
  std::vector<uint8_t> marked(bsp.faces.size(), 0);
  for (const BspLeaf& l : bsp.leaves)
    for (uint32_t i = 0; i < l.marksurface_count; ++i)
      marked[bsp.marksurfaces[l.first_marksurface + i]] = 1;
  const Box3 bounds = scene.bounds();
  const EmbreeScene embree(scene, 0, tris ? (bounds.min + bounds.max) * 0.5 : Vec3{0, 0, 0});
  const RayCrossingIndex crossings(scene, 0);
  std::vector<uint32_t> tri_plane(tris, kNoTrianglePlane);
  std::vector<uint8_t> degenerate(tris, 0), never_drawn(tris, 0);
  for (uint32_t f = 0; f < faces.size(); ++f) {
    const BspFaceTriangles& ft = faces[f];
    if (!ft.imported || ft.triangle_count == 0) continue;
    if (!marked[f]) ++result.never_drawn_faces;
    for (uint32_t t = ft.first_triangle; t < ft.first_triangle + ft.triangle_count; ++t) {
      tri_plane[t] = bsp.faces[f].plane;
      never_drawn[t] = !marked[f];
    }
  }
  for (size_t t = 0; t < tris; ++t) {
    const auto& v = scene.triangles[t];
    const Vec3 p0 = scene.positions[0][v[0]];
    const Vec3 n = cross(scene.positions[0][v[1]] - p0, scene.positions[0][v[2]] - p0);
    degenerate[t] = n.x == 0 && n.y == 0 && n.z == 0;
    result.degenerate_triangles += degenerate[t];
    result.never_drawn_triangles += never_drawn[t] && !degenerate[t];
  }

  std::vector<double> insets;
  const std::vector<EyeRegion> regions =
      bsp_leaf_eye_regions(bsp, cell_leaf, options.z_near, &insets);

  result.leaves.resize(cell_leaf.size());
  auto one_cell = [&](size_t c) {
    VisCompareLeaf& row = result.leaves[c];
    const uint32_t leaf = cell_leaf[c];
    row.cell = uint32_t(c);
    row.leaf = leaf;
    row.contents = bsp.leaves[leaf].contents;
    std::vector<uint32_t> theirs = bsp_leaf_drawn_triangles(bsp, faces, leaf);
    std::vector<uint8_t> in_ours(tris, 0), in_theirs(tris, 0);
    for (uint32_t t : ours[c]) in_ours[t] = 1;
    for (uint32_t t : theirs) in_theirs[t] = 1;
    for (uint32_t t : ours[c]) {
      if (degenerate[t]) continue;
      if (never_drawn[t]) {
        ++row.never_drawn;
        continue;
      }
      ++row.ours;
      if (in_theirs[t]) ++row.common;
    }
    for (uint32_t t : theirs)
      if (!degenerate[t]) {
        ++row.theirs;
        if (!in_ours[t]) row.lacks.push_back(t);
      }

    Rng witness_rng(Rng::derive(options.seed, 2 * uint64_t(c)));
    Rng sample_rng(Rng::derive(options.seed, 2 * uint64_t(c) + 1));
    const EyeRegion& region = regions[c];
    const std::vector<Vec3>& region_corners = region.leaf_corners;
    row.inset = insets[c];
    VisCompareOptions cell_options = options;
    cell_options.z_near = std::min(options.z_near, region.near_limit);
    const Context ctx{bsp,
                      scene,
                      embree,
                      cell_options,
                      SeeingRule{scene, cell_options.z_near, options.eps_z},
                      tri_plane,
                      degenerate,
                      never_drawn,
                      crossings};
    std::vector<Vec3> eyes;  // scene coordinates
    if (!region_corners.empty()) {
      const Vec3 mid = centroid(region_corners);
      eyes.push_back(quake_to_scene(mid));
      for (const Vec3& q : region_corners) {
        if (int(eyes.size()) >= options.witness_eyes) break;
        eyes.push_back(quake_to_scene(q + (mid - q) * 0.01));
      }
      while (int(eyes.size()) < options.witness_eyes)
        eyes.push_back(random_eye(region, witness_rng));
    }
    for (uint32_t t : ours[c]) {
      if (in_theirs[t] || ctx.degenerate[t] || ctx.never_drawn[t]) continue;
      VisWitness w;
      const Search found =
          eyes.empty() ? Search::none : find_witness(ctx, t, eyes, in_theirs, witness_rng, w);
      if (found == Search::witness)
        row.confirmed.push_back(w);
      else if (found == Search::coincident)
        row.coincident.push_back(t);
      else
        row.unconfirmed.push_back(t);
    }
    if (options.kernel_witnesses && !row.unconfirmed.empty()) {
      row.kernel_rerun = true;
      settle_with_kernel(ctx, row, options.kernel_witnesses(uint32_t(c), row.unconfirmed),
                         in_theirs);
    }
    if (options.samples > 0 && region.kind != EyeRegion::none)
      sample_leaf(ctx, row, region, in_ours, in_theirs, sample_rng);
  };
  for_cells_in_chunks(cell_leaf.size(), one_cell, progress);
  return result;
}

double median_tightness(const VisCompareResult& r) {
  std::vector<double> v;
  for (const VisCompareLeaf& l : r.leaves)
    if (std::isfinite(l.tightness())) v.push_back(l.tightness());
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

double mean_tightness(const VisCompareResult& r) {
  double s = 0;
  size_t k = 0;
  for (const VisCompareLeaf& l : r.leaves)
    if (std::isfinite(l.tightness())) s += l.tightness(), ++k;
  return k ? s / double(k) : 0;
}

std::string vis_compare_json(const VisCompareResult& r) {
  using nlohmann::json;
  json rows = json::array();
  size_t ours = 0, theirs = 0, common = 0, confirmed = 0, unconfirmed = 0, coincident = 0,
         lacks = 0, never = 0, false_witness = 0, tie = 0, rerun = 0, by_kernel = 0;
  uint64_t rays = 0, our_misses = 0, their_misses = 0, their_never = 0, ambiguous = 0, no_hit = 0;
  json our_miss_leaves = json::array(), their_miss_leaves = json::array();
  for (const VisCompareLeaf& l : r.leaves) {
    auto witnesses = [](const std::vector<VisWitness>& ws) {
      json w = json::array();
      for (const VisWitness& v : ws)
        w.push_back({{"triangle", v.tri},
                     {"eye", {v.eye.x, v.eye.y, v.eye.z}},
                     {"direction", {v.dir.x, v.dir.y, v.dir.z}},
                     {"source", v.from_kernel ? "kernel" : "rays"}});
      return w;
    };
    const json w = witnesses(l.confirmed);
    const double t = l.tightness();
    rows.push_back({{"cell", l.cell},
                    {"leaf", l.leaf},
                    {"contents", l.contents},
                    {"inset", l.inset},
                    {"ours", l.ours},
                    {"theirs", l.theirs},
                    {"common", l.common},
                    {"tightness", std::isfinite(t) ? json(t) : json(nullptr)},
                    {"never_drawn", l.never_drawn},
                    {"extras_confirmed", w},
                    {"extras_unconfirmed", l.unconfirmed},
                    {"extras_coincident", l.coincident},
                    {"extras_false_witness", witnesses(l.false_witnesses)},
                    {"extras_tie", witnesses(l.tie_witnesses)},
                    {"kernel_rerun", l.kernel_rerun},
                    {"ours_lacks", l.lacks},
                    {"sampled_rays", l.rays},
                    {"no_hit", l.no_hit},
                    {"ambiguous", l.ambiguous},
                    {"our_misses", l.our_misses},
                    {"their_misses", l.their_misses},
                    {"their_never_drawn", l.their_never_drawn},
                    {"our_missed", l.our_missed},
                    {"their_missed", l.their_missed}});
    ours += l.ours, theirs += l.theirs, common += l.common, never += l.never_drawn;
    confirmed += l.confirmed.size(), unconfirmed += l.unconfirmed.size();
    coincident += l.coincident.size(), lacks += l.lacks.size();
    false_witness += l.false_witnesses.size(), rerun += l.kernel_rerun;
    tie += l.tie_witnesses.size();
    for (const VisWitness& v : l.confirmed) by_kernel += v.from_kernel;
    rays += l.rays, our_misses += l.our_misses, their_misses += l.their_misses;
    their_never += l.their_never_drawn, ambiguous += l.ambiguous, no_hit += l.no_hit;
    if (l.our_misses) our_miss_leaves.push_back(l.leaf);
    if (l.their_misses) their_miss_leaves.push_back(l.leaf);
  }
  json j = {{"leaves", r.leaves.size()},
            {"degenerate_triangles", r.degenerate_triangles},
            {"never_drawn_faces", r.never_drawn_faces},
            {"never_drawn_triangles", r.never_drawn_triangles},
            {"totals",
             {{"ours", ours},
              {"theirs", theirs},
              {"common", common},
              {"tightness", theirs ? double(ours) / double(theirs) : 0.0},
              {"mean_tightness", mean_tightness(r)},
              {"median_tightness", median_tightness(r)},
              {"extras_confirmed", confirmed},
              {"extras_unconfirmed", unconfirmed},
              {"extras_coincident", coincident},
              {"extras_false_witness", false_witness},
              {"extras_tie", tie},
              {"extras_confirmed_by_kernel", by_kernel},
              {"kernel_rerun_leaves", rerun},
              {"ours_lacks", lacks},
              {"never_drawn", never},
              {"sampled_rays", rays},
              {"no_hit", no_hit},
              {"ambiguous", ambiguous},
              {"our_misses", our_misses},
              {"their_misses", their_misses},
              {"their_never_drawn", their_never},
              {"our_miss_leaves", our_miss_leaves},
              {"their_miss_leaves", their_miss_leaves}}},
            {"per_leaf", rows}};
  return j.dump(1);
}

}  // namespace vislib
