// stereo.h: single-render stereo by reprojection: render one eye, build the other eye
// by moving every pixel to where its world point projects in the other eye, then fill the holes.
//
// Paper: ../shared/papers/yoro-single-render-stereo.txt (YORO, MobiSys '25) §5-7, Alg. 1-3,
// Eq. 6, with the errors listed in docs/stereo.md fixed:
//  - No matrices (the paper's Eq. 1-5 are inconsistent: V is singular, Eq. 3 is orthographic):
//    a source pixel with range r becomes the world point P = eye + r * d/|d| (d = camera_ray) and
//    is projected into the target camera with the full perspective divide (camera_project), so
//    any pair of cameras works: parallel, canted (toe-in), asymmetric (off-axis) frusta, other
//    resolutions. Pixels may then move in +x, -x and y.
//  - Splatting (reproject, Splatting::Exact): each source sample goes to the target pixel whose
//    centre is nearest its projected position; per target pixel the sample with the smallest
//    target view depth wins (ties: the smaller source index). A pixel nothing lands on stays a
//    hole: nothing is written into holes, so a background sample landing in a gap is never
//    rejected ("holes not poisoned"; Alg. 2 as printed writes the foreground's depth there).
//    Background (sky) samples are points at infinity: their direction is reprojected.
//  - Alg. 2 as printed (Splatting::Alg2AsPrinted, for measuring its defect) is offered for
//    parallel eyes with identical projections only (its scan assumes rows stay rows).
//
// Holes are classified (HoleKind): Crack (a one-pixel gap between two samples of one surface:
// row or column neighbours both filled, from source pixels at most kStereoCrackSourceSpan apart
// with view depths within kStereoSurfaceDepthRatio), OutsideView (the pixel's ray, at the range of
// the farther filled pixel ending its hole run in the row, projects outside the source image),
// Disocclusion (the rest: surface hidden from the source eye).
//
// Determinism: reproject and every patcher are TBB-parallel over target rows and write one slot
// per pixel; splat winners are chosen by a total order (depth, source index), so every output is
// identical for any thread count. All functions are thread-safe.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <vector>

#include "vislib/base/vec.h"
#include "vislib/eval/embree_scene.h"
#include "vislib/eval/render.h"
#include "vislib/scene/scene.h"

namespace vislib {

// Two filled neighbours of a one-pixel hole are one surface when their source pixels are at most
// this many pixels apart (Chebyshev distance in the source image) ...
constexpr int kStereoCrackSourceSpan = 2;
// ... and their target view depths differ by at most this factor (farther / nearer). Also the
// factor by which a kernel sample must be nearer than a hole's background edge to be skipped as
// foreground by the yoro patcher (Observation O2).
constexpr double kStereoSurfaceDepthRatio = 1.05;
// Colour written into unpatched holes (Patcher::None): pure black, which no shaded pixel of
// render_frame has (the ambient term keeps every channel of a lit colour >= 0.1 * 0.65 * 255).
constexpr std::array<uint8_t, 3> kStereoHoleColour = {0, 0, 0};

enum class HoleKind : uint8_t { Filled = 0, Disocclusion = 1, Crack = 2, OutsideView = 3 };
enum class Splatting : uint8_t { Exact = 0, Alg2AsPrinted = 1 };

// The eye cameras of a head at `centre` (its eye is the point between the eyes): both copy
// `centre` and are moved by -/+ ipd/2 along the camera's right vector r = normalize(forward x up).
// `toe_in_degrees` > 0 cants each eye inward by that angle about the up vector (converging);
// `shift` sets an off-axis frustum per eye (left eye Camera::shift_x = +shift, right eye -shift,
// i.e. both image windows moved toward the nose when shift > 0). ipd >= 0.
struct StereoPair {
  Camera left, right;
};
StereoPair stereo_pair(const Camera& centre, double ipd, double toe_in_degrees = 0,
                       double shift = 0);

// The second eye built from the first.
struct Reprojection {
  int width = 0, height = 0;
  std::vector<uint8_t>
      rgb;  // 3 per pixel: the source colour (source eye's shading); kStereoHoleColour at holes
  std::vector<float> depth;      // range |P - target eye|; +inf at background and holes
  std::vector<uint32_t> tri;     // triangle id; kNoHit at background and holes
  std::vector<uint32_t> source;  // source pixel index (y*W + x); kNoSource at holes
  std::vector<HoleKind> hole;    // Filled where a sample landed
  size_t pixel_count() const { return size_t(width) * size_t(height); }
  size_t count(HoleKind kind) const;
  size_t holes() const { return pixel_count() - count(HoleKind::Filled); }
};
constexpr uint32_t kNoSource = 0xFFFFFFFFu;

// Reprojects `source` (rendered by render_frame through `source_camera`: rgb, range, tri) into
// `target_camera` (any size, any pose, any off-axis shift). With Splatting::Alg2AsPrinted the two
// cameras must differ only by an eye offset along the common right vector (same forward, up,
// vfov, size, shift, near plane), else std::invalid_argument is thrown; its scan runs in the
// direction pixels move (left to right for a target eye left of the source, the paper's case; the
// mirror image otherwise) and its depth test uses reversed Z (1 / view depth, 0 for background;
// the buffer starts below every depth so that background can land). Holes are classified (see the
// top of this file) in both modes.
Reprojection reproject(const Frame& source, const Camera& source_camera,
                       const Camera& target_camera, Splatting splatting = Splatting::Exact);

// Hole fillers. Each returns a full Frame of the target eye (rgb, range, tri) that equals the
// reprojection at filled pixels; `patched` (if not null) receives how many holes it filled.
//  - patch_none: holes keep kStereoHoleColour, range +inf, tri kNoHit.
//  - patch_median: repeated passes (at most 64); per pass every hole with a filled pixel in its
//    5 x 5 window takes the whole pixel (colour, range, tri) of the median of those pixels ordered
//    by luminance (ties: lower index); holes filled in a pass count as filled in the next.
//  - patch_yoro: Alg. 3 with Eq. 6, fixed (docs/stereo.md): per hole pixel u of a hole run [a, b]
//    in its row, the background edge e is whichever of a-1, b+1 is filled and farther (the only
//    one at the image border); the kernel is w = b - a + 1 columns wide starting at e and running
//    away from the hole, 3 rows (v-1, v, v+1) high; it is walked from e outward (nearest column
//    first); samples nearer than the edge by more than kStereoSurfaceDepthRatio (foreground) and
//    holes are skipped; a column's colour is the mean of its kept samples and gets the weight
//    W = w_rem * (1/2 + 0.3 t), t = |u - e| / w in (0, 1] (Eq. 6 with pixel units on both sides);
//    the result is sum / (1 - w_rem). tri and range come from the first kept sample. A hole run
//    without a filled end (a whole empty row) or with no kept sample is left to patch_median.
//    `as_printed` walks the kernel from the far end instead (the paper's order) and uses 1 row.
//  - patch_rays: re-casts the hole pixels of the target camera through `rt` among the `allowed`
//    triangles (render_frame's rays and shading: the same pixels as render_frame(scene, rt,
//    target, allowed) up to Embree's marginal-ray caveat of EmbreeScene::first_hits); `rays`
//    receives the number of rays cast.
Frame patch_none(const Reprojection& r, size_t* patched = nullptr);
Frame patch_median(const Reprojection& r, size_t* patched = nullptr);
Frame patch_yoro(const Reprojection& r, bool as_printed = false, size_t* patched = nullptr);
Frame patch_rays(const Reprojection& r, const Scene& scene, const EmbreeScene& rt,
                 const Camera& target, const uint8_t* allowed, size_t* rays = nullptr);

// Eq. 6's weights for a hole pixel at fraction t in (0, 1] of its hole and a kernel of `width`
// >= 1 columns, all kept: element k is the weight W = w_rem (1/2 + 0.3 t) of the k-th sample
// visited (w_rem starts at 1), divided by their sum 1 - w_rem (the normalisation of Alg. 3
// line 15). The fixed patcher visits the column next to the hole first; the printed one the far
// end, which so gets element 0: between 52% and 80% of the weight for width >= 5.
std::vector<double> yoro_kernel_weights(int width, double t);

// --reshade: recomputes, in place, what render_frame would show from the target eye at the pixels
// the reprojection filled and at its cracks, from triangle ids (run it before a patcher): each
// such pixel's ray (camera_ray of `target`) is intersected exactly (double, two-sided) with the
// triangles of the filled pixels of its 3 x 3 neighbourhood in `r`; the nearest hit beyond
// target.z_near gives tri, range and render_frame's shading for this eye (shade_triangle).
//  - A crack whose ray hits a candidate becomes Filled (source: the neighbour that supplied the
//    triangle); else it stays a crack.
//  - A filled pixel whose ray hits no candidate, its own triangle included, shows a surface the
//    splat got wrong (a sample rounded across a silhouette or into a newly visible face): it
//    becomes a Disocclusion hole (source kNoSource, hole colour) for the patcher. Background
//    pixels whose ray hits no candidate stay background.
// `target` must be the camera `r` was reprojected into. Thread-safe, deterministic.
struct ReshadeStats {
  size_t cracks_resolved = 0;  // cracks that became Filled
  size_t unresolved = 0;       // filled pixels that became holes
};
ReshadeStats reshade(Reprojection& r, const Scene& scene, const Camera& target);

// An RGB picture of the hole mask over a darkened frame: Filled pixels at 30% of frame.rgb,
// Disocclusion red (255, 0, 0), Crack yellow (255, 255, 0), OutsideView blue (0, 96, 255).
std::vector<uint8_t> hole_mask_image(const Frame& frame, const std::vector<HoleKind>& hole);

// Two equally sized RGB images side by side (left | right): (2W) x H.
std::vector<uint8_t> side_by_side(int width, int height, const std::vector<uint8_t>& left,
                                  const std::vector<uint8_t>& right);

}  // namespace vislib
