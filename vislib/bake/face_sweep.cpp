// face_sweep.cpp: even and adaptive chord sweeps of a face (face_sweep.h).
#include "vislib/bake/face_sweep.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <iterator>

#include "vislib/base/cubemap.h"
#include "vislib/kernel/segment_visibility.h"

namespace vislib {

std::optional<FaceSweep> face_sweep_of(const std::vector<Vec3>& face, Vec3 normal,
                                       double min_length) {
  const size_t m = face.size();
  if (m < 3) return std::nullopt;
  size_t longest = 0;
  for (size_t i = 1; i < m; ++i)
    if (length(face[(i + 1) % m] - face[i]) > length(face[(longest + 1) % m] - face[longest]))
      longest = i;
  Vec3 d = face[(longest + 1) % m] - face[longest];
  if (length(d) <= min_length) return std::nullopt;
  d = d * (1.0 / length(d));
  Vec3 w = cross(normal, d);
  if (!(length(w) > 0)) return std::nullopt;
  w = w * (1.0 / length(w));
  FaceSweep s{face, d, w, dot(w, face[0]), dot(w, face[0])};
  for (const Vec3& p : face) {
    s.lo = std::min(s.lo, dot(w, p));
    s.hi = std::max(s.hi, dot(w, p));
  }
  if (!(s.hi - s.lo > min_length)) return std::nullopt;
  return s;
}

std::optional<Segment> face_chord(const FaceSweep& sweep, double h, double min_length) {
  const std::vector<Vec3>& poly = sweep.face;
  const size_t m = poly.size();
  bool any = false;
  Vec3 a{}, b{};
  double ta = 0, tb = 0;
  for (size_t i = 0; i < m; ++i) {
    const Vec3& u = poly[i];
    const Vec3& v = poly[(i + 1) % m];
    const double hu = dot(sweep.across, u), hv = dot(sweep.across, v);
    if (hu == hv || h < std::min(hu, hv) || h > std::max(hu, hv)) continue;
    const Vec3 p = u + (v - u) * ((h - hu) / (hv - hu));
    const double t = dot(sweep.along, p);
    if (!any || t < ta) {
      a = p;
      ta = t;
    }
    if (!any || t > tb) {
      b = p;
      tb = t;
    }
    any = true;
  }
  if (!any) return std::nullopt;
  if (ta < sweep.t_lo || tb > sweep.t_hi) {  // a strip's piece (the whole chord bit for bit else)
    if (tb < sweep.t_lo || ta > sweep.t_hi || !(ta < tb)) return std::nullopt;
    const Vec3 d = b - a;
    const double s0 = std::max(ta, sweep.t_lo), s1 = std::min(tb, sweep.t_hi);
    b = s1 < tb ? a + d * ((s1 - ta) / (tb - ta)) : b;
    a = s0 > ta ? a + d * ((s0 - ta) / (tb - ta)) : a;
  }
  if (!(length(b - a) > min_length)) return std::nullopt;
  return Segment{a, b, sweep.side_normal, sweep.side};
}

std::vector<FaceSweep> sweep_strips(const FaceSweep& sweep, double length) {
  assert(length > 0);
  double t0 = INFINITY, t1 = -INFINITY;
  for (const Vec3& p : sweep.face) {
    t0 = std::min(t0, dot(sweep.along, p));
    t1 = std::max(t1, dot(sweep.along, p));
  }
  const int n = t1 - t0 > length ? int(std::ceil((t1 - t0) / length)) : 1;
  std::vector<FaceSweep> out(size_t(n), sweep);
  for (int k = 1; k < n; ++k) {
    const double cut = t0 + (t1 - t0) * double(k) / double(n);
    out[size_t(k) - 1].t_hi = cut;
    out[size_t(k)].t_lo = cut;
  }
  return out;
}

FaceSweep crossed_sweep(const FaceSweep& sweep) {
  FaceSweep out = sweep;
  out.along = sweep.across;
  out.across = sweep.along * -1.0;  // along x across keeps the face's normal
  out.lo = INFINITY, out.hi = -INFINITY;
  for (const Vec3& p : sweep.face) {
    out.lo = std::min(out.lo, dot(out.across, p));
    out.hi = std::max(out.hi, dot(out.across, p));
  }
  out.t_lo = -INFINITY, out.t_hi = INFINITY;
  out.crossed = true;
  return out;
}

namespace {

// Whether two sweeps are of one family (AdaptiveSpacing::new_to_family): strips of one face's
// sweep, or that face's crossed sweep's, on one side.
bool same_family(const FaceSweep& a, const FaceSweep& b) {
  return a.face == b.face && a.along == b.along && a.crossed == b.crossed &&
         a.side_normal == b.side_normal && a.side == b.side;
}

// The even grid's interval count over the sweep's width at most `spacing` apart (>= 1).
int even_steps(const FaceSweep& sweep, double spacing) {
  const double width = sweep.hi - sweep.lo;
  return width > spacing ? int(std::ceil(width / spacing)) : 1;
}

double even_position(const FaceSweep& sweep, int k, int steps) {
  return sweep.lo + (sweep.hi - sweep.lo) * double(k) / double(steps);
}

constexpr std::pair<ChordTiles, const char*> kChordTilesNames[] = {
    {ChordTiles::All, "all"},
    {ChordTiles::New, "new"},
    {ChordTiles::NewEveryFace, "new-every-face"}};

}  // namespace

const char* chord_tiles_name(ChordTiles tiles) {
  for (const auto& [value, name] : kChordTilesNames)
    if (value == tiles) return name;
  assert(false);
  return "";
}

std::vector<std::string_view> chord_tiles_names() {
  std::vector<std::string_view> out;
  for (const auto& [value, name] : kChordTilesNames) out.push_back(name);
  return out;
}

std::optional<ChordTiles> chord_tiles_named(std::string_view name) {
  for (const auto& [value, n] : kChordTilesNames)
    if (name == n) return value;
  return std::nullopt;
}

std::vector<Segment> even_chords(const FaceSweep& sweep, double spacing, double min_length) {
  assert(spacing > 0);
  std::vector<Segment> out;
  const int steps = even_steps(sweep, spacing);
  for (int k = 1; k < steps; ++k)
    if (auto c = face_chord(sweep, even_position(sweep, k, steps), min_length)) out.push_back(*c);
  return out;
}

double expected_probes(double width, double floor, double refine) {
  assert(floor > 0 && refine >= 0 && refine <= 1);
  // One probe a level, the children's share 2 refine a level down, while the halves are wider
  // than the floor (as adaptive_sweep inserts them).
  double expected = 0, weight = 1;
  for (double w = width; w > floor; w *= 0.5) {
    expected += weight;
    weight *= 2 * refine;
  }
  return expected;
}

double expected_adaptive_probes(const std::vector<FaceSweep>& sweeps,
                                const AdaptiveSpacing& spacing, double refine) {
  double expected = 0;
  for (const FaceSweep& f : sweeps) {
    const int steps = even_steps(f, spacing.coarse);
    const double width = (f.hi - f.lo) / double(steps);
    expected +=
        double(steps - 1) + double(steps) * expected_probes(width, spacing.floor_of(f), refine);
  }
  return expected;
}

namespace {

// Tolerance of the cone tests of chord_tiles_toward (cosine of the angle by which a direction may
// lie outside a face of the cone and still count as inside): the test only decides whether a
// cube corner's tile is flagged, so erring inside flags more and stays conservative.
constexpr double kConeSlack = 1e-9;
// Sine of the angle under which two of the cone's points count as parallel and bound no plane:
// their cross product's direction is then rounding noise. Skipping a pair only drops a candidate
// plane, so cone_holds says yes more often.
constexpr double kConeParallel = 1e-12;

// The directions p - e (p a point of a triangle, e an eye of a segment) form the cone over the
// polytope P = conv{c_i - e_j} (3 corners, 2 ends: 6 points). Within a cube face's frustum that
// cone is the cone over P ∩ frustum, whose image on the face is the convex hull of its vertices'
// images: P's vertices inside the frustum, the points where P's edges cross the frustum's planes
// (both are ends of the 15 segments between the 6 points, clipped to the frustum), and the
// frustum's corner rays that pass through P (cone_holds). face_image takes the box of those.
struct DirectionCone {
  Vec3 v[6];
  Vec3 facet[15];  // the cone's bounding planes found among the pairs (normals pointing in)
  int facets = 0;

  // False when no pair of the points bounds the cone (the triangle meets the segment: its
  // directions are not one side of any plane).
  bool build() {
    double lv[6];
    for (int k = 0; k < 6; ++k) lv[k] = length(v[k]);
    for (int i = 0; i < 6; ++i)
      for (int j = i + 1; j < 6; ++j) {
        const Vec3 n = cross(v[i], v[j]);
        const double ln = length(n);
        if (!(ln > kConeParallel * lv[i] * lv[j])) continue;  // parallel: no plane
        bool pos = true, neg = true;
        for (int k = 0; k < 6; ++k) {
          const double d = dot(n, v[k]) / (ln * lv[k]);
          pos = pos && d >= -kConeSlack;
          neg = neg && d <= kConeSlack;
        }
        if (pos)
          facet[facets++] = n * (1 / ln);
        else if (neg)
          facet[facets++] = n * (-1 / ln);
      }
    return facets > 0;
  }

  // Whether direction c may lie in the cone (every bounding plane holds it, within kConeSlack):
  // the planes found contain the cone, so this never says no for a direction in it.
  bool cone_holds(Vec3 c) const {
    const double lc = length(c);
    for (int k = 0; k < facets; ++k)
      if (dot(facet[k], c) < -kConeSlack * lc) return false;
    return true;
  }
};

// Grows lo/hi (pixel coordinates on `axes`' face, resolution n) by the image of the cone's part in
// the face's frustum; false when nothing of it lies there.
bool face_image(const DirectionCone& cone, const FaceAxes& axes, int n, double lo[2],
                double hi[2]) {
  bool any = false;
  auto add = [&](Vec3 d) {
    const double depth = dot(d, axes.F);
    if (!(depth > 0)) return;  // the apex only (the frustum holds no other point of depth 0)
    const double c[2] = {pixel_coord(std::clamp(dot(d, axes.S) / depth, -1.0, 1.0), n),
                         pixel_coord(std::clamp(dot(d, axes.T) / depth, -1.0, 1.0), n)};
    for (int k = 0; k < 2; ++k) {
      lo[k] = std::min(lo[k], c[k]);
      hi[k] = std::max(hi[k], c[k]);
    }
    any = true;
  };
  // The frustum: dot(d, F ± S) >= 0 and dot(d, F ± T) >= 0.
  const Vec3 planes[4] = {axes.F + axes.S, axes.F - axes.S, axes.F + axes.T, axes.F - axes.T};
  for (int i = 0; i < 6; ++i)
    for (int j = i + 1; j < 6; ++j) {  // every point ends 5 of the 15 segments
      const Vec3 a = cone.v[i], b = cone.v[j];
      double u0 = 0, u1 = 1;
      for (const Vec3& pl : planes) {  // keep dot(a + u (b - a), pl) >= 0
        const double ga = dot(a, pl), gb = dot(b, pl);
        if (ga < 0 && gb < 0) {
          u0 = 1, u1 = 0;
          break;
        }
        if (ga < 0) u0 = std::max(u0, ga / (ga - gb));
        if (gb < 0) u1 = std::min(u1, ga / (ga - gb));
      }
      if (u0 > u1) continue;
      add(a + (b - a) * u0);
      add(a + (b - a) * u1);
    }
  for (double s : {-1.0, 1.0})
    for (double t : {-1.0, 1.0}) {
      const Vec3 corner = axes.F + axes.S * s + axes.T * t;
      if (cone.cone_holds(corner)) add(corner);
    }
  return any;
}

}  // namespace

std::optional<std::vector<uint8_t>> chord_tiles_toward(const Scene& scene, size_t state,
                                                       const Segment& chord,
                                                       const std::vector<uint32_t>& tris, int n,
                                                       int tile_size, int margin, bool every_face) {
  assert(n >= 1 && tile_size >= 1 && margin >= 0);
  if (tris.empty()) return std::nullopt;
  const int tiles = tiles_per_side(n, tile_size);
  std::vector<uint8_t> mask(size_t(kCubeFaces) * size_t(tiles) * size_t(tiles), 0);
  FaceAxes axes[kCubeFaces];
  for (int f = 0; f < kCubeFaces; ++f) axes[f] = face_axes(f, Mat3{});
  // Flags the tiles of a box of pixel coordinates on `face`, with the slack and margin.
  auto flag = [&](int face, const double lo[2], const double hi[2]) {
    int first[2], last[2];  // tiles
    for (int a = 0; a < 2; ++a) {
      const int x0 = std::clamp(int(std::floor(lo[a])) - 1, 0, n - 1);
      const int x1 = std::clamp(int(std::ceil(hi[a])) + 1, 0, n - 1);
      first[a] = std::max(0, x0 / tile_size - margin);
      last[a] = std::min(tiles - 1, x1 / tile_size + margin);
    }
    for (int y = first[1]; y <= last[1]; ++y)
      for (int x = first[0]; x <= last[0]; ++x) mask[tile_mask_index(face, x, y, tiles)] = 1;
  };
  for (uint32_t t : tris) {
    if (every_face) {
      DirectionCone cone;
      int k = 0;
      for (const Vec3& eye : {chord.from, chord.to})
        for (const Vec3& p : scene.corners(t, state)) cone.v[k++] = p - eye;
      if (!cone.build()) return std::nullopt;
      for (int face = 0; face < kCubeFaces; ++face) {
        double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
        if (face_image(cone, axes[face], n, lo, hi)) flag(face, lo, hi);
      }
      continue;
    }
    // One face: the box of the corners' images from both ends, when they all lie in front of it.
    int face = -1;
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};  // pixel coordinates
    for (const Vec3& eye : {chord.from, chord.to})
      for (const Vec3& p : scene.corners(t, state)) {
        const Vec3 d = p - eye;
        int best = 0;
        for (int f = 1; f < kCubeFaces; ++f)
          if (dot(d, axes[f].F) > dot(d, axes[best].F)) best = f;
        const double depth = dot(d, axes[best].F);
        if (!(depth > 0) || (face >= 0 && best != face)) return std::nullopt;
        face = best;
        const double c[2] = {pixel_coord(dot(d, axes[face].S) / depth, n),
                             pixel_coord(dot(d, axes[face].T) / depth, n)};
        for (int a = 0; a < 2; ++a) {
          lo[a] = std::min(lo[a], c[a]);
          hi[a] = std::max(hi[a], c[a]);
        }
      }
    flag(face, lo, hi);
  }
  return mask;
}

size_t adaptive_sweep(const std::vector<FaceSweep>& sweeps, const AdaptiveSpacing& spacing,
                      const std::vector<std::vector<uint32_t>>& bases, double min_length,
                      const ChordRound& run_round, const SweepEstimate& estimate) {
  assert(spacing.valid());
  assert(bases.size() == sweeps.size());
  // Every position's set, by index (f < sweeps.size(): face f's base, what its extreme positions
  // and a degenerate chord of it see); an open interval is one whose midpoint the next round
  // probes.
  std::vector<std::vector<uint32_t>> sets = bases;
  struct Interval {
    size_t face;
    double a, b;
    size_t set_a, set_b;
    size_t fresh;  // index in `fresh`: what the probe that opened it saw new
  };
  std::vector<Interval> open;
  // Round 0: the coarse grid.
  std::vector<Segment> chords;
  struct Probe {
    size_t face;
    double h;
    size_t fresh;
  };
  // The new ids of the probes that opened intervals (index 0: none).
  std::vector<std::vector<uint32_t>> fresh(1);
  std::vector<Probe> probes;
  std::vector<std::vector<double>> grid(sweeps.size());
  for (size_t f = 0; f < sweeps.size(); ++f) {
    const int steps = even_steps(sweeps[f], spacing.coarse);
    for (int k = 0; k <= steps; ++k) grid[f].push_back(even_position(sweeps[f], k, steps));
    for (int k = 1; k < steps; ++k) probes.push_back({f, grid[f][size_t(k)], 0});
  }
  // Runs `probes` as one round; returns the set index of each (its face's base for a degenerate
  // chord).
  size_t run = 0;
  auto run_probes = [&]() {
    std::vector<Segment> segs;
    std::vector<size_t> which, sweep_of;
    std::vector<std::vector<uint32_t>> parents_fresh;
    std::vector<size_t> index(probes.size());
    for (size_t i = 0; i < probes.size(); ++i) {
      index[i] = probes[i].face;
      if (auto c = face_chord(sweeps[probes[i].face], probes[i].h, min_length)) {
        segs.push_back(*c);
        which.push_back(i);
        sweep_of.push_back(probes[i].face);
        parents_fresh.push_back(fresh[probes[i].fresh]);
      }
    }
    if (segs.empty()) return index;
    std::vector<std::vector<uint32_t>> seen = run_round(segs, sweep_of, parents_fresh);
    assert(seen.size() == segs.size());
    run += segs.size();
    for (size_t j = 0; j < which.size(); ++j) {
      index[which[j]] = sets.size();
      sets.push_back(std::move(seen[j]));
    }
    return index;
  };
  // With new_to_family: each sweep's family (the first sweep of it), and what each family has
  // seen before the round being judged (its base, then every round's probes).
  const size_t families = spacing.new_to_family ? sweeps.size() : 0;
  std::vector<size_t> family(families);
  std::vector<std::vector<uint32_t>> family_seen(families);
  std::vector<uint32_t> merged;
  auto union_into = [&](std::vector<uint32_t>& out, const std::vector<uint32_t>& ids) {
    merged.clear();
    std::set_union(out.begin(), out.end(), ids.begin(), ids.end(), std::back_inserter(merged));
    out.swap(merged);
  };
  auto add_seen = [&](size_t f, const std::vector<uint32_t>& ids) {
    if (spacing.new_to_family) union_into(family_seen[family[f]], ids);
  };
  for (size_t f = 0; f < families; ++f) {
    family[f] = f;
    for (size_t g = 0; g < f; ++g)
      if (same_family(sweeps[g], sweeps[f])) {
        family[f] = family[g];
        break;
      }
    add_seen(f, sets[f]);
  }
  if (estimate) estimate(0, expected_adaptive_probes(sweeps, spacing, kRefinePrior));
  {
    const std::vector<size_t> index = run_probes();
    size_t p = 0;
    for (size_t f = 0; f < sweeps.size(); ++f) {
      std::vector<size_t> at(grid[f].size(), f);
      for (size_t k = 1; k + 1 < grid[f].size(); ++k) {
        at[k] = index[p++];
        add_seen(f, sets[at[k]]);
      }
      for (size_t k = 0; k + 1 < grid[f].size(); ++k)
        if (grid[f][k + 1] - grid[f][k] > spacing.floor_of(sweeps[f]))
          open.push_back({f, grid[f][k], grid[f][k + 1], at[k], at[k + 1], 0});
    }
  }
  double refine = kRefinePrior;  // the share of the last round's probes that saw a new id
  while (!open.empty()) {
    probes.clear();
    for (const Interval& i : open) probes.push_back({i.face, 0.5 * (i.a + i.b), i.fresh});
    if (estimate) {
      double expected = double(run);
      for (const Interval& i : open)
        expected += expected_probes(i.b - i.a, spacing.floor_of(sweeps[i.face]), refine);
      estimate(run, expected);
    }
    const std::vector<size_t> index = run_probes();
    size_t refined = 0;
    std::vector<Interval> next;
    std::vector<uint32_t> both;
    for (size_t k = 0; k < open.size(); ++k) {
      const Interval& i = open[k];
      const double m = probes[k].h;
      both.clear();
      std::set_union(sets[i.set_a].begin(), sets[i.set_a].end(), sets[i.set_b].begin(),
                     sets[i.set_b].end(), std::back_inserter(both));
      if (spacing.new_to_family) union_into(both, family_seen[family[i.face]]);
      const std::vector<uint32_t>& s = sets[index[k]];
      if (std::includes(both.begin(), both.end(), s.begin(), s.end())) continue;
      ++refined;
      if (m - i.a > spacing.floor_of(sweeps[i.face])) {
        std::vector<uint32_t> seen_new;
        std::set_difference(s.begin(), s.end(), both.begin(), both.end(),
                            std::back_inserter(seen_new));
        fresh.push_back(std::move(seen_new));
        next.push_back({i.face, i.a, m, i.set_a, index[k], fresh.size() - 1});
        next.push_back({i.face, m, i.b, index[k], i.set_b, fresh.size() - 1});
      }
    }
    for (size_t k = 0; k < open.size(); ++k) add_seen(open[k].face, sets[index[k]]);
    refine = double(refined) / double(open.size());
    open = std::move(next);
  }
  return run;
}

}  // namespace vislib
