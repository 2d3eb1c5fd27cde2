// image_io.h: writing and reading the renderer's images with OpenImageIO (PNG for 8-bit RGB
// colour, OpenEXR for float depth). The file format follows the extension of `path`.
//
// Writes go to a temporary file beside `path` (same folder, name + ".tmp.<pid>") that is renamed
// into place, so a crash never leaves a half-written image. Write failures throw
// std::runtime_error naming the file; read failures throw InputError (bad input tier).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace vislib {

// Writes a width x height 8-bit RGB image (3 bytes per pixel, row-major from the top-left) to
// `path`, usually .png. `rgb` must hold 3*width*height bytes; width, height >= 1.
void write_rgb8_image(const std::string& path, int width, int height,
                      const std::vector<uint8_t>& rgb);

// Writes a width x height single-channel 32-bit float image (channel "Z"; +inf stays +inf) to
// `path`, usually .exr. `values` must hold width*height floats; width, height >= 1.
void write_float_image(const std::string& path, int width, int height,
                       const std::vector<float>& values);

// Reads an image as 8-bit RGB (grey is repeated, alpha dropped); sets width and height.
std::vector<uint8_t> read_rgb8_image(const std::string& path, int& width, int& height);

// Reads the first channel of an image as float; sets width and height.
std::vector<float> read_float_image(const std::string& path, int& width, int& height);

}  // namespace vislib
