// image_io.cpp: the four functions of image_io.h over the image module (image_module/), which
// holds every OpenImageIO call and is loaded with dlopen on first use: a process that never reads
// or writes an image does not load OpenImageIO's ~250 shared libraries (image_module.h says why).
#include "vislib/eval/image_io.h"

#include <dlfcn.h>
#include <link.h>
#include <unistd.h>

#include <cassert>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <new>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "vislib/base/error.h"
#include "vislib/eval/image_module/image_module.h"

namespace vislib {

namespace {

struct ImageModule {
  vislib_image_write_fn write = nullptr;
  vislib_image_read_fn read = nullptr;
};

#ifdef VISLIB_IMAGE_MODULE_LINKED
const ImageModule& image_module() {
  static const ImageModule module{&vislib_image_write, &vislib_image_read};
  return module;
}
#else
// A byte of this file's object: dladdr of its address names the program or shared object that
// holds this code (the static vislib::eval is linked into `pvs`, pyvislib's module, an engine).
const char kWhereAmI = 0;

// The file of the program or shared object holding this code (empty if unknown), symbolic links
// resolved, so that a link to an installed program still leads to its prefix.
std::filesystem::path holder_file() {
  Dl_info info{};
  link_map* map = nullptr;
  std::filesystem::path file;
  if (dladdr1(&kWhereAmI, &info, reinterpret_cast<void**>(&map), RTLD_DL_LINKMAP) != 0 && map &&
      map->l_name && map->l_name[0] != '\0')
    file = map->l_name;
  else  // the main program: its link map has no name, dladdr would give argv[0]
    file = "/proc/self/exe";
  std::error_code ec;
  auto resolved = std::filesystem::canonical(file, ec);
  return ec ? std::filesystem::path() : resolved;
}

// A place to look for the module, and what to say when nothing is there.
struct Candidate {
  std::string path;
  std::string absent;  // the message when path is empty or missing
};

// Where the module may be, in order: $VISLIB_IMAGE_MODULE; <dir>/<libdir>/vislib/<name> for the
// nearest folder <dir> above the program or shared object holding this code (an install prefix
// or a build folder: `bin/pvs`, pyvislib in `lib/python3.X/dist-packages`, `build/cli/pvs` all
// reach it, wherever the prefix was moved); the dynamic loader's own search (LD_LIBRARY_PATH,
// the RUNPATH of the holder).
std::vector<Candidate> module_candidates() {
  std::vector<Candidate> out;
  if (const char* env = std::getenv("VISLIB_IMAGE_MODULE"); env && *env)
    out.push_back({env, std::string(env) + " (absent)"});
  const std::filesystem::path relative =
      std::filesystem::path(VISLIB_IMAGE_MODULE_RELATIVE_DIR) / VISLIB_IMAGE_MODULE_NAME;
  const std::filesystem::path holder = holder_file();
  Candidate above{"", relative.string() + " (in no folder above " +
                          (holder.empty() ? std::string("this program") : holder.string()) + ")"};
  for (auto dir = holder.parent_path(); !dir.empty(); dir = dir.parent_path()) {
    std::error_code ec;
    if (std::filesystem::exists(dir / relative, ec)) {
      above.path = (dir / relative).string();
      break;
    }
    if (dir == dir.parent_path()) break;
  }
  out.push_back(above);
  out.push_back({VISLIB_IMAGE_MODULE_NAME, ""});
  return out;
}

const ImageModule& image_module() {
  static ImageModule module;
  static std::string failure;
  static std::once_flag once;
  std::call_once(once, [] {
    std::string tried;
    for (const Candidate& c : module_candidates()) {
      const std::string& path = c.path;
      const bool bare = !path.empty() && path.find('/') == std::string::npos;
      if (!bare && (path.empty() || !std::filesystem::exists(path))) {
        tried += "\n  " + c.absent;
        continue;
      }
      void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
      if (!handle) {
        const char* e = dlerror();
        tried += "\n  " + path + " (" + (e ? e : "dlopen failed") + ")";
        continue;
      }
      module.write =
          reinterpret_cast<vislib_image_write_fn>(dlsym(handle, VISLIB_IMAGE_WRITE_SYMBOL));
      module.read = reinterpret_cast<vislib_image_read_fn>(dlsym(handle, VISLIB_IMAGE_READ_SYMBOL));
      if (module.write && module.read) return;  // the handle stays open for the process
      tried += "\n  " + path + " (lacks the " VISLIB_IMAGE_WRITE_SYMBOL " / " +
               VISLIB_IMAGE_READ_SYMBOL " functions)";
      module = ImageModule{};
      dlclose(handle);
    }
    failure =
        "the image module (OpenImageIO) could not be loaded; set VISLIB_IMAGE_MODULE to the "
        "path of libvislib_image_oiio.so. Tried:" +
        tried;
  });
  if (!module.write) throw std::runtime_error(failure);
  return module;
}
#endif

void write_image(const std::string& path, int width, int height, int channels, bool is_float,
                 const char* channel_name, const void* pixels) {
  const ImageModule& m = image_module();
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  char err[1024] = "";
  if (m.write(path.c_str(), tmp.c_str(), width, height, channels, is_float ? 1 : 0, channel_name,
              pixels, err, sizeof err) != 0) {
    std::remove(tmp.c_str());
    throw std::runtime_error(path + ": " + err);
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw std::runtime_error(path + ": cannot rename " + tmp + " into place");
  }
}

// The pixels of `path` (uint8 or float32, at most max_channels channels) in a vector of T.
template <class T>
std::vector<T> read_image(const std::string& path, int max_channels, int& width, int& height,
                          int& channels) {
  struct Target {
    std::vector<T> pixels;
    bool out_of_memory = false;
  } target;
  auto alloc = [](void* ctx, size_t bytes) noexcept -> void* {
    auto* t = static_cast<Target*>(ctx);
    try {
      t->pixels.resize(bytes / sizeof(T));
      return t->pixels.data();
    } catch (const std::bad_alloc&) {
      t->out_of_memory = true;
      return nullptr;
    }
  };
  char err[1024] = "";
  const int rc = image_module().read(path.c_str(), std::is_same_v<T, float> ? 1 : 0, max_channels,
                                     alloc, &target, &width, &height, &channels, err, sizeof err);
  if (target.out_of_memory) throw std::bad_alloc();
  if (rc != 0) throw InputError(path, err);
  return std::move(target.pixels);
}

}  // namespace

void write_rgb8_image(const std::string& path, int width, int height,
                      const std::vector<uint8_t>& rgb) {
  assert(width >= 1 && height >= 1 && rgb.size() == 3 * size_t(width) * size_t(height));
  write_image(path, width, height, 3, false, nullptr, rgb.data());
}

void write_float_image(const std::string& path, int width, int height,
                       const std::vector<float>& values) {
  assert(width >= 1 && height >= 1 && values.size() == size_t(width) * size_t(height));
  write_image(path, width, height, 1, true, "Z", values.data());
}

std::vector<uint8_t> read_rgb8_image(const std::string& path, int& width, int& height) {
  int nc = 0;
  std::vector<uint8_t> all = read_image<uint8_t>(path, 0, width, height, nc);
  std::vector<uint8_t> rgb(size_t(width) * size_t(height) * 3);
  for (size_t p = 0; p < size_t(width) * size_t(height); ++p)
    for (int k = 0; k < 3; ++k)
      rgb[3 * p + size_t(k)] = all[p * size_t(nc) + size_t(nc >= 3 ? k : 0)];
  return rgb;
}

std::vector<float> read_float_image(const std::string& path, int& width, int& height) {
  int nc = 0;
  return read_image<float>(path, 1, width, height, nc);
}

}  // namespace vislib
