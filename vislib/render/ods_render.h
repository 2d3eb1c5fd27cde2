// ods_render.h: omnidirectional stereo (ODS) equirectangular panoramas of a triangle set (a cell's
// PVS or the full scene), by two methods, and the measures `pvs view
// --ods` reports.
//
// Paper: ../shared/papers/omnidirectional-stereo.txt (Marrinan & Papka). The conventions (y up,
// longitude -atan2(x, z), row 0 at the top, pixel centres, the viewing circle, Eq. 6 at the ray's
// latitude) and the pure functions are those of runtime/ods.h; docs/ods.md describes both.
//
//  - render_ods_rays: the reference. Pixel (x, y) of eye s casts pvs_runtime::ods_pixel_ray (from
//    C + s h_m right(lon), h_m = IPD/2 * pole merge factor of the row's latitude) through Embree,
//    one row per task, rays with their own origins (EmbreeScene::first_hits_from). Build `rt`
//    with its origin at the panorama centre (EmbreeScene(scene, 0, centre)): float error then
//    scales with the distance to the centre, so a scene 1e5 m from the world origin keeps its
//    2 cm-scale disparity.
//  - render_ods_raster: the paper's method on the CPU. Each triangle is tessellated (Alg. 1 edge
//    levels from the mono projection of its vertices and edge midpoints, Eq. 4 inner level, or a
//    static level), every tessellated vertex projected per eye (Eq. 1-5 as printed, or the exact
//    tangent-ray projection), each small triangle split at the seam and at the poles (§3.2, pole
//    from the axis crossing point), and rasterised into a z-buffer: pixel centres, top-left fill
//    rule, range interpolated linearly in image space (the paper's orthographic z = -|v_dir|).
//    Ties in range go to the lower triangle id, so the image does not depend on the order of
//    drawing or on the thread count. With the exact projection, a small triangle with a vertex
//    inside the viewing circle (seen by no ODS ray) is dropped; the paper's formula draws it.
// Both write a vislib::Frame: tri = scene triangle id (kNoHit where nothing), depth = range from
// the eye's ray origin (scene units), rgb = render_frame's shading (shade_triangle with the
// pixel's direction), kRenderBackground where nothing.
// Both are deterministic and identical for any thread count. Thread-safe.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "pvs_format/pvs_format.h"
#include "runtime/ods.h"
#include "vislib/base/vec.h"
#include "vislib/eval/embree_scene.h"
#include "vislib/eval/render.h"
#include "vislib/scene/scene.h"

namespace vislib {

struct OdsSettings {
  Vec3 centre;                      // C, the viewing circle's centre
  double ipd = 0.064;               // interpupillary distance, scene units, >= 0
  pvs_runtime::PoleMerge merge;     // Eq. 6 (default: none)
  int width = 2048, height = 1024;  // pixels, >= 2 and >= 1
  double z_near = kDefaultNear;  // hits nearer than this along the ray (scene units) do not count
};

// The ODS panorama of `eye` by ray casting. rt must be built from `scene` at tau = 0 (normals for
// the shading come from key state 0), preferably with origin() = settings.centre. allowed: null
// renders every triangle, else scene.triangle_count() bytes, nonzero = drawn.
Frame render_ods_rays(const Scene& scene, const EmbreeScene& rt, const OdsSettings& settings,
                      pvs_runtime::Eye eye, const uint8_t* allowed = nullptr);

enum class OdsFormula : uint8_t { Paper = 0, Exact = 1 };

struct OdsRasterSettings {
  OdsFormula formula = OdsFormula::Exact;
  // 0: dynamic tessellation (Alg. 1 + Eq. 4, levels rounded up to integers as OpenGL's
  // equal_spacing does); k >= 1: every edge and the inside at level k (the paper's "static k";
  // 1 = no tessellation). At most 64.
  int static_level = 0;
};

struct OdsRasterStats {
  size_t input_triangles = 0;        // triangles of `ids`
  size_t tessellated = 0;            // small triangles after tessellation
  size_t drawn = 0;                  // image-space triangles rasterised (after seam/pole split)
  size_t pole_triangles = 0;         // small triangles crossing the vertical axis through C
  size_t dropped_inside_circle = 0;  // Exact: small triangles with a vertex seen by no ray
};

// The ODS panorama of `eye` by the paper's rasterisation of the triangles `ids` (each <
// triangle_count(); positions of key state 0). `stats`, if not null, receives the counts.
Frame render_ods_raster(const Scene& scene, const std::vector<uint32_t>& ids,
                        const OdsSettings& settings, pvs_runtime::Eye eye,
                        const OdsRasterSettings& raster, OdsRasterStats* stats = nullptr);

// ---- Images and measures for `pvs view --ods` ------------------------------------------------

// The left panorama above the right one (the usual top-bottom ODS packing): W x 2H RGB.
std::vector<uint8_t> pack_top_bottom(const Frame& left, const Frame& right);
// Red-cyan anaglyph: red from the left eye's luminance, green and blue from the right eye's.
std::vector<uint8_t> anaglyph(const Frame& left, const Frame& right);

// Left/right disagreement per latitude band of `band_degrees` (bands from +90 down to -90; a row
// belongs to the band of its centre latitude): the share of pixels where the two eyes show
// different triangles (or one shows nothing), and the mean absolute luminance difference (0-255).
// Pole merging drives both to 0 where the IPD reaches 0. left and right have the same size.
struct BandDisagreement {
  double lat_max_deg = 0, lat_min_deg = 0;
  size_t pixels = 0;
  double triangle_mismatch = 0, mean_abs_luma = 0;
};
std::vector<BandDisagreement> lr_disagreement_by_latitude(const Frame& left, const Frame& right,
                                                          double band_degrees = 5);

// Continuity across the seam: column 0 against column W-1 (neighbours across lon = +-180), and
// for scale the same measures averaged over every other pair of adjacent columns.
struct SeamContinuity {
  double seam_triangle_mismatch = 0, seam_mean_abs_rgb = 0;        // rows where col 0 != col W-1
  double typical_triangle_mismatch = 0, typical_mean_abs_rgb = 0;  // mean over columns x, x+1
};
SeamContinuity seam_continuity(const Frame& frame);

// True when the centre and 64 points of the rim of the viewing disc (`radius` about `centre`, in
// the horizontal plane y = centre.y) each lie in the view region of one of `cells` (closed boxes):
// the cells' visible sets then serve every eye position of the panorama (pvs view --ods).
bool ods_disc_covered(const pvs::CellLayout& layout, const std::vector<uint32_t>& cells,
                      Vec3 centre, double radius);

}  // namespace vislib
