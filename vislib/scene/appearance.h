// appearance.h: what a viewer needs of a scene that visibility does not: vertex normals and
// texture coordinates, materials (base colour factor and texture), the images they reference, and
// the asset's copyright. Kept apart from Scene so that bakes neither load nor carry it; it is
// aligned with the Scene loaded from the same file with the same LoadOptions (same vertex and
// triangle ids), and used by the glTF writer (write_gltf.h).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "vislib/base/vec.h"
#include "vislib/scene/import.h"

namespace vislib {

// An image a material references: its bytes when they could be read (embedded GLB buffer view,
// data: URI or a file next to the glTF), else only the URI as written in the source.
struct AppearanceImage {
  std::string name;
  std::string mime_type;  // image/png or image/jpeg ("" when unknown)
  std::string bytes;      // the encoded image, or empty
  std::string uri;        // the source's URI (not a data: URI), or empty
};

// glTF 2.0 pbrMetallicRoughness material, reduced to what survives a visible-set export.
struct AppearanceMaterial {
  std::string name;
  std::array<double, 4> base_color{1, 1, 1, 1};  // baseColorFactor, linear RGBA in [0,1]
  int32_t base_color_image = -1;                 // index into images, or -1
  uint32_t base_color_texcoord = 0;              // must be 0 (only TEXCOORD_0 is kept)
  double metallic = 1, roughness = 1;
  std::array<double, 3> emissive{0, 0, 0};
  std::string alpha_mode = "OPAQUE";  // OPAQUE, MASK or BLEND
  double alpha_cutoff = 0.5;
  bool double_sided = false;
};

struct SceneAppearance {
  // Per vertex (index as in Scene::positions[0]), or empty. A vertex whose primitive has no such
  // attribute holds NaN in every component. Normals are unit, in world space, in the state-0 pose
  // (the node transform's inverse transpose; skinned vertices: the weight blend of the joints').
  std::vector<Vec3> normals;
  std::vector<std::array<double, 2>> uvs;  // TEXCOORD_0
  // Per triangle: index into materials, or -1 (the glTF default material); or empty.
  std::vector<int32_t> triangle_material;
  std::vector<AppearanceMaterial> materials;
  std::vector<AppearanceImage> images;
  std::string copyright;  // glTF asset.copyright of the source
};

// The appearance of the scene file `path` as load_scene(path, options) would load it. glTF only:
// other formats give an empty appearance. Throws InputError on a bad file, as load_scene does.
// Texture files that cannot be read leave the image's bytes empty and add a warning.
SceneAppearance load_appearance(const std::string& path, const LoadOptions& options = {},
                                std::vector<std::string>* warnings = nullptr);

}  // namespace vislib
