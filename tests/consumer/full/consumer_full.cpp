// A program on the installed whole library: loads a scene, writes an image and reads it back
// (the image module, loaded on first image I/O).
#include <cstdint>
#include <cstdio>
#include <vector>

#include "vislib/eval/image_io.h"
#include "vislib/scene/import.h"

int main(int argc, char** argv) {
  if (argc != 3) return 2;
  const vislib::Scene scene = vislib::load_scene(argv[1]);
  std::vector<uint8_t> rgb(4 * 3 * 3);
  for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = static_cast<uint8_t>(i * 7);
  vislib::write_rgb8_image(argv[2], 4, 3, rgb);
  int w = 0, h = 0;
  if (vislib::read_rgb8_image(argv[2], w, h) != rgb || w != 4 || h != 3) {
    std::fprintf(stderr, "consumer_full: %s did not read back as written\n", argv[2]);
    return 1;
  }
  std::printf("consumer_full: %s has %zu triangles; %s written and read back\n", argv[1],
              scene.triangle_count(), argv[2]);
  return 0;
}
