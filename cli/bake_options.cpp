// bake_options.cpp: the options of `pvs bake` and what they map to (bake_options.h).
#include "cli/bake_options.h"

#include <fmt/format.h>

#include <array>
#include <cassert>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <optional>

#include "cli/commands.h"
#include "cli/options.h"
#include "cli/threads.h"
#include "vislib/base/error.h"
#include "vislib/scene/quake_bsp.h"

namespace pvs_cli {
namespace {

// Quality presets (like vis's -fast / -level): what --preset sets unless given explicitly.
struct Preset {
  int resolution, runs;
  double cell_size;
};
Preset preset_values(const std::string& name) {
  if (name == "draft") return {128, 1, 8.0};
  if (name == "final") return {2048, 4, 1.0};
  return {512, 1, 2.0};  // default: the options' own defaults
}

}  // namespace

vislib::Shard parse_shard(const std::string& text) {
  unsigned i = 0, n = 0;
  char extra;
  if (std::sscanf(text.c_str(), "%u/%u%c", &i, &n, &extra) != 2 || n == 0 || i >= n)
    throw CLI::ValidationError("--shard", "expected i/N with 0 <= i < N, got '" + text + "'");
  return {i, n};
}

namespace {

// --walkable-from x,y,z (each given): three finite numbers; or "none" alone (no start).
std::vector<vislib::WalkStart> parse_starts(const BakeArgs& a) {
  std::vector<vislib::WalkStart> starts;
  if (a.walkable_from.size() == 1 && a.walkable_from[0] == "none") return starts;
  for (const std::string& text : a.walkable_from) {
    std::vector<double> v;
    try {
      v = parse_doubles(text, "--walkable-from", 3);
    } catch (const CLI::ValidationError&) {
      v.clear();
    }
    if (v.size() != 3 || !std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]))
      throw CLI::ValidationError("--walkable-from",
                                 "expected x,y,z (three finite numbers, scene coordinates) or "
                                 "'none' alone, got '" +
                                     text + "'");
    starts.push_back({{v[0], v[1], v[2]}, "--walkable-from"});
  }
  return starts;
}

// The placement of the options (parsed here; their combination is checked by the library).
vislib::CellPlacement placement_of(const BakeArgs& a) {
  vislib::CellPlacement p;
  if (!a.eye.empty()) {
    auto h = parse_doubles(a.eye, "--eye-height", 2);
    if (!(h[0] <= h[1])) throw CLI::ValidationError("--eye-height", "expected h0,h1 with h0 <= h1");
    p.eye = vislib::EyeBand{h[0], h[1]};
  }
  if (!a.box.empty()) {
    auto b = parse_doubles(a.box, "--box", 6);
    p.box = vislib::Box3{};
    p.box->extend({b[0], b[1], b[2]});
    p.box->extend({b[3], b[4], b[5]});
    for (int k = 0; k < 6; ++k)
      if (!std::isfinite(b[k])) throw CLI::ValidationError("--box", "coordinates must be finite");
  }
  p.walkable = a.walkable;
  p.cell_size = a.cell_size;
  p.max_slope_degrees = a.max_slope;
  p.require_headroom = !a.no_headroom;
  p.starts = parse_starts(a);
  const auto given = [](double v) { return std::isnan(v) ? std::nullopt : std::optional(v); };
  p.agent_height = given(a.agent_height);
  p.agent_radius = given(a.agent_radius);
  p.agent_step = given(a.agent_step);
  p.band_levels = a.band_levels;
  if (!a.wall_traces.empty()) p.wall_traces = a.wall_traces == "on";
  if (!a.vertical_edges.empty()) p.vertical_edges = a.vertical_edges == "on";
  p.near = a.near;
  return p;
}

// --grid nx,ny,nz: three integers in [1, 10^6].
std::array<uint32_t, 3> parse_grid(const std::string& text) {
  auto g = parse_doubles(text, "--grid", 3);
  for (double v : g)
    if (!(v >= 1 && v == std::floor(v) && v <= 1e6))
      throw CLI::ValidationError("--grid", "expected three integers >= 1");
  return {uint32_t(g[0]), uint32_t(g[1]), uint32_t(g[2])};
}

// The library's refusal, named after the options that caused it.
CLI::ValidationError placement_error(vislib::PlacementProblem problem) {
  using P = vislib::PlacementProblem;
  switch (problem) {
    case P::GridWithWalkable:
      return CLI::ValidationError("--grid", "cannot be combined with --walkable");
    case P::TooManyColumns:
      return CLI::ValidationError("--cell-size",
                                  "more than 10^7 columns: use a larger cell size or a --box");
    case P::NoBox:
      return CLI::ValidationError("--box", "give --box with --grid or --cell-size, or --walkable");
    case P::GridAndCellSize:
      return CLI::ValidationError("--grid", "give --grid or --cell-size, not both");
    case P::TooManyGridCells:
      return CLI::ValidationError("--grid", "more than 10^7 cells");
    case P::NoGridNorCellSize:
      return CLI::ValidationError("--grid", "give --grid nx,ny,nz or --cell-size S with --box");
    case P::BadAgent:
      return CLI::ValidationError("--agent-height",
                                  "the agent's height (default: the eye band's top) must be > 0");
    case P::TooManySizedCells:
    case P::StartWithoutFloor:  // reported with the library's message (make_cells)
      break;
  }
  return CLI::ValidationError("--cell-size", "more than 10^7 cells");
}

}  // namespace

namespace {

bool ends_with_bsp(const std::string& path) {
  if (path.size() < 4) return false;
  std::string ext = path.substr(path.size() - 4);
  for (char& ch : ext) ch = char(std::tolower(static_cast<unsigned char>(ch)));
  return ext == ".bsp";
}

// --leaves ITEM[,ITEM...]: the cell leaves of the map named by any item, where an item is A (one
// leaf number), A-B (A to B) or A-B/K (A, A+K, A+2K, ... up to B: a spread sample of a large map).
std::vector<uint32_t> parse_leaves(const std::string& text, const std::vector<uint32_t>& all) {
  const auto bad = [&] {
    return CLI::ValidationError("--leaves",
                                "expected A, A-B or A-B/K (leaf numbers, A <= B, K > 0), "
                                "comma-separated; got '" +
                                    text + "'");
  };
  // One item, whole: "%u" alone would also take a sign, spaces or trailing text.
  const auto parse_item = [&](const std::string& item, unsigned& lo, unsigned& hi, unsigned& step) {
    if (item.empty() || item[0] == '-' ||
        item.find_first_not_of("0123456789-/") != std::string::npos)
      throw bad();
    int used = -1;
    step = 1;
    if (std::sscanf(item.c_str(), "%u-%u/%u%n", &lo, &hi, &step, &used) != 3) {
      used = -1;
      step = 1;
      if (std::sscanf(item.c_str(), "%u-%u%n", &lo, &hi, &used) != 2) {
        used = -1;
        if (std::sscanf(item.c_str(), "%u%n", &lo, &used) != 1) throw bad();
        hi = lo;
      }
    }
    if (size_t(used) != item.size() || lo > hi || step == 0) throw bad();
  };
  const uint32_t last = all.empty() ? 0 : all.back();
  std::vector<bool> wanted(size_t(last) + 1, false);
  for (size_t start = 0; start <= text.size();) {
    const size_t comma = std::min(text.find(',', start), text.size());
    unsigned lo = 0, hi = 0, step = 1;
    parse_item(text.substr(start, comma - start), lo, hi, step);
    for (uint64_t l = lo; l <= std::min<uint64_t>(hi, last); l += step) wanted[size_t(l)] = true;
    start = comma + 1;
  }
  std::vector<uint32_t> out;
  for (uint32_t l : all)
    if (wanted[l]) out.push_back(l);
  if (out.empty())
    throw CLI::ValidationError("--leaves", "no empty or liquid leaf of model 0 in " + text);
  return out;
}

}  // namespace

void check_cells_options(const BakeArgs& a, const CLI::App& cmd) {
  static const char* const kWalkableOnly[] = {"--walkable-from", "--agent-height", "--agent-radius",
                                              "--agent-step"};
  if (a.cells != "bsp-leaves") {
    for (const char* o :
         {"--face-spacing", "--leaves", "--face-sweep", "--chord-coarse", "--chord-floor",
          "--chord-piece", "--chord-tiles", "--chord-tile-size", "--chord-cross",
          "--chord-cross-floor", "--chord-new", "--sweep", "--bound", "--portal-edges"})
      if (cmd.count(o)) throw CLI::ValidationError(o, "only applies with --cells bsp-leaves");
    for (const char* o : kWalkableOnly)
      if (!a.walkable && cmd.count(o))
        throw CLI::ValidationError(o, "only applies with --walkable");
    parse_starts(a);
    return;
  }
  for (const char* o : {"--walkable", "--box", "--grid", "--cell-size", "--eye-height",
                        "--band-levels", "--vertical-edges", "--wall-traces", "--walkable-from",
                        "--agent-height", "--agent-radius", "--agent-step"})
    if (cmd.count(o))
      throw CLI::ValidationError(o,
                                 "cannot be combined with --cells bsp-leaves (the cells are "
                                 "the map's BSP leaves)");
  if (cmd.count("--bound") && a.sweep != "portals" && a.bound != "none")
    throw CLI::ValidationError("--bound", "restricts the runs of --sweep portals only");
  if (cmd.count("--portal-edges") && a.sweep != "portals")
    throw CLI::ValidationError("--portal-edges", "applies to --sweep portals only");
  if (!ends_with_bsp(a.scene))
    throw vislib::InputError(a.scene,
                             "--cells bsp-leaves needs a Quake map (.bsp): the cells are its BSP "
                             "leaves");
}

vislib::ViewCells make_cells(const BakeArgs& a, const vislib::Scene& scene,
                             const vislib::QuakeBsp* map) {
  if (a.cells == "bsp-leaves") {
    assert(map);
    const vislib::QuakeBsp& bsp = *map;
    vislib::BspCellOptions o;
    o.face_spacing = a.face_spacing.value_or(a.sweep == "portals" ? vislib::kBspPortalSpacing
                                                                  : vislib::kBspFaceSpacing);
    o.near = a.near;
    const bool portals = a.sweep == "portals";
    if (a.face_sweep.value_or(portals ? "adaptive" : "even") == "adaptive") {
      const vislib::AdaptiveSpacing d =
          portals ? vislib::kBspPortalChords : vislib::AdaptiveSpacing{};
      vislib::AdaptiveSpacing chords{
          a.chord_coarse.value_or(d.coarse),
          a.chord_floor.value_or(d.floor),
          a.chord_piece.value_or(d.piece),
          a.chord_tiles ? *vislib::chord_tiles_named(*a.chord_tiles) : d.tiles,
          a.chord_tile_size.value_or(d.tile_size),
          a.chord_cross ? *a.chord_cross == "on" : d.crossed};
      if (!(chords.floor <= chords.coarse))
        throw CLI::ValidationError("--chord-floor", "must not exceed --chord-coarse");
      // Unset: the default's, kept between the floor and the coarse spacing given.
      chords.crossed_floor = a.chord_cross_floor.value_or(
          std::min(chords.coarse, std::max(chords.floor, d.crossed_floor)));
      if (a.chord_cross_floor && !chords.crossed)
        throw CLI::ValidationError("--chord-cross-floor", "only applies with --chord-cross on");
      if (!chords.valid())  // the floor and the coarse spacing are checked above
        throw CLI::ValidationError("--chord-cross-floor",
                                   "must lie between --chord-floor and --chord-coarse");
      chords.new_to_family = a.chord_new ? *a.chord_new == "family" : d.new_to_family;
      if (a.chord_tile_size && chords.tiles == vislib::ChordTiles::All)
        throw CLI::ValidationError("--chord-tile-size",
                                   "only applies with --chord-tiles new or new-every-face");
      o.adaptive = chords;
    }
    if (!a.leaves.empty()) o.leaves = parse_leaves(a.leaves, vislib::bsp_cell_leaves(bsp));
    o.scene = load_options_of(a.import);
    o.sweep = a.sweep == "portals" ? vislib::BspSweep::Portals : vislib::BspSweep::Faces;
    o.bound = !portals               ? vislib::BspBound::None
              : a.bound == "portals" ? vislib::BspBound::Portals
              : a.bound == "map-vis" ? vislib::BspBound::MapVis
                                     : vislib::BspBound::None;
    o.share_edges = a.portal_edges == "shared";
    return vislib::bsp_leaf_cells(bsp, o, &scene);
  }
  vislib::CellPlacement p = placement_of(a);
  // A Quake map: its faces are wound clockwise seen from the front (floors, walls' fronts).
  if (ends_with_bsp(a.scene)) p.clockwise_front = true;
  if (a.walkable && ends_with_bsp(a.scene)) {
    // Quake's player walks, from the map's player starts unless given.
    if (!p.agent_height) p.agent_height = vislib::kQuakePlayerHeight;
    if (!p.agent_radius) p.agent_radius = vislib::kQuakePlayerRadius;
    if (!p.agent_step) p.agent_step = vislib::kQuakeStepHeight;
    if (a.walkable_from.empty()) {
      std::optional<vislib::QuakeBsp> own;
      const vislib::QuakeBsp& bsp = map ? *map : own.emplace(vislib::read_quake_bsp(a.scene));
      for (const vislib::BspEntityPoint& e : vislib::bsp_player_starts(bsp))
        p.starts.push_back({e.origin, e.classname});
      p.required_starts = false;
      if (p.starts.empty())
        warn(a.scene + ": the map names no player start: walkable cells over every floor level");
    }
  }
  try {
    // --grid is parsed only where the library would use it, so that a conflicting combination is
    // reported before a malformed --grid (as before the placement moved into the library).
    if (!a.grid.empty()) {
      const bool grid_used = !a.walkable && p.box && !(a.cell_size > 0);
      p.grid = grid_used ? parse_grid(a.grid) : std::array<uint32_t, 3>{1, 1, 1};
    }
    return vislib::place_view_cells(scene, p);
  } catch (const vislib::PlacementError& e) {
    if (e.problem() == vislib::PlacementProblem::StartWithoutFloor)
      throw CLI::ValidationError(a.walkable_from.empty() ? "--walkable" : "--walkable-from",
                                 e.what());
    throw placement_error(e.problem());
  }
}

// The preset fills the options not given and says so on stderr.
void apply_preset(BakeArgs& a, const CLI::App& cmd) {
  const Preset preset = preset_values(a.preset);
  if (cmd.count("--res") == 0) a.resolution = preset.resolution;
  if (cmd.count("--runs") == 0) a.runs = preset.runs;
  const bool cell_size_given = cmd.count("--cell-size") > 0;
  // Cell size: walkable cells, or a grid over --box by size when a preset is named (without
  // one, --box still needs --grid or --cell-size).
  if (!cell_size_given && a.grid.empty() && (a.walkable || cmd.count("--preset")))
    a.cell_size = preset.cell_size;
  if (show_progress() && cmd.count("--preset"))
    std::fprintf(
        stderr, "pvs bake: preset %s: --res %d%s, --runs %d%s, --cell-size %s\n", a.preset.c_str(),
        a.resolution, cmd.count("--res") ? " (given)" : "", a.runs,
        cmd.count("--runs") ? " (given)" : "",
        !a.grid.empty()
            ? "none (--grid)"
            : (fmt::format("{:g}", a.cell_size) + (cell_size_given ? " (given)" : "")).c_str());
}

vislib::BakeSettings settings_of(const BakeArgs& a) {
  vislib::BakeSettings s;
  s.region.segment.resolution = a.resolution;
  s.region.segment.near = a.near;
  s.region.segment.eps_len = a.eps_len;
  s.region.segment.tile_size = a.tile;
  s.long_segments = a.long_segments == "auto" ? 0 : std::stoi(a.long_segments);
  s.bvh = a.bvh == "on";
  s.region.segment.fans = a.fans == "on";
  s.region.runs = a.runs;
  s.region.seed = a.seed;
  s.granularity =
      a.granularity == "object" ? vislib::Granularity::Object : vislib::Granularity::Triangle;
  s.region.segment.mode =
      a.mode == "decoupled" ? vislib::DynamicMode::Decoupled : vislib::DynamicMode::Diagonal;
  s.region.segment.coplanar =
      a.coplanar == "first" ? vislib::CoplanarRule::First : vislib::CoplanarRule::Both;
  s.region.segment.eps_z = a.eps_z;
  return s;
}

void add_bake_options(CLI::App* cmd, BakeArgs& a) {
  cmd->add_option("SCENE", a.scene, "Scene file (.glb .gltf .obj .ply .off .stl .bsp)")->required();
  cmd->add_option("-o,--output", a.output, "Output PVS file (a shard file with --shard)")
      ->required();
  cmd->add_option("--cells", a.cells,
                  "'bsp-leaves': one cell per empty or liquid leaf of a Quake map's BSP tree "
                  "(docs/quake.md); default: a grid over --box or --walkable cells")
      ->check(CLI::IsMember({"bsp-leaves"}));
  cmd->add_option("--sweep", a.sweep,
                  "bsp-leaves: 'portals' (each portal between two leaves swept once for both, "
                  "directions split by its plane, plus the triangles on or in each leaf) or "
                  "'faces' (every face of each leaf's view region, walls included; docs/quake.md)")
      ->check(CLI::IsMember({"portals", "faces"}))
      ->capture_default_str();
  cmd->add_option("--bound", a.bound,
                  "bsp-leaves, --sweep portals: restrict each portal's runs to the triangles that "
                  "can be visible through it: 'portals' (our portal flow: exact), 'map-vis' (the "
                  "leaves the map's own vis data says its two leaves see: exact only where that "
                  "is conservative) or 'none' (docs/quake.md \"Restriction\")")
      ->check(CLI::IsMember({"none", "portals", "map-vis"}))
      ->capture_default_str();
  cmd->add_option("--face-spacing", a.face_spacing,
                  "bsp-leaves: sweep each swept polygon (a portal, or a face of a leaf's view "
                  "region) with parallel segments at most this far apart (Quake units; 0 = its "
                  "edges only; default 8 with --sweep portals, 16 with faces)")
      ->check(in_range(0.0, 1e6));
  cmd->add_option("--face-sweep", a.face_sweep,
                  "bsp-leaves: 'even' (chords --face-spacing apart) or 'adaptive' (coarse chords, "
                  "one inserted between two neighbours while it sees ids neither sees, down to "
                  "--chord-floor; docs/quake.md); default adaptive with --sweep portals, even "
                  "with faces")
      ->check(CLI::IsMember({"even", "adaptive"}));
  cmd->add_option("--chord-coarse", a.chord_coarse,
                  "bsp-leaves, adaptive: the first chords at most this far apart (Quake units; "
                  "default 256 with --sweep portals, 64 with faces)")
      ->check(in_range(1e-3, 1e6));
  cmd->add_option("--chord-floor", a.chord_floor,
                  "bsp-leaves, adaptive: no chord is inserted closer than this to a neighbour "
                  "(Quake units, at most --chord-coarse; default 4)")
      ->check(in_range(1e-3, 1e6));
  cmd->add_option("--chord-piece", a.chord_piece,
                  "bsp-leaves, adaptive: cut each swept polygon into strips at most this long "
                  "along its chords, each refined on its own (Quake units; 0 = whole chords; "
                  "default 256 with --sweep portals, 0 with faces)")
      ->check(in_range(0.0, 1e6));
  cmd->add_option("--chord-tiles", a.chord_tiles,
                  "bsp-leaves, adaptive: 'all' (every chord computes its whole cube), 'new' (a "
                  "chord inserted because its parent saw new ids computes only the cube tiles "
                  "where those can appear, one tile around, or its whole cube when one is seen "
                  "across a cube face's edge) or 'new-every-face' (those tiles on every face "
                  "where they can appear; docs/quake.md); default new-every-face with --sweep "
                  "portals, all with faces")
      ->check(CLI::IsMember([] {
        const std::vector<std::string_view> names = vislib::chord_tiles_names();
        return std::vector<std::string>(names.begin(), names.end());
      }()));
  cmd->add_option("--chord-tile-size", a.chord_tile_size,
                  "bsp-leaves, --chord-tiles new or new-every-face: the side of those tiles in "
                  "pixels (the margin is one tile; whole cubes keep the kernel's tiles; default "
                  "16)")
      ->check(in_range(1, vislib::kMaxTileSize));
  cmd->add_option("--chord-cross", a.chord_cross,
                  "bsp-leaves, adaptive: 'on' also sweeps each polygon with chords perpendicular "
                  "to the first, refined the same way (a slit seen through a thin patch of a "
                  "portal is crossed by one of the two; docs/quake.md); default on with --sweep "
                  "portals, off with faces")
      ->check(CLI::IsMember({"on", "off"}));
  cmd->add_option("--chord-cross-floor", a.chord_cross_floor,
                  "bsp-leaves, --chord-cross on: no crossed chord is inserted closer than this to "
                  "a neighbour (Quake units, between --chord-floor and --chord-coarse; the "
                  "patches the crossed chords are there for are long across them; default 16 "
                  "with --sweep portals, else --chord-floor)")
      ->check(in_range(1e-3, 1e6));
  cmd->add_option("--chord-new", a.chord_new,
                  "bsp-leaves, adaptive: when a probe's ids are new, so that chords are inserted "
                  "beside it: 'neighbours' (neither neighbour saw one of them) or 'family' "
                  "(nor did any chord of its family run before it: the strips of one polygon "
                  "with one direction of chords); default family with --sweep portals, "
                  "neighbours with faces")
      ->check(CLI::IsMember({"neighbours", "family"}));
  cmd->add_option("--portal-edges", a.portal_edges,
                  "bsp-leaves, --sweep portals: 'own' (each portal's edges are its own runs) or "
                  "'shared' (where open portals meet along a line, their edges, a few hundredths "
                  "of a unit apart, share one run split by each portal's plane: fewer runs, but "
                  "a leaf can take ids seen past a wall that ends there; docs/quake.md)")
      ->check(CLI::IsMember({"own", "shared"}))
      ->capture_default_str();
  cmd->add_option("--leaves", a.leaves,
                  "bsp-leaves: bake only these leaves, for a partial measurement: A, A-B, or "
                  "A-B/K (every K-th from A), comma-separated");
  cmd->add_option("--box", a.box,
                  "Grid box x0,y0,z0,x1,y1,z1 (with --walkable: only place cells in it)");
  cmd->add_option("--grid", a.grid, "Grid cells nx,ny,nz over --box");
  cmd->add_flag("--walkable", a.walkable, "Place cells automatically over upward-facing floors");
  cmd->add_option("--cell-size", a.cell_size,
                  "Cell side: walkable columns (default 2) or grid cells over --box")
      ->check(positive());
  cmd->add_option("--eye-height", a.eye,
                  "Eye band h0,h1 above the floor / the cell bottom (walkable default 1.5,1.8)");
  cmd->add_option("--band-levels", a.band_levels,
                  "Grid and walkable cells: the runs are the perimeters of the eye band's "
                  "rectangles at this many heights, bottom to top evenly spaced (2: the bottom and "
                  "the top, the paper's rule, and the default; more miss less of what eyes inside "
                  "the band see, at about levels / 2 times the cost; docs/bake.md \"Eye band\")")
      ->check(CLI::Range(vislib::kPaperBandLevels, vislib::kMaxBandLevels));
  cmd->add_option("--vertical-edges", a.vertical_edges,
                  "Grid and walkable cells: also run the four vertical edges of a cell's view "
                  "region, which pass through every height of the band (an eye between two band "
                  "levels sees past the region's sides what no level's perimeter does); default "
                  "on for walkable cells, off for a grid (docs/bake.md \"Eye band\")")
      ->check(CLI::IsMember({"on", "off"}));
  cmd->add_option("--wall-traces", a.wall_traces,
                  "Grid and walkable cells: also run along the walls that cross the middle of a "
                  "cell's eye band, a little off each wall's front (an eye next to a wall inside "
                  "the cell sees past its edges what the perimeter samples coarsely); default on "
                  "for walkable cells, off for a grid (docs/bake.md \"Eye band\")")
      ->check(CLI::IsMember({"on", "off"}));
  cmd->add_option("--max-slope", a.max_slope, "Walkable: steepest floor, degrees from horizontal")
      ->check(in_range(0.0, 90.0))
      ->capture_default_str();
  cmd->add_option("--walkable-from", a.walkable_from,
                  "Walkable: keep only the floor an agent can stand on and walk to (steps up, "
                  "drops down) from this point x,y,z (repeatable; default: a Quake map's player "
                  "starts, else every floor level; 'none': every floor level)")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_option("--agent-height", a.agent_height,
                  "Walkable reachability: the agent's height (default: the eye band's top; Quake "
                  "maps 56)")
      ->check(positive());
  cmd->add_option("--agent-radius", a.agent_radius,
                  "Walkable reachability: the agent's radius (default: a quarter of the eye "
                  "band's top; Quake maps 16)")
      ->check(non_negative());
  cmd->add_option("--agent-step", a.agent_step,
                  "Walkable reachability: the highest step the agent climbs (default: a quarter "
                  "of the eye band's top; Quake maps 18)")
      ->check(non_negative());
  cmd->add_flag("--no-headroom", a.no_headroom,
                "Walkable: keep floors covered by other geometry (under buildings)");
  cmd->add_option("--res", a.resolution, "Cube face resolution N of the from-segment runs")
      ->check(in_range(1, 16384))
      ->capture_default_str();
  cmd->add_option("--runs", a.runs, "Cube orientations K per boundary segment")
      ->check(in_range(1, 100000))
      ->capture_default_str();
  cmd->add_option("--seed", a.seed, "Seed of the orientations (derived per cell)")
      ->capture_default_str();
  cmd->add_option("--near", a.near, "Near plane (view depth, scene units)")
      ->check(positive())
      ->capture_default_str();
  cmd->add_option("--eps-len", a.eps_len, "Final pieces must be longer than this (in t) to count")
      ->check(in_range(0.0, 1.0))
      ->capture_default_str();
  cmd->add_option("--tile", a.tile,
                  "Kernel tile side in pixels; 0: 32 for static scenes, 16 with moving triangles "
                  "or spheres")
      ->check(in_range(0, vislib::kMaxTileSize))
      ->capture_default_str();
  cmd->add_option("--long-segments", a.long_segments,
                  "Run the world-aligned pass of up to this many cell edges lying end to end as "
                  "one long segment, split per edge (1 = off; static scenes; pays for many small "
                  "cells over a large scene, see docs/bake.md); 'auto': a pilot over a few rows "
                  "of edges picks 1, 2, 4 or 8 from the kernel's counted work")
      ->check(CLI::IsMember({"1", "2", "3", "4", "5", "6", "7", "8", "auto"}))
      ->capture_default_str();
  cmd->add_option("--bvh", a.bvh,
                  "Static scenes: every run walks one BVH of the triangles front to back per "
                  "tile (built once per bake); 'off' bins every triangle on every face of every "
                  "run. The file is the same either way")
      ->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str();
  add_fans_option(*cmd, a.fans);
  add_import_options(cmd, a.import);
  cmd->add_option("--states", a.states,
                  "Key states to sample glTF animations into (dynamic scenes)")
      ->check(in_range(1, 100000));
  cmd->add_option("--mode", a.mode,
                  "Dynamic scenes: 'diagonal' or 'decoupled' (as for pvs segment)")
      ->check(CLI::IsMember({"diagonal", "decoupled"}))
      ->capture_default_str();
  cmd->add_option("--coplanar", a.coplanar,
                  "Depth ties: 'both' (within --eps-z) or 'first' (as for pvs segment)")
      ->check(CLI::IsMember({"both", "first"}))
      ->capture_default_str();
  cmd->add_option("--eps-z", a.eps_z,
                  "Depth tie tolerance, relative to the front depth (as for pvs segment)")
      ->check(in_range(0.0, 0.1))
      ->capture_default_str();
  cmd->add_option("--granularity", a.granularity,
                  "Store triangle ids (spheres after them) or object ids")
      ->check(CLI::IsMember({"triangle", "object"}))
      ->capture_default_str();
  cmd->add_option("-j,--threads", a.threads,
                  "Threads, as make -j (0 = one per core); never changes the output")
      ->check(in_range(0, kMaxThreads));
  cmd->add_option("--shard", a.shard,
                  "Bake only cells c with c % N == i, into a shard file for pvs merge")
      ->capture_default_str();
  cmd->add_flag("--resume", a.resume, "Continue an interrupted bake from its checkpoint");
  cmd->add_option("--checkpoint", a.checkpoint, "Checkpoint file (default OUTPUT.ckpt)");
  cmd->add_flag("--dry-run", a.dry_run, "Place the cells, print their count and stop");
  cmd->add_option("--json", a.json_out,
                  "Write a bake report (timings per cell, sizes) as JSON ('-' = stdout)");
  cmd->add_option("--preset", a.preset,
                  "Quality preset: draft (--res 128, --runs 1, --cell-size 8), default (512, 1, 2) "
                  "or final (2048, 4, 1); options given explicitly win")
      ->check(CLI::IsMember({"draft", "default", "final"}))
      ->capture_default_str();
}

}  // namespace pvs_cli
