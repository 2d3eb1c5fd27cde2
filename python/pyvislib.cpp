// pyvislib.cpp: the Python module `pyvislib`, pybind11 bindings of the vislib
// library as it is: load a scene, from-segment and from-region visibility, read a PVS file through
// the runtime, render frames with the Embree reference renderer and compare them with the frame
// metrics. Nothing is recomputed here: every function calls the library function named in its
// docstring, so a result equals what the `pvs` command prints for the same inputs
// (tests/python/ checks this against the CLI). docs/python.md documents the module.
//
// Errors: vislib::InputError (a bad scene file) -> pyvislib.InputError (a ValueError naming the
// file); pvs::FormatError (a malformed PVS) -> pyvislib.FormatError (a ValueError with the byte
// offset); pvs_runtime::OpenError (a PVS that cannot be opened) -> OSError with its errno (so a
// missing file is a FileNotFoundError), the message naming the path; a violated precondition
// (bad option, wrong array shape) -> ValueError or IndexError before the library is called.
//
// Threads: each compute call takes `threads` (0 = all cores) and holds a tbb::global_control for
// its duration, as the CLI's -j does; the GIL is released while the library works. Results never
// depend on the thread count (the library's determinism contract).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <tbb/global_control.h>

#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "pvs_format/pvs_format.h"
#include "runtime/pvs_runtime.h"
#include "vislib/base/cubemap.h"
#include "vislib/base/error.h"
#include "vislib/eval/discontinuity.h"
#include "vislib/eval/embree_scene.h"
#include "vislib/eval/image_io.h"
#include "vislib/eval/metrics.h"
#include "vislib/eval/render.h"
#include "vislib/kernel/region_visibility.h"
#include "vislib/kernel/segment_visibility.h"
#include "vislib/kernel/triangle_bvh.h"
#include "vislib/scene/import.h"
#include "vislib/scene/scene.h"
#include "vislib/scene/scene_fingerprint.h"

namespace py = pybind11;

namespace {

using U32Array = py::array_t<uint32_t>;

U32Array to_numpy(const std::vector<uint32_t>& v) {
  U32Array a(py::ssize_t(v.size()));
  if (!v.empty()) std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

std::unique_ptr<tbb::global_control> thread_limit(int threads) {
  if (threads < 0) throw py::value_error("threads must be >= 0 (0 = all cores)");
  if (threads == 0) return nullptr;
  return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                               size_t(threads));
}

vislib::Vec3 vec3(const std::vector<double>& v, const char* name) {
  if (v.size() != 3) throw py::value_error(std::string(name) + " must hold 3 numbers (x, y, z)");
  for (double x : v)
    if (!std::isfinite(x)) throw py::value_error(std::string(name) + " must be finite");
  return {v[0], v[1], v[2]};
}

py::tuple vec_tuple(vislib::Vec3 v) {
  return py::make_tuple(v.x, v.y, v.z);
}

// A loaded scene, shared by the results and renderers that refer to it.
struct PyScene {
  std::string path;
  vislib::Scene scene;
  std::vector<std::string> warnings;

  // The runs of collinear edges for key state `state`, built on first use and kept with the
  // scene (which never changes once loaded), as a bake builds them once: without them every
  // kernel call would rebuild its own (edge_lines.h).
  const vislib::EdgeLines& edge_lines(size_t state) {
    std::lock_guard<std::mutex> lock(lines_mutex);
    std::unique_ptr<vislib::EdgeLines>& l = lines_by_state[state];
    if (!l) l = std::make_unique<vislib::EdgeLines>(vislib::build_edge_lines(scene, state));
    return *l;
  }

 private:
  std::mutex lines_mutex;
  std::map<size_t, std::unique_ptr<vislib::EdgeLines>> lines_by_state;
};
using ScenePtr = std::shared_ptr<PyScene>;

vislib::SegmentOptions segment_options(int resolution, double near, double eps_len, double eps_z,
                                       int tile_size, const std::string& coplanar,
                                       const std::string& mode, bool depth_culling, bool simd,
                                       size_t state, size_t state_count) {
  if (resolution < 1) throw py::value_error("resolution must be >= 1");
  if (!(near > 0) || !std::isfinite(near)) throw py::value_error("near must be > 0 and finite");
  if (!(eps_len >= 0)) throw py::value_error("eps_len must be >= 0");
  if (!(eps_z >= 0)) throw py::value_error("eps_z must be >= 0");
  if (tile_size < 0) throw py::value_error("tile_size must be >= 0 (0: the kernel's choice)");
  if (coplanar != "both" && coplanar != "first")
    throw py::value_error("coplanar must be 'both' or 'first'");
  if (mode != "diagonal" && mode != "decoupled")
    throw py::value_error("mode must be 'diagonal' or 'decoupled'");
  if (state_count > 0 && state >= state_count)
    throw py::value_error("state must be < the scene's state count");
  vislib::SegmentOptions o;
  o.resolution = resolution;
  o.near = near;
  o.eps_len = eps_len;
  o.eps_z = eps_z;
  o.tile_size = tile_size;
  o.coplanar = coplanar == "first" ? vislib::CoplanarRule::First : vislib::CoplanarRule::Both;
  o.mode = mode == "decoupled" ? vislib::DynamicMode::Decoupled : vislib::DynamicMode::Diagonal;
  o.depth_culling = depth_culling;
  o.simd = simd;
  o.state = state;
  return o;
}

// The kernel's counters under the names of `pvs segment --json`'s "counts".
py::dict stats_dict(const vislib::SegmentStats& s) {
  py::dict d;
  d["triangle_pixel_pairs"] = s.pair_tests;
  d["culled_pixel_pairs"] = s.culled_pairs;
  d["covered_pairs"] = s.covered_pairs;
  d["hidden_pairs"] = s.hidden_pairs;
  d["final_pieces"] = s.final_pieces;
  d["pixels_with_pieces"] = s.pixels_with_pieces;
  d["pieces_per_pixel"] = s.pieces_per_pixel();
  d["max_pieces_per_pixel"] = s.max_pieces_per_pixel;
  d["triangle_tiles"] = s.triangle_tiles;
  d["culled_triangle_tiles"] = s.culled_triangle_tiles;
  d["peak_tile_bytes"] = s.peak_tile_bytes;
  d["seconds"] = s.seconds;
  return d;
}

struct PySegmentResult {
  std::vector<uint32_t> visible, visible_spheres;
  vislib::SegmentStats stats;
};

struct PyRegionResult {
  std::vector<uint32_t> visible, visible_spheres;
  size_t segments = 0, runs = 0;
  double seconds = 0;
};

// A PVS file opened through the runtime (mmap). Not thread-safe (as pvs_runtime::Pvs).
struct PyPvs {
  std::string path;
  pvs_runtime::Pvs pvs;
};

uint32_t checked_cell(const PyPvs& p, int64_t cell) {
  if (cell < 0 || cell >= int64_t(p.pvs.cell_count()))
    throw py::index_error("cell " + std::to_string(cell) + " out of range (the file has " +
                          std::to_string(p.pvs.cell_count()) + " cells)");
  return uint32_t(cell);
}

py::tuple box_tuple(const pvs::Box& b) {
  return py::make_tuple(py::make_tuple(b.min[0], b.min[1], b.min[2]),
                        py::make_tuple(b.max[0], b.max[1], b.max[2]));
}

// A renderer: the Embree BVH of a scene, re-centred at `origin` (the CLI's `pvs view` centres it
// at the eye; frames are identical up to float rounding of the BVH coordinates).
struct PyRenderer {
  ScenePtr scene;
  std::unique_ptr<vislib::EmbreeScene> rt;
};

py::array_t<uint8_t> rgb_array(const vislib::Frame& f) {
  py::array_t<uint8_t> a({py::ssize_t(f.height), py::ssize_t(f.width), py::ssize_t(3)});
  std::copy(f.rgb.begin(), f.rgb.end(), a.mutable_data());
  return a;
}

// An H x W x 3 uint8 C-contiguous array into the library's RGB buffer.
std::vector<uint8_t> rgb_vector(
    const py::array_t<uint8_t, py::array::c_style | py::array::forcecast>& a, int& width,
    int& height, const char* name) {
  if (a.ndim() != 3 || a.shape(2) != 3)
    throw py::value_error(std::string(name) + " must be an H x W x 3 uint8 array");
  height = int(a.shape(0));
  width = int(a.shape(1));
  return std::vector<uint8_t>(a.data(), a.data() + a.size());
}

void same_size(const vislib::Frame& a, const vislib::Frame& b) {
  if (a.width != b.width || a.height != b.height)
    throw py::value_error("the two frames differ in size");
}

// The exceptions of the module and their translation (see the top of this file).
void bind_errors(py::module_& m) {
  static py::exception<vislib::InputError> input_error(m, "InputError", PyExc_ValueError);
  static py::exception<pvs::FormatError> format_error(m, "FormatError", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const vislib::InputError& e) {
      input_error(e.what());
    } catch (const pvs::FormatError& e) {
      format_error(e.what());
    } catch (const pvs_runtime::OpenError& e) {
      // OSError(errno, message): Python picks the subclass (FileNotFoundError for ENOENT).
      py::object err = py::reinterpret_steal<py::object>(
          PyObject_CallFunction(PyExc_OSError, "is", e.error_number(), e.what()));
      PyErr_SetObject(PyExc_OSError, err.ptr());
    }
  });
}

void bind_scenes(py::module_& m) {
  // ---- Scenes --------------------------------------------------------------------------------
  py::class_<PyScene, ScenePtr>(m, "Scene",
                                "A loaded scene (vislib::Scene); triangle ids in file order.")
      .def_property_readonly("path", [](const PyScene& s) { return s.path; })
      .def_property_readonly("triangle_count",
                             [](const PyScene& s) { return s.scene.triangle_count(); })
      .def_property_readonly("vertex_count",
                             [](const PyScene& s) { return s.scene.vertex_count(); })
      .def_property_readonly("object_count",
                             [](const PyScene& s) { return s.scene.objects.size(); })
      .def_property_readonly("sphere_count",
                             [](const PyScene& s) { return s.scene.sphere_count(); })
      .def_property_readonly("state_count", [](const PyScene& s) { return s.scene.state_count(); })
      .def_property_readonly("is_dynamic", [](const PyScene& s) { return s.scene.is_dynamic(); })
      .def_property_readonly(
          "bounds",
          [](const PyScene& s) {
            vislib::Box3 b = s.scene.bounds();
            return py::make_tuple(vec_tuple(b.min), vec_tuple(b.max));
          },
          "((xmin, ymin, zmin), (xmax, ymax, zmax)) over all states (vislib::Scene::bounds)")
      .def_property_readonly("warnings", [](const PyScene& s) { return s.warnings; })
      .def_property_readonly(
          "fingerprint", [](const PyScene& s) { return vislib::scene_fingerprint(s.scene); },
          "The 64-bit scene fingerprint a PVS of this scene stores (scene_fingerprint)")
      .def_property_readonly(
          "triangle_objects", [](const PyScene& s) { return to_numpy(s.scene.triangle_object); },
          "Object id of each triangle (uint32 array of triangle_count)")
      .def(
          "objects_of",
          [](const PyScene& s, const std::vector<uint32_t>& triangles) {
            for (uint32_t t : triangles)
              if (t >= s.scene.triangle_count()) throw py::index_error("triangle id out of range");
            return to_numpy(vislib::objects_of(s.scene, triangles));
          },
          py::arg("triangles"), "Sorted object ids owning the given triangle ids (objects_of)")
      .def("__repr__", [](const PyScene& s) {
        return "<pyvislib.Scene '" + s.path + "': " + std::to_string(s.scene.triangle_count()) +
               " triangles, " + std::to_string(s.scene.objects.size()) + " objects>";
      });

  m.def(
      "load_scene",
      [](const std::string& path, int states, int animation) {
        if (states < 1) throw py::value_error("states must be >= 1");
        auto s = std::make_shared<PyScene>();
        s->path = path;
        vislib::LoadOptions lo;
        lo.states = states;
        lo.animation = animation;
        py::gil_scoped_release release;
        s->scene = vislib::load_scene(path, lo, &s->warnings);
        return s;
      },
      py::arg("path"), py::arg("states") = 1, py::arg("animation") = -1,
      "Loads .glb .gltf .obj .ply .off .stl .spheres .bsp (vislib::load_scene). Raises "
      "pyvislib.InputError naming the file on a missing or malformed file.");
}

void bind_visibility(py::module_& m) {
  // ---- Visibility -----------------------------------------------------------------------------
  py::class_<PySegmentResult>(m, "SegmentResult")
      .def_property_readonly(
          "visible", [](const PySegmentResult& r) { return to_numpy(r.visible); },
          "Sorted visible triangle ids (uint32)")
      .def_property_readonly("visible_spheres",
                             [](const PySegmentResult& r) { return to_numpy(r.visible_spheres); })
      .def_property_readonly(
          "seconds", [](const PySegmentResult& r) { return r.stats.seconds; },
          "Wall time of the kernel call")
      .def_property_readonly("stats", [](const PySegmentResult& r) { return stats_dict(r.stats); });

  m.def(
      "segment_visibility",
      [](const ScenePtr& scene, const std::vector<double>& from, const std::vector<double>& to,
         int resolution, double near, double eps_len, double eps_z, int tile_size,
         const std::string& coplanar, const std::string& mode, bool depth_culling, bool simd,
         size_t state, std::optional<std::vector<double>> orientation, int threads) {
        vislib::SegmentOptions o =
            segment_options(resolution, near, eps_len, eps_z, tile_size, coplanar, mode,
                            depth_culling, simd, state, scene->scene.state_count());
        if (orientation) {
          if (orientation->size() != 9)
            throw py::value_error("orientation must hold 9 numbers (row-major rotation)");
          std::copy(orientation->begin(), orientation->end(), o.orientation.m);
          if (!vislib::is_rotation(o.orientation))
            throw py::value_error("orientation is not a rotation matrix (orthonormal, det +1)");
        }
        vislib::Vec3 v0 = vec3(from, "from_"), v1 = vec3(to, "to");
        auto r = std::make_unique<PySegmentResult>();
        {
          py::gil_scoped_release release;
          auto limit = thread_limit(threads);
          if (vislib::bvh_applies(scene->scene)) o.edge_lines = &scene->edge_lines(o.state);
          vislib::SegmentResult s = vislib::segment_visibility(scene->scene, v0, v1, o);
          r->visible = std::move(s.visible);
          r->visible_spheres = std::move(s.visible_spheres);
          r->stats = s.stats;
        }
        return r;
      },
      py::arg("scene"), py::arg("from_"), py::arg("to"), py::kw_only(), py::arg("resolution") = 512,
      py::arg("near") = vislib::kDefaultNear, py::arg("eps_len") = vislib::kDefaultEpsLen,
      py::arg("eps_z") = vislib::kDefaultEpsZ, py::arg("tile_size") = 0,
      py::arg("coplanar") = "both", py::arg("mode") = "diagonal", py::arg("depth_culling") = true,
      py::arg("simd") = true, py::arg("state") = 0, py::arg("orientation") = py::none(),
      py::arg("threads") = 0,
      "Triangles visible from the segment from_ -> to (vislib::segment_visibility): a cubemap of "
      "six resolution x resolution faces translating along it. Same options and defaults as "
      "`pvs segment` (--res, --near, --eps-len, --eps-z, --tile, --coplanar, --mode, "
      "--orientation, -j).");

  py::class_<PyRegionResult>(m, "RegionResult")
      .def_property_readonly("visible", [](const PyRegionResult& r) { return to_numpy(r.visible); })
      .def_property_readonly("visible_spheres",
                             [](const PyRegionResult& r) { return to_numpy(r.visible_spheres); })
      .def_readonly("segment_count", &PyRegionResult::segments)
      .def_readonly("run_count", &PyRegionResult::runs)
      .def_readonly("seconds", &PyRegionResult::seconds);

  m.def(
      "region_visibility",
      [](const ScenePtr& scene, const std::vector<double>& box_min,
         const std::vector<double>& box_max, int runs, uint64_t seed, int resolution, double near,
         double eps_len, double eps_z, int tile_size, const std::string& coplanar,
         const std::string& mode, int threads) {
        if (runs < 1) throw py::value_error("runs must be >= 1");
        vislib::RegionOptions ro;
        ro.segment = segment_options(resolution, near, eps_len, eps_z, tile_size, coplanar, mode,
                                     true, true, 0, scene->scene.state_count());
        ro.runs = runs;
        ro.seed = seed;
        vislib::Box3 box;
        box.extend(vec3(box_min, "box_min"));
        box.extend(vec3(box_max, "box_max"));
        auto r = std::make_unique<PyRegionResult>();
        {
          py::gil_scoped_release release;
          auto limit = thread_limit(threads);
          if (vislib::bvh_applies(scene->scene))
            ro.segment.edge_lines = &scene->edge_lines(ro.segment.state);
          vislib::RegionResult s = vislib::region_visibility(scene->scene, box, ro);
          r->visible = std::move(s.visible);
          r->visible_spheres = std::move(s.visible_spheres);
          r->segments = s.segments.size();
          r->runs = s.runs.size();
          r->seconds = s.seconds;
        }
        return r;
      },
      py::arg("scene"), py::arg("box_min"), py::arg("box_max"), py::kw_only(), py::arg("runs") = 1,
      py::arg("seed") = 1, py::arg("resolution") = 512, py::arg("near") = vislib::kDefaultNear,
      py::arg("eps_len") = vislib::kDefaultEpsLen, py::arg("eps_z") = vislib::kDefaultEpsZ,
      py::arg("tile_size") = 0, py::arg("coplanar") = "both", py::arg("mode") = "diagonal",
      py::arg("threads") = 0,
      "Triangles visible from the box box_min..box_max (vislib::region_visibility): runs cube "
      "orientations on each perimeter segment, united. Same as `pvs region --box ... --runs K`.");
}

void bind_pvs_files(py::module_& m) {
  // ---- PVS files ------------------------------------------------------------------------------
  py::class_<PyPvs>(m, "Pvs", "A PVS file opened through the runtime (pvs_runtime::Pvs, mmap).")
      .def(py::init([](const std::string& path, std::optional<uint64_t> expected_fingerprint,
                       bool verify_all_blocks) {
             pvs_runtime::OpenOptions o;
             o.expected_fingerprint = expected_fingerprint;
             o.verify_all_blocks = verify_all_blocks;
             return new PyPvs{path, pvs_runtime::Pvs::open(path, o)};
           }),
           py::arg("path"), py::arg("expected_fingerprint") = py::none(),
           py::arg("verify_all_blocks") = false,
           "Opens `path`. OSError (FileNotFoundError, ...) when it cannot be opened, "
           "pyvislib.FormatError on a malformed file or a fingerprint mismatch.")
      .def_property_readonly("path", [](const PyPvs& p) { return p.path; })
      .def_property_readonly("cell_count", [](const PyPvs& p) { return p.pvs.cell_count(); })
      .def_property_readonly("universe", [](const PyPvs& p) { return p.pvs.info().universe; })
      .def_property_readonly(
          "granularity",
          [](const PyPvs& p) {
            return p.pvs.info().granularity == pvs::Granularity::Object ? "object" : "triangle";
          })
      .def_property_readonly("scene_fingerprint",
                             [](const PyPvs& p) { return p.pvs.info().scene_fingerprint; })
      .def_property_readonly("partial", [](const PyPvs& p) { return p.pvs.info().partial; })
      .def_property_readonly("metadata", [](const PyPvs& p) { return p.pvs.info().metadata; })
      .def_property_readonly("file_size", [](const PyPvs& p) { return p.pvs.file_size(); })
      .def(
          "find_cell",
          [](const PyPvs& p, const std::vector<double>& position) -> std::optional<uint32_t> {
            if (position.size() != 3) throw py::value_error("position must hold 3 numbers");
            return p.pvs.find_cell(position.data());
          },
          py::arg("position"), "The cell containing position (x, y, z), or None (Pvs::find_cell)")
      .def(
          "cell_box",
          [](const PyPvs& p, int64_t cell) {
            return box_tuple(p.pvs.info().layout.cell_box(checked_cell(p, cell)));
          },
          py::arg("cell"), "The lookup box ((min), (max)) of a cell")
      .def(
          "view_region",
          [](const PyPvs& p, int64_t cell) {
            return box_tuple(p.pvs.info().layout.view_region(checked_cell(p, cell)));
          },
          py::arg("cell"), "The view region ((min), (max)) the cell's set was baked for")
      .def(
          "visible_count",
          [](const PyPvs& p, int64_t cell) { return p.pvs.visible_count(checked_cell(p, cell)); },
          py::arg("cell"))
      .def(
          "is_absent",
          [](PyPvs& p, int64_t cell) { return p.pvs.is_absent(checked_cell(p, cell)); },
          py::arg("cell"))
      .def(
          "visible_ids",
          [](PyPvs& p, int64_t cell) { return to_numpy(p.pvs.visible_ids(checked_cell(p, cell))); },
          py::arg("cell"),
          "Sorted visible ids of a cell as a uint32 array (Pvs::visible_ids); triangle or object "
          "ids as `granularity` says")
      .def(
          "neighbours",
          [](const PyPvs& p, int64_t cell, double margin) {
            if (!(margin >= 0)) throw py::value_error("margin must be >= 0");
            return to_numpy(p.pvs.neighbours(checked_cell(p, cell), margin));
          },
          py::arg("cell"), py::arg("margin") = 0.0);
}

void bind_frames(py::module_& m) {
  // ---- Frames ---------------------------------------------------------------------------------
  py::class_<vislib::Frame>(m, "Frame", "A rendered frame (vislib::Frame).")
      .def_readonly("width", &vislib::Frame::width)
      .def_readonly("height", &vislib::Frame::height)
      .def_property_readonly("rgb", &rgb_array, "H x W x 3 uint8 colours")
      .def_property_readonly(
          "depth",
          [](const vislib::Frame& f) {
            py::array_t<float> a({py::ssize_t(f.height), py::ssize_t(f.width)});
            std::copy(f.depth.begin(), f.depth.end(), a.mutable_data());
            return a;
          },
          "H x W float32 hit distance, +inf where nothing is hit")
      .def_property_readonly(
          "triangles",
          [](const vislib::Frame& f) {
            U32Array a({py::ssize_t(f.height), py::ssize_t(f.width)});
            std::copy(f.tri.begin(), f.tri.end(), a.mutable_data());
            return a;
          },
          "H x W uint32 triangle id per pixel, NO_HIT where nothing is hit")
      .def(
          "save",
          [](const vislib::Frame& f, const std::string& path) {
            vislib::write_rgb8_image(path, f.width, f.height, f.rgb);
          },
          py::arg("path"), "Writes the colours as an image (PNG, EXR, ... by extension; OIIO)");
  m.attr("NO_HIT") = vislib::kNoHit;

  py::class_<PyRenderer>(m, "Renderer",
                         "The Embree reference renderer of a scene (vislib::render_frame).")
      .def(
          py::init([](const ScenePtr& scene, std::optional<std::vector<double>> origin) {
            vislib::Box3 b = scene->scene.bounds();
            vislib::Vec3 o = origin ? vec3(*origin, "origin")
                                    : vislib::Vec3{(b.min.x + b.max.x) / 2, (b.min.y + b.max.y) / 2,
                                                   (b.min.z + b.max.z) / 2};
            auto r = new PyRenderer{scene, nullptr};
            py::gil_scoped_release release;
            r->rt = std::make_unique<vislib::EmbreeScene>(scene->scene, 0.0, o);
            return r;
          }),
          py::arg("scene"), py::arg("origin") = py::none(),
          "Builds the BVH (key state 0) re-centred at `origin` (default: the centre of the scene's "
          "bounds; `pvs view` centres it at the eye).")
      .def(
          "render",
          [](const PyRenderer& r, const std::vector<double>& eye,
             const std::vector<double>& forward, const std::vector<double>& up, double vfov_degrees,
             int width, int height, double z_near, std::optional<std::vector<uint32_t>> visible,
             int threads) {
            vislib::Camera c;
            c.eye = vec3(eye, "eye");
            c.forward = vec3(forward, "forward");
            c.up = vec3(up, "up");
            if (vislib::length(c.forward) == 0) throw py::value_error("forward must be non-zero");
            if (vislib::length(vislib::cross(c.forward, c.up)) == 0)
              throw py::value_error("up must not be parallel to forward");
            if (!(vfov_degrees > 0 && vfov_degrees < 180))
              throw py::value_error("vfov_degrees must be in (0, 180)");
            if (width < 1 || height < 1) throw py::value_error("width and height must be >= 1");
            if (!(z_near > 0)) throw py::value_error("z_near must be > 0");
            c.vfov_degrees = vfov_degrees;
            c.width = width;
            c.height = height;
            c.z_near = z_near;
            size_t n = r.scene->scene.triangle_count();
            std::vector<uint8_t> mask;
            if (visible) {
              for (uint32_t t : *visible)
                if (t >= n) throw py::index_error("visible: triangle id out of range");
              std::vector<uint32_t> ids = *visible;
              std::sort(ids.begin(), ids.end());
              mask = vislib::triangle_mask(n, ids);
            }
            py::gil_scoped_release release;
            auto limit = thread_limit(threads);
            return vislib::render_frame(r.scene->scene, *r.rt, c, visible ? mask.data() : nullptr);
          },
          py::arg("eye"), py::arg("forward"), py::arg("up") = std::vector<double>{0, 1, 0},
          py::kw_only(), py::arg("vfov_degrees") = 90.0, py::arg("width") = 640,
          py::arg("height") = 480, py::arg("z_near") = vislib::kDefaultNear,
          py::arg("visible") = py::none(), py::arg("threads") = 0,
          "Renders the full scene, or only the triangle ids in `visible` (a visible set), from "
          "a perspective camera (render.h's convention).");
}

void bind_metrics(py::module_& m) {
  // ---- Metrics --------------------------------------------------------------------------------
  py::class_<vislib::FrameQuality>(m, "FrameQuality")
      .def_readonly("pixels", &vislib::FrameQuality::pixels)
      .def_readonly("missed_pixels", &vislib::FrameQuality::missed_pixels)
      .def_readonly("epsilon", &vislib::FrameQuality::epsilon, "share of missed pixels, [0, 1]")
      .def_readonly("mse", &vislib::FrameQuality::mse)
      .def_readonly("psnr", &vislib::FrameQuality::psnr, "dB; inf when identical")
      .def_readonly("ssim", &vislib::FrameQuality::ssim, "windowed SSIM of luminance")
      .def("__repr__", [](const vislib::FrameQuality& q) {
        return "<FrameQuality epsilon=" + std::to_string(q.epsilon) +
               " psnr=" + std::to_string(q.psnr) + " ssim=" + std::to_string(q.ssim) + ">";
      });
  m.def(
      "frame_quality",
      [](const vislib::Frame& truth, const vislib::Frame& test) {
        same_size(truth, test);
        if (truth.width < vislib::kSsimWindow || truth.height < vislib::kSsimWindow)
          throw py::value_error("frames must be at least 11 x 11 pixels (the SSIM window)");
        py::gil_scoped_release release;
        return vislib::frame_quality(truth, test);
      },
      py::arg("truth"), py::arg("test"),
      "epsilon, MSE, PSNR and windowed SSIM of `test` against the full-scene `truth` "
      "(vislib::frame_quality).");
  m.def(
      "missed_pixels",
      [](const vislib::Frame& truth, const vislib::Frame& test) {
        same_size(truth, test);
        std::vector<uint8_t> v = vislib::missed_pixels(truth, test);
        py::array_t<bool> a({py::ssize_t(truth.height), py::ssize_t(truth.width)});
        for (size_t i = 0; i < v.size(); ++i) a.mutable_data()[i] = v[i] != 0;
        return a;
      },
      py::arg("truth"), py::arg("test"), "H x W bool mask of the pixels epsilon counts");
  m.def(
      "psnr",
      [](const py::array_t<uint8_t, py::array::c_style | py::array::forcecast>& a,
         const py::array_t<uint8_t, py::array::c_style | py::array::forcecast>& b) {
        int wa, ha, wb, hb;
        auto va = rgb_vector(a, wa, ha, "a"), vb = rgb_vector(b, wb, hb, "b");
        if (wa != wb || ha != hb || va.empty())
          throw py::value_error("a and b must be the same non-empty size");
        return vislib::psnr_rgb(va, vb);
      },
      py::arg("a"), py::arg("b"), "PSNR in dB of two H x W x 3 uint8 images (psnr_rgb)");
  m.def(
      "ssim",
      [](const py::array_t<uint8_t, py::array::c_style | py::array::forcecast>& a,
         const py::array_t<uint8_t, py::array::c_style | py::array::forcecast>& b,
         bool whole_image) {
        int wa, ha, wb, hb;
        auto va = rgb_vector(a, wa, ha, "a"), vb = rgb_vector(b, wb, hb, "b");
        if (wa != wb || ha != hb) throw py::value_error("a and b must be the same size");
        if (whole_image) {
          if (wa < 1 || ha < 1) throw py::value_error("images must be non-empty");
          return vislib::ssim_whole_image(wa, ha, va, vb);
        }
        if (wa < vislib::kSsimWindow || ha < vislib::kSsimWindow)
          throw py::value_error("images must be at least 11 x 11 pixels (the SSIM window)");
        return vislib::ssim_luminance(wa, ha, va, vb);
      },
      py::arg("a"), py::arg("b"), py::arg("whole_image") = false,
      "SSIM of the luminance of two H x W x 3 uint8 images: windowed (ssim_luminance, 11 x 11 "
      "Gaussian) or with one window over the whole image (ssim_whole_image, CloVR's continuity "
      "figure).");
  m.def(
      "discontinuity",
      [](const py::array_t<double, py::array::c_style | py::array::forcecast>& truth_xy,
         double radius) {
        if (truth_xy.ndim() != 3 || truth_xy.shape(2) != 2)
          throw py::value_error("truth_xy must be an H x W x 2 array (NaN = no position)");
        if (!(radius > 0)) throw py::value_error("radius must be > 0");
        const int h = int(truth_xy.shape(0)), w = int(truth_xy.shape(1));
        if (w < 1 || h < 1) throw py::value_error("truth_xy must be non-empty");
        std::vector<double> xy(truth_xy.data(), truth_xy.data() + truth_xy.size());
        vislib::Discontinuity d;
        {
          py::gil_scoped_release release;
          d = vislib::discontinuity(w, h, xy, radius);
        }
        py::array_t<double> map({py::ssize_t(h), py::ssize_t(w)});
        std::copy(d.delta.begin(), d.delta.end(), map.mutable_data());
        py::dict r;
        r["delta"] = map;
        r["pixels"] = d.pixels;
        r["mean"] = d.mean;
        r["mean_abs"] = d.mean_abs;
        r["max"] = d.max;
        r["share_above_half"] = d.share_above_half;
        r["coincident_pairs"] = d.coincident_pairs;
        return r;
      },
      py::arg("truth_xy"), py::arg("radius") = vislib::kDiscontinuityRadius,
      "The near-far paper's discontinuity delta (Eqs. 7-8, vislib::discontinuity): truth_xy[y, x] "
      "is the truth-image position (column, row) of the scene point pixel (x, y) shows; returns "
      "the per-pixel map (NaN where undefined) and its summaries.");
  m.def(
      "project_to_pixel",
      [](const std::vector<double>& eye, const std::vector<double>& forward,
         const std::vector<double>& up, const std::vector<double>& point, double vfov_degrees,
         int width, int height) -> std::optional<py::tuple> {
        vislib::Camera c;
        c.eye = vec3(eye, "eye");
        c.forward = vec3(forward, "forward");
        c.up = vec3(up, "up");
        if (vislib::length(vislib::cross(c.forward, c.up)) == 0)
          throw py::value_error("forward must be non-zero and not parallel to up");
        if (!(vfov_degrees > 0 && vfov_degrees < 180) || width < 1 || height < 1)
          throw py::value_error("bad camera (vfov in (0, 180), width and height >= 1)");
        c.vfov_degrees = vfov_degrees;
        c.width = width;
        c.height = height;
        auto t = vislib::project_to_pixel(c, vec3(point, "point"));
        if (!t) return std::nullopt;
        return py::make_tuple((*t)[0], (*t)[1]);
      },
      py::arg("eye"), py::arg("forward"), py::arg("up"), py::arg("point"), py::kw_only(),
      py::arg("vfov_degrees") = 90.0, py::arg("width") = 640, py::arg("height") = 480,
      "Where `point` lands in the camera's image (column, row; pixel centres at integers), or None "
      "behind the camera (vislib::project_to_pixel, the inverse of the renderer's pixel rays).");
  m.def(
      "compare_sets",
      [](std::vector<uint32_t> set, std::vector<uint32_t> reference) {
        std::sort(set.begin(), set.end());
        set.erase(std::unique(set.begin(), set.end()), set.end());
        std::sort(reference.begin(), reference.end());
        reference.erase(std::unique(reference.begin(), reference.end()), reference.end());
        vislib::SetComparison c = vislib::compare_sets(set, reference);
        py::dict d;
        d["size"] = c.size;
        d["reference_size"] = c.reference_size;
        d["common"] = c.common;
        d["missed"] = c.missed;
        d["extra"] = c.extra;
        return d;
      },
      py::arg("set"), py::arg("reference"),
      "Sizes of set, reference, their intersection, reference ids the set misses and extra ids "
      "(vislib::compare_sets)");
}

}  // namespace

PYBIND11_MODULE(pyvislib, m) {
  m.doc() =
      "vislib from Python: scenes, from-segment/region visibility, PVS files, reference frames "
      "and their metrics (docs/python.md).";
  m.attr("__license__") = VISLIB_LICENSE;  // SPDX identifier, set by python/CMakeLists.txt

  bind_errors(m);
  bind_scenes(m);
  bind_visibility(m);
  bind_pvs_files(m);
  bind_frames(m);
  bind_metrics(m);
}
