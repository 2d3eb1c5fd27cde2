// A C++ engine's use of the installed runtime: open a PVS, look up a cell, read its set.
#include <cstdio>

#include "runtime/near_far.h"
#include "runtime/pvs_runtime.h"
#include "runtime/vislib_version.h"

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  pvs_runtime::Pvs pvs = pvs_runtime::Pvs::open(argv[1]);
  pvs::Box box = pvs.info().layout.cell_box(0);
  const double centre[3] = {0.5 * (box.min[0] + box.max[0]), 0.5 * (box.min[1] + box.max[1]),
                            0.5 * (box.min[2] + box.max[2])};
  auto cell = pvs.find_cell(centre);
  if (!cell || *cell != 0) {
    std::fprintf(stderr, "consumer_cpp: the centre of cell 0 is not in cell 0\n");
    return 1;
  }
  const size_t n = pvs.visible_ids(0).size();
  if (n != pvs.visible_count(0)) return 1;
  const double w = pvs_runtime::morph_user_weight(1.5, 1.0, 2.0);
  std::printf("consumer_cpp: vislib %s, %u cells, cell 0 sees %zu ids, w_U(1.5) = %g\n", VISLIB_VERSION_STRING,
              pvs.cell_count(), n, w);
  return w == 0.5 ? 0 : 1;
}
