// engine_frame_bench: the C API's per-frame cost of what an engine's loop does with a PVS
// in order: find the cell of the eye; on entering a cell, read its visible ids, partition them
// near/far around the cell's default cylinders and start a CloVR growth; every frame, advance the
// CloVR scheduler (and fetch its near set when it changed). Geometry comes from the scene file
// (as an engine's own buffers would), everything else through runtime/near_far_c.h.
//
//   engine_frame_bench SCENE PVS [FRAMES] [SPEED]
//
// The eye walks a boustrophedon over the cells' box at eye height (the centre y of cell 0),
// SPEED scene units per frame (default: a cell width / 20). Prints per-frame times (mean, median,
// p99, max) for all frames, for the frames that enter a new cell and for the others.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "runtime/near_far_c.h"
#include "runtime/pvs_runtime_c.h"
#include "vislib/scene/import.h"

namespace {

struct Stats {
  std::vector<double> ns;
  void print(const char* what) {
    if (ns.empty()) return std::printf("%-14s no frames\n", what), void();
    std::sort(ns.begin(), ns.end());
    double sum = 0;
    for (double x : ns) sum += x;
    std::printf("%-14s %7zu frames: mean %9.1f us, median %9.1f us, p99 %9.1f us, max %9.1f us\n",
                what, ns.size(), sum / ns.size() / 1e3, ns[ns.size() / 2] / 1e3,
                ns[std::min(ns.size() - 1, ns.size() * 99 / 100)] / 1e3, ns.back() / 1e3);
  }
};

int fail(const char* what, pvs_rt_status s) {
  std::fprintf(stderr, "engine_frame_bench: %s: %s: %s\n", what, pvs_rt_status_name(s),
               pvs_rt_last_error());
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: engine_frame_bench SCENE PVS [FRAMES] [SPEED]\n");
    return 2;
  }
  const int frames = argc > 3 ? std::atoi(argv[3]) : 20000;
  const vislib::Scene scene = vislib::load_scene(argv[1]);
  std::vector<float> positions;
  for (const auto& p : scene.positions[0])
    positions.insert(positions.end(), {float(p.x), float(p.y), float(p.z)});
  std::vector<uint32_t> indices;
  for (const auto& t : scene.triangles) indices.insert(indices.end(), t.begin(), t.end());
  const pvs_rt_geometry g{positions.data(),
                          scene.vertex_count(),
                          indices.data(),
                          scene.triangle_count(),
                          scene.triangle_object.data(),
                          scene.objects.size(),
                          nullptr};

  pvs_rt* pvs = nullptr;
  if (pvs_rt_status s = pvs_rt_open(argv[2], 0, 0, &pvs)) return fail("open", s);
  pvs_rt_info info;
  pvs_rt_get_info(pvs, &info);
  if (info.granularity != 0)
    return std::fprintf(stderr, "engine_frame_bench: needs a triangle-id PVS\n"), 2;
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300}, c0min[3], c0max[3];
  for (uint32_t c = 0; c < info.cell_count; ++c) {
    double a[3], b[3];
    pvs_rt_cell_box(pvs, c, a, b);
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], a[k]), hi[k] = std::max(hi[k], b[k]);
  }
  pvs_rt_cell_box(pvs, 0, c0min, c0max);
  const double speed = argc > 4 ? std::atof(argv[4]) : (c0max[0] - c0min[0]) / 20.0;
  const double eye_y = 0.5 * (c0min[1] + c0max[1]);
  const double row_step = (c0max[2] - c0min[2]);
  std::printf(
      "%s: %u cells, %u triangles; %s: %zu triangles, %zu objects; %d frames at %.3f units/frame\n",
      argv[2], info.cell_count, info.universe, argv[1], scene.triangle_count(),
      scene.objects.size(), frames, speed);

  std::vector<uint32_t> ids(info.universe), nf[6];
  for (auto& v : nf) v.resize(info.universe);
  std::vector<uint32_t> near(info.universe);
  pvs_rt_near_far part{nf[0].data(),
                       nf[1].data(),
                       nf[2].data(),
                       nf[3].data(),
                       nf[4].data(),
                       nf[5].data(),
                       info.universe,
                       0,
                       0,
                       0,
                       0,
                       0,
                       0};
  pvs_rt_clovr* clovr = nullptr;
  pvs_rt_clovr_params params;
  pvs_rt_clovr_default_params(0.0, &params);  // final radius: the cell's r2, set below
  Stats all, entering, staying;
  uint32_t current = UINT32_MAX;
  double x = lo[0] + 1e-3, z = lo[2] + 0.5 * row_step, dir = 1;
  size_t ids_total = 0, near_total = 0;
  int outside = 0;
  for (int f = 0; f < frames; ++f) {
    x += dir * speed;
    if (x > hi[0] || x < lo[0]) {  // next row
      dir = -dir;
      x += 2 * dir * speed;
      z += row_step;
      if (z > hi[2]) z = lo[2] + 0.5 * row_step;
    }
    const double eye[3] = {x, eye_y, z};
    const auto t0 = std::chrono::steady_clock::now();
    uint32_t cell;
    pvs_rt_status s = pvs_rt_find_cell(pvs, eye, &cell);
    bool entered = false;
    if (s == PVS_RT_NOT_FOUND) {
      ++outside;
    } else if (s != PVS_RT_OK) {
      return fail("find_cell", s);
    } else if (cell != current) {
      entered = true;
      current = cell;
      size_t n = 0;
      if ((s = pvs_rt_visible_ids(pvs, cell, ids.data(), ids.size(), &n)))
        return fail("visible_ids", s);
      double centre[3], r1, r2;
      if ((s = pvs_rt_cell_near_far(pvs, cell, centre, &r1, &r2))) return fail("cell_near_far", s);
      if ((s = pvs_rt_partition_near_far(&g, ids.data(), n, centre, r1, r2, &part)))
        return fail("partition", s);
      if (!clovr || r2 != params.final_radius) {  // the scheduler is made once per cell size
        if (clovr) pvs_rt_clovr_destroy(clovr);
        pvs_rt_clovr_default_params(r2, &params);
        if ((s = pvs_rt_clovr_create(&g, &params, &clovr))) return fail("clovr_create", s);
      }
      if ((s = pvs_rt_clovr_start(clovr, ids.data(), n, centre))) return fail("clovr_start", s);
      ids_total += n;
    }
    if (clovr) {
      pvs_rt_clovr_frame fr;
      if ((s = pvs_rt_clovr_next_frame(clovr, &fr))) return fail("clovr_next_frame", s);
      if (fr.near_changed) {
        size_t nn = 0;
        if ((s = pvs_rt_clovr_near_ids(clovr, near.data(), near.size(), &nn)))
          return fail("clovr_near_ids", s);
        near_total += nn;
      }
    }
    const double ns = double(
        std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - t0)
            .count());
    all.ns.push_back(ns);
    (entered ? entering : staying).ns.push_back(ns);
  }
  all.print("all");
  entering.print("entering cell");
  staying.print("same cell");
  std::printf("%d frames outside every cell; %zu ids read, %zu near ids fetched (checksum)\n",
              outside, ids_total, near_total);
  if (clovr) pvs_rt_clovr_destroy(clovr);
  pvs_rt_close(pvs);
  return 0;
}
