// bake_metadata.cpp (cli): reading a bake's metadata (bake_metadata.h).
#include "cli/bake_metadata.h"

#include "cli/commands.h"
#include "vislib/base/error.h"
#include "vislib/scene/scene_fingerprint.h"

namespace pvs_cli {

nlohmann::json find_key(const nlohmann::json& j, const std::string& key) {
  if (j.is_object()) {
    if (j.contains(key)) return j[key];
    for (const auto& [k, v] : j.items()) {
      nlohmann::json r = find_key(v, key);
      if (!r.is_null()) return r;
    }
  } else if (j.is_array()) {
    for (const auto& v : j) {
      nlohmann::json r = find_key(v, key);
      if (!r.is_null()) return r;
    }
  }
  return nullptr;
}

void import_from_metadata(const nlohmann::json& md, const std::string& key, std::string& value,
                          const CLI::App& cmd, const std::string& flag, const std::string& pvs) {
  const nlohmann::json v = find_key(md, key);
  if (!v.is_string()) return;
  const std::string recorded = v.get<std::string>();
  if (cmd.count(flag) && value != recorded)
    warn(flag + " " + value + " ignored: " + pvs + " was baked with " + recorded);
  value = recorded;
}

vislib::Scene load_baked_scene(const std::string& scene_path, const pvs::FileInfo& info,
                               const nlohmann::json& md, ImportArgs& import, const CLI::App& cmd,
                               const std::string& pvs) {
  if (!md.is_discarded()) {
    import_from_metadata(md, "bsp_liquids", import.bsp_liquids, cmd, "--bsp-liquids", pvs);
    import_from_metadata(md, "bsp_models", import.bsp_models, cmd, "--bsp-models", pvs);
  }
  vislib::Scene scene = load_scene_for_cli(scene_path, 1, import);
  if (vislib::scene_fingerprint(scene) != info.scene_fingerprint)
    throw vislib::InputError(pvs, "was not baked from " + scene_path +
                                      " imported with --bsp-models " + import.bsp_models +
                                      " --bsp-liquids " + import.bsp_liquids +
                                      " (scene fingerprints differ)");
  return scene;
}

void check_leaf_cells(const pvs::FileInfo& info, const vislib::QuakeBsp& bsp,
                      const std::string& map, const std::string& pvs) {
  const std::vector<uint32_t>& cell_leaf = info.layout.cell_leaf;
  for (uint32_t c = 0; c < cell_leaf.size(); ++c)
    if (cell_leaf[c] == 0 || cell_leaf[c] >= bsp.leaves.size())
      throw vislib::InputError(pvs, "cell " + std::to_string(c) + " is leaf " +
                                        std::to_string(cell_leaf[c]) +
                                        ", not a non-solid leaf of " + map);
}

BakeSampling bake_sampling(const nlohmann::json& md, const std::string& pvs, int resolution) {
  BakeSampling s;
  if (md.is_object()) {
    if (md.contains("resolution") && md["resolution"].is_number_integer())
      s.resolution = md["resolution"].get<int>();
    if (md.contains("near") && md["near"].is_number()) s.near = md["near"].get<double>();
    if (md.contains("eps_z") && md["eps_z"].is_number()) s.eps_z = md["eps_z"].get<double>();
    if (md.contains("runs") && md["runs"].is_number_integer()) s.runs = md["runs"].get<int>();
    if (md.contains("seed") && md["seed"].is_number_unsigned()) s.seed = md["seed"].get<uint64_t>();
  }
  if (resolution > 0) s.resolution = resolution;
  if (!(s.resolution >= 1 && s.near > 0 && s.eps_z >= 0 && s.runs >= 1))
    throw vislib::InputError(pvs, "metadata holds an invalid resolution, near, eps_z or runs");
  return s;
}

}  // namespace pvs_cli
