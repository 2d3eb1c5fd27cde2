// scene_loader_fuzz.cpp: libFuzzer targets for the scene loaders (vislib::load_scene, import.h),
// one executable per format: the same source built with VISLIB_FUZZ_EXT = ".glb", ".gltf", ".obj",
// ".ply", ".off", ".stl", ".spheres" or ".bsp" (fuzz/CMakeLists.txt). The input is written to a
// file with that extension in a private temporary folder (beside a 64-byte "buffer.bin", so that
// external glTF buffers are reached) and loaded. Any input must either load into a scene that keeps
// the contract of scene.h or be rejected with vislib::InputError; a crash, an out-of-bounds access,
// a leak, another exception, or an allocation above -malloc_limit_mb (libFuzzer) is a finding.
//
// Build and run: scripts/fuzz.sh (clang++ -fsanitize=fuzzer,address,undefined).
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>

#include "vislib/base/error.h"
#include "vislib/scene/import.h"

#ifndef VISLIB_FUZZ_EXT
#error "define VISLIB_FUZZ_EXT, the file extension of the format to fuzz"
#endif

namespace {

void check(bool ok) {
  if (!ok) __builtin_trap();
}

// The private folder (a plain array: the exit handler that removes it runs after the destructors
// of static objects).
char g_dir[4096];

void remove_dir() {
  std::error_code ec;
  std::filesystem::remove_all(g_dir, ec);
}

const std::string& input_path() {
  static const std::string path = [] {
    std::string dir = (std::filesystem::temp_directory_path() / "vislib_fuzz_XXXXXX").string();
    if (dir.size() >= sizeof g_dir || !::mkdtemp(dir.data())) std::abort();
    std::memcpy(g_dir, dir.c_str(), dir.size() + 1);
    std::atexit(remove_dir);
    FILE* f = std::fopen((dir + "/buffer.bin").c_str(), "wb");
    if (!f) std::abort();
    for (int i = 0; i < 64; ++i) std::fputc(i % 3 == 0 ? 0 : 0x3f, f);  // small floats and zeros
    std::fclose(f);
    return dir + "/input" VISLIB_FUZZ_EXT;
  }();
  return path;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string& path = input_path();
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) std::abort();
  if (size && std::fwrite(data, 1, size, f) != size) std::abort();
  std::fclose(f);
  vislib::LoadOptions options;
  options.states = (size % 3) + 1;  // also sample animations into 2 and 3 key states
  // Quake maps: every model or the world only, liquids kept or omitted.
  options.bsp_models = size % 2 ? vislib::BspModels::all : vislib::BspModels::world;
  options.bsp_liquids = size % 4 < 2 ? vislib::BspLiquids::opaque : vislib::BspLiquids::omit;
  try {
    vislib::Scene s = vislib::load_scene(path, options);
    // The contract of scene.h, checked here even though load_scene checks it too (NDEBUG).
    check(s.triangle_object.size() == s.triangles.size());
    check(s.sphere_object.size() == s.sphere_radius.size());
    const size_t n = s.vertex_count();
    for (const auto& t : s.triangles)
      for (uint32_t i : t) check(i < n);
    for (uint32_t o : s.triangle_object) check(o < s.objects.size());
    for (uint32_t o : s.sphere_object) check(o < s.objects.size());
    for (const auto& state : s.positions)
      for (const auto& p : state)
        check(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
  } catch (const vislib::InputError&) {
  }
  return 0;
}
