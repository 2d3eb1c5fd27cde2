// bake_options.h: the options of `pvs bake` (cmd_bake.cpp) and what they map to: the quality
// presets, the shard, the placement of the view cells (vislib/bake/view_cells.h) and the bake
// settings. Parsing only: errors are CLI::ValidationError naming the option (exit 2).
#pragma once

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "cli/load_scene.h"
#include "vislib/bake/bake.h"
#include "vislib/bake/bsp_cells.h"
#include "vislib/bake/view_cells.h"
#include "vislib/scene/scene.h"

namespace pvs_cli {

struct BakeArgs {
  std::string scene, output, checkpoint, json_out;
  std::string box, grid, eye, shard = "0/1";
  bool walkable = false, resume = false, no_headroom = false, dry_run = false;
  double cell_size = 0, max_slope = 45;
  int resolution = 512, runs = 1, threads = 0, tile = 0;
  uint64_t seed = 1;
  double near = vislib::kDefaultNear, eps_len = vislib::kDefaultEpsLen;
  std::string granularity = "triangle";
  std::string mode = "diagonal";
  std::string coplanar = "both";
  double eps_z = vislib::kDefaultEpsZ;
  int states = 1;
  ImportArgs import;
  std::string preset = "default";
  std::string bvh = "on";           // --bvh on|off
  std::string fans = "on";          // --fans on|off
  std::string long_segments = "1";  // --long-segments: 1..8 or auto
  std::string cells;                // --cells: "" (grid or walkable) or bsp-leaves
  // --face-spacing (bsp-leaves), Quake units; unset: kBspPortalSpacing or kBspFaceSpacing.
  std::optional<double> face_spacing;
  std::string leaves;  // --leaves A-B (bsp-leaves)
  // --face-sweep even|adaptive (bsp-leaves); unset: adaptive with --sweep portals, even with faces.
  std::optional<std::string> face_sweep;
  std::string sweep = "portals";     // --sweep portals|faces (bsp-leaves)
  std::string bound = "portals";     // --bound none|portals|map-vis (bsp-leaves, --sweep portals)
  std::string portal_edges = "own";  // --portal-edges own|shared (BspCellOptions::share_edges)
  // --chord-coarse, --chord-floor, --chord-piece, --chord-tiles (adaptive: the last is
  // AdaptiveSpacing::tiles, by chord_tiles_name); unset: kBspPortalChords with --sweep portals,
  // else AdaptiveSpacing's defaults.
  std::optional<double> chord_coarse, chord_floor, chord_piece;
  std::optional<std::string> chord_tiles;
  std::optional<int> chord_tile_size;       // --chord-tile-size (AdaptiveSpacing::tile_size)
  std::optional<std::string> chord_cross;   // --chord-cross on|off (AdaptiveSpacing::crossed)
  std::optional<double> chord_cross_floor;  // --chord-cross-floor (AdaptiveSpacing::crossed_floor)
  std::optional<std::string> chord_new;     // --chord-new neighbours|family (new_to_family)
  std::vector<std::string> walkable_from;   // --walkable-from x,y,z (repeatable)
  std::optional<int> band_levels;           // --band-levels (grid and walkable cells)
  std::string wall_traces;                  // --wall-traces on|off ("": the placement's default)
  std::string vertical_edges;               // --vertical-edges on|off ("": the placement's default)
  double agent_height = NAN, agent_radius = NAN, agent_step = NAN;  // --agent-*: NaN = default
};

// Adds the options of `pvs bake` to `cmd`, storing into `a` (which must outlive `cmd`).
void add_bake_options(CLI::App* cmd, BakeArgs& a);

// --shard i/N.
vislib::Shard parse_shard(const std::string& text);

// The preset fills the options not given and says so on stderr (not -q).
void apply_preset(BakeArgs& a, const CLI::App& cmd);

// --cells bsp-leaves: refuses (CLI::ValidationError, exit 2) the options that place cells
// otherwise (--walkable, --box, --grid, --cell-size, --eye-height, --walkable-from, --agent-*)
// and, before the scene is loaded, a scene that is not a .bsp (InputError naming it). Without
// --cells: refuses --face-spacing and --leaves; without --walkable, --walkable-from and
// --agent-*; a --walkable-from that is not three finite numbers.
void check_cells_options(const BakeArgs& a, const CLI::App& cmd);

// The view cells of the options over `scene` (vislib::place_view_cells, or with --cells
// bsp-leaves vislib::bsp_leaf_cells of `map`, the map `scene` was imported from, which must then
// be given); a refused placement is reported as the option that caused it. Walkable cells of a
// Quake map (.bsp): the agent's defaults are Quake's player, and without --walkable-from the
// starts are the map's player starts (vislib::bsp_player_starts of `map` when given, else of the
// map read from a.scene; one without floor under it is left out).
vislib::ViewCells make_cells(const BakeArgs& a, const vislib::Scene& scene,
                             const vislib::QuakeBsp* map);

// The kernel and bake settings of the options.
vislib::BakeSettings settings_of(const BakeArgs& a);

}  // namespace pvs_cli
