// segment_visibility.cpp: from-segment visibility for static triangles.
// Paper: "Complex VEs on All-In-One VR Headsets Through Continuous From-Segment Visibility
// Computation", §3.1, Alg. 1. Math: shared/design/visibility-math.md §1, §2, §5.1, §6, §7.
//
// Structure (per cube face): (1) every triangle's footprint bounding box and nearest possible
// depth; (2) counting-sort binning into tiles of tile_size^2 pixels; (3) tiles in parallel: the
// tile's triangles front to back, coverage interval per pixel of the footprint's row spans,
// lower-envelope insertion; triangles whose nearest depth lies behind everything in a fully
// covered tile are skipped (exact: they cannot be first anywhere there); (4) per-tile results
// reduced in tile order, so nothing depends on scheduling.
#include "vislib/kernel/segment_visibility.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cassert>
#include <chrono>
#include <cmath>

#include "vislib/kernel/dynamic_visibility.h"
#include "vislib/kernel/footprint.h"
#include "vislib/kernel/kernel_support.h"
#include "vislib/kernel/static_coverage.h"

namespace vislib {

StaticTriangle prepare_static_triangle(const Vec3 c[3], Vec3 v0, Vec3 v1) {
  StaticTriangle st;
  const Vec3 delta = v1 - v0;
  Vec3 r[3] = {c[0] - v0, c[1] - v0, c[2] - v0};  // re-centred (math note §6)
  for (int e = 0; e < 3; ++e) {
    int i = e, j = (e + 1) % 3;
    // Canonical orientation: P is the lexicographically smaller world endpoint (§2.5).
    bool forward = !lex_less(c[j], c[i]);
    const Vec3& P = forward ? r[i] : r[j];
    const Vec3& Q = forward ? r[j] : r[i];
    Vec3 E = Q - P;
    st.KA[e] = cross(E, delta);
    st.KB[e] = cross(E, -P);
    st.rho[e] = forward ? 1.0 : -1.0;
  }
  st.n = cross(r[1] - r[0], r[2] - r[0]);
  st.N0 = dot(st.n, r[0]);
  st.N1 = dot(st.n, delta);
  return st;
}

namespace {

// Keeps t with A t + B > 0 inside [lo, hi]; false when nothing is left.
inline bool halfline(double A, double B, double& lo, double& hi) {
  if (A > 0) {
    lo = std::max(lo, -B / A);
  } else if (A < 0) {
    hi = std::min(hi, -B / A);
  } else if (!(B > 0)) {
    return false;
  }
  return lo < hi;
}

}  // namespace

bool static_coverage(const StaticTriangle& tri, Vec3 d, Vec3 S, Vec3 T, double near, double& lo,
                     double& hi, LinearDepth& depth) {
  const double Dn = dot(d, tri.n);
  if (Dn == 0) return false;  // ray parallel to the plane, or degenerate triangle (§2.2)
  const double sigma = Dn > 0 ? 1.0 : -1.0;
  lo = 0;
  hi = 1;
  for (int e = 0; e < 3; ++e) {
    double A = dot(d, tri.KA[e]), B = dot(d, tri.KB[e]);
    if (A == 0 && B == 0) {  // persistent on-edge tie: perturb d -> d + eps S + eps^2 T (§2.5)
      A = dot(S, tri.KA[e]);
      B = dot(S, tri.KB[e]);
      if (A == 0 && B == 0) {
        A = dot(T, tri.KA[e]);
        B = dot(T, tri.KB[e]);
      }
    }
    double f = sigma * tri.rho[e];
    if (!halfline(f * A, f * B, lo, hi)) return false;
  }
  // In front of the near plane: lambda(t) > near  <=>  sigma (N0 - near Dn - N1 t) > 0.
  if (!halfline(-sigma * tri.N1, sigma * (tri.N0 - near * Dn), lo, hi)) return false;
  depth = LinearDepth{tri.N0, tri.N1, Dn};
  return true;
}

namespace {

struct FaceTriangle {
  uint32_t id;
  float zmin;  // nearest possible view depth over the segment (rounded down)
};

}  // namespace

SegmentResult segment_visibility(const Scene& scene, Vec3 v0, Vec3 v1, const SegmentOptions& opt) {
  assert(opt.resolution >= 1 && opt.near > 0 && opt.tile_size >= 1);
  if (scene.sphere_count() > 0 || scene.is_dynamic())
    return dynamic_segment_visibility(scene, v0, v1, opt);
  auto start = std::chrono::steady_clock::now();
  const int N = opt.resolution;
  const int TS = opt.tile_size;
  const int tiles_x = (N + TS - 1) / TS;
  const int tile_count = tiles_x * tiles_x;
  const size_t ntri = scene.triangle_count();

  SegmentResult result;
  if (opt.want_pieces) result.pieces.resize(size_t(6) * N * N);
  std::vector<SegmentStats> tile_stats(size_t(6) * tile_count);

  // Scratch per thread: the pixel lists of one tile (capacity kept between tiles), and for each
  // pixel whether its list covers [0,1] and its farthest depth (for depth culling).
  struct TileScratch {
    std::vector<PieceList> lists;
    std::vector<uint8_t> full;
    std::vector<double> far;
    std::vector<std::vector<TieRecord>> ties;  // per pixel (CoplanarRule::Both)
  };
  tbb::enumerable_thread_specific<TileScratch> scratch([TS] {
    return TileScratch{std::vector<PieceList>(size_t(TS) * TS), std::vector<uint8_t>(size_t(TS) * TS),
                       std::vector<double>(size_t(TS) * TS), std::vector<std::vector<TieRecord>>(size_t(TS) * TS)};
  });
  const bool keep_ties = opt.coplanar == CoplanarRule::Both;
  // Depth culling stays exact with ties: a triangle tied with the front lies within eps_z of it,
  // so only triangles beyond far * (1 + eps_z) are skipped (2 eps_z covers the rounding).
  const double far_scale = keep_ties ? 1 + 2 * opt.eps_z : 1.0;
  tbb::enumerable_thread_specific<FoundMarks> found_by_thread([&] { return FoundMarks(ntri, opt.want_witnesses); });

  std::vector<int> bbox(ntri * 4);
  std::vector<float> zmin(ntri);
  std::vector<uint32_t> bin_start(tile_count + 1);
  std::vector<FaceTriangle> bins;

  for (int face = 0; face < 6; ++face) {
    const FaceAxes axes = face_axes(face, opt.orientation);
    // (1) footprint bounds and nearest depth of every triangle on this face.
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, ntri, 1024), [&](const tbb::blocked_range<size_t>& r) {
          for (size_t t = r.begin(); t != r.end(); ++t) {
            auto c = scene.corners(uint32_t(t), opt.state);
            Vec3 rel[6] = {c[0] - v0, c[1] - v0, c[2] - v0, c[0] - v1, c[1] - v1, c[2] - v1};
            int* b = &bbox[t * 4];
            Footprint fp = compute_footprint(rel, 6, axes, opt.near);
            if (!footprint_pixel_bounds(fp, N, b[0], b[1], b[2], b[3])) {
              b[0] = 1;
              b[1] = 0;  // empty
              continue;
            }
            double z = INFINITY;
            for (const Vec3& q : rel) z = std::min(z, dot(axes.F, q));
            float zf = float(z);
            if (double(zf) > z) zf = std::nextafter(zf, -INFINITY);
            zmin[t] = zf;
          }
        });
    // (2) bin by tile (counting sort, in id order).
    bin_by_tile(bbox, ntri, TS, tiles_x, bin_start, bins, [&](size_t t) {
      return FaceTriangle{uint32_t(t), zmin[t]};
    });

    // (3) tiles in parallel.
    tbb::parallel_for(
        tbb::blocked_range<int>(0, tile_count, 1), [&](const tbb::blocked_range<int>& r) {
          TileScratch& sc = scratch.local();
          auto& lists = sc.lists;
          FoundMarks& found = found_by_thread.local();
          for (int tile = r.begin(); tile != r.end(); ++tile) {
            SegmentStats& stats = tile_stats[size_t(face) * tile_count + tile];
            const int tx0 = (tile % tiles_x) * TS, ty0 = (tile / tiles_x) * TS;
            const int tx1 = std::min(N, tx0 + TS) - 1, ty1 = std::min(N, ty0 + TS) - 1;
            const int tw = tx1 - tx0 + 1, th = ty1 - ty0 + 1;
            for (auto& l : lists) l.clear();
            for (auto& l : sc.ties) l.clear();
            std::fill(sc.full.begin(), sc.full.end(), 0);
            std::fill(sc.far.begin(), sc.far.end(), INFINITY);
            FaceTriangle* tb = bins.data() + bin_start[tile];
            FaceTriangle* te = bins.data() + bin_start[tile + 1];
            // Front to back (nearest possible depth), ties by id: the order only affects speed.
            std::sort(tb, te, [](const FaceTriangle& a, const FaceTriangle& b) {
              return a.zmin < b.zmin || (a.zmin == b.zmin && a.id < b.id);
            });
            stats.triangle_tiles += uint64_t(te - tb);
            // Depth culling (exact): a pixel whose list covers [0,1] with every piece nearer than a
            // triangle's nearest possible depth cannot show that triangle; when that holds for
            // every pixel of the tile, no later triangle (sorted by that depth) can show anywhere
            // in it.
            double tile_far = INFINITY;
            int since_check = 0;
            for (FaceTriangle* ft = tb; ft != te; ++ft) {
              const double tz = double(ft->zmin);
              if (opt.depth_culling) {
                if (++since_check >= 16 || ft == tb) {
                  since_check = 0;
                  double far = -INFINITY;
                  for (int k = 0; k < th && far < INFINITY; ++k)
                    for (int i = 0; i < tw; ++i) far = std::max(far, sc.far[size_t(k) * TS + i]);
                  tile_far = far;
                }
                if (tz > tile_far) {
                  stats.culled_triangle_tiles += uint64_t(te - ft);
                  break;
                }
              }
              auto c = scene.corners(ft->id, opt.state);
              Vec3 corners[3] = {c[0], c[1], c[2]};
              StaticTriangle st = prepare_static_triangle(corners, v0, v1);
              if (st.n == Vec3{0, 0, 0}) continue;  // degenerate: never covers (H5)
              Vec3 rel[6] = {c[0] - v0, c[1] - v0, c[2] - v0, c[0] - v1, c[1] - v1, c[2] - v1};
              Footprint fp = compute_footprint(rel, 6, axes, opt.near);
              int y0 = std::max(ty0, bbox[size_t(ft->id) * 4 + 2]);
              int y1 = std::min(ty1, bbox[size_t(ft->id) * 4 + 3]);
              for (int y = y0; y <= y1; ++y) {
                int x0, x1;
                if (!footprint_row_span(fp, N, y, x0, x1)) continue;
                x0 = std::max(x0, tx0);
                x1 = std::min(x1, tx1);
                for (int x = x0; x <= x1; ++x) {
                  const size_t k = size_t(y - ty0) * TS + (x - tx0);
                  if (opt.depth_culling && tz > sc.far[k]) {
                    ++stats.culled_pairs;
                    continue;
                  }
                  ++stats.pair_tests;
                  Vec3 d = pixel_direction(axes, x, y, N);
                  double lo, hi;
                  LinearDepth depth;
                  if (!static_coverage(st, d, axes.S, axes.T, opt.near, lo, hi, depth)) continue;
                  ++stats.covered_pairs;
                  PieceList& l = lists[k];
                  TieRule rule{opt.eps_z, keep_ties ? &sc.ties[k] : nullptr};
                  if (insert_piece(l, Piece{lo, hi, ft->id, depth}, rule) && opt.depth_culling &&
                      covers_segment(l))
                    sc.far[k] = farthest_depth(l) * far_scale;
                }
              }
            }
            // Tile results: marks, witnesses, statistics.
            size_t bytes = 0;
            for (int y = ty0; y <= ty1; ++y)
              for (int x = tx0; x <= tx1; ++x) {
                PieceList& l = lists[size_t(y - ty0) * TS + (x - tx0)];
                bytes += l.capacity() * sizeof(Piece);
                if (l.empty()) continue;
                ++stats.pixels_with_pieces;
                stats.final_pieces += l.size();
                stats.max_pieces_per_pixel =
                    std::max<uint64_t>(stats.max_pieces_per_pixel, l.size());
                const auto& ties = sc.ties[size_t(y - ty0) * TS + (x - tx0)];
                for_each_visible(l, ties, [&](uint32_t id, double t0, double t1) {
                  double len = t1 - t0;
                  if (!(len > opt.eps_len)) return;
                  Witness w;
                  w.tri = id;
                  w.face = face;
                  w.x = x;
                  w.y = y;
                  w.t = 0.5 * (t0 + t1);
                  found.mark(id, len, w);
                });
                if (opt.want_pieces) result.pieces[(size_t(face) * N + y) * N + x] = l;
              }
            stats.peak_tile_bytes = double(bytes);
          }
        });
  }

  // (4) reduce: statistics in tile order; marks and witnesses over threads by a total order.
  for (const SegmentStats& ts : tile_stats) result.stats.add(ts);
  std::vector<uint8_t> seen;
  std::vector<Witness> best;
  reduce_found(found_by_thread, ntri, opt.want_witnesses, seen, best);
  for (size_t t = 0; t < ntri; ++t)
    if (seen[t]) {
      result.visible.push_back(uint32_t(t));
      if (opt.want_witnesses) result.witnesses.push_back(best[t]);
    }
  result.stats.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace vislib
