// point_visibility.cpp: from-point cubemaps and sampled region baselines (docs/visibility-math.md
// §8).
#include "vislib/eval/point_visibility.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cassert>
#include <chrono>

#include "vislib/base/random.h"

namespace vislib {

namespace {

// Calls row_fn(row, dirs) for each of the 6 n rows of the cube's faces (row = face * n + y), rows
// in parallel, with dirs the row's n pixel directions; each call writes only its row's outputs.
template <class RowFn>
void for_each_cube_row(const Mat3& R, int n, RowFn&& row_fn) {
  const size_t side = size_t(n), rows = size_t(kCubeFaces) * side;
  FaceAxes axes[kCubeFaces];
  for (int k = 0; k < kCubeFaces; ++k) axes[k] = face_axes(k, R);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, rows), [&](const tbb::blocked_range<size_t>& r) {
    std::vector<Vec3> dirs(side);
    for (size_t row = r.begin(); row != r.end(); ++row) {
      const int face = int(row / side), y = int(row % side);
      for (int x = 0; x < n; ++x) dirs[size_t(x)] = pixel_direction(axes[face], x, y, n);
      row_fn(row, dirs);
    }
  });
}

}  // namespace

std::vector<uint32_t> point_cubemap(const EmbreeScene& scene, Vec3 eye, const Mat3& R, int n,
                                    double z_near) {
  assert(n >= 1 && z_near >= 0.0);
  const size_t side = size_t(n);
  std::vector<uint32_t> ids(size_t(kCubeFaces) * side * side, kNoHit);
  for_each_cube_row(R, n, [&](size_t row, const std::vector<Vec3>& dirs) {
    thread_local std::vector<Hit> hits;
    hits.resize(side);
    scene.first_hits(eye, dirs.data(), side, z_near, hits.data());
    uint32_t* out = ids.data() + row * side;
    for (size_t x = 0; x < side; ++x) out[x] = hits[x].tri;
  });
  return ids;
}

std::vector<uint32_t> visible_set(const std::vector<uint32_t>& cubemap) {
  std::vector<uint32_t> ids;
  ids.reserve(1024);
  for (uint32_t id : cubemap)
    if (id != kNoHit) ids.push_back(id);
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  return ids;
}

std::vector<uint32_t> point_visible_set(const EmbreeScene& scene, Vec3 eye, const Mat3& R, int n,
                                        double z_near) {
  if (!scene.has_see_through()) return visible_set(point_cubemap(scene, eye, R, n, z_near));
  // The see-through rule: each pixel's first opaque hit and the see-through hits in front of it.
  const size_t side = size_t(n);
  std::vector<std::vector<uint32_t>> row_ids(size_t(kCubeFaces) * side);
  for_each_cube_row(R, n, [&](size_t row, const std::vector<Vec3>& dirs) {
    thread_local std::vector<Hit> hits;
    hits.resize(side);
    std::vector<uint32_t>& ids = row_ids[row];
    scene.hits_through(eye, dirs.data(), side, z_near, hits.data(), ids);
    for (const Hit& h : hits)
      if (h.tri != kNoHit) ids.push_back(h.tri);
  });
  std::vector<uint32_t> all;
  for (const auto& ids : row_ids) all.insert(all.end(), ids.begin(), ids.end());
  return visible_set(all);
}

namespace {

// Runs the K viewpoints given by `viewpoint(i)` and records the growth of the union.
template <class ViewpointFn>
SampledVisibility sample_union(const EmbreeScene& scene, const PointSampling& opt,
                               ViewpointFn viewpoint, const SamplingProgress& progress) {
  assert(opt.runs >= 1);
  using clock = std::chrono::steady_clock;
  const auto start = clock::now();
  SampledVisibility out;
  std::vector<uint32_t> seen(scene.triangle_count(), 0);  // 0 = not yet, else 1 + first run
  size_t count = 0;
  for (int i = 0; i < opt.runs; ++i) {
    const Vec3 eye = viewpoint(i);
    const Mat3 R =
        opt.random_orientation ? random_orientation(Rng::derive(opt.seed, uint64_t(i))) : opt.R;
    for (uint32_t id : point_visible_set(scene, eye, R, opt.n, opt.z_near))
      if (!seen[id]) seen[id] = uint32_t(i) + 1, ++count;
    out.viewpoints.push_back(eye);
    out.union_size.push_back(count);
    out.elapsed_seconds.push_back(std::chrono::duration<double>(clock::now() - start).count());
    if (progress) progress(size_t(i) + 1, size_t(opt.runs));
  }
  out.ids.reserve(count);
  out.first_run.reserve(count);
  for (size_t id = 0; id < seen.size(); ++id)
    if (seen[id]) out.ids.push_back(uint32_t(id)), out.first_run.push_back(seen[id] - 1);
  return out;
}

}  // namespace

SampledVisibility sample_segment(const EmbreeScene& scene, Vec3 v0, Vec3 v1,
                                 const PointSampling& opt, const SamplingProgress& progress) {
  return sample_union(
      scene, opt,
      [&](int i) {
        const double t = opt.runs == 1 ? 0.5 : double(i) / double(opt.runs - 1);
        return lerp(v0, v1, t);
      },
      progress);
}

SampledVisibility sample_box(const EmbreeScene& scene, const Box3& box, const PointSampling& opt,
                             const SamplingProgress& progress) {
  assert(!box.empty());
  Rng rng(opt.seed);
  return sample_union(
      scene, opt,
      [&](int) {
        Vec3 p;
        for (int k = 0; k < 3; ++k) p[k] = rng.uniform(box.min[k], box.max[k]);
        return p;
      },
      progress);
}

}  // namespace vislib
