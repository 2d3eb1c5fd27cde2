// render.h: the Embree reference renderer of the frame-quality metrics (paper §4.3): perspective
// frames of the full scene (ground truth) or of a visible set, with colour, depth and triangle id
// per pixel.
//
// Camera convention. f = forward/|forward|, r = (f x up)/|f x up|, u = r x f. Pixel (x, y) of a
// W x H frame (x = column from the left, y = row from the top, row-major index y*W + x) looks
// along the pixel centre
//   d = f + sx*r + sy*u,  sx = ((2x+1)/W - 1 + shift_x) * tan(vfov/2) * W/H,
//   sy = (1 - (2y+1)/H + shift_y) * tan(vfov/2)   (shift_x = shift_y = 0 unless off-axis)
// (not normalised: f.d = 1, so Embree's hit distance along d is the view depth, as in cubemap.h).
// A hit counts at view depth > z_near (a rasteriser's near plane).
//
// Shading (plain and readable, not physically based): an object colour drawn from a hash of the
// object id (object_colour) times
//   shade = kRenderAmbient + (1 - kRenderAmbient) * max(|n.v|, kRenderSky * |n.y|)
// with n the unit geometric normal of the triangle and v the unit ray direction: a two-sided
// headlight, and light from above (+y) so that floors and roofs seen at a grazing angle (a street
// from eye height) keep most of their colour; a surface facing the eye shows its colour exactly.
// Each channel is rounded to 8 bits. Pixels that hit nothing get kRenderBackground.
//
// Subset frames: render_frame with an `allowed` mask casts the same rays through the same BVH with
// an intersect filter (EmbreeScene::first_hits_among), so a pixel whose full-scene first hit is
// allowed gets exactly the full frame's triangle, depth and colour; other pixels show whatever
// allowed surface lies behind, or the background.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "vislib/base/tolerances.h"
#include "vislib/base/vec.h"
#include "vislib/eval/embree_scene.h"
#include "vislib/scene/scene.h"

namespace vislib {

// Light not from the headlight: the share of the object colour a surface seen edge-on keeps.
constexpr double kRenderAmbient = 0.35;
// Light from above: a horizontal surface is lit at least as if seen at |n.v| = kRenderSky.
constexpr double kRenderSky = 0.6;
// RGB of pixels that hit no triangle.
constexpr std::array<uint8_t, 3> kRenderBackground = {150, 170, 195};

struct Camera {
  Vec3 eye;                       // world position
  Vec3 forward{0, 0, -1};         // view direction; must be finite and non-zero
  Vec3 up{0, 1, 0};               // must not be parallel to forward
  double vfov_degrees = 90;       // vertical field of view, in (0, 180)
  int width = 640, height = 480;  // pixels, each >= 1
  double z_near = kDefaultNear;   // near plane: view depth (scene units), > 0
  // Off-axis (asymmetric) frustum: the image window is moved by shift_x half-widths to the right
  // and shift_y half-heights up (sx and sy below gain + shift_x * tan(vfov/2) * W/H and
  // + shift_y * tan(vfov/2)). 0 = the symmetric frustum. Finite.
  double shift_x = 0, shift_y = 0;
};

// One rendered frame. Vectors are row-major from the top-left pixel.
struct Frame {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;   // 3 bytes per pixel
  std::vector<float> depth;   // range |hit - eye| in scene units; +inf where nothing is hit
  std::vector<uint32_t> tri;  // triangle id, or kNoHit
  size_t pixel_count() const { return size_t(width) * size_t(height); }
};

// The camera's frame of the convention above: the unit vectors f, r, u and the image-window
// scales sx_scale = tan(vfov/2) * W/H, sy_scale = tan(vfov/2). Every pixel ray and projection of
// vislib is computed from it, so a frame computed once serves a whole image.
struct CameraBasis {
  Vec3 f, r, u;
  double sx_scale = 0, sy_scale = 0;
};
// `camera` must satisfy the Camera preconditions.
CameraBasis camera_basis(const Camera& camera);

// The un-normalised direction d of pixel (x, y) (see the convention above); world coordinates.
// `camera` must satisfy the Camera preconditions; 0 <= x < width, 0 <= y < height.
Vec3 camera_ray(const Camera& camera, int x, int y);
// The same from basis = camera_basis(camera) (bit-identical); x and y may lie outside the image.
Vec3 camera_ray(const CameraBasis& basis, const Camera& camera, int x, int y);

// Where a world point appears in a camera: continuous pixel coordinates (pixel (x, y)'s centre is
// at exactly (x, y); the image covers [-0.5, W-0.5) x [-0.5, H-0.5)) and its view depth (distance
// along the unit forward axis). nullopt when the point is not in front of the camera
// (view depth <= 0). The exact inverse of camera_ray, off-axis shift included.
struct PixelPosition {
  double x = 0, y = 0;
  double view_depth = 0;
};
std::optional<PixelPosition> camera_project(const Camera& camera, Vec3 world);
// The same for a point at infinity in direction `dir` (non-zero): view_depth is +inf.
std::optional<PixelPosition> camera_project_direction(const Camera& camera, Vec3 dir);
// The same two from basis = camera_basis(camera) (bit-identical).
std::optional<PixelPosition> camera_project(const CameraBasis& basis, const Camera& camera,
                                            Vec3 world);
std::optional<PixelPosition> camera_project_direction(const CameraBasis& basis,
                                                      const Camera& camera, Vec3 dir);
// True when a PixelPosition lies in the image of `camera`.
bool in_image(const Camera& camera, const PixelPosition& p);

// The colour of object `object`: hue, saturation in [0.45, 0.8] and value in [0.65, 1] from a
// SplitMix64 hash of the id. Same id, same colour on every platform.
std::array<uint8_t, 3> object_colour(uint32_t object);

// render_frame's colour of triangle `tri` (< triangle_count) seen along `dir` (non-zero; the
// un-normalised pixel direction): object_colour times the shade above, with the normal from key
// state 0. Thread-safe.
std::array<uint8_t, 3> shade_triangle(const Scene& scene, uint32_t tri, Vec3 dir);

// Renders `scene` through `rt`, which must have been built from `scene` at tau = 0 (normals are
// taken from key state 0). `allowed`: null renders every triangle; else it must hold
// scene.triangle_count() bytes and only triangles t with allowed[t] != 0 are rendered.
// TBB-parallel over rows; every pixel is written by one task, so the frame is identical for any
// thread count. Thread-safe.
Frame render_frame(const Scene& scene, const EmbreeScene& rt, const Camera& camera,
                   const uint8_t* allowed = nullptr);

// A per-triangle mask for render_frame: 1 for the ids in `ids` (each < triangle_count), else 0.
std::vector<uint8_t> triangle_mask(size_t triangle_count, const std::vector<uint32_t>& ids);

}  // namespace vislib
