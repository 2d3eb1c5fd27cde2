// image_oiio.cpp: the image module (image_module.h), OpenImageIO behind two C functions. Built as
// the shared module libvislib_image_oiio.so and loaded by image_io.cpp on first use.
#include <OpenImageIO/imageio.h>

#include <cstdio>
#include <cstring>
#include <exception>
#include <memory>
#include <string>

#include "vislib/eval/image_module/image_module.h"

namespace {

int fail(int code, const std::string& message, char* err, size_t errlen) {
  std::snprintf(err, errlen, "%s", message.c_str());
  return code;
}

}  // namespace

extern "C" __attribute__((visibility("default"))) int vislib_image_write(
    const char* final_path, const char* tmp_path, int width, int height, int channels, int is_float,
    const char* channel_name, const void* pixels, char* err, size_t errlen) {
  try {
    // The plugin is chosen by the final name; the pixels go to the temporary name.
    auto out = OIIO::ImageOutput::create(final_path);
    if (!out)
      return fail(kImageModuleWriteError, "cannot write image: " + OIIO::geterror(), err, errlen);
    const OIIO::TypeDesc type = is_float ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8;
    OIIO::ImageSpec spec(width, height, channels, type);
    if (channel_name && channels == 1) {
      spec.channelnames = {channel_name};
      spec.z_channel = 0;
    }
    bool ok = out->open(tmp_path, spec) && out->write_image(type, pixels);
    ok = out->close() && ok;
    if (!ok)
      return fail(kImageModuleWriteError, "image write failed: " + out->geterror(), err, errlen);
    return 0;
  } catch (const std::exception& e) {
    return fail(kImageModuleWriteError, std::string("image write failed: ") + e.what(), err,
                errlen);
  }
}

extern "C" __attribute__((visibility("default"))) int vislib_image_read(
    const char* path, int want_float, int max_channels, void* (*alloc)(void* ctx, size_t bytes),
    void* ctx, int* width, int* height, int* channels, char* err, size_t errlen) {
  try {
    auto in = OIIO::ImageInput::open(path);
    if (!in)
      return fail(kImageModuleInputError, "cannot read image: " + OIIO::geterror(), err, errlen);
    const OIIO::ImageSpec& spec = in->spec();
    if (spec.width < 1 || spec.height < 1 || spec.nchannels < 1)
      return fail(kImageModuleInputError, "image has no pixels or no channels", err, errlen);
    const int nc =
        max_channels > 0 && max_channels < spec.nchannels ? max_channels : spec.nchannels;
    const OIIO::TypeDesc type = want_float ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8;
    const size_t bytes = size_t(spec.width) * size_t(spec.height) * size_t(nc) * type.size();
    void* data = alloc(ctx, bytes);
    if (!data) return fail(kImageModuleInputError, "no memory for the pixels", err, errlen);
    if (!in->read_image(0, 0, 0, nc, type, data))
      return fail(kImageModuleInputError, "cannot decode image: " + in->geterror(), err, errlen);
    *width = spec.width;
    *height = spec.height;
    *channels = nc;
    return 0;
  } catch (const std::exception& e) {
    return fail(kImageModuleInputError, std::string("cannot read image: ") + e.what(), err, errlen);
  }
}
