// Tests of vislib/eval/image_io.h: PNG and EXR round trips, atomic writes, bad input.
#include "vislib/eval/image_io.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "tests/test_support.h"
#include "vislib/base/error.h"

using namespace vislib;

TEST(ImageIo, PngRoundTripIsExact) {
  const std::string dir = vislib_test::temp_dir("image_png");
  std::vector<uint8_t> rgb(3 * 7 * 5);
  for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = uint8_t(i * 37);
  write_rgb8_image(dir + "/a.png", 7, 5, rgb);
  int w = 0, h = 0;
  EXPECT_EQ(read_rgb8_image(dir + "/a.png", w, h), rgb);
  EXPECT_EQ(w, 7);
  EXPECT_EQ(h, 5);
  // Only the final file is left behind (the temporary was renamed).
  size_t files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) files += e.is_regular_file();
  EXPECT_EQ(files, 1u);
}

TEST(ImageIo, ExrRoundTripKeepsFloatsAndInfinity) {
  const std::string dir = vislib_test::temp_dir("image_exr");
  std::vector<float> depth = {1.5f, 1e-3f, 12345.678f, INFINITY, 0.1f, 7.0f};
  write_float_image(dir + "/d.exr", 3, 2, depth);
  int w = 0, h = 0;
  EXPECT_EQ(read_float_image(dir + "/d.exr", w, h), depth);
  EXPECT_EQ(w, 3);
  EXPECT_EQ(h, 2);
}

TEST(ImageIo, MissingFileIsBadInputNamingThePath) {
  int w, h;
  try {
    read_rgb8_image("/nonexistent/x.png", w, h);
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/x.png"), std::string::npos);
  }
}

TEST(ImageIo, UnwritablePathThrows) {
  std::vector<uint8_t> rgb(3, 0);
  EXPECT_THROW(write_rgb8_image("/nonexistent/dir/x.png", 1, 1, rgb), std::runtime_error);
}
