// kernel_rerun.cpp (cli): the cells and runs of a bake rebuilt from its metadata for kernel
// witnesses (kernel_rerun.h).
#include "cli/kernel_rerun.h"

#include <stdexcept>

#include "cli/bake_metadata.h"
#include "vislib/bake/bsp_cells.h"
#include "vislib/bake/cell_visibility.h"
#include "vislib/base/error.h"

namespace pvs_cli {

KernelRerun::KernelRerun(const nlohmann::json& md, const std::string& pvs, const std::string& mode,
                         const vislib::QuakeBsp& bsp, const vislib::Scene& scene,
                         const std::vector<uint32_t>& cell_leaf,
                         const vislib::LoadOptions& scene_options)
    : scene_(scene) {
  const nlohmann::json spacing = md.is_discarded() ? nullptr : find_key(md, "face_spacing");
  if (!spacing.is_number()) missing_ = "face_spacing";
  for (const char* k : {"resolution", "near", "eps_len", "eps_z", "runs", "seed"})
    if (missing_.empty() && (md.is_discarded() || !md.contains(k) || !md[k].is_number()))
      missing_ = k;
  if (mode == "on" && !missing_.empty())
    throw vislib::InputError(pvs, "its metadata lacks '" + missing_ +
                                      "', needed to re-run its cells for kernel witnesses");
  enabled_ = mode != "off" && missing_.empty();
  if (!enabled_) return;
  vislib::BspCellOptions co;
  co.face_spacing = spacing.get<double>();
  const nlohmann::json sweep = find_key(md, "face_sweep");
  if (sweep.is_string() && sweep.get<std::string>() == "adaptive") {
    const nlohmann::json coarse = find_key(md, "chord_coarse"), floor = find_key(md, "chord_floor");
    if (!coarse.is_number() || !floor.is_number() || !(floor.get<double>() > 0) ||
        !(floor.get<double>() <= coarse.get<double>()))
      throw vislib::InputError(pvs, "metadata holds an invalid chord_coarse or chord_floor");
    const nlohmann::json piece = find_key(md, "chord_piece");  // absent: whole chords
    if (!piece.is_null() && !(piece.is_number() && piece.get<double>() >= 0))
      throw vislib::InputError(pvs, "metadata holds an invalid chord_piece");
    const nlohmann::json tiles = find_key(md, "chord_tiles");  // absent: all
    const std::optional<vislib::ChordTiles> chord_tiles =
        tiles.is_null()     ? vislib::ChordTiles::All
        : tiles.is_string() ? vislib::chord_tiles_named(tiles.get<std::string>())
                            : std::nullopt;
    if (!chord_tiles)
      throw vislib::InputError(
          pvs, "metadata holds an invalid chord_tiles (all, new or new-every-face)");
    if (*chord_tiles != vislib::ChordTiles::All &&
        find_key(md, "chord_tile_margin") != vislib::kChordTileMargin)
      throw vislib::InputError(pvs, "metadata holds a chord_tile_margin this build cannot re-run");
    // Absent: the chords were masked by the kernel's tiles (kStaticTileSize).
    const nlohmann::json tile_size = find_key(md, "chord_tile_size");
    if (!tile_size.is_null() && !(tile_size.is_number_integer() && tile_size.get<int>() >= 1 &&
                                  tile_size.get<int>() <= vislib::kMaxTileSize))
      throw vislib::InputError(pvs, "metadata holds an invalid chord_tile_size");
    const nlohmann::json crossed = find_key(md, "chord_crossed");  // absent: one family
    if (!crossed.is_null() && !crossed.is_boolean())
      throw vislib::InputError(pvs, "metadata holds an invalid chord_crossed");
    co.adaptive = vislib::AdaptiveSpacing{
        coarse.get<double>(),
        floor.get<double>(),
        piece.is_null() ? 0.0 : piece.get<double>(),
        *chord_tiles,
        tile_size.is_null() ? vislib::kStaticTileSize : tile_size.get<int>(),
        !crossed.is_null() && crossed.get<bool>()};
    const nlohmann::json judged = find_key(md, "chord_new");  // absent: by the neighbours
    if (!judged.is_null() && judged != "neighbours" && judged != "family")
      throw vislib::InputError(pvs, "metadata holds an invalid chord_new (neighbours or family)");
    co.adaptive->new_to_family = judged == "family";
    // Absent: the crossed chords went down to the floor (crossed_floor 0).
    const nlohmann::json cross_floor = find_key(md, "chord_cross_floor");
    if (!cross_floor.is_null()) {
      if (!cross_floor.is_number() || !(cross_floor.get<double>() > 0))
        throw vislib::InputError(pvs, "metadata holds an invalid chord_cross_floor");
      co.adaptive->crossed_floor = cross_floor.get<double>();
      if (!co.adaptive->valid())
        throw vislib::InputError(
            pvs, "metadata holds a chord_cross_floor outside chord_floor .. chord_coarse");
    }
  }
  co.leaves = cell_leaf;
  co.scene = scene_options;
  const nlohmann::json kind = find_key(md, "sweep");
  if (kind.is_string() && kind.get<std::string>() == "portals")
    co.sweep = vislib::BspSweep::Portals;
  // Absent: baked before portals' edges shared their runs.
  const nlohmann::json edges = find_key(md, "portal_edges");
  if (!edges.is_null() && edges != "shared" && edges != "own")
    throw vislib::InputError(pvs, "metadata holds an invalid portal_edges (shared or own)");
  co.share_edges = edges == "shared";
  const nlohmann::json bound = find_key(md, "bound");  // absent: none
  if (bound.is_string() && co.sweep == vislib::BspSweep::Portals)
    co.bound = bound.get<std::string>() == "portals"   ? vislib::BspBound::Portals
               : bound.get<std::string>() == "map-vis" ? vislib::BspBound::MapVis
                                                       : vislib::BspBound::None;
  ro_.segment.resolution = md["resolution"].get<int>();
  ro_.segment.near = md["near"].get<double>();
  co.near = ro_.segment.near;
  ro_.segment.eps_len = md["eps_len"].get<double>();
  ro_.segment.eps_z = md["eps_z"].get<double>();
  ro_.runs = md["runs"].get<int>();
  ro_.seed = md["seed"].get<uint64_t>();
  // Files baked before fans were composited as polygons record none: their runs took the
  // triangles one by one.
  const nlohmann::json fans = find_key(md, "fans");
  ro_.segment.fans = fans.is_boolean() && fans.get<bool>();
  const nlohmann::json coplanar = find_key(md, "coplanar");
  ro_.segment.coplanar = coplanar.is_string() && coplanar.get<std::string>() == "first"
                             ? vislib::CoplanarRule::First
                             : vislib::CoplanarRule::Both;
  if (!(co.face_spacing >= 0 && ro_.segment.resolution >= 1 && ro_.segment.near > 0 &&
        ro_.segment.eps_len >= 0 && ro_.segment.eps_z >= 0 && ro_.runs >= 1))
    throw vislib::InputError(
        pvs, "metadata holds an invalid face_spacing, resolution, near, eps_len, eps_z or runs");
  try {
    cells_ = vislib::bsp_leaf_cells(bsp, co, &scene);
  } catch (const std::invalid_argument& e) {
    throw vislib::InputError(pvs,
                             std::string("its cells are not the map's leaf cells: ") + e.what());
  }
}

std::function<std::vector<vislib::VisWitness>(uint32_t, const std::vector<uint32_t>&)>
KernelRerun::witnesses() {
  if (!enabled_) return {};
  return [this](uint32_t cell, const std::vector<uint32_t>& extras) {
    // The tree and the edge lines the bake's runs used, built once the first leaf needs them.
    std::call_once(built_, [&] {
      bvh_ =
          vislib::build_triangle_bvh(scene_, ro_.segment.fans ? vislib::BvhPrimitives::Groups
                                                              : vislib::BvhPrimitives::Triangles);
      ro_.segment.bvh = &bvh_;
      lines_ = vislib::build_edge_lines(scene_);
      ro_.segment.edge_lines = &lines_;
    });
    std::vector<vislib::VisWitness> out;
    for (const vislib::CellWitnessRay& w :
         vislib::cell_witness_rays(scene_, cells_, cell, ro_, extras))
      out.push_back({w.tri, w.eye, w.dir, true});
    return out;
  };
}

}  // namespace pvs_cli
