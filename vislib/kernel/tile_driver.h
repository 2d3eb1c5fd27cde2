// tile_driver.h: the one tile driver of the from-segment kernels. Static
// triangles (segment_visibility.cpp) and the runs of moving triangles and spheres
// (dynamic_visibility.cpp) share it; the primitive kind is its template parameter.
//
// Per cube face: (1) every primitive's pixel rectangle and nearest possible view depth on the
// face (the kind's footprint bounds); (2) counting-sort binning into tiles of tile_size^2 pixels,
// in primitive order; (3) tiles in parallel: the tile's primitives front to back by nearest depth
// (ties by id), each handed to the kind, which tests coverage at the pixels of its footprint and
// composites the intervals into the pixel lists; once every pixel of the tile covers [0, 1]
// nearer than a primitive's nearest depth, that primitive and all later ones are skipped (exact:
// none of them can be first anywhere in the tile), and one that lies beyond every block (of 4 x 4)
// of the tile its rectangle meets is skipped alone (TileFar); then the kind reports each pixel's
// final list
// (marks, witnesses, pieces). Per-tile statistics are kept apart and reduced in tile order by the
// caller, so nothing depends on scheduling.
//
// With a BVH (static triangles with SegmentOptions::bvh, triangle_bvh.h), steps (1) and (2) are
// skipped: each tile walks the tree nearest node first (a heap ordered by nearest depth, ties by
// index), keeps the nodes and triangles whose footprint rectangle meets the tile and that do not
// lie behind the blocks of the tile they meet (TileFar), and stops when the nearest entry lies
// behind every pixel of the tile, so the nodes behind it are never opened.
// Node and triangle rectangles are computed once per face, by the first tile that needs them.
// The nodes' rectangles contain their triangles' and their depths lie below them
// (box_footprint_bounds), so the tile meets exactly the triangles it meets without the tree,
// less those the culling skips; the lists, marks and witnesses are the same.
//
// What a kind provides (see StaticKind and DynamicKind):
//   using Scratch = ...;   per-thread tile state with, per pixel of a tile: `lists` (its pieces),
//                          `ties` (its tie records) and `far` (a depth that its list covers
//                          [0, 1] nearer than; inf until it does); the driver resets all three
//                          for every tile
//   void begin_tile(Scratch&) const;  reset what else the kind keeps per tile (called after them)
//   size_t held_bytes(const Scratch&) const;  bytes of that, for SegmentStats::peak_tile_bytes
//   Scratch make_scratch(int tile_size) const;
//   size_t count() const;  primitives
//   bool bounds(size_t p, int face, const FaceAxes&, int* box, double& zmin);
//                          pixel rectangle (x0, x1, y0, y1) and nearest depth; false when empty.
//                          Called in parallel for different p.
//   void cover(Scratch&, const TileItem&, const int* box, const TileRect&, const FaceAxes&,
//              SegmentStats&) const;         coverage and compositing of one primitive (the kind
//                          may hold it back; culling bounds it has not yet lowered stay bounds)
//   void flush(Scratch&, const TileRect&, const FaceAxes&, SegmentStats&) const;
//                          composite what cover() held back; called before the driver
//                          recomputes its culling bounds, and before the tile's results
//   void finish_tile(Scratch&, int face, const TileRect&, const FaceAxes&, FoundMarks&,
//                    SegmentStats&) const;  after the last flush, with the tile's lists final:
//                          mark what is tested against them without being composited
//                          (see-through triangles)
//   void finish_pixel(Scratch&, size_t k, int face, int x, int y, FoundMarks&) const;
//                          report the non-empty list of pixel k = (y - y0) * stride + (x - x0)
//   static constexpr bool kHasBvh;          true: also
//   const TriangleBvh* bvh() const;         the tree (null: bin every primitive), and
//   bool node_bounds(uint32_t node, const FaceAxes&, int* box, double& zmin) const;
#pragma once

#include <sys/mman.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <new>
#include <optional>
#include <type_traits>
#include <vector>

#include "vislib/base/cubemap.h"
#include "vislib/base/phase_times.h"
#include "vislib/kernel/footprint.h"
#include "vislib/kernel/kernel_support.h"
#include "vislib/kernel/segment_visibility.h"
#include "vislib/kernel/triangle_bvh.h"

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
                        Vec3 rel[12];
                        const int k = relative(t, rel);
                        faces[t] = uint8_t(reachable_faces(rel, k, opt.orientation, opt.near));
                      }
                    });
  return faces;
}

// Per-face, compute-once rectangles and depths (of BVH nodes, or of triangles by their position in
// the tree's leaf order): the first thread to need entry i computes it and publishes it; a thread
// that finds it being written computes its own copy (the same values: the computation is
// deterministic). An entry is ready when its stamp is the current face's: each face has its own
// generation number, so a new face makes every entry stale without touching it.
// Memory: the arrays are mapped untouched (mmap), so a run's resident memory grows with the
// entries its walk touches (nodes and leaves lie in tree order, so those are few pages), not with
// the scene. Arrays of at most kFaceBoundsKeepBytes stay resident from face to face and from run
// to run (FaceBoundsCaches::take): on lqdm1 (4,208 triangles, N = 128) handing the pages back at
// every face and faulting them in again was 13% of a short run, most of it the other cores'
// TLB flushes. Larger arrays hand their pages back at every new face (madvise MADV_DONTNEED: they
// read as zeros, stale stamps, when touched again), so a run holds one face's entries, not the
// union of its six faces' (on the 1M-triangle city at N = 512, an 8 m segment's six faces touch
// 6.6 MB of entries, one face at most 2.1 MB), and are unmapped at the run's end: several runs of
// a bake hold these at once.
// Callers call next_face only while no tile of the run reads the cache.
constexpr size_t kFaceBoundsKeepBytes = size_t(4) << 20;

class FaceBoundsCache {
  static_assert(std::is_trivially_default_constructible_v<std::atomic<uint32_t>>);

 public:
  FaceBoundsCache() = default;
  FaceBoundsCache(const FaceBoundsCache&) = delete;
  FaceBoundsCache& operator=(const FaceBoundsCache&) = delete;
  ~FaceBoundsCache() { release(); }
  // Makes every entry stale, for a face of a run over `n` entries.
  void next_face(size_t n) {
    if (n > size_) {
      release();
      // std::atomic<uint32_t> is trivially constructible: zeroed memory holds stale stamps.
      size_ = n;
      stamp_ = static_cast<std::atomic<uint32_t>*>(map_untouched(stamp_bytes()));
      box_ = static_cast<int*>(map_untouched(box_bytes()));  // read only under a stamp
      zmin_ = static_cast<float*>(map_untouched(zmin_bytes()));
      if (!stamp_ || !box_ || !zmin_) {
        release();
        throw std::bad_alloc();
      }
    } else if (!kept()) {
      // box_ and zmin_ are read only under a ready stamp: discarding them only frees memory.
      if (!discard(stamp_, stamp_bytes())) clear_stamps();
      discard(box_, box_bytes());
      discard(zmin_, zmin_bytes());
    }
    if (++generation_ > kLastGeneration) {  // stamps of the first generations come back
      clear_stamps();
      generation_ = 1;
    }
  }
  // True when the arrays stay resident between faces and runs (kFaceBoundsKeepBytes).
  bool kept() const { return stamp_bytes() + box_bytes() + zmin_bytes() <= kFaceBoundsKeepBytes; }
  // Rectangle (x0, x1, y0, y1) in box and nearest depth (rounded down) in z; false when empty.
  template <class Compute>
  bool get(size_t i, int* box, float& z, Compute compute) {
    const uint32_t ready = 2 * generation_ + 1, writing = 2 * generation_;
    uint32_t seen = stamp_[i].load(std::memory_order_acquire);
    if (seen != ready) {
      double zd = 0;
      bool ok = compute(box, zd);
      if (!ok) {
        box[0] = 1;
        box[1] = 0;
      }
      z = ok ? round_down_to_float(zd) : 0.0f;
      if (seen != writing &&
          stamp_[i].compare_exchange_strong(seen, writing, std::memory_order_acq_rel)) {
        std::copy(box, box + 4, &box_[i * 4]);
        zmin_[i] = z;
        stamp_[i].store(ready, std::memory_order_release);
      }
      return ok;
    }
    std::copy(&box_[i * 4], &box_[i * 4] + 4, box);
    z = zmin_[i];
    return box[0] <= box[1];
  }

 private:
  // An entry's stamp: 2g + 1 ready in generation g, 2g claimed by a writer in generation g
  // (g >= 1); anything else, zero included, is stale.
  static constexpr uint32_t kLastGeneration = (uint32_t(1) << 31) - 1;
  size_t stamp_bytes() const { return size_ * sizeof(std::atomic<uint32_t>); }
  size_t box_bytes() const { return size_ * 4 * sizeof(int); }
  size_t zmin_bytes() const { return size_ * sizeof(float); }
  void clear_stamps() {
    for (size_t i = 0; i < size_; ++i) stamp_[i].store(0, std::memory_order_relaxed);
  }
  // Zeroed pages straight from the kernel, resident only once written, and returned to it by
  // release(). (malloc would hand back memory freed by earlier runs, resident already: every run
  // in flight would then hold its whole arrays.)
  static void* map_untouched(size_t bytes) {
    void* p = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    return p == MAP_FAILED ? nullptr : p;
  }
  // Hands the pages back; zero-filled on the next touch. False if the system refused.
  static bool discard(void* p, size_t bytes) { return madvise(p, bytes, MADV_DONTNEED) == 0; }
  static void unmap(void* p, size_t bytes) {
    if (p) munmap(p, bytes);
  }
  void release() {
    unmap(stamp_, stamp_bytes());
    unmap(box_, box_bytes());
    unmap(zmin_, zmin_bytes());
    stamp_ = nullptr;
    box_ = nullptr;
    zmin_ = nullptr;
    size_ = 0;
    generation_ = 0;
  }
  std::atomic<uint32_t>* stamp_ = nullptr;
  int* box_ = nullptr;
  float* zmin_ = nullptr;
  size_t size_ = 0;
  uint32_t generation_ = 0;  // the current face's; 0 before the first
};

// The node and triangle caches of one run. take() hands out the calling thread's pair (a new
// one when it has none, or when its pair is in use further up the stack: a thread waiting on its
// run's tiles may take up another run);
// give_back() keeps the pair for the thread's next run when both stay within
// kFaceBoundsKeepBytes, and frees it otherwise.
struct FaceBoundsCaches {
  FaceBoundsCache nodes, triangles;
  static std::unique_ptr<FaceBoundsCaches> take() {
    std::unique_ptr<FaceBoundsCaches> c = std::move(slot());
    if (!c) c.reset(new FaceBoundsCaches);
    return c;
  }
  static void give_back(std::unique_ptr<FaceBoundsCaches> c) {
    if (!slot() && c->nodes.kept() && c->triangles.kept()) slot() = std::move(c);
  }

 private:
  static std::unique_ptr<FaceBoundsCaches>& slot() {
    thread_local std::unique_ptr<FaceBoundsCaches> c;
    return c;
  }
};

// The culling bounds of one tile: the farthest `far` over its pixels (inf while some pixel does
// not cover [0, 1]), and the same over each of its 4 x 4 blocks, recomputed every 16 primitives
// (far only decreases once finite, so an older value stays a bound). A primitive whose nearest
// depth lies beyond the blocks its rectangle meets is hidden at every pixel it can reach: the
// per-pixel culling of the kind would skip each of its pairs, so skipping it whole is exact and
// changes nothing.
template <class Scratch>
struct TileFar {
  const Scratch& sc;
  const TileRect& rect;
  int tw, th;
  double value = INFINITY;
  double block[16];
  int bs = 1;  // block side in pixels
  int since = 16;
  TileFar(const Scratch& s, const TileRect& r) : sc(s), rect(r) {
    tw = r.x1 - r.x0 + 1;
    th = r.y1 - r.y0 + 1;
    bs = (r.stride + 3) / 4;
    std::fill(block, block + 16, INFINITY);
  }
  void refresh() {
    std::fill(block, block + 16, -INFINITY);
    for (int k = 0; k < th; ++k) {
      const double* row = &sc.far[size_t(k) * size_t(rect.stride)];
      double* b = &block[(k / bs) * 4];
      for (int x0 = 0, bx = 0; x0 < tw; x0 += bs, ++bx) {
        double m = b[bx];
        for (int i = x0, e = std::min(tw, x0 + bs); i < e; ++i) m = std::max(m, row[i]);
        b[bx] = m;
      }
    }
    value = -INFINITY;
    for (int i = 0; i < 16; ++i) value = std::max(value, block[i]);
  }
  // True when a primitive whose nearest depth is zmin lies behind every pixel of the tile.
  // `count` false: a BVH node, which does not advance the 16 (the same bound as before).
  // `before_refresh` runs before the bounds are recomputed: the kind composites what it holds
  // back, so that the bounds are those of every primitive covered so far.
  template <class F>
  bool culls(float zmin, bool count, F&& before_refresh) {
    if (count && ++since >= 16) {
      since = 0;
      before_refresh();
      refresh();
    }
    return double(zmin) > value;
  }
  // True when it lies behind every pixel of the tile inside box (x0, x1, y0, y1).
  bool culls_box(float zmin, const int* box) const {
    const int bx0 = (std::max(box[0], rect.x0) - rect.x0) / bs;
    const int bx1 = (std::min(box[1], rect.x1) - rect.x0) / bs;
    const int by0 = (std::max(box[2], rect.y0) - rect.y0) / bs;
    const int by1 = (std::min(box[3], rect.y1) - rect.y0) / bs;
    double m = -INFINITY;
    for (int y = by0; y <= by1; ++y)
      for (int x = bx0; x <= bx1; ++x) m = std::max(m, block[y * 4 + x]);
    return double(zmin) > m;
  }
};

// A tile's queue entry with a BVH: a node or a triangle (with its rectangle), under one 64-bit key
// ordered as the walk needs it: nearest depth first; at equal depths nodes before triangles, then
// by index or id. Then the triangles leave the queue in exactly the order of the binned path
// (nearest depth, then id): a node's depth lies below its triangles', so every triangle ordered
// before one leaving the queue has already left it. The order matters: in floating point, the
// final lists of insert_piece depend slightly on it (interval_list.h).
struct QueueItem {
  uint64_t key;
  int box[4];
};
constexpr uint32_t kTriangleBit = 0x80000000u;
inline uint64_t queue_key(float zmin, uint32_t low) {
  uint32_t bits;
  const float z = zmin + 0.0f;  // -0 -> +0: equal depths, equal keys
  std::memcpy(&bits, &z, 4);
  bits = bits & 0x80000000u ? ~bits : bits | 0x80000000u;  // ascending as the floats
  return uint64_t(bits) << 32 | low;
}
inline float queue_zmin(uint64_t key) {
  uint32_t bits = uint32_t(key >> 32);
  bits = bits & 0x80000000u ? bits & 0x7fffffffu : ~bits;
  float z;
  std::memcpy(&z, &bits, 4);
  return z;
}
struct QueueAfter {  // min-heap order for std::push_heap / pop_heap
  bool operator()(const QueueItem& a, const QueueItem& b) const { return a.key > b.key; }
};

// One tile with a BVH: nearest entry first; a node's children (or a leaf's triangles) enter the
// queue when their rectangle meets the tile; a triangle is covered when it leaves the queue,
// unless it lies behind the blocks its rectangle meets (skipped), or behind every pixel of the
// tile (it and everything after it: the walk ends).
template <class Kind, class Scratch>
void walk_tile(Kind& kind, const TriangleBvh& bvh, int face, const FaceAxes& axes,
               const TileRect& rect, bool culling, Scratch& sc, TileFar<Scratch>& tile_far,
               FaceBoundsCache& node_cache, FaceBoundsCache& tri_cache,
               std::vector<QueueItem>& queue, SegmentStats& stats) {
  auto meets = [&rect](const int* b) {
    return b[0] <= b[1] && b[0] <= rect.x1 && b[1] >= rect.x0 && b[2] <= rect.y1 && b[3] >= rect.y0;
  };
  auto push_node = [&](uint32_t node) {
    QueueItem q;
    float z;
    node_cache.get(node, q.box, z,
                   [&](int* b, double& zd) { return kind.node_bounds(node, axes, b, zd); });
    if (!meets(q.box) || (culling && tile_far.culls_box(z, q.box))) return;
    q.key = queue_key(z, node);
    queue.push_back(q);
    std::push_heap(queue.begin(), queue.end(), QueueAfter{});
  };
  auto flush = [&] { kind.flush(sc, rect, axes, stats); };
  queue.clear();
  if (bvh.nodes.empty()) return;
  push_node(0);
  uint64_t queued_triangles = 0;
  while (!queue.empty()) {
    std::pop_heap(queue.begin(), queue.end(), QueueAfter{});
    const QueueItem q = queue.back();
    queue.pop_back();
    const float z = queue_zmin(q.key);
    const uint32_t low = uint32_t(q.key);
    if (culling && tile_far.culls(z, low & kTriangleBit, flush)) {
      uint64_t left = low & kTriangleBit ? 1 : 0;
      for (const QueueItem& e : queue) left += uint32_t(e.key) & kTriangleBit ? 1 : 0;
      stats.culled_triangle_tiles += left;
      break;
    }
    if (culling && tile_far.culls_box(z, q.box)) {
      stats.culled_triangle_tiles += low & kTriangleBit ? 1 : 0;
      continue;
    }
    if (low & kTriangleBit) {
      kind.cover(sc, TileItem{low & ~kTriangleBit, z}, q.box, rect, axes, stats);
      continue;
    }
    const TriangleBvh::Node& n = bvh.nodes[low];
    ++stats.bvh_nodes_opened;
    if (n.count == 0) {
      push_node(n.first);
      push_node(n.first + 1);
      continue;
    }
    for (uint32_t i = n.first; i < n.first + n.count; ++i) {
      const uint32_t t = bvh.order[i];
      QueueItem e;
      float tz;
      tri_cache.get(i, e.box, tz,
                    [&](int* b, double& zd) { return kind.bounds(t, face, axes, b, zd); });
      if (!meets(e.box)) continue;
      ++queued_triangles;
      if (culling && tile_far.culls_box(tz, e.box)) {
        ++stats.culled_triangle_tiles;
        continue;
      }
      e.key = queue_key(tz, t | kTriangleBit);
      queue.push_back(e);
      std::push_heap(queue.begin(), queue.end(), QueueAfter{});
    }
  }
  stats.triangle_tiles += queued_triangles;
}

// Working memory a thread keeps between tiles, in MB: the tile scratch of a kind (its pixels'
// lists, ties and pools) and the BVH walk's queue. One set per thread, whatever the runs in flight
// (a thread runs one tile at a time; TBB hands it tiles of whichever run waits), reused by every
// run of every segment on that thread. A set that ends a tile holding more than this is kept
// only for the rest of that run: the thread frees it when it next takes a tile of another run.
// So a run of deep tiles costs its memory only while it runs, and its tiles reuse the lists'
// capacity instead of growing them again one tile after another (freeing the set after every
// such tile cost the speed suite's deep case, alone in its process, 15%: a 32-pixel tile there
// holds up to 25 MB, and the freed pages were faulted in again). 0.75 MB held on the 2 m street
// of the 300K-triangle city at N = 512 with 32-pixel tiles; see docs/performance.md, "Memory per
// thread".
constexpr double kThreadTileMemoryBudgetMB = 8.0;

// The tile scratch and walk queue of one thread (see kThreadTileMemoryBudgetMB).
template <class Scratch>
struct TileWork {
  Scratch sc;
  std::vector<QueueItem> queue;
  uint64_t over_budget_run = 0;  // the run (next_serial) that left it over budget; 0: within
};

// A number unique in the process, never 0: tells the tile driver's runs apart, and the segments
// whose per-thread caches hold results of theirs (StaticKind's fan edges).
inline uint64_t next_serial() {
  static std::atomic<uint64_t> last{0};
  return ++last;
}

// Hands out the calling thread's TileWork for `Scratch` (made by `make` when the thread has none,
// or when its own was made for another tile size, or was left over budget by another run, or is
// in use further up the stack) and takes it back after the tile.
template <class Scratch>
class ThreadTileWork {
 public:
  template <class Make>
  static std::unique_ptr<TileWork<Scratch>> take(int tile_size, uint64_t run, Make make) {
    std::unique_ptr<TileWork<Scratch>> w = std::move(slot());
    if (!w || w->sc.lists.size() != size_t(tile_size) * size_t(tile_size) ||
        (w->over_budget_run != 0 && w->over_budget_run != run))
      w.reset(new TileWork<Scratch>{make(), {}, 0});
    return w;
  }
  // `bytes`: what the scratch holds (the peak_tile_bytes of its tile); `run`: the tile's run.
  static void give_back(std::unique_ptr<TileWork<Scratch>> w, size_t bytes, uint64_t run) {
    if (slot()) return;  // a set further up the stack came back first: this one is freed
    const size_t queue_bytes = w->queue.capacity() * sizeof(QueueItem);
    const bool over = double(bytes + queue_bytes) > kThreadTileMemoryBudgetMB * 1e6;
    w->over_budget_run = over ? run : 0;
    slot() = std::move(w);
  }

 private:
  static std::unique_ptr<TileWork<Scratch>>& slot() {
    thread_local std::unique_ptr<TileWork<Scratch>> w;
    return w;
  }
};

// Runs the six faces of one from-segment run of `kind`. tile_stats has 6 * tiles^2 entries
// (counts are added to them, so several runs can share them); found_by_thread gets the marks.
template <class Kind>
void run_tiles(Kind& kind, const SegmentOptions& opt,
               tbb::enumerable_thread_specific<FoundMarks>& found_by_thread,
               std::vector<SegmentStats>& tile_stats) {
  const int N = opt.resolution, TS = opt.tile_size;
  const int tiles_x = tiles_per_side(N, TS), tile_count = tiles_x * tiles_x;
  const std::vector<uint8_t>& mask = opt.tile_mask;  // empty: every tile
  const size_t count = kind.count();
  using Work = ThreadTileWork<typename Kind::Scratch>;
  const uint64_t run = next_serial();
  auto take_work = [&kind, TS, run] {
    return Work::take(TS, run, [&] { return kind.make_scratch(TS); });
  };
  const TriangleBvh* bvh = nullptr;
  if constexpr (Kind::kHasBvh) bvh = kind.bvh();
  std::vector<int> bbox(bvh ? 0 : count * 4);
  std::vector<float> zmin(bvh ? 0 : count);
  std::vector<uint32_t> bin_start;
  std::vector<TileItem> bins;
  std::unique_ptr<FaceBoundsCaches> caches = FaceBoundsCaches::take();
  FaceBoundsCache &node_cache = caches->nodes, &tri_cache = caches->triangles;

  for (int face = 0; face < kCubeFaces; ++face) {
    const FaceAxes axes = face_axes(face, opt.orientation);
    auto computed = [&](int tile) {
      return mask.empty() || mask[tile_mask_index(face, tile % tiles_x, tile / tiles_x, tiles_x)];
    };
    if (!mask.empty()) {
      bool any = false;
      for (int tile = 0; tile < tile_count && !any; ++tile) any = computed(tile);
      if (!any) continue;
    }
    if (bvh) {
      node_cache.next_face(bvh->nodes.size());
      tri_cache.next_face(count);
    } else {
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
      // The pass above bounded every primitive: counted once per face, in its first tile's stats.
      tile_stats[size_t(face) * size_t(tile_count)].primitives_bounded += count;
      // (2) bin by tile (counting sort, in id order).
      bin_by_tile(bbox, count, TS, tiles_x, bin_start, bins, [&](size_t p) {
        return TileItem{uint32_t(p), zmin[p]};
      });
    }

    // (3) tiles in parallel.
    tbb::parallel_for(tbb::blocked_range<int>(0, tile_count, 1),
                      [&](const tbb::blocked_range<int>& r) {
                        // A thread lent to this run from outside any phase of its own (a
                        // bake's thread with no cell) times its tiles as helping.
                        std::optional<PhaseScope> helping;
                        if (!PhaseScope::open_on_this_thread()) helping.emplace(Phase::Helping);
                        auto work = take_work();  // this thread's scratch and walk queue
                        auto& sc = work->sc;
                        size_t held = 0;
                        FoundMarks& found = found_by_thread.local();
                        for (int tile = r.begin(); tile != r.end(); ++tile) {
                          if (!computed(tile)) continue;
                          // Counted apart, added once at the tile's end: the entries of
                          // neighbouring tiles share cache lines, and another thread may be
                          // running the next tile.
                          SegmentStats stats;
                          TileRect rect;
                          rect.x0 = (tile % tiles_x) * TS;
                          rect.y0 = (tile / tiles_x) * TS;
                          rect.x1 = std::min(N, rect.x0 + TS) - 1;
                          rect.y1 = std::min(N, rect.y0 + TS) - 1;
                          rect.stride = TS;
                          for (auto& l : sc.lists) l.clear();
                          for (auto& l : sc.ties) l.clear();
                          std::fill(sc.far.begin(), sc.far.end(), INFINITY);
                          kind.begin_tile(sc);
                          TileFar<typename Kind::Scratch> tile_far(sc, rect);
                          auto flush = [&] { kind.flush(sc, rect, axes, stats); };
                          if (bvh) {
                            if constexpr (Kind::kHasBvh)
                              walk_tile(kind, *bvh, face, axes, rect, opt.depth_culling, sc,
                                        tile_far, node_cache, tri_cache, work->queue, stats);
                          } else {
                            TileItem* tb = bins.data() + bin_start[tile];
                            TileItem* te = bins.data() + bin_start[tile + 1];
                            // Front to back (nearest possible depth), ties by id: the order only
                            // affects speed.
                            std::sort(tb, te, [](const TileItem& a, const TileItem& b) {
                              return a.zmin < b.zmin || (a.zmin == b.zmin && a.id < b.id);
                            });
                            stats.triangle_tiles += uint64_t(te - tb);
                            for (TileItem* it = tb; it != te; ++it) {
                              const int* box = &bbox[size_t(it->id) * 4];
                              if (opt.depth_culling) {
                                if (tile_far.culls(it->zmin, true, flush)) {
                                  stats.culled_triangle_tiles += uint64_t(te - it);
                                  break;
                                }
                                if (tile_far.culls_box(it->zmin, box)) {
                                  ++stats.culled_triangle_tiles;
                                  continue;
                                }
                              }
                              kind.cover(sc, *it, box, rect, axes, stats);
                            }
                          }
                          flush();  // what the kind still holds back
                          kind.finish_tile(sc, face, rect, axes, found, stats);
                          // Tile results: marks, witnesses, pieces, statistics.
                          size_t bytes = kind.held_bytes(sc);
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
                          held = std::max(held, bytes);
                          tile_stats[size_t(face) * tile_count + tile].add(stats);
                        }
                        Work::give_back(std::move(work), held, run);
                      });
  }
  FaceBoundsCaches::give_back(std::move(caches));
}

}  // namespace vislib
