// walkable_reach.h: the floor an agent can stand on and walk to from given start points, for
// walkable view cells (view_cells.h) that lie only where a player can be.
//
// The scene is voxelized with Recast (recastnavigation's heightfield, as navigation-mesh builders
// do: Mikko Mononen, "Recast Navigation", the rcHeightfield / rcCompactHeightfield stage): a voxel
// column of `voxel` x `voxel` in x and z holds spans of solid; the top of a solid span whose
// surface is floor (the rule of walkable_cells: facing up, (b - a) x (c - a) with a positive y
// component, no steeper than the slope limit) is walkable when the open space above it is at least
// the agent's height. Two walkable spans of side-by-side columns are connected (Recast's
// connections) when their floors differ by at most the agent's step and the opening between them
// is at least the agent's height. Reachable floor: a flood fill from the starts over the
// connections and over drops (an agent walks off a ledge onto any lower floor of the next column
// whose open space reaches the agent's head on the ledge; the way back up is only by a step).
// The agent's radius then removes the floor its disc does not fit on (Recast's erosion of the
// walkable area by the radius): reachable floor closer than the radius to a wall or a drop is not
// standable. The flood fill itself treats the agent as a point (a gap narrower than the agent is
// passed), so the rule errs towards keeping floor.
//
// Jumps, jump pads, ladders, lifts and teleporters are not modelled: a floor reached only by them
// needs a start of its own (or a larger step, which models a jump as a climb).
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "vislib/base/vec.h"
#include "vislib/scene/scene.h"

namespace vislib {

// The floor rule of walkable cells: the triangle faces up and its normal is within
// `max_slope_degrees` of +y. Its front normal is (b - a) x (c - a) (counter-clockwise front
// faces, glTF's convention), or the opposite with `clockwise_front` (Quake maps' convention).
// False for a degenerate triangle.
bool floor_triangle(const std::array<Vec3, 3>& corners, double max_slope_degrees,
                    bool clockwise_front = false);

// The agent that walks: height (floor to the top of its head), radius (half its width in x and
// z) and step (the highest ledge it climbs), in scene units.
struct WalkAgent {
  double height = 1.8, radius = 0.45, step = 0.45;
};

// A start point in scene coordinates and where it came from ("--walkable-from",
// "info_player_start", ...: recorded in the cells' description).
struct WalkStart {
  Vec3 point;
  std::string source;
};

struct ReachOptions {
  WalkAgent agent;                // height > 0, radius >= 0, step >= 0
  double max_slope_degrees = 45;  // floor triangles (floor_triangle), in [0, 90)
  bool clockwise_front = false;   // floor_triangle's winding
  std::vector<WalkStart> starts;  // at least one
  // Side of a voxel column in x and z (> 0); raised so that the voxel grid over the scene bounds
  // has at most kMaxReachColumns columns. Its height is chosen from the agent (ReachableFloor).
  double voxel = 0.5;
  size_t state = 0;  // key state whose geometry is used
};

// At most this many voxel columns over the scene's x/z bounds (the voxel side is raised to fit).
constexpr double kMaxReachColumns = 1 << 22;

// Where the agent can stand: per voxel column, the heights of the reachable floors on which its
// disc fits.
struct ReachableFloor {
  double voxel = 0, voxel_height = 0;  // the voxel's side in x and z, and its height in y
  double min_x = 0, min_z = 0;         // the grid's corner (scene bounds)
  int width = 0, depth = 0;            // columns in x and in z
  // The floor heights (scene y, rounded up to the voxel height: a floor at y is recorded within
  // [y, y + voxel_height]) of column (i, k), in columns[k * width + i], increasing.
  std::vector<std::vector<double>> columns;
  // Per start (same order): the height of the floor it stands on (the highest walkable floor of
  // its column, or of the nearest column within the agent's radius + 1 voxel, at or below the
  // point + the step), or none when there is no such floor (it is outside the walkable space).
  std::vector<std::optional<double>> start_floors;

  // True when a reachable floor lies in a column whose centre is in [x0, x1) x [z0, z1), at a
  // height (as recorded) in [y0, y1].
  bool any_in(double x0, double x1, double z0, double z1, double y0, double y1) const;
  size_t floor_count() const;  // the reachable floors of all columns
};

// The reachable floor of `scene` for `options` (see the top of this file). Deterministic
// (sequential). options.starts must not be empty; the scene must have triangles. Throws
// std::runtime_error if Recast fails (memory).
ReachableFloor reachable_floor(const Scene& scene, const ReachOptions& options);

}  // namespace vislib
