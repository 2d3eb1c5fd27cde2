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
#include "vislib/eval/ray_reference.h"
#include "vislib/scene/quake_bsp_volumes.h"

namespace vislib {
namespace {

constexpr uint32_t kNoPlane = std::numeric_limits<uint32_t>::max();
// A random eye of a view region is drawn uniformly in its bounding box up to this many times
// until it falls inside; a region thinner than that allows gets a random convex combination of
// its corners instead.
constexpr int kRejectionTries = 64;

struct Context {
  const QuakeBsp& bsp;
  const Scene& scene;
  const EmbreeScene& embree;
  const VisCompareOptions& opt;             // z_near: the cell's (its leaf's near_limit applied)
  const std::vector<uint32_t>& tri_plane;   // map plane of each triangle's face (kNoPlane: none)
  const std::vector<uint8_t>& degenerate;   // per triangle
  const std::vector<uint8_t>& never_drawn;  // per triangle: its face is in no marksurfaces
};

bool inside(const ConvexPolytope& p, Vec3 q) {
  for (const HalfSpace& h : p.halfspaces)
    if (dot(h.normal, q) > h.offset) return false;
  return true;
}

std::vector<Vec3> corners(const ConvexPolytope& p) {
  std::vector<Vec3> v;
  for (const auto& f : p.faces)
    for (const Vec3& q : f)
      if (std::find(v.begin(), v.end(), q) == v.end()) v.push_back(q);
  return v;
}

// A random point of the region (Quake coordinates).
Vec3 random_point(const ConvexPolytope& p, const std::vector<Vec3>& c, Rng& rng) {
  const Box3 b = p.bounds();
  for (int i = 0; i < kRejectionTries; ++i) {
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

Vec3 centroid(const std::vector<Vec3>& c) {
  Vec3 s{0, 0, 0};
  for (const Vec3& q : c) s = s + q;
  return s * (1.0 / double(c.size()));
}

// The crossing of `tri` among `cr`, if any.
const RayCrossing* crossing_of(const std::vector<RayCrossing>& cr, uint32_t tri) {
  for (const RayCrossing& c : cr)
    if (c.tri == tri) return &c;
  return nullptr;
}

// The seeing rule of vis_compare.h: `tri` is crossed inside its edges beyond z_near and no opaque
// crossing lies in front of it by more than eps_z. Returns its depth, or a negative value.
double seen_depth(const Context& ctx, const std::vector<RayCrossing>& cr, uint32_t tri) {
  const RayCrossing* t = crossing_of(cr, tri);
  if (!t || t->min_bary <= kReferenceBarycentric || t->lambda <= ctx.opt.z_near + kReferenceNear)
    return -1;
  const double front = t->lambda * (1.0 - ctx.opt.eps_z);
  for (const RayCrossing& c : cr)
    if (c.tri != tri && !ctx.scene.triangle_see_through(c.tri) &&
        c.lambda > ctx.opt.z_near - kReferenceNear && c.lambda < front)
      return -1;
  return t->lambda;
}

// The tie class of vis_compare.h: `tri` is crossed beyond z_near but not farther than
// kReferenceBarycentric inside its edges (so seen_depth refused it), and no opaque crossing lies
// in front of it by more than eps_z: only the kernel's tie rules decide such a ray.
bool seen_at_tie(const Context& ctx, const std::vector<RayCrossing>& cr, uint32_t tri) {
  const RayCrossing* t = crossing_of(cr, tri);
  if (!t || t->lambda <= ctx.opt.z_near + kReferenceNear) return false;
  const double front = t->lambda * (1.0 - ctx.opt.eps_z);
  for (const RayCrossing& c : cr)
    if (c.tri != tri && !ctx.scene.triangle_see_through(c.tri) &&
        c.lambda > ctx.opt.z_near - kReferenceNear && c.lambda < front)
      return false;
  return true;
}

// Whether a triangle with in_set != 0 is crossed within eps_z of depth `lambda`.
bool set_at_depth(const Context& ctx, const std::vector<RayCrossing>& cr, double lambda,
                  const std::vector<uint8_t>& in_set) {
  for (const RayCrossing& c : cr)
    if (in_set[c.tri] && std::fabs(c.lambda - lambda) <= ctx.opt.eps_z * lambda) return true;
  return false;
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
      const std::vector<RayCrossing> cr = ray_crossings(ctx.scene, 0, eye, dir);
      const double lambda = seen_depth(ctx, cr, tri);
      if (lambda < 0) continue;
      // Seen, but where a triangle of theirs lies at the same depth (a coincident face they
      // draw), the ray shows no miss of theirs: search on.
      if (set_at_depth(ctx, cr, lambda, in_theirs)) {
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
    const std::vector<RayCrossing> cr = ray_crossings(ctx.scene, 0, w.eye, w.dir);
    const double lambda = seen_depth(ctx, cr, t);
    if (lambda < 0 && seen_at_tie(ctx, cr, t))
      row.tie_witnesses.push_back(w);
    else if (lambda < 0)
      row.false_witnesses.push_back(w);
    else if (set_at_depth(ctx, cr, lambda, in_theirs))
      row.coincident.push_back(t);
    else
      row.confirmed.push_back(w);
  }
  row.unconfirmed = std::move(still);
  std::sort(row.coincident.begin(), row.coincident.end());
  std::sort(row.confirmed.begin(), row.confirmed.end(),
            [](const VisWitness& a, const VisWitness& b) { return a.tri < b.tri; });
}

// One hit `x` of the ray (eye, dir), missing from ours and/or theirs: the pre-filter (the next
// surface behind it, on the same map plane, in the set) then the double-precision re-cast.
void check_hit(const Context& ctx, VisCompareLeaf& row, Vec3 eye, Vec3 dir, uint32_t x,
               const std::vector<uint8_t>& in_ours, const std::vector<uint8_t>& in_theirs,
               std::vector<uint32_t>& our_missed, std::vector<uint32_t>& their_missed) {
  bool need_ours = !in_ours[x], need_theirs = !in_theirs[x];
  if (!need_ours && !need_theirs) return;
  if (!ctx.scene.triangle_see_through(x)) {
    const Hit g = ctx.embree.first_hit_excluding(eye, dir, ctx.opt.z_near, x);
    if (g.tri != kNoHit && ctx.tri_plane[g.tri] != kNoPlane &&
        ctx.tri_plane[g.tri] == ctx.tri_plane[x]) {
      if (in_ours[g.tri]) need_ours = false;
      if (in_theirs[g.tri]) need_theirs = false;
    }
    if (!need_ours && !need_theirs) return;
  }
  const std::vector<RayCrossing> cr = ray_crossings(ctx.scene, 0, eye, dir);
  const double lambda = seen_depth(ctx, cr, x);
  if (lambda < 0) {
    ++row.ambiguous;
    return;
  }
  if (need_ours && !set_at_depth(ctx, cr, lambda, in_ours)) {
    ++row.our_misses;
    our_missed.push_back(x);
  }
  if (need_theirs && !set_at_depth(ctx, cr, lambda, in_theirs)) {
    if (ctx.never_drawn[x]) {
      ++row.their_never_drawn;
    } else {
      ++row.their_misses;
      their_missed.push_back(x);
    }
  }
}

void sort_unique(std::vector<uint32_t>& v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
}

void sample_leaf(const Context& ctx, VisCompareLeaf& row, const ConvexPolytope& region,
                 const std::vector<Vec3>& region_corners, const std::vector<uint8_t>& in_ours,
                 const std::vector<uint8_t>& in_theirs, Rng& rng) {
  const int n = ctx.opt.resolution;
  FaceAxes axes[kCubeFaces];
  for (int k = 0; k < kCubeFaces; ++k) axes[k] = face_axes(k, identity_orientation());
  std::vector<Vec3> dirs(static_cast<size_t>(n));
  std::vector<Hit> hits(static_cast<size_t>(n));
  std::vector<uint32_t> passed;
  std::vector<uint32_t> our_missed, their_missed;
  const bool see_through = ctx.embree.has_see_through();
  for (int s = 0; s < ctx.opt.samples; ++s) {
    const Vec3 eye = quake_to_scene(random_point(region, region_corners, rng));
    for (int k = 0; k < kCubeFaces; ++k) {
      for (int y = 0; y < n; ++y) {
        for (int x = 0; x < n; ++x) dirs[size_t(x)] = pixel_direction(axes[k], x, y, n);
        bool redo = false;
        if (see_through) {
          passed.clear();
          ctx.embree.hits_through(eye, dirs.data(), size_t(n), ctx.opt.z_near, hits.data(), passed);
          for (uint32_t p : passed)
            if (!in_ours[p] || !in_theirs[p]) redo = true;
        } else {
          ctx.embree.first_hits(eye, dirs.data(), size_t(n), ctx.opt.z_near, hits.data());
        }
        row.rays += uint64_t(n);
        for (int x = 0; x < n; ++x) {
          const Vec3 d = dirs[size_t(x)];
          if (redo) {  // this row passed a see-through triangle missing from a set: ray by ray
            Hit h;
            passed.clear();
            ctx.embree.hits_through(eye, &d, 1, ctx.opt.z_near, &h, passed);
            sort_unique(passed);
            for (uint32_t p : passed)
              check_hit(ctx, row, eye, d, p, in_ours, in_theirs, our_missed, their_missed);
          }
          const uint32_t h = hits[size_t(x)].tri;
          if (h == kNoHit) {
            ++row.no_hit;
            continue;
          }
          check_hit(ctx, row, eye, d, h, in_ours, in_theirs, our_missed, their_missed);
        }
      }
    }
  }
  sort_unique(our_missed);
  sort_unique(their_missed);
  row.our_missed = std::move(our_missed);
  row.their_missed = std::move(their_missed);
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
  std::vector<uint32_t> tri_plane(tris, kNoPlane);
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

  std::vector<int64_t> piece_of(bsp.leaves.size(), -1);
  const std::vector<BspLeafPiece> pieces = bsp_leaf_pieces(bsp);
  for (size_t i = 0; i < pieces.size(); ++i)
    if (pieces[i].leaf != 0) piece_of[pieces[i].leaf] = int64_t(i);

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
    ConvexPolytope region;
    VisCompareOptions cell_options = options;
    if (piece_of[leaf] >= 0) {
      BspViewRegion r = bsp_leaf_view_region(pieces[size_t(piece_of[leaf])].volume, options.z_near);
      region = std::move(r.volume);
      row.inset = r.inset;
      cell_options.z_near = std::min(options.z_near, r.near_limit);
    }
    const Context ctx{bsp, scene, embree, cell_options, tri_plane, degenerate, never_drawn};
    const std::vector<Vec3> region_corners = corners(region);
    std::vector<Vec3> eyes;  // scene coordinates
    if (!region_corners.empty()) {
      const Vec3 mid = centroid(region_corners);
      eyes.push_back(quake_to_scene(mid));
      for (const Vec3& q : region_corners) {
        if (int(eyes.size()) >= options.witness_eyes) break;
        eyes.push_back(quake_to_scene(q + (mid - q) * 0.01));
      }
      while (int(eyes.size()) < options.witness_eyes)
        eyes.push_back(quake_to_scene(random_point(region, region_corners, witness_rng)));
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
    if (options.samples > 0 && !region_corners.empty())
      sample_leaf(ctx, row, region, region_corners, in_ours, in_theirs, sample_rng);
  };
  // Chunks of cells in parallel, progress reported between them from the calling thread.
  constexpr size_t kChunk = 64;
  for (size_t first = 0; first < cell_leaf.size(); first += kChunk) {
    const size_t last = std::min(cell_leaf.size(), first + kChunk);
    tbb::parallel_for(first, last, one_cell);
    if (progress) progress(last, cell_leaf.size());
  }
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
