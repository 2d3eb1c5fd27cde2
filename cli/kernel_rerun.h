// kernel_rerun.h (cli): the kernel witnesses of `pvs vis-compare --kernel-witnesses`: a Quake
// map's leaf cells rebuilt and their runs re-made as the bake's metadata records them
// (vislib/eval/vis_compare.h "Kernel witnesses"; docs/quake.md).
#pragma once

#include <functional>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "vislib/bake/view_cells.h"
#include "vislib/eval/vis_compare.h"
#include "vislib/kernel/region_visibility.h"
#include "vislib/kernel/triangle_bvh.h"
#include "vislib/scene/quake_bsp.h"
#include "vislib/scene/scene.h"

namespace pvs_cli {

class KernelRerun {
 public:
  // `mode` is auto (re-run when the metadata `md` of the file `pvs` records the bake), on (throws
  // InputError naming `pvs` when it does not) or off. Throws InputError naming `pvs` when the
  // recorded values are invalid or the cells are not the map's leaf cells. `scene`, `bsp` and
  // this object must outlive every call of witnesses().
  KernelRerun(const nlohmann::json& md, const std::string& pvs, const std::string& mode,
              const vislib::QuakeBsp& bsp, const vislib::Scene& scene,
              const std::vector<uint32_t>& cell_leaf, const vislib::LoadOptions& scene_options);
  KernelRerun(const KernelRerun&) = delete;
  KernelRerun& operator=(const KernelRerun&) = delete;

  bool enabled() const { return enabled_; }
  // The first metadata key a re-run needs that the metadata lacks ("" when none).
  const std::string& missing() const { return missing_; }
  // For VisCompareOptions::kernel_witnesses (empty when not enabled). Thread-safe.
  std::function<std::vector<vislib::VisWitness>(uint32_t, const std::vector<uint32_t>&)>
  witnesses();

 private:
  const vislib::Scene& scene_;
  bool enabled_ = false;
  std::string missing_;
  vislib::ViewCells cells_;
  vislib::RegionOptions ro_;
  vislib::TriangleBvh bvh_;
  vislib::EdgeLines lines_;
  std::once_flag built_;
};

}  // namespace pvs_cli
