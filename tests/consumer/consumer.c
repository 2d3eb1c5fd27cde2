/* A C engine's use of the installed shared runtime: version check, open, lookup, near-far. */
#include <stdio.h>
#include <string.h>

#include "runtime/near_far_c.h"
#include "runtime/pvs_runtime_c.h"

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  if (pvs_rt_version() != VISLIB_VERSION || strcmp(pvs_rt_version_string(), VISLIB_VERSION_STRING) != 0) {
    fprintf(stderr, "consumer_c: header %s, library %s\n", VISLIB_VERSION_STRING, pvs_rt_version_string());
    return 1;
  }
  pvs_rt* pvs = NULL;
  if (pvs_rt_open(argv[1], 0, 0, &pvs) != PVS_RT_OK) {
    fprintf(stderr, "consumer_c: %s\n", pvs_rt_last_error());
    return 1;
  }
  double centre[3], r1, r2;
  uint32_t count = 0;
  if (pvs_rt_cell_near_far(pvs, 0, centre, &r1, &r2) != PVS_RT_OK || pvs_rt_visible_count(pvs, 0, &count) != PVS_RT_OK)
    return 1;
  /* A bad argument is a status and a message, never a crash. */
  double w;
  if (pvs_rt_morph_weight(1.0, 2.0, 1.0, PVS_RT_CURVE_LINEAR, &w) != PVS_RT_INVALID_ARGUMENT) return 1;
  printf("consumer_c: vislib %s, cell 0 sees %u ids, default r1 %.3f r2 %.3f (\"%s\" rejected)\n",
         pvs_rt_version_string(), count, r1, r2, pvs_rt_last_error());
  pvs_rt_close(pvs);
  return 0;
}
