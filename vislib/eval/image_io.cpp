// image_io.cpp: OpenImageIO behind the four functions of image_io.h.
#include "vislib/eval/image_io.h"

#include <OpenImageIO/imageio.h>
#include <unistd.h>

#include <cassert>
#include <cstdio>
#include <stdexcept>

#include "vislib/base/error.h"

namespace vislib {

namespace {

void write_image(const std::string& path, const OIIO::ImageSpec& spec, OIIO::TypeDesc type,
                 const void* data) {
  // The plugin is chosen by the final name; the pixels go to a temporary name, renamed on success.
  auto out = OIIO::ImageOutput::create(path);
  if (!out) throw std::runtime_error(path + ": cannot write image: " + OIIO::geterror());
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  bool ok = out->open(tmp, spec) && out->write_image(type, data);
  ok = out->close() && ok;
  if (!ok) {
    std::string err = out->geterror();
    std::remove(tmp.c_str());
    throw std::runtime_error(path + ": image write failed: " + err);
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw std::runtime_error(path + ": cannot rename " + tmp + " into place");
  }
}

std::unique_ptr<OIIO::ImageInput> open_input(const std::string& path, int& width, int& height) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw InputError(path, "cannot read image: " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  width = spec.width;
  height = spec.height;
  if (width < 1 || height < 1 || spec.nchannels < 1)
    throw InputError(path, "image has no pixels or no channels");
  return in;
}

}  // namespace

void write_rgb8_image(const std::string& path, int width, int height,
                      const std::vector<uint8_t>& rgb) {
  assert(width >= 1 && height >= 1 && rgb.size() == 3 * size_t(width) * size_t(height));
  write_image(path, OIIO::ImageSpec(width, height, 3, OIIO::TypeDesc::UINT8), OIIO::TypeDesc::UINT8,
              rgb.data());
}

void write_float_image(const std::string& path, int width, int height,
                       const std::vector<float>& values) {
  assert(width >= 1 && height >= 1 && values.size() == size_t(width) * size_t(height));
  OIIO::ImageSpec spec(width, height, 1, OIIO::TypeDesc::FLOAT);
  spec.channelnames = {"Z"};
  spec.z_channel = 0;
  write_image(path, spec, OIIO::TypeDesc::FLOAT, values.data());
}

std::vector<uint8_t> read_rgb8_image(const std::string& path, int& width, int& height) {
  auto in = open_input(path, width, height);
  const int nc = in->spec().nchannels;
  std::vector<uint8_t> all(size_t(width) * size_t(height) * size_t(nc));
  if (!in->read_image(0, 0, 0, nc, OIIO::TypeDesc::UINT8, all.data()))
    throw InputError(path, "cannot decode image: " + in->geterror());
  std::vector<uint8_t> rgb(size_t(width) * size_t(height) * 3);
  for (size_t p = 0; p < size_t(width) * size_t(height); ++p)
    for (int k = 0; k < 3; ++k)
      rgb[3 * p + size_t(k)] = all[p * size_t(nc) + size_t(nc >= 3 ? k : 0)];
  return rgb;
}

std::vector<float> read_float_image(const std::string& path, int& width, int& height) {
  auto in = open_input(path, width, height);
  std::vector<float> values(size_t(width) * size_t(height));
  if (!in->read_image(0, 0, 0, 1, OIIO::TypeDesc::FLOAT, values.data()))
    throw InputError(path, "cannot decode image: " + in->geterror());
  return values;
}

}  // namespace vislib
