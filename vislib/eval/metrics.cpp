// metrics.cpp: frame-quality metrics of paper §4.3 (epsilon, PSNR, SSIM) and set comparison.
// SSIM follows Wang et al., "Image quality assessment: from error visibility to structural
// similarity", IEEE TIP 13(4), 2004, and their reference implementation ssim_index.m.
#include "vislib/eval/metrics.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <limits>

namespace vislib {

std::vector<uint8_t> missed_pixels(const Frame& truth, const Frame& test) {
  assert(truth.width == test.width && truth.height == test.height);
  const size_t n = truth.pixel_count();
  assert(truth.depth.size() == n && test.depth.size() == n);
  std::vector<uint8_t> missed(n, 0);
  for (size_t p = 0; p < n; ++p) {
    const double t = truth.depth[p], s = test.depth[p];
    if (std::isinf(t)) continue;  // background in truth: a subset cannot miss anything there
    missed[p] = s > t * (1.0 + kPixelErrorDepthTolerance) ? 1 : 0;
  }
  return missed;
}

double pixel_error(const Frame& truth, const Frame& test) {
  const auto m = missed_pixels(truth, test);
  size_t count = 0;
  for (uint8_t v : m) count += v;
  return m.empty() ? 0.0 : double(count) / double(m.size());
}

double mse_rgb(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
  assert(a.size() == b.size() && !a.empty());
  uint64_t sum = 0;  // exact integer sum
  for (size_t i = 0; i < a.size(); ++i) {
    const int64_t d = int64_t(a[i]) - int64_t(b[i]);
    sum += uint64_t(d * d);
  }
  return double(sum) / double(a.size());
}

double psnr_rgb(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
  const double mse = mse_rgb(a, b);
  if (mse == 0) return std::numeric_limits<double>::infinity();
  return 10.0 * std::log10(255.0 * 255.0 / mse);
}

namespace {

std::vector<double> luminance(const std::vector<uint8_t>& rgb, size_t n) {
  std::vector<double> y(n);
  for (size_t p = 0; p < n; ++p)
    y[p] = 0.299 * rgb[3 * p] + 0.587 * rgb[3 * p + 1] + 0.114 * rgb[3 * p + 2];
  return y;
}

// The normalised 1D Gaussian; the 2D window is its outer product (which then sums to 1 too).
std::array<double, kSsimWindow> gaussian_1d() {
  std::array<double, kSsimWindow> g;
  double sum = 0;
  const int r = kSsimWindow / 2;
  for (int i = 0; i < kSsimWindow; ++i) {
    const double d = double(i - r);
    g[size_t(i)] = std::exp(-d * d / (2.0 * kSsimSigma * kSsimSigma));
    sum += g[size_t(i)];
  }
  for (double& v : g) v /= sum;
  return g;
}

}  // namespace

double ssim_whole_image(int width, int height, const std::vector<uint8_t>& a_rgb,
                        const std::vector<uint8_t>& b_rgb) {
  assert(width >= 1 && height >= 1);
  const size_t n = size_t(width) * size_t(height);
  assert(a_rgb.size() == 3 * n && b_rgb.size() == 3 * n);
  if (a_rgb == b_rgb) return 1.0;
  const std::vector<double> x = luminance(a_rgb, n), y = luminance(b_rgb, n);
  double mx = 0, my = 0;
  for (size_t i = 0; i < n; ++i) mx += x[i], my += y[i];
  mx /= double(n), my /= double(n);
  double vx = 0, vy = 0, cxy = 0;  // two-pass: no cancellation
  for (size_t i = 0; i < n; ++i) {
    const double dx = x[i] - mx, dy = y[i] - my;
    vx += dx * dx, vy += dy * dy, cxy += dx * dy;
  }
  vx /= double(n), vy /= double(n), cxy /= double(n);
  const double c1 = (kSsimK1 * 255.0) * (kSsimK1 * 255.0);
  const double c2 = (kSsimK2 * 255.0) * (kSsimK2 * 255.0);
  return ((2.0 * mx * my + c1) * (2.0 * cxy + c2)) / ((mx * mx + my * my + c1) * (vx + vy + c2));
}

double ssim_luminance(int width, int height, const std::vector<uint8_t>& a_rgb,
                      const std::vector<uint8_t>& b_rgb) {
  assert(width >= kSsimWindow && height >= kSsimWindow);
  const size_t w = size_t(width), h = size_t(height), n = w * h;
  assert(a_rgb.size() == 3 * n && b_rgb.size() == 3 * n);
  const std::vector<double> x = luminance(a_rgb, n), y = luminance(b_rgb, n);
  const auto g = gaussian_1d();
  const size_t win = kSsimWindow, ow = w - win + 1, oh = h - win + 1;
  // Horizontal pass: for each image row and valid column, the weighted sums of x, y, x^2, y^2, xy.
  std::vector<double> hx(h * ow), hy(h * ow), hxx(h * ow), hyy(h * ow), hxy(h * ow);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, h), [&](const tbb::blocked_range<size_t>& rows) {
    for (size_t r = rows.begin(); r != rows.end(); ++r)
      for (size_t c = 0; c < ow; ++c) {
        double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
        for (size_t k = 0; k < win; ++k) {
          const double a = x[r * w + c + k], b = y[r * w + c + k], gk = g[k];
          sx += gk * a, sy += gk * b, sxx += gk * (a * a), syy += gk * (b * b), sxy += gk * (a * b);
        }
        const size_t o = r * ow + c;
        hx[o] = sx, hy[o] = sy, hxx[o] = sxx, hyy[o] = syy, hxy[o] = sxy;
      }
  });
  const double c1 = (kSsimK1 * 255.0) * (kSsimK1 * 255.0);
  const double c2 = (kSsimK2 * 255.0) * (kSsimK2 * 255.0);
  // Vertical pass and the SSIM map, summed per output row; rows are added in order afterwards.
  std::vector<double> row_sum(oh, 0.0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, oh), [&](const tbb::blocked_range<size_t>& rows) {
    for (size_t r = rows.begin(); r != rows.end(); ++r) {
      double total = 0;
      for (size_t c = 0; c < ow; ++c) {
        double mx = 0, my = 0, exx = 0, eyy = 0, exy = 0;
        for (size_t k = 0; k < win; ++k) {
          const size_t o = (r + k) * ow + c;
          const double gk = g[k];
          mx += gk * hx[o], my += gk * hy[o], exx += gk * hxx[o], eyy += gk * hyy[o],
              exy += gk * hxy[o];
        }
        const double vx = exx - mx * mx, vy = eyy - my * my, cxy = exy - mx * my;
        total +=
            ((2.0 * mx * my + c1) * (2.0 * cxy + c2)) / ((mx * mx + my * my + c1) * (vx + vy + c2));
      }
      row_sum[r] = total;
    }
  });
  double sum = 0;
  for (double v : row_sum) sum += v;
  return sum / double(ow * oh);
}

FrameQuality frame_quality(const Frame& truth, const Frame& test) {
  FrameQuality q;
  q.pixels = truth.pixel_count();
  for (uint8_t v : missed_pixels(truth, test)) q.missed_pixels += v;
  q.epsilon = q.pixels ? double(q.missed_pixels) / double(q.pixels) : 0.0;
  q.mse = mse_rgb(truth.rgb, test.rgb);
  q.psnr = q.mse == 0 ? std::numeric_limits<double>::infinity()
                      : 10.0 * std::log10(255.0 * 255.0 / q.mse);
  q.ssim = ssim_luminance(truth.width, truth.height, truth.rgb, test.rgb);
  return q;
}

SetComparison compare_sets(const std::vector<uint32_t>& set,
                           const std::vector<uint32_t>& reference) {
  assert(std::is_sorted(set.begin(), set.end()) &&
         std::is_sorted(reference.begin(), reference.end()));
  SetComparison c;
  c.size = set.size();
  c.reference_size = reference.size();
  size_t i = 0, j = 0;
  while (i < set.size() && j < reference.size()) {
    if (set[i] < reference[j])
      ++i;
    else if (reference[j] < set[i])
      ++j;
    else
      ++c.common, ++i, ++j;
  }
  c.missed = c.reference_size - c.common;
  c.extra = c.size - c.common;
  return c;
}

std::vector<uint8_t> error_heat_map(const Frame& frame, const std::vector<uint8_t>& missed) {
  const size_t n = frame.pixel_count();
  assert(missed.size() == n && frame.rgb.size() == 3 * n);
  std::vector<uint8_t> out(3 * n);
  for (size_t p = 0; p < n; ++p) {
    if (missed[p]) {
      out[3 * p] = 255, out[3 * p + 1] = 0, out[3 * p + 2] = 0;
      continue;
    }
    for (size_t k = 0; k < 3; ++k) out[3 * p + k] = uint8_t(frame.rgb[3 * p + k] * 3 / 10);
  }
  return out;
}

}  // namespace vislib
