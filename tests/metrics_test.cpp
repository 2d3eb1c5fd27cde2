// Tests of vislib/eval/metrics.h against hand-computed values on tiny images.
#include "vislib/eval/metrics.h"

#include <gtest/gtest.h>

#include <cmath>

#include "vislib/base/random.h"

using namespace vislib;

namespace {

std::vector<uint8_t> random_rgb(int w, int h, uint64_t seed) {
  Rng rng(seed);
  std::vector<uint8_t> v(3 * size_t(w) * size_t(h));
  for (auto& c : v) c = uint8_t(rng.below(256));
  return v;
}

// A frame of constant depth `depth` everywhere and random colours.
Frame flat_frame(int w, int h, float depth, uint64_t seed) {
  Frame f;
  f.width = w, f.height = h;
  f.rgb = random_rgb(w, h, seed);
  f.depth.assign(size_t(w) * size_t(h), depth);
  f.tri.assign(size_t(w) * size_t(h), 0);
  return f;
}

}  // namespace

TEST(Metrics, SsimOfIdenticalImagesIsExactlyOne) {
  const auto a = random_rgb(32, 24, 1);
  EXPECT_EQ(ssim_luminance(32, 24, a, a), 1.0);
  const auto b = random_rgb(11, 11, 2);  // a single window position
  EXPECT_EQ(ssim_luminance(11, 11, b, b), 1.0);
}

TEST(Metrics, SsimOfTwoConstantImagesIsTheLuminanceTerm) {
  // Constant images: sigma = 0 in every window, so SSIM = (2 mx my + C1) / (mx^2 + my^2 + C1).
  const int w = 20, h = 15;
  std::vector<uint8_t> a(3 * w * h, 100), b(3 * w * h, 150);
  const double c1 = (0.01 * 255) * (0.01 * 255);
  // Y = (0.299 + 0.587 + 0.114) v = v up to rounding of the weights.
  const double expected = (2.0 * 100 * 150 + c1) / (100.0 * 100 + 150.0 * 150 + c1);
  EXPECT_NEAR(ssim_luminance(w, h, a, b), expected, 1e-12);
  EXPECT_NEAR(ssim_luminance(w, h, b, a), expected, 1e-12);
}

TEST(Metrics, SsimOfAStructuralChangeIsBelowOneAndSymmetric) {
  const auto a = random_rgb(40, 30, 3);
  auto b = a;
  for (size_t i = 0; i < b.size(); i += 7) b[i] = uint8_t(255 - b[i]);
  const double s = ssim_luminance(40, 30, a, b);
  EXPECT_LT(s, 0.99);
  EXPECT_GT(s, -1.0);
  EXPECT_DOUBLE_EQ(s, ssim_luminance(40, 30, b, a));
}

TEST(Metrics, PsnrOfAKnownError) {
  const auto a = random_rgb(16, 16, 4);
  auto b = a;
  for (auto& c : b) c = uint8_t(c < 128 ? c + 10 : c - 10);  // |error| = 10 on every channel
  EXPECT_DOUBLE_EQ(mse_rgb(a, b), 100.0);
  EXPECT_NEAR(psnr_rgb(a, b), 10 * std::log10(255.0 * 255.0 / 100.0), 1e-12);  // 28.13 dB
  auto c = a;
  c[5] = uint8_t(c[5] ^ 0x80);  // one channel of one pixel off by 128
  EXPECT_DOUBLE_EQ(mse_rgb(a, c), 128.0 * 128.0 / (3 * 256));
  EXPECT_TRUE(std::isinf(psnr_rgb(a, a)));
}

TEST(Metrics, PixelErrorCountsOnlyFartherDepthsBeyondTheTolerance) {
  Frame truth = flat_frame(4, 4, 10.0f, 5), test = truth;
  truth.depth[15] = INFINITY;  // background in truth
  test.depth[0] = 12.0f;       // the visible triangle was missed: a surface behind shows
  test.depth[1] = INFINITY;    // missed, nothing behind: background
  test.depth[2] = 8.0f;        // nearer (cannot happen for a subset, but is not a miss)
  test.depth[3] = float(10.0 * (1 + 0.5 * kPixelErrorDepthTolerance));  // within tolerance
  test.depth[4] = float(10.0 * (1 + 2.0 * kPixelErrorDepthTolerance));  // beyond tolerance
  test.depth[15] = INFINITY;                                            // background in both
  const auto m = missed_pixels(truth, test);
  std::vector<uint8_t> expected(16, 0);
  expected[0] = expected[1] = expected[4] = 1;
  EXPECT_EQ(m, expected);
  EXPECT_DOUBLE_EQ(pixel_error(truth, test), 3.0 / 16.0);
}

TEST(Metrics, FrameQualityOfAConstructedMiss) {
  const int w = 16, h = 12;
  Frame truth = flat_frame(w, h, 5.0f, 6), test = truth;
  // Four missed pixels show a far surface in another colour.
  for (size_t p : {0u, 17u, 40u, 191u}) {
    test.depth[p] = 50.0f;
    test.rgb[3 * p] = uint8_t(test.rgb[3 * p] ^ 0xFF);
  }
  const FrameQuality q = frame_quality(truth, test);
  EXPECT_EQ(q.pixels, size_t(w * h));
  EXPECT_EQ(q.missed_pixels, 4u);
  EXPECT_DOUBLE_EQ(q.epsilon, 4.0 / (w * h));
  EXPECT_DOUBLE_EQ(q.psnr, psnr_rgb(truth.rgb, test.rgb));
  EXPECT_LT(q.ssim, 1.0);
  const FrameQuality same = frame_quality(truth, truth);
  EXPECT_EQ(same.missed_pixels, 0u);
  EXPECT_TRUE(std::isinf(same.psnr));
  EXPECT_EQ(same.ssim, 1.0);
}

TEST(Metrics, HeatMapMarksExactlyTheMissedPixels) {
  const int w = 23, h = 17;
  Frame f = flat_frame(w, h, 1.0f, 7);
  f.rgb[0] = 255, f.rgb[1] = 0, f.rgb[2] = 0;  // a red pixel in the frame itself, not missed
  Rng rng(8);
  std::vector<uint8_t> missed(size_t(w * h));
  for (auto& m : missed) m = rng.uniform() < 0.2 ? 1 : 0;
  missed[0] = 0;
  const auto heat = error_heat_map(f, missed);
  ASSERT_EQ(heat.size(), f.rgb.size());
  for (size_t p = 0; p < missed.size(); ++p) {
    const bool red = heat[3 * p] == 255 && heat[3 * p + 1] == 0 && heat[3 * p + 2] == 0;
    EXPECT_EQ(red, missed[p] != 0) << "pixel " << p;
    if (!missed[p]) {
      for (size_t k = 0; k < 3; ++k) EXPECT_EQ(heat[3 * p + k], f.rgb[3 * p + k] * 3 / 10);
    }
  }
}

TEST(Metrics, CompareSetsCountsMissedAndExtraTriangles) {
  const std::vector<uint32_t> set = {1, 2, 5, 9, 10}, reference = {2, 3, 5, 7, 10, 11};
  const SetComparison c = compare_sets(set, reference);
  EXPECT_EQ(c.size, 5u);
  EXPECT_EQ(c.reference_size, 6u);
  EXPECT_EQ(c.common, 3u);  // 2 5 10
  EXPECT_EQ(c.missed, 3u);  // 3 7 11
  EXPECT_EQ(c.extra, 2u);   // 1 9
  EXPECT_EQ(compare_sets({}, reference).missed, 6u);
}

// Whole-image SSIM (CloVR's visual continuity): one window over all pixels. Two half-black,
// half-white images whose halves are swapped: means equal (127.5), variances equal (127.5^2),
// covariance -127.5^2: the luminance term is 1 and the structure term
// is (2 cov + C2) / (2 var + C2) (negative).
TEST(Metrics, WholeImageSsimUsesTheStatisticsOfAllPixels) {
  const int w = 24, h = 12;
  std::vector<uint8_t> a(3 * w * h), b(3 * w * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) {
        a[3 * (y * w + x) + c] = x < w / 2 ? 0 : 255;
        b[3 * (y * w + x) + c] = x < w / 2 ? 255 : 0;
      }
  const double c1 = (0.01 * 255) * (0.01 * 255), c2 = (0.03 * 255) * (0.03 * 255);
  // Y = (0.299 + 0.587 + 0.114) * 255 up to the rounding of the weights.
  const double m = 127.5, v = 127.5 * 127.5;
  const double expected = ((2 * m * m + c1) * (-2 * v + c2)) / ((2 * m * m + c1) * (2 * v + c2));
  EXPECT_NEAR(ssim_whole_image(w, h, a, b), expected, 1e-9);
  EXPECT_EQ(ssim_whole_image(w, h, a, a), 1.0);
  EXPECT_DOUBLE_EQ(ssim_whole_image(w, h, a, b), ssim_whole_image(w, h, b, a));
}
