// generate.h: deterministic procedural test scenes modelled on the virtual environments of the
// from-segment visibility paper (Table 1): a city (stand-in for Manhattan/Medieval: strong
// occlusion along streets), a wind-swept grass field (Grass / Swaying Grass) and bouncing spheres
// (Bouncing Spheres: 10,000 spheres of radius 4 m over 100 x 100 m, 25 states).
//
// All generators are pure functions of their options: same options (seed included) give
// bit-identical scenes (vislib::Rng only, fixed evaluation order, no threads). Rng is the same
// everywhere; sin/cos/pow come from the C library, so another libm may differ in the last bit.
// Coordinates are meters, +Y up (as glTF), scenes centred on the origin in x and z.
// Triangles of one object are contiguous and objects appear in order, so writing the objects as
// glTF nodes in order and importing them back preserves triangle ids.
#pragma once

#include <cstdint>
#include <functional>

#include "vislib/scene/scene.h"

namespace vislib {

// Called with the fraction done in [0, 1], from the calling thread; may be empty.
using GenerateProgress = std::function<void(double fraction)>;

struct CityOptions {
  int blocks_x = 6, blocks_z = 6;          // city blocks along x and z; each must be >= 1
  double block_size = 60;                  // side of a square block between streets (m), > 0
  double street_width = 14;                // street between blocks (m), > 0
  int lots_per_side = 3;                   // a block is a lots x lots grid of buildings, >= 1
  double min_height = 8, max_height = 60;  // building height range (m), 0 < min <= max
  // Facade panel size (m): walls are split into panels of about this size (window panels), which
  // only adds triangles. 0 = no split (a wall is one quad).
  double panel_size = 0;
  // If > 0: picks panel_size (and, if auto_blocks, the block grid) so that the triangle count is
  // within a few percent of this. Requests below the undivided count of the grid give that count.
  uint64_t target_triangles = 0;
  bool auto_blocks = false;  // with target_triangles: choose blocks_x = blocks_z from the target
  uint64_t seed = 1;
  GenerateProgress progress;
};

// A city: one Object "ground" (a flat plane at y = 0 covering the blocks, streets and a margin of
// one street width, split into near-square triangles of about a quarter block) followed by one
// Object "building_<i>_<j>_<l>" per building (block i along x, block j along z, lot l). A building
// is a stack of 1-3 boxes (setback tiers, the upper ones towers) standing on y = 0, as one closed
// 2-manifold mesh: shared vertices, every edge in exactly two triangles, outward (CCW seen from
// outside) winding, no degenerate triangles. Buildings line the block edges with gaps of 0.5-2 m.
// Single state.
Scene generate_city(const CityOptions& options);

// The triangle count generate_city(options) would give (ignores target_triangles).
uint64_t city_triangle_count(const CityOptions& options);

struct GrassOptions {
  double size = 100;               // side of the square field (m), > 0
  double terrain_cell = 1;         // terrain grid spacing (m), > 0
  double terrain_amplitude = 1.5;  // height of the gentle rolling hills (m), >= 0
  double density = 20;      // blades per square meter (ignored when target_triangles > 0), >= 0
  int blade_triangles = 3;  // triangles per blade: a curved tapering strip, 2..5
  double blade_height = 0.5, blade_width = 0.02;  // mean blade height and base width (m)
  double patch_size = 5;        // blades are grouped into one Object per patch of this side (m)
  int states = 10;              // key states of the wind animation, >= 1
  double wind_amplitude = 0.6;  // tip bend angle of a gust (radians), >= 0
  double wind_wavelength = 20;  // wavelength of the travelling gust wave (m), > 0
  // If > 0: the blade count is chosen so that the total triangle count is this (exactly, when it
  // exceeds the terrain's triangle count).
  uint64_t target_triangles = 0;
  uint64_t seed = 1;
  GenerateProgress progress;
};

// A grass field: Object "terrain" (an indexed heightfield grid, static, upward-facing) followed by
// one Object "grass_<i>_<j>" per patch of blades (patch i along x, j along z). Each blade is a
// single-sided strip of blade_triangles triangles whose two base vertices sit on the terrain and
// never move. `states` key states sample one period of a wind gust wave travelling along +x
// (state k at phase k/states, so state `states` would equal state 0): the gust bends each blade
// downwind along a circular arc of its own length (the centre line keeps its length exactly), the
// base stays fixed. The terrain is identical in every state.
Scene generate_grass(const GrassOptions& options);

struct SphereOptions {
  int count = 10000;         // number of spheres, >= 0
  double radius = 4;         // sphere radius (m), > 0
  double area = 100;         // centres stay within an area x area square centred at the origin (m)
  int states = 25;           // key states, >= 1
  double duration = 6;       // simulated seconds between the first and the last state, > 0
  double max_height = 40;    // initial centre heights are uniform in [radius, radius + this] (m)
  double speed = 8;          // initial velocity components uniform in [-speed, speed] (m/s)
  double restitution = 0.8;  // vertical speed kept at a bounce, in [0, 1]
  double gravity = 9.81;     // m/s^2
  uint64_t seed = 1;
};

// Bouncing spheres: ballistic arcs under gravity, bouncing on the ground y = 0 (centre at
// y = radius) with `restitution`, and elastically on the vertical walls of the area, solved in
// closed form per flight (no time-step error). Spheres do not collide with each other (they may
// interpenetrate). Scene: no triangles, sphere_radius, sphere_centers[state][sphere] with
// center.y >= radius in every state, sphere_object[i] = i, objects "sphere<i>".
Scene generate_spheres(const SphereOptions& options);

}  // namespace vislib
