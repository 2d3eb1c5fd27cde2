// image_module.h: the C interface between image_io.cpp and the image module, a shared library
// (libvislib_image_oiio.so) holding every call into OpenImageIO. OpenImageIO pulls in about 250
// shared libraries (OpenVDB, GDAL, Poppler, ...) whose loading costs each process ~0.6 s of CPU and
// ~130 MB of resident memory before main(); loaded with dlopen on the first image read or write,
// only the commands that touch images pay for it (docs/performance.md, "Start-up").
//
// Both functions return 0 on success, kImageModuleInputError when the file cannot be opened or
// decoded (bad input), kImageModuleWriteError when writing fails; on failure `err` receives a
// NUL-terminated message (at most errlen bytes, errlen >= 1).
#pragma once

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

enum { kImageModuleInputError = 1, kImageModuleWriteError = 2 };

// Writes width x height pixels of `channels` interleaved channels (uint8 when is_float == 0, else
// float32) to tmp_path in the format that final_path's extension names (the caller renames
// tmp_path to final_path). channel_name, when not NULL, names the single channel of a one-channel
// float image and marks it as depth.
typedef int (*vislib_image_write_fn)(const char* final_path, const char* tmp_path, int width,
                                     int height, int channels, int is_float,
                                     const char* channel_name, const void* pixels, char* err,
                                     size_t errlen);

// Reads the first `max_channels` channels (all when max_channels <= 0) of the image at path as
// uint8 (want_float == 0) or float32 into a buffer from alloc(ctx, bytes); sets width, height and
// the number of channels read.
typedef int (*vislib_image_read_fn)(const char* path, int want_float, int max_channels,
                                    void* (*alloc)(void* ctx, size_t bytes), void* ctx, int* width,
                                    int* height, int* channels, char* err, size_t errlen);

#define VISLIB_IMAGE_WRITE_SYMBOL "vislib_image_write"
#define VISLIB_IMAGE_READ_SYMBOL "vislib_image_read"

// The module's two functions (image_oiio.cpp), called directly when the module is linked in
// (sanitizer builds, VISLIB_IMAGE_MODULE_LINKED) instead of loaded.
int vislib_image_write(const char* final_path, const char* tmp_path, int width, int height,
                       int channels, int is_float, const char* channel_name, const void* pixels,
                       char* err, size_t errlen);
int vislib_image_read(const char* path, int want_float, int max_channels,
                      void* (*alloc)(void* ctx, size_t bytes), void* ctx, int* width, int* height,
                      int* channels, char* err, size_t errlen);

#ifdef __cplusplus
}
#endif
