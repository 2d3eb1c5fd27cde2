// discontinuity.h: the near-far paper's image discontinuity metric delta (near-far-partitioning.txt
// §5, Eqs. 6-8), which PSNR and SSIM cannot give: they assume an identity mapping between the truth
// and the processed image, so they favour a frame whose far region is displaced in one piece (the
// conventional, discontinuous partition) over one that is morphed continuously (Fig. 8, 9).
//
// For a processed image I (a near-far frame) and the ground-truth camera Pi_0 (the same camera,
// rendering the full scene), every pixel p of I that shows a surface has an original 3D point
// Pi^-1(p): the scene point it stands for (before the Eq. 1 morph, or the point the environment map
// shows; render_near_far's PixelSources). Its truth position is t(p) = Pi_0(Pi^-1(p)), in pixel
// units. Then (Eq. 8) N_p = { q != p : |t(q) - t(p)| < radius } and (Eq. 7)
//   delta(p) = (1 / |N_p|) sum_{q in N_p} |p - q| / |t(p) - t(q)|  -  1,
// with p, q the pixel positions in I (column, row). The ground truth itself has t(p) = p, hence
// delta = 0 everywhere; a region displaced away from its neighbours in I, whose truth positions are
// near, gives large ratios. Pixels without a point, without a neighbour (N_p empty), or whose point
// lies behind the camera (no truth position) have no delta; pairs q with t(q) = t(p) exactly (a
// ratio of infinity) are left out of N_p and counted (`coincident_pairs`).
//
// The paper's figures use radius = 17 pixels (Fig. 9). It does not say how the per-pixel values
// are summarised over an image (Fig. 10 shows the map); we report the mean over the pixels that
// have a delta, the mean of |delta| (a compressed region, delta < 0, does not cancel a torn one),
// the maximum, and the share of those pixels with delta above 0.5.
#pragma once
#include <array>
#include <cstddef>
#include <optional>
#include <vector>

#include "vislib/base/vec.h"
#include "vislib/eval/render.h"

namespace vislib {

// The paper's neighbourhood radius epsilon of Eq. 8, in pixels (Fig. 9).
constexpr double kDiscontinuityRadius = 17.0;

// The position (column, row) of world point `point` in `camera`'s image, in pixels, continuous:
// camera_project's (render.h), the exact inverse of camera_ray, so the centre of pixel (x, y) maps
// to (x, y) up to rounding. nullopt when the point is not in front of the camera (view depth <= 0)
// or not finite.
std::optional<std::array<double, 2>> project_to_pixel(const Camera& camera, Vec3 point);

struct Discontinuity {
  // delta(p) per pixel, row-major (width * height); NaN where it is undefined (see above).
  std::vector<double> delta;
  size_t pixels = 0;            // pixels with a delta
  double mean = 0;              // mean delta over them (0 when none); delta < 0 where the frame
                                // compresses what the truth shows (ratios below 1)
  double mean_abs = 0;          // mean |delta| over them (compression and tearing both count)
  double max = 0;               // largest delta (0 when none)
  double share_above_half = 0;  // share of them with delta > 0.5
  size_t coincident_pairs = 0;  // (p, q) pairs left out because t(p) = t(q) exactly
};

// Eqs. 7-8 on truth positions: `truth_xy` holds 2 doubles per pixel of a width x height image
// (row-major), NaN (either) for a pixel without one. radius > 0. Deterministic, independent of the
// thread count (TBB over rows, one slot per pixel, the summaries reduced in pixel order).
// Cost: O(pixels x pixels in a radius-disc); about 900 neighbours per pixel at radius 17.
Discontinuity discontinuity(int width, int height, const std::vector<double>& truth_xy,
                            double radius = kDiscontinuityRadius);

// The same from each pixel's original 3D point (NaN for none; width * height points) and the
// ground-truth camera: truth positions by project_to_pixel.
Discontinuity frame_discontinuity(const Camera& truth_camera, const std::vector<Vec3>& points,
                                  double radius = kDiscontinuityRadius);

}  // namespace vislib
