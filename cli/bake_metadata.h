// bake_metadata.h (cli): what the commands that re-check a bake (vis-compare, check) read from the
// JSON metadata `pvs bake` records in a PVS file (vislib/bake/bake.h, bake_file_info).
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "cli/load_scene.h"
#include "pvs_format/pvs_format.h"
#include "vislib/base/tolerances.h"
#include "vislib/scene/quake_bsp.h"
#include "vislib/scene/scene.h"

namespace pvs_cli {

// The first value of `key` anywhere in `j` (depth first, object keys in order), or null.
nlohmann::json find_key(const nlohmann::json& j, const std::string& key);

// Import options recorded in the metadata override the flags (the scene must be the one the bake
// used): the first string value of `key` (find_key) replaces `value`; a flag given with another
// value is warned about.
void import_from_metadata(const nlohmann::json& md, const std::string& key, std::string& value,
                          const CLI::App& cmd, const std::string& flag, const std::string& pvs);

// The scene of the file `pvs` (its `info`, its parsed metadata `md`), loaded from `scene_path`
// (first key state) with the import options the metadata records (bsp_liquids, bsp_models: they
// replace those of `import`, import_from_metadata); InputError naming `pvs` when the scene's
// fingerprint is not the file's.
vislib::Scene load_baked_scene(const std::string& scene_path, const pvs::FileInfo& info,
                               const nlohmann::json& md, ImportArgs& import, const CLI::App& cmd,
                               const std::string& pvs);

// Every cell of `info` (a BSP-tree layout) is a non-solid leaf of `bsp` (read from `map`), else
// InputError naming `pvs`.
void check_leaf_cells(const pvs::FileInfo& info, const vislib::QuakeBsp& bsp,
                      const std::string& map, const std::string& pvs);

// The cubemaps the bake cast: resolution N, near distance, depth tie tolerance, orientations per
// segment (runs) and seed. Defaults where the metadata lacks a key.
struct BakeSampling {
  int resolution = 64;
  double near = vislib::kDefaultNear;
  double eps_z = vislib::kDefaultEpsZ;
  int runs = 1;
  uint64_t seed = 1;
};
// Reads the top-level numbers "resolution", "near", "eps_z", "runs" and "seed" of `md` (null or
// discarded: none); `resolution` > 0 replaces the recorded resolution. Throws InputError naming
// `pvs` when a value read is out of range (resolution or runs < 1, near <= 0, eps_z < 0).
BakeSampling bake_sampling(const nlohmann::json& md, const std::string& pvs, int resolution = 0);

}  // namespace pvs_cli
