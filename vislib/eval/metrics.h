// metrics.h: frame quality of a visible set against ground truth (paper §4.3) and set comparison.
//
// All frame metrics compare a frame rendered from a visible set (`test`) with the ground-truth
// frame of the full scene from the same camera (`truth`); both must have the same size.
//  - Pixel error epsilon: the share of pixels whose depth in `test` is farther than in `truth`
//    (by more than kPixelErrorDepthTolerance relative to the truth depth; +inf = background), i.e.
//    the triangle visible there was missed by the set. Reported as a fraction in [0, 1] (the
//    paper prints it in percent).
//  - PSNR over RGB: 10 log10(255^2 / MSE), MSE the mean squared difference of all 3*W*H 8-bit
//    channel values; +inf for identical colours.
//  - SSIM (Wang, Bovik, Sheikh, Simoncelli 2004, as their reference ssim_index.m): on luminance
//    Y = 0.299 R + 0.587 G + 0.114 B (Rec. 601, 8-bit scale, not rounded), 11 x 11 Gaussian
//    window with sigma = 1.5 normalised to sum 1, K1 = 0.01, K2 = 0.03, L = 255
//    (C1 = (K1 L)^2, C2 = (K2 L)^2), local statistics mu, sigma^2 and sigma_xy as weighted means
//    over the window, evaluated at every position where the window lies inside the image ("valid"
//    filtering: (W-10) x (H-10) positions, no padding, no downsampling), averaged uniformly.
//    Identical images give exactly 1.
// Every function is deterministic and thread-safe; ssim_luminance is TBB-parallel over rows with
// a fixed-order reduction (same result for any thread count).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "vislib/eval/render.h"

namespace vislib {

// SSIM parameters (see above).
constexpr int kSsimWindow = 11;
constexpr double kSsimSigma = 1.5;
constexpr double kSsimK1 = 0.01, kSsimK2 = 0.03;

// 1 where the pixel of `test` is missed (see epsilon above), else 0; W*H entries.
std::vector<uint8_t> missed_pixels(const Frame& truth, const Frame& test);

// Pixel error epsilon in [0, 1]: the share of missed pixels.
double pixel_error(const Frame& truth, const Frame& test);

// Mean squared error over the 8-bit channel values of two equally long RGB buffers (non-empty).
double mse_rgb(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b);

// PSNR in dB of two equally long RGB buffers; +inf when they are identical.
double psnr_rgb(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b);

// Mean SSIM of the luminance of two width x height RGB images (3 bytes per pixel, row-major).
// width and height must be >= kSsimWindow.
double ssim_luminance(int width, int height, const std::vector<uint8_t>& a_rgb,
                      const std::vector<uint8_t>& b_rgb);

// SSIM of the luminance with one window equal to the whole image, uniform weights (as CloVR's
// visual-continuity metric, "a window size equal to the entire image"): the SSIM formula above
// with mu, sigma^2 and sigma_xy the population statistics of all W*H pixels. Identical images give
// exactly 1. width, height >= 1.
double ssim_whole_image(int width, int height, const std::vector<uint8_t>& a_rgb,
                        const std::vector<uint8_t>& b_rgb);

struct FrameQuality {
  size_t pixels = 0;         // W*H
  size_t missed_pixels = 0;  // pixels counted by epsilon
  double epsilon = 0;        // missed_pixels / pixels
  double mse = 0;            // RGB mean squared error
  double psnr = 0;           // dB; +inf when the colours are identical
  double ssim = 1;           // mean SSIM of luminance
};

// All of the above for one pair of frames (same size, each side >= kSsimWindow).
FrameQuality frame_quality(const Frame& truth, const Frame& test);

// A visible set against a reference set (both sorted unique triangle ids).
struct SetComparison {
  size_t size = 0;            // |set|
  size_t reference_size = 0;  // |reference|
  size_t common = 0;          // |set ∩ reference|
  size_t missed = 0;          // |reference \ set|: reference triangles the set lacks
  size_t extra = 0;           // |set \ reference|: set triangles not in the reference
};
SetComparison compare_sets(const std::vector<uint32_t>& set,
                           const std::vector<uint32_t>& reference);

// An error heat map: RGB image of `frame`'s size with the pixels where `missed` is non-zero in
// pure red (255, 0, 0) and every other pixel darkened to 30% of frame.rgb (floor(0.3 v), so at
// most 76 per channel: red marks the missed pixels and nothing else). `missed` must hold W*H.
std::vector<uint8_t> error_heat_map(const Frame& frame, const std::vector<uint8_t>& missed);

}  // namespace vislib
