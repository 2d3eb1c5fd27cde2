// ods.h: omnidirectional stereo (ODS) equirectangular panoramas with pole merging, as pure
// functions an engine or a reference renderer calls. Standard library
// only, like near_far.h.
//
// Paper (../shared/papers/omnidirectional-stereo.txt, Marrinan & Papka): Eq. 1-3 equirectangular
// projection, Alg. 1 + Eq. 4 dynamic tessellation levels, §3.2 seam and pole discontinuities,
// Eq. 5 per-vertex ODS camera offset, Eq. 6 pole merging. Errors of the paper handled here (each
// kept in tests/ods_test.cpp or docs/ods.md):
//  - Eq. 5 offsets the camera at right angles to the vertex direction: the longitude moves by
//    atan(h/r_h) where the ray tangent to the viewing circle needs asin(h/r_h), and the latitude
//    uses sqrt(r_h^2 + h^2) where the tangent ray has sqrt(r_h^2 - h^2) (h = IPD/2, r_h = the
//    vertex's horizontal distance to the centre). ods_project_exact is exact; ods_project_paper
//    keeps Eq. 1-5 for comparison.
//  - A point inside the viewing circle (r_h <= h) is seen by no ODS ray; Eq. 5 still places it.
//  - Eq. 5 is undefined straight up or down (normalize of 0): ods_project_paper uses no offset
//    there; the pole a triangle covers comes from its axis crossing point (axis_crossing), not
//    from its first vertex.
//  - Eq. 6 divides by zero when start = end (0/0 at the paper's own "no merging" setting
//    start = end = 0): here start = end means factor 1, without dividing. The paper does not say
//    which latitude Eq. 6 takes: here the latitude of the ODS ray (the pixel-centre ray's
//    direction), so a ray tracer knows it per row; the exact vertex projection then solves for it.
//  - Eq. 2 lacks the z < 0 branch: longitude = -atan2(x, z) covers all four quadrants. Alg. 1
//    loops "0 to 3" over 3 vertices: the loops here run i = 0, 1, 2.
//
// Conventions (the project's, used by vislib/render/ods_render.h and `pvs view --ods`):
//  - y is up. Longitude lon = -atan2(d.x, d.z) in (-pi, pi] (the paper's Eq. 2): lon = 0 looks
//    along +z, lon = -pi/2 along +x, lon = +pi/2 along -x; increasing lon turns right (right of
//    +z with y up is -x). Latitude lat = asin(d.y/|d|) in [-pi/2, pi/2], + up. Angles in radians
//    unless a name says _deg. Direction of (lon, lat): (-sin lon cos lat, sin lat, cos lon cos
//    lat).
//  - A W x H panorama (H = W/2 for the usual 2:1) has column u in [0, W) and row v in [0, H) as
//    continuous coordinates, row 0 at the top: lon = -pi + 2 pi u / W, lat = pi/2 - pi v / H.
//    Pixel (x, y) covers [x, x+1) x [y, y+1); its centre is (x + 0.5, y + 0.5). Column 0 and
//    column W-1 are neighbours across the seam lon = +-pi (straight behind, -z).
//  - ODS: the eyes sit on the horizontal viewing circle of radius h = IPD/2 about the centre C.
//    The ray of direction (lon, lat) starts at C + s h_m right(lon), s = -1 left eye, +1 right
//    eye, right(lon) = (-cos lon, 0, -sin lon) = direction(lon + pi/2, 0) (Eq. 5's
//    normalize(forward x up)), h_m = h * pole_merge_factor(lat). It is tangent to the circle of
//    radius h_m in the horizontal plane.
// Every function is pure, deterministic and thread-safe; arithmetic in double.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "runtime/near_far.h"  // Point3

namespace pvs_runtime {

constexpr double kOdsPi = 3.14159265358979323846;

// ---- Pole merging (Eq. 6) ---------------------------------------------------------------------

// One pole's parameters, as the paper's: angles measured from the pole, in degrees. Merging
// starts start_deg away from the pole (IPD full below it) and ends end_deg away (IPD 0 beyond it);
// the factor between is (1 - x)^exponent, x going linearly 0 -> 1 from start to end.
// Preconditions: 0 <= end_deg <= start_deg <= 90, exponent > 0. start_deg == end_deg means no
// merging (factor 1 everywhere; the paper's 0,0 setting), never a division by zero.
struct PoleMergeSide {
  double start_deg = 0, end_deg = 0, exponent = 1;
};
// Separate settings for the top (lat > 0) and bottom (lat < 0) poles. Default: no merging.
struct PoleMerge {
  PoleMergeSide top, bottom;
};

// Eq. 6's factor a in [0, 1] (the IPD is multiplied by it) at latitude `lat` (radians, in
// [-pi/2, pi/2]): the top side's parameters for lat > 0, the bottom side's for lat < 0, 1 at
// lat = 0 unless a side starts merging at the equator (start_deg = 90 gives a(0) = 1 anyway).
// Non-increasing in |lat| on each side; continuous unless exponent is tiny.
double pole_merge_factor(double lat, const PoleMerge& merge);

// ---- Equirectangular projection (Eq. 1-3) -------------------------------------------------

struct LonLat {
  double lon = 0, lat = 0;  // radians
};

// lon wrapped into (-pi, pi].
double wrap_longitude(double lon);
// Longitude and latitude of direction d (Eq. 2 for all quadrants, Eq. 3). d must be non-zero; a
// vertical d (d.x = d.z = 0) gets lon = 0.
LonLat direction_lonlat(const Point3& d);
// The unit direction of (lon, lat).
Point3 lonlat_direction(const LonLat& ll);
// Continuous pixel coordinates (u = column, v = row) of (lon, lat) in a W x H panorama, and back.
// u in [0, W] (lon = pi maps to W, i.e. the seam), v in [0, H]. width, height >= 1.
std::array<double, 2> lonlat_to_pixel(const LonLat& ll, int width, int height);
LonLat pixel_to_lonlat(double u, double v, int width, int height);

// ---- ODS rays and vertex projections (Eq. 5, 6) ----------------------------------------------

enum class Eye : int8_t { Left = -1, Right = 1 };

struct Ray {
  Point3 origin, direction;  // direction has unit length
};

// The ODS ray of direction (lon, lat) for `eye`: origin C + s h_m right(lon), h_m = ipd/2 *
// pole_merge_factor(lat, merge). ipd >= 0 (scene units); ipd = 0 gives the mono panorama's ray.
Ray ods_ray(const LonLat& ll, const Point3& centre, double ipd, Eye eye, const PoleMerge& merge);
// The ray of pixel (x, y)'s centre in a W x H panorama: ods_ray(pixel_to_lonlat(x+0.5, y+0.5)).
// 0 <= x < width, 0 <= y < height.
Ray ods_pixel_ray(int x, int y, int width, int height, const Point3& centre, double ipd, Eye eye,
                  const PoleMerge& merge);

struct OdsProjection {
  bool visible = false;  // false: no ODS ray of this eye passes through the point
  LonLat ll;             // where the point appears (valid when visible)
  double range = 0;      // distance from the ray origin to the point (valid when visible)
  double h = 0;          // the eye offset used (ipd/2 * pole merge factor)
  int iterations = 0;    // fixed-point steps taken (0 without merging)
};

// Exact ODS projection of point p: the (lon, lat) whose ods_ray passes through p. With r_h =
// horizontal distance of p from the centre, dy = p.y - C.y, lon_c = p's longitude from C:
//   lon = lon_c - s asin(h/r_h),  lat = atan2(dy, sqrt(r_h^2 - h^2)),
// and with pole merging (h = ipd/2 * a(lat) depends on lat) lat is the fixed point of that
// equation, found by iteration from the h = 0 latitude (2-3 steps at r_h >> h; a bracketing
// bisection takes over if it has not converged to 1e-15 rad in 32 steps; the solution is unique
// because the right side falls as |lat| grows). Not visible when r_h <= h at the solution (p is
// inside the viewing circle: no tangent ray reaches it). A point on the axis (r_h = 0) is visible
// only if h = 0 at the pole latitude; it is then returned with lon = 0 (every longitude of the
// pole row shows it). p may equal C only if ipd = 0 is false -> not visible (range 0 points are
// never visible).
OdsProjection ods_project_exact(const Point3& p, const Point3& centre, double ipd, Eye eye,
                                const PoleMerge& merge);

// The paper's per-vertex projection (Eq. 1-5, Eq. 6 at the vertex's latitude seen from the
// centre): forward = p - C, right = normalize(forward x up), camera = C + s h right,
// (lon, lat) = Eq. 2-3 of p - camera. Always "visible" (also inside the viewing circle, as the
// paper does); straight above or below C (forward x up = 0) the offset is taken as 0 (Eq. 5 is
// undefined there). p must differ from C.
OdsProjection ods_project_paper(const Point3& p, const Point3& centre, double ipd, Eye eye,
                                const PoleMerge& merge);

// ---- Tessellation levels (Alg. 1, Eq. 4) ---------------------------------------------------

// lonDist of the paper's footnote, in degrees: |a - b| taken the short way round, in [0, 180].
double lon_dist_deg(double a_deg, double b_deg);

// Alg. 1 lines 6-14 for one edge: the outer level of the edge between projected endpoints a and
// b whose 3D midpoint projects to mid (all radians in, converted to degrees as the paper's
// constants are): edge = (lonDist, 0.5 max |dlat|), d = max(0.125 |edge|, 1), pole multiplier
// max(2.8284/90 * max |lat|, 1), level = min(pole multiplier * d, 64). Symmetric in a, b: a
// shared edge gets the same level from both triangles (no cracks). In [1, 64].
double edge_outer_level(const LonLat& a, const LonLat& b, const LonLat& mid);

struct TessLevels {
  std::array<double, 3> outer{};  // outer[i]: the edge opposite vertex i (vertices i+1, i+2)
  double inner = 1;
};
// Alg. 1: projected[i] = projected vertex i, mid_projected[i] = projection of the midpoint of the
// edge opposite vertex i. inner from line 16: max(max_tess - 2, min(max_tess, 3)).
TessLevels tessellation_levels(const std::array<LonLat, 3>& projected,
                               const std::array<LonLat, 3>& mid_projected);
// Eq. 4 written as the paper's piecewise function (max_tess - 2 above 5, 3 on [3, 5], max_tess
// below 3). Equal to line 16 for every max_tess >= 1 (tests/ods_test.cpp checks it).
double inner_level_eq4(double max_tess);

// A tessellation of one triangle in barycentric coordinates. points[k] = weights of vertices
// 0, 1, 2 (summing to 1); triangles index points, wound as the input (0, 1, 2).
struct Tessellation {
  std::vector<std::array<double, 3>> points;
  std::vector<std::array<uint32_t, 3>> triangles;
};
// Tessellates with integer levels (each >= 1, <= 64): a uniform grid of n = max(outer[0..2],
// inner) segments a side, then the grid points on edge i moved to the nearest of that edge's own
// outer[i] + 1 equally spaced points (monotone snapping; triangles that collapse are dropped).
// The boundary of edge i is then exactly its outer[i]-segment polyline, the same from both
// triangles sharing the edge (crack-free like the GPU's outer levels). Unlike OpenGL's
// tessellator the interior has n, not inner, segments: at least as dense (Eq. 4's inner <= n).
Tessellation tessellate_triangle(const std::array<int, 3>& outer, int inner);

// ---- Seam and pole split (§3.2) -------------------------------------------------------------

// Where the vertical axis through `centre` crosses triangle v (barycentric weights of the
// crossing in the x-z plane, all >= 0 when it crosses, edges and vertices included) and which
// pole the triangle covers: +1 (top) if the 3D crossing point lies above the centre, -1 below
// (0 exactly level: taken as +1). Triangles degenerate in x-z (vertical) never cross.
struct AxisCrossing {
  bool crosses = false;
  std::array<double, 3> bary{};
  Point3 point;  // the crossing point (valid when crosses)
  int pole = 0;  // +1 / -1 (valid when crosses)
};
AxisCrossing axis_crossing(const std::array<Point3, 3>& v, const Point3& centre);

// A projected vertex: position in the panorama (radians; lon may lie outside [-pi, pi] after the
// split, to be clipped by the rasteriser), its range (interpolated linearly, as the paper's
// orthographic z = -|v_dir|) and lon_centre, the longitude of the 3D point seen from the centre
// C (direction_lonlat(p - C).lon), the reference for unwrapping. The eye offset moves a vertex's
// longitude by up to 90 degrees (asin(h/r_h) or atan(h/r_h)) and by different amounts for the
// vertices of one triangle near the axis, so the short way between eye longitudes can be the
// wrong way round; between centre longitudes it is right for any triangle that the axis does not
// cross.
struct ProjVertex {
  double lon = 0, lat = 0, range = 0, lon_centre = 0;
};
struct ProjTriangle {
  std::array<ProjVertex, 3> v;
};
// The triangles to rasterise for one small (tessellated) triangle with projected vertices v
// (lon in (-pi, pi]). Unwrapping: vertex i is placed at
//   v[0].lon_centre + wrap(v[i].lon_centre - v[0].lon_centre) + wrap(v[i].lon - v[i].lon_centre),
// its centre longitude unwrapped the short way from v[0]'s plus its own eye offset.
//  - no pole (pole = 0): the unwrapped triangle; if it spills past -pi or pi, a second copy
//    shifted by 2 pi the other way (the paper's "draw twice, let clipping remove"); 1 or 2
//    triangles.
//  - a pole (pole = +1 / -1, pole_range = the range of the axis crossing point): the paper's
//    case 3 strip, for each edge (a, b) the quad a, b, (b.lon, pole lat), (a.lon, pole lat) with
//    b unwrapped from a (pole vertices get pole_range), as two triangles, each with its shifted
//    copy if it spills; up to 12 triangles. (Cases 1 and 2 of the paper, a vertex or edge on the
//    axis, are the same strip with collapsed quads, which the rasteriser skips.)
std::vector<ProjTriangle> split_seam_pole(const std::array<ProjVertex, 3>& v, int pole,
                                          double pole_range);

// ---- The viewing disc and the PVS cells -----------------------------------------------------

// The eyes of an ODS panorama centred at c lie on the horizontal disc of radius `radius` (IPD/2)
// about c. A cell's visible set is valid for eyes in its view region (an axis-aligned box
// [lo, hi], boundaries inclusive): the set alone is enough when the whole disc lies in the box;
// else the union of the sets of every cell whose view region the disc touches (find them with
// Pvs::neighbours(cell, radius), then this test). radius >= 0.
bool disc_inside_box(const Point3& c, double radius, const double lo[3], const double hi[3]);
bool disc_touches_box(const Point3& c, double radius, const double lo[3], const double hi[3]);

}  // namespace pvs_runtime
