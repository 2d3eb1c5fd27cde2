// tile_driver.h: the one tile driver of the from-segment kernels (issue 13, item 1). Static
// triangles (segment_visibility.cpp) and the runs of moving triangles and spheres
// (dynamic_visibility.cpp) share it; the primitive kind is its template parameter.
//
// Per cube face: (1) every primitive's pixel rectangle and nearest possible view depth on the
// face (the kind's footprint bounds); (2) counting-sort binning into tiles of tile_size^2 pixels,
// in primitive order; (3) tiles in parallel: the tile's primitives front to back by nearest depth
// (ties by id), each handed to the kind, which tests coverage at the pixels of its footprint and
// composites the intervals into the pixel lists; once every pixel of the tile covers [0, 1]
// nearer than a primitive's nearest depth, that primitive and all later ones are skipped (exact:
// none of them can be first anywhere in the tile); then the kind reports each pixel's final list
// (marks, witnesses, pieces). Per-tile statistics are kept apart and reduced in tile order by the
// caller, so nothing depends on scheduling.
//
// What a kind provides (see StaticKind and DynamicKind):
//   using Scratch = ...;   per-thread tile state with, per pixel of a tile: `lists` (its pieces),
//                          `ties` (its tie records) and `far` (a depth that its list covers
//                          [0, 1] nearer than; inf until it does); the driver resets all three
//                          for every tile
//   Scratch make_scratch(int tile_size) const;
//   size_t count() const;  primitives
//   bool bounds(size_t p, int face, const FaceAxes&, int* box, double& zmin);
//                          pixel rectangle (x0, x1, y0, y1) and nearest depth; false when empty.
//                          Called in parallel for different p.
//   void cover(Scratch&, const TileItem&, const int* box, const TileRect&, const FaceAxes&,
//              SegmentStats&) const;         coverage and compositing of one primitive
//   void finish_pixel(Scratch&, size_t k, int face, int x, int y, FoundMarks&) const;
//                          report the non-empty list of pixel k = (y - y0) * stride + (x - x0)
#pragma once

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "vislib/base/cubemap.h"
#include "vislib/kernel/footprint.h"
#include "vislib/kernel/kernel_support.h"
#include "vislib/kernel/segment_visibility.h"

namespace vislib {

// A primitive binned into a tile: its id and its nearest possible view depth on the face, rounded
// down to a float (8 bytes to sort; culling against a smaller bound stays exact).
struct TileItem {
  uint32_t id;
  float zmin;
};

// A tile's pixels [x0, x1] x [y0, y1] (inclusive); pixel (x, y) is scratch index
// (y - y0) * stride + (x - x0).
struct TileRect {
  int x0, y0, x1, y1, stride;
  size_t index(int x, int y) const { return size_t(y - y0) * size_t(stride) + size_t(x - x0); }
};

inline float round_down_to_float(double z) {
  float f = float(z);
  if (double(f) > z) f = std::nextafter(f, -INFINITY);
  return f;
}

// The faces each of n triangles can reach (bit k: face k), for all six faces at once
// (reachable_faces); relative(t, rel) writes triangle t's six eye-relative corners. Most
// triangles reach one face, and a kind's bounds() skips the other five.
template <class Relative>
std::vector<uint8_t> classify_faces(size_t n, const SegmentOptions& opt, const Relative& relative) {
  std::vector<uint8_t> faces(n);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1024),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t t = r.begin(); t != r.end(); ++t) {
                        Vec3 rel[6];
                        relative(t, rel);
                        faces[t] = uint8_t(reachable_faces(rel, 6, opt.orientation, opt.near));
                      }
                    });
  return faces;
}

// Runs the six faces of one from-segment run of `kind`. tile_stats has 6 * tiles^2 entries
// (counts are added to them, so several runs can share them); found_by_thread gets the marks.
template <class Kind>
void run_tiles(Kind& kind, const SegmentOptions& opt,
               tbb::enumerable_thread_specific<FoundMarks>& found_by_thread,
               std::vector<SegmentStats>& tile_stats) {
  const int N = opt.resolution, TS = opt.tile_size;
  const int tiles_x = (N + TS - 1) / TS, tile_count = tiles_x * tiles_x;
  const size_t count = kind.count();
  tbb::enumerable_thread_specific<typename Kind::Scratch> scratch(
      [&kind, TS] { return kind.make_scratch(TS); });
  std::vector<int> bbox(count * 4);
  std::vector<float> zmin(count);
  std::vector<uint32_t> bin_start;
  std::vector<TileItem> bins;

  for (int face = 0; face < kCubeFaces; ++face) {
    const FaceAxes axes = face_axes(face, opt.orientation);
    // (1) footprint bounds and nearest depth of every primitive on this face.
    tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 512),
                      [&](const tbb::blocked_range<size_t>& r) {
                        for (size_t p = r.begin(); p != r.end(); ++p) {
                          int* b = &bbox[p * 4];
                          double z = 0;
                          if (!kind.bounds(p, face, axes, b, z)) {
                            b[0] = 1;
                            b[1] = 0;  // empty
                            continue;
                          }
                          zmin[p] = round_down_to_float(z);
                        }
                      });
    // (2) bin by tile (counting sort, in id order).
    bin_by_tile(bbox, count, TS, tiles_x, bin_start, bins, [&](size_t p) {
      return TileItem{uint32_t(p), zmin[p]};
    });

    // (3) tiles in parallel.
    tbb::parallel_for(tbb::blocked_range<int>(0, tile_count, 1),
                      [&](const tbb::blocked_range<int>& r) {
                        auto& sc = scratch.local();
                        FoundMarks& found = found_by_thread.local();
                        for (int tile = r.begin(); tile != r.end(); ++tile) {
                          SegmentStats& stats = tile_stats[size_t(face) * tile_count + tile];
                          TileRect rect;
                          rect.x0 = (tile % tiles_x) * TS;
                          rect.y0 = (tile / tiles_x) * TS;
                          rect.x1 = std::min(N, rect.x0 + TS) - 1;
                          rect.y1 = std::min(N, rect.y0 + TS) - 1;
                          rect.stride = TS;
                          const int tw = rect.x1 - rect.x0 + 1, th = rect.y1 - rect.y0 + 1;
                          for (auto& l : sc.lists) l.clear();
                          for (auto& l : sc.ties) l.clear();
                          std::fill(sc.far.begin(), sc.far.end(), INFINITY);
                          TileItem* tb = bins.data() + bin_start[tile];
                          TileItem* te = bins.data() + bin_start[tile + 1];
                          // Front to back (nearest possible depth), ties by id: the order only
                          // affects speed.
                          std::sort(tb, te, [](const TileItem& a, const TileItem& b) {
                            return a.zmin < b.zmin || (a.zmin == b.zmin && a.id < b.id);
                          });
                          stats.triangle_tiles += uint64_t(te - tb);
                          double tile_far = INFINITY;
                          int since_check = 0;
                          for (TileItem* it = tb; it != te; ++it) {
                            if (opt.depth_culling) {
                              // Every 16 primitives: the farthest `far` over the tile's pixels.
                              if (++since_check >= 16 || it == tb) {
                                since_check = 0;
                                double f = -INFINITY;
                                for (int k = 0; k < th && f < INFINITY; ++k)
                                  for (int i = 0; i < tw; ++i)
                                    f = std::max(f, sc.far[size_t(k) * TS + i]);
                                tile_far = f;
                              }
                              if (double(it->zmin) > tile_far) {
                                stats.culled_triangle_tiles += uint64_t(te - it);
                                break;
                              }
                            }
                            kind.cover(sc, *it, &bbox[size_t(it->id) * 4], rect, axes, stats);
                          }
                          // Tile results: marks, witnesses, pieces, statistics.
                          size_t bytes = 0;
                          for (int y = rect.y0; y <= rect.y1; ++y)
                            for (int x = rect.x0; x <= rect.x1; ++x) {
                              const size_t k = rect.index(x, y);
                              const auto& l = sc.lists[k];
                              bytes += l.capacity() * sizeof(l[0]);
                              if (l.empty()) continue;
                              ++stats.pixels_with_pieces;
                              stats.final_pieces += l.size();
                              stats.max_pieces_per_pixel =
                                  std::max<uint64_t>(stats.max_pieces_per_pixel, l.size());
                              kind.finish_pixel(sc, k, face, x, y, found);
                            }
                          stats.peak_tile_bytes = std::max(stats.peak_tile_bytes, double(bytes));
                        }
                      });
  }
}

}  // namespace vislib
