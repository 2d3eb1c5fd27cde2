// near_far.h: near-far partition of a cell's visible set, with the continuous morph, and the
// progressive near region, as pure functions an engine or a reference renderer calls
// Standard library only.
//
// Papers (../shared/papers/):
//  - near-far-partitioning.txt §3-4 ("Continuous near-far partitioning"): two co-axial vertical
//    cylinders of radii r1 < r2 around a centre O split the scene into near (r <= r1), intermediate
//    and far (r >= r2); Eq. 1 morphs intermediate vertices, Eq. 2 displaces dynamic far vertices,
//    Eq. 3 depth-tests their fragments against a per-pixel range cube map rendered from O.
//    Misprint fixed (docs/visibility-math.md, appendix): in Eq. 1 the undefined `a`
//    is r2 - r, r = distance of the vertex to the cylinder axis.
//  - clovr-progressive-near-region.txt §3-4 (CloVR): the near region grows ring by ring (equal-area
//    rings, then merged), new geometry injected with Alg. 1. Misprint fixed: Alg. 1 line 8 is
//    w = (R - r)/(R - R_n).
//
// Conventions: y is up, so the cylinders are vertical and r = distance in the x-z plane. U is the
// user eye, O the environment-map viewpoint (on the axis). Ranges are Euclidean distances. All
// arithmetic is in double. Every function is pure, deterministic and thread-safe.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace pvs_runtime {

struct Point3 {
  double x = 0, y = 0, z = 0;
};

// Fragment range r_U passes Eq. 3 while r_U <= r_O * (1 + kRangeRelativeTolerance). Relative,
// unitless; errs towards visible (the safe side). It exceeds 16x the rounding of a range stored as
// binary32 (2^-24 relative), so a surface of the range map itself, re-projected exactly (a vertex
// on r2 lands at range r_O), is never culled by its own depth. It does not absorb the
// discretisation of the map (a range is one value per pixel).
constexpr double kRangeRelativeTolerance = 1e-6;

// Distance from p to the vertical axis through o (x-z plane).
double axis_distance(const Point3& p, const Point3& o);

// ---- Near-far partition (near-far paper §3) -------------------------------------------------

enum class Region : uint8_t { Near = 0, Intermediate = 1, Far = 2 };

// Region of a vertex at axis distance r: Near if r <= r1, Far if r >= r2, else Intermediate.
// r1 must be >= 0 and < r2.
Region vertex_region(double r, double r1, double r2);

// How w_U falls from 1 at r1 to 0 at r2 (x = (r2 - r)/(r2 - r1) in [0, 1]):
// Linear: w_U = x (Eq. 1); Quadratic: w_U = x^2 (Eq. 4); SCurve: 2x^2 below 0.5, else
// 1 - 2(x - 1)^2 (Eq. 5). All three are 1 at r1 and 0 at r2.
enum class MorphCurve : uint8_t { Linear = 0, Quadratic = 1, SCurve = 2 };

// w_U of a vertex at axis distance r: 1 for r <= r1, 0 for r >= r2, the curve in between.
double morph_user_weight(double r, double r1, double r2, MorphCurve curve = MorphCurve::Linear);

// The displaced position Q of vertex P, drawn then with the user's ordinary projection (the
// paper's unified vertex shader, §4.1): near (r <= r1): Q = P; far (r >= r2): Q = U + P - O
// (Eq. 2); intermediate: Eq. 1 with a = r2 - r:
//   d = normalize(w_U d_U + w_O d_O), d_U = (P-U)/|P-U|, d_O = (P-O)/|P-O|, w_O = 1 - w_U,
//   t = |UP| w_U + |OP| w_O,  Q = U + t d.
// Continuous: at r = r1 Q = P; at r = r2 Q = U + |OP| d_O, i.e. seen from U in the direction O
// sees P, at the range the cube map stores for it (Eq. 3 then compares equal ranges).
// Preconditions: 0 <= r1 < r2; U's axis distance must be < r1 (the user is in the near region;
// then d_U and d_O never cancel) and P != U, P != O for intermediate vertices.
Point3 morph_vertex(const Point3& p, const Point3& u, const Point3& o, double r1, double r2,
                    MorphCurve curve = MorphCurve::Linear);

// Eq. 2: a dynamic far vertex is displaced to Q = U + P - O.
Point3 displace_far(const Point3& p, const Point3& u, const Point3& o);

// The triangles of a cell's visible set, by region. A triangle is Near if all its vertices are,
// Far if all are, else Intermediate (its near vertices stay, its others morph: the per-vertex
// morph is continuous, so a triangle crossing r1 or r2 stays in one piece).
struct NearFarPartition {
  std::vector<uint32_t> near_ids;
  std::vector<uint32_t> intermediate_ids;
  std::vector<uint32_t> far_static_ids;   // drawn only through the environment map
  std::vector<uint32_t> far_dynamic_ids;  // drawn per frame with Eq. 2 and tested with Eq. 3
  // What goes into the environment cube map rendered from O (the paper's SF bin, §4.1): the static
  // triangles with a vertex beyond r2, i.e. far_static_ids plus the static intermediate triangles
  // that cross r2 ("both SF and NSF contain the triangles with vertices on both sides of the r2
  // boundary", so no hairline crack opens between the two). Sorted.
  std::vector<uint32_t> environment_map_ids;
  // What is drawn from geometry every frame with morph_vertex (NSF): near, intermediate and
  // dynamic far triangles. Sorted.
  std::vector<uint32_t> geometry_ids;
};

// Partitions the triangles `ids` (e.g. a cell's visible ids from Pvs::visible_ids; sorted output
// lists keep their order) around the axis through o with radii r1 < r2.
// positions: 3 floats (x, y, z) per vertex, vertex_count vertices; indices: 3 vertex indices per
// triangle, triangle_count triangles; dynamic: one byte per triangle, nonzero = the triangle moves
// (it is then never put in the environment map), or null if the whole scene is static.
// Preconditions: every id < triangle_count, every index < vertex_count, 0 <= r1 < r2.
NearFarPartition partition_near_far(const float* positions, size_t vertex_count,
                                    const uint32_t* indices, size_t triangle_count,
                                    const uint8_t* dynamic, const uint32_t* ids, size_t id_count,
                                    const Point3& o, double r1, double r2);

// ---- The range cube map and Eq. 3 -----------------------------------------------------------

// A per-pixel range map from O: 6 square faces of size x size pixels, in vislib's binding cubemap
// convention (vislib/base/cubemap.h, identity orientation): faces 0..5 = +X, -X, +Y, -Y, +Z, -Z
// with forward/S/T axes
//   +X: F=(1,0,0)  S=(0,0,-1) T=(0,-1,0)     -X: F=(-1,0,0) S=(0,0,1)  T=(0,-1,0)
//   +Y: F=(0,1,0)  S=(1,0,0)  T=(0,0,1)      -Y: F=(0,-1,0) S=(1,0,0)  T=(0,0,-1)
//   +Z: F=(0,0,1)  S=(1,0,0)  T=(0,-1,0)     -Z: F=(0,0,-1) S=(-1,0,0) T=(0,-1,0)
// pixel (x, y) (column, row) has the centre direction F + sc S + tc T, sc = (2x+1)/size - 1,
// tc = (2y+1)/size - 1. range[(face * size + y) * size + x] is the Euclidean distance from O to
// the first stationary far surface along that pixel, +infinity where there is none.
// The face table above, the one copy of the convention (vislib/base/cubemap.h reads it too):
// kCubeFaceAxes[face] = {F, S, T}.
struct CubeFaceAxes {
  Point3 f, s, t;
};
inline constexpr CubeFaceAxes kCubeFaceAxes[6] = {
    {{1, 0, 0}, {0, 0, -1}, {0, -1, 0}},   // +X
    {{-1, 0, 0}, {0, 0, 1}, {0, -1, 0}},   // -X
    {{0, 1, 0}, {1, 0, 0}, {0, 0, 1}},     // +Y
    {{0, -1, 0}, {1, 0, 0}, {0, 0, -1}},   // -Y
    {{0, 0, 1}, {1, 0, 0}, {0, -1, 0}},    // +Z
    {{0, 0, -1}, {-1, 0, 0}, {0, -1, 0}},  // -Z
};

struct RangeCubeMap {
  int size = 0;
  const float* range = nullptr;  // 6 * size * size values, not owned
};

struct CubePixel {
  int face = 0, x = 0, y = 0;
};

// The pixel whose square contains direction d (d != 0). The face is that of the largest |d|
// component (ties: x before y before z).
CubePixel cube_pixel(const Point3& d, int size);
// The (unnormalised) centre direction of a pixel.
Point3 cube_pixel_direction(int face, int x, int y, int size);
// The range stored for direction d.
double cube_range(const RangeCubeMap& map, const Point3& d);

// Eq. 3: a fragment at displaced position q (from displace_far or morph_vertex, interpolated over
// a triangle) survives iff r_U = |q - u| <= r_O (1 + kRangeRelativeTolerance), where
// r_O = cube_range(map, (q - u) / r_U). q must differ from u.
bool passes_range_test(const Point3& q, const Point3& u, const RangeCubeMap& map);

// ---- Progressive near region (CloVR §3.1) ---------------------------------------------------

// Outer radii of rings of area ring_area (scene units^2) around the axis, from 0 up to
// final_radius: R_k = sqrt(k * ring_area / pi), k = 1, 2, ..., with the last radius exactly
// final_radius (its ring is then no larger than the others). Increasing. Requires ring_area > 0,
// final_radius > 0. (CloVR: 314 m^2 rings, first radius 10 m.)
std::vector<double> equal_area_ring_radii(double ring_area, double final_radius);

// Sum of item_weight over the items whose radius falls in each ring: ring k is
// [radii[k-1], radii[k]) (ring 0 starts at 0); items at or beyond the last radius are ignored.
// For CloVR an item is an object, its radius the smallest axis distance of its vertices (an object
// enters the near region with its first vertex), its weight what the ring costs or brings:
// e.g. its visible triangle count (a PVS-visible set accounts for "visibility"), divided by its
// distance to the user (perspective foreshortening).
std::vector<double> ring_contributions(const std::vector<double>& radii,
                                       const std::vector<double>& item_radius,
                                       const std::vector<double>& item_weight);

// Merges consecutive rings, inside out, until each merged ring contributes at least
// min_contribution; a last group below it joins the group before. Returns the outer radii of the
// merged rings (a subsequence of radii ending with its last element). The paper states the goal
// (merge "based on visibility and distance from user", giving 10, 14, 17, 22, 32, 63 m for its
// City from 10 m equal-area rings) but no rule; this greedy rule is ours. Requires
// contribution.size() == radii.size().
std::vector<double> merge_rings(const std::vector<double>& radii,
                                const std::vector<double>& contribution, double min_contribution);

// Alg. 1's weight of the user view for a vertex at axis distance r while the near region has
// radius R and the near subregion R_n: 1 for r <= R_n, w = (R - r)/(R - R_n) in between, 0 for
// r >= R. Requires 0 <= R_n < R (CloVR uses R_n = 0.7 R).
double injection_weight(double r, double big_r, double r_n);

// Alg. 1: the displaced position Q of vertex P (then projected with the user's view): r < R_n:
// Q = P; else Q is where the ray from U with direction normalize(w d_U + (1 - w) d_O) leaves the
// vertical cylinder of radius r (P's own) around O, w = injection_weight (0 beyond R: the
// environment-map direction). Continuous in P and in R. Requires 0 <= R_n < R and U's axis
// distance < R_n.
Point3 inject_vertex(const Point3& p, const Point3& u, const Point3& o, double big_r, double r_n);

// The CloVR partition at near radius R (object level, §3): an object is near if any of its
// vertices has axis distance < R. Returns, for the triangles `ids`, those of near objects (drawn
// from geometry with inject_vertex) and the others (rendered into the ring's environment map).
struct ProgressivePartition {
  std::vector<uint32_t> near_ids, environment_map_ids;
};
// triangle_object: object id of each triangle (< object_count). Other arguments as
// partition_near_far.
ProgressivePartition partition_progressive(const float* positions, size_t vertex_count,
                                           const uint32_t* indices, size_t triangle_count,
                                           const uint32_t* triangle_object, size_t object_count,
                                           const uint32_t* ids, size_t id_count, const Point3& o,
                                           double big_r);

}  // namespace pvs_runtime
