/* engine_loop.c: how an engine applies a PVS each frame, through the C API
 * (runtime/pvs_runtime_c.h).
 *
 *   engine_loop FILE.pvs [FINGERPRINT_HEX] [--frames N]
 *
 * Opens the file (refusing a PVS of another scene when a fingerprint is given, as an engine always
 * should: it computes its scene's fingerprint from its own buffers, docs/pvs-format.md), then
 * walks an eye in a straight line from the centre of the first cell to the centre of the last
 * one. Per frame: position -> cell; on entering a new cell, fetch its visible ids (this is where
 * an engine would rebuild its draw list) and prefetch the neighbours. Prints one line per cell
 * change and a summary. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "runtime/pvs_runtime_c.h"

static int die(const char* what, pvs_rt_status s) {
  fprintf(stderr, "engine_loop: %s failed (%s): %s\n", what, pvs_rt_status_name(s),
          pvs_rt_last_error());
  return 1;
}

int main(int argc, char** argv) {
  const char* path = NULL;
  int check = 0, frames = 600;
  uint64_t fingerprint = 0;
  for (int i = 1; i < argc; ++i) {
    if (strcmp(argv[i], "--frames") == 0 && i + 1 < argc)
      frames = atoi(argv[++i]);
    else if (!path)
      path = argv[i];
    else {
      fingerprint = strtoull(argv[i], NULL, 16);
      check = 1;
    }
  }
  if (!path || frames < 1) {
    fprintf(stderr, "usage: engine_loop FILE.pvs [FINGERPRINT_HEX] [--frames N]\n");
    return 2;
  }

  pvs_rt* pvs = NULL;
  pvs_rt_status s = pvs_rt_open(path, check, fingerprint, &pvs);
  if (s != PVS_RT_OK) return die("open", s);
  pvs_rt_info info;
  pvs_rt_get_info(pvs, &info);
  printf("%s: %u cells, %u %s ids, scene %016llx\n", path, info.cell_count, info.universe,
         info.granularity ? "object" : "triangle", (unsigned long long)info.scene_fingerprint);

  double a_min[3], a_max[3], b_min[3], b_max[3], from[3], to[3];
  pvs_rt_cell_box(pvs, 0, a_min, a_max);
  pvs_rt_cell_box(pvs, info.cell_count - 1, b_min, b_max);
  for (int k = 0; k < 3; ++k) {
    from[k] = 0.5 * (a_min[k] + a_max[k]);
    to[k] = 0.5 * (b_min[k] + b_max[k]);
  }

  uint32_t* ids = NULL;
  size_t ids_capacity = 0;
  uint32_t* neighbours = NULL;
  size_t neighbours_capacity = 0;
  uint32_t current = UINT32_MAX;
  long changes = 0, outside = 0;
  unsigned long long ids_total = 0;
  for (int f = 0; f < frames; ++f) {
    double t = frames > 1 ? (double)f / (frames - 1) : 0.0, eye[3];
    for (int k = 0; k < 3; ++k) eye[k] = from[k] + (to[k] - from[k]) * t;

    uint32_t cell;
    s = pvs_rt_find_cell(pvs, eye, &cell);
    if (s == PVS_RT_NOT_FOUND) {
      ++outside;
      continue;
    } /* keep drawing the last cell's set */
    if (s != PVS_RT_OK) return die("find_cell", s);
    if (cell == current) continue;
    current = cell;
    ++changes;

    uint32_t n;
    pvs_rt_visible_count(pvs, cell, &n);
    if (n > ids_capacity) {
      ids_capacity = n;
      ids = (uint32_t*)realloc(ids, ids_capacity * sizeof *ids);
      if (!ids) {
        fprintf(stderr, "engine_loop: out of memory\n");
        return 1;
      }
    }
    size_t count = 0;
    s = pvs_rt_visible_ids(pvs, cell, ids, ids_capacity, &count);
    if (s == PVS_RT_ABSENT) { /* a shard: this cell's set is in another file */
      printf("frame %4d: cell %u has no data in this file (%s)\n", f, cell, pvs_rt_last_error());
      continue;
    }
    if (s != PVS_RT_OK) return die("visible_ids", s);
    ids_total += count;
    /* ... here the engine draws only triangles ids[0..count) ... */

    size_t nn = 0;
    s = pvs_rt_neighbours(pvs, cell, 0.0, neighbours, neighbours_capacity, &nn);
    if (s == PVS_RT_BUFFER_TOO_SMALL) { /* grow to the size it reported, ask again */
      neighbours_capacity = nn;
      neighbours = (uint32_t*)realloc(neighbours, neighbours_capacity * sizeof *neighbours);
      if (!neighbours) {
        fprintf(stderr, "engine_loop: out of memory\n");
        return 1;
      }
      s = pvs_rt_neighbours(pvs, cell, 0.0, neighbours, neighbours_capacity, &nn);
    }
    if (s != PVS_RT_OK) return die("neighbours", s);
    for (size_t i = 0; i < nn; ++i) pvs_rt_prefetch(pvs, neighbours[i]);
    printf(
        "frame %4d eye (%.2f, %.2f, %.2f): cell %u, %zu visible ids, %zu neighbours prefetched\n",
        f, eye[0], eye[1], eye[2], cell, count, nn);
  }
  printf("%d frames, %ld cell changes, %ld frames outside every cell, %llu ids fetched\n", frames,
         changes, outside, ids_total);
  free(ids);
  free(neighbours);
  pvs_rt_close(pvs);
  return 0;
}
