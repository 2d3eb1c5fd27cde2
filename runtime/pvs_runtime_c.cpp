// pvs_runtime_c.cpp: the C API (runtime/pvs_runtime_c.h) over pvs_runtime::Pvs. Every entry
// point catches every exception and maps it to a status code plus a per-thread message.
#include "runtime/pvs_runtime_c.h"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <new>
#include <string>

#include "runtime/c_api_support.h"
#include "runtime/pvs_runtime.h"

struct pvs_rt {
  pvs_runtime::Pvs pvs;
};

namespace {

thread_local std::string g_last_error;  // per thread, so calls on distinct handles never race

using pvs_runtime::detail::fail;

// Runs f() and maps exceptions to status codes.
template <class F>
pvs_rt_status guarded(F&& f) {
  try {
    return f();
  } catch (const pvs_runtime::FingerprintMismatch& e) {
    return fail(PVS_RT_FINGERPRINT, e.what());
  } catch (const pvs::FormatError& e) {
    return fail(PVS_RT_FORMAT, e.what());
  } catch (const pvs_runtime::OpenError& e) {
    return fail(PVS_RT_IO, e.what());
  } catch (const std::bad_alloc&) {
    return fail(PVS_RT_OUT_OF_MEMORY, "out of memory");
  } catch (const std::exception& e) {
    return fail(PVS_RT_INTERNAL, e.what());
  } catch (...) {
    return fail(PVS_RT_INTERNAL, "unknown error");
  }
}

pvs_rt_status check_cell(const pvs_rt* h, uint32_t cell) {
  if (cell >= h->pvs.cell_count())
    return fail(PVS_RT_INVALID_ARGUMENT, "cell " + std::to_string(cell) +
                                             " out of range (the file has " +
                                             std::to_string(h->pvs.cell_count()) + " cells)");
  return PVS_RT_OK;
}

}  // namespace

namespace pvs_runtime::detail {
pvs_rt_status fail(pvs_rt_status s, const std::string& message) {
  g_last_error = message;
  return s;
}
}  // namespace pvs_runtime::detail

extern "C" {

pvs_rt_status pvs_rt_open(const char* path, int check_fingerprint, uint64_t expected_fingerprint,
                          pvs_rt** out) {
  if (out) *out = nullptr;
  if (!path || !out)
    return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_open: path and out must not be null");
  return guarded([&] {
    pvs_runtime::OpenOptions opt;
    if (check_fingerprint) opt.expected_fingerprint = expected_fingerprint;
    *out = new pvs_rt{pvs_runtime::Pvs::open(path, opt)};
    return PVS_RT_OK;
  });
}

pvs_rt_status pvs_rt_open_ranges(uint64_t file_size, pvs_rt_read_fn read, void* user,
                                 int check_fingerprint, uint64_t expected_fingerprint,
                                 pvs_rt** out) {
  if (out) *out = nullptr;
  if (!read || !out)
    return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_open_ranges: read and out must not be null");
  return guarded([&] {
    pvs_runtime::OpenOptions opt;
    if (check_fingerprint) opt.expected_fingerprint = expected_fingerprint;
    auto fn = [read, user](uint64_t offset, size_t n, char* dst) {
      if (read(user, offset, uint64_t(n), dst) != 0)
        throw pvs_runtime::OpenError("cannot read " + std::to_string(n) + " bytes at byte " +
                                         std::to_string(offset) + " (the read callback failed)",
                                     EIO);
    };
    *out = new pvs_rt{pvs_runtime::Pvs::open_ranges(file_size, fn, opt)};
    return PVS_RT_OK;
  });
}

void pvs_rt_close(pvs_rt* handle) {
  delete handle;
}

pvs_rt_status pvs_rt_get_info(const pvs_rt* h, pvs_rt_info* out) {
  if (!h || !out) return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_get_info: null argument");
  const pvs::FileInfo& i = h->pvs.info();
  out->format_version = i.version;
  out->cell_count = h->pvs.cell_count();
  out->universe = i.universe;
  out->granularity = uint32_t(i.granularity);
  out->layout = uint32_t(i.layout.kind);
  out->partial = i.partial ? 1 : 0;
  out->scene_fingerprint = i.scene_fingerprint;
  out->file_size = h->pvs.file_size();
  return PVS_RT_OK;
}

pvs_rt_status pvs_rt_find_cell(const pvs_rt* h, const double position[3], uint32_t* cell) {
  if (!h || !position || !cell)
    return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_find_cell: null argument");
  for (int k = 0; k < 3; ++k)
    if (!std::isfinite(position[k]))
      return fail(PVS_RT_INVALID_ARGUMENT,
                  "pvs_rt_find_cell: position[" + std::to_string(k) + "] is not finite");
  return guarded([&] {
    auto c = h->pvs.find_cell(position);
    if (!c)
      return fail(PVS_RT_NOT_FOUND, "no cell contains (" + std::to_string(position[0]) + ", " +
                                        std::to_string(position[1]) + ", " +
                                        std::to_string(position[2]) + ")");
    *cell = *c;
    return PVS_RT_OK;
  });
}

pvs_rt_status pvs_rt_cell_box(const pvs_rt* h, uint32_t cell, double min[3], double max[3]) {
  if (!h || !min || !max) return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_cell_box: null argument");
  if (pvs_rt_status s = check_cell(h, cell)) return s;
  pvs::Box b = h->pvs.info().layout.cell_box(cell);
  for (int k = 0; k < 3; ++k) {
    min[k] = b.min[k];
    max[k] = b.max[k];
  }
  return PVS_RT_OK;
}

pvs_rt_status pvs_rt_neighbours(const pvs_rt* h, uint32_t cell, double margin, uint32_t* out,
                                size_t capacity, size_t* count) {
  if (!h || !count || (capacity && !out))
    return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_neighbours: null argument");
  if (!(margin >= 0))
    return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_neighbours: margin must be >= 0");
  if (pvs_rt_status s = check_cell(h, cell)) return s;
  return guarded([&] {
    std::vector<uint32_t> n = h->pvs.neighbours(cell, margin);
    *count = n.size();
    if (n.size() > capacity)
      return fail(PVS_RT_BUFFER_TOO_SMALL, "pvs_rt_neighbours: " + std::to_string(n.size()) +
                                               " neighbours, capacity " + std::to_string(capacity));
    if (!n.empty()) std::memcpy(out, n.data(), n.size() * sizeof(uint32_t));
    return PVS_RT_OK;
  });
}

pvs_rt_status pvs_rt_visible_count(const pvs_rt* h, uint32_t cell, uint32_t* count) {
  if (!h || !count) return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_visible_count: null argument");
  if (pvs_rt_status s = check_cell(h, cell)) return s;
  *count = h->pvs.visible_count(cell);
  return PVS_RT_OK;
}

pvs_rt_status pvs_rt_visible_ids(pvs_rt* h, uint32_t cell, uint32_t* out, size_t capacity,
                                 size_t* count) {
  if (!h || !count || (capacity && !out))
    return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_visible_ids: null argument");
  if (pvs_rt_status s = check_cell(h, cell)) return s;
  return guarded([&] {
    uint32_t n = h->pvs.visible_count(cell);
    *count = n;
    if (n > capacity)
      return fail(PVS_RT_BUFFER_TOO_SMALL, "pvs_rt_visible_ids: cell " + std::to_string(cell) +
                                               " has " + std::to_string(n) + " ids, capacity " +
                                               std::to_string(capacity));
    if (h->pvs.info().partial && h->pvs.is_absent(cell))
      return fail(PVS_RT_ABSENT, "cell " + std::to_string(cell) +
                                     " is absent (this file is a shard; merge the shards first)");
    std::vector<uint32_t> ids =
        h->pvs.visible_ids(cell);  // checks the decoded count against the index
    *count = ids.size();
    if (!ids.empty()) std::memcpy(out, ids.data(), ids.size() * sizeof(uint32_t));
    return PVS_RT_OK;
  });
}

pvs_rt_status pvs_rt_block_range(const pvs_rt* h, uint32_t cell, uint64_t* offset, uint32_t* size) {
  if (!h || !offset || !size)
    return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_block_range: null argument");
  if (pvs_rt_status s = check_cell(h, cell)) return s;
  const auto r = h->pvs.block_range(cell);
  *offset = r.first;
  *size = r.second;
  return PVS_RT_OK;
}

pvs_rt_status pvs_rt_delta_chain(pvs_rt* h, uint32_t cell, uint32_t* out, size_t capacity,
                                 size_t* count) {
  if (!h || !count || (capacity && !out))
    return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_delta_chain: null argument");
  if (pvs_rt_status s = check_cell(h, cell)) return s;
  return guarded([&] {
    const std::vector<uint32_t> chain = h->pvs.delta_chain(cell);
    *count = chain.size();
    if (chain.size() > capacity)
      return fail(PVS_RT_BUFFER_TOO_SMALL, "pvs_rt_delta_chain: cell " + std::to_string(cell) +
                                               "'s chain has " + std::to_string(chain.size()) +
                                               " cells, capacity " + std::to_string(capacity));
    std::memcpy(out, chain.data(), chain.size() * sizeof(uint32_t));
    return PVS_RT_OK;
  });
}

pvs_rt_status pvs_rt_prefetch(pvs_rt* h, uint32_t cell) {
  if (!h) return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_prefetch: null handle");
  if (pvs_rt_status s = check_cell(h, cell)) return s;
  h->pvs.prefetch(cell);
  return PVS_RT_OK;
}

uint32_t pvs_rt_version(void) {
  return VISLIB_VERSION;
}

const char* pvs_rt_version_string(void) {
  return VISLIB_VERSION_STRING;
}

// The byte stream of docs/pvs-format.md, "The scene fingerprint" (the same stream as
// vislib::scene_fingerprint, which the fingerprint test compares against), through the one
// implementation of that stream, pvs::SceneFingerprint.
pvs_rt_status pvs_rt_scene_fingerprint(const pvs_rt_mesh* meshes, size_t mesh_count,
                                       uint32_t state_count, uint32_t object_count,
                                       uint64_t* fingerprint) {
  if (!fingerprint || (mesh_count && !meshes))
    return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_scene_fingerprint: null argument");
  if (state_count < 1)
    return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_scene_fingerprint: state_count must be >= 1");
  uint64_t vertices = 0, triangles = 0;
  for (size_t m = 0; m < mesh_count; ++m) {
    const pvs_rt_mesh& mesh = meshes[m];
    const std::string where = "pvs_rt_scene_fingerprint: mesh " + std::to_string(m) + ": ";
    if (bool(mesh.positions_f32) == bool(mesh.positions_f64) && mesh.vertex_count)
      return fail(PVS_RT_INVALID_ARGUMENT,
                  where + "give exactly one of positions_f32 and positions_f64");
    if (mesh.triangle_count && !mesh.indices)
      return fail(PVS_RT_INVALID_ARGUMENT, where + "indices is null");
    for (size_t t = 0; t < mesh.triangle_count; ++t) {
      const uint32_t ob = mesh.triangle_objects ? mesh.triangle_objects[t] : mesh.object_id;
      if (ob >= object_count)
        return fail(PVS_RT_INVALID_ARGUMENT,
                    where + "object " + std::to_string(ob) + " of triangle " + std::to_string(t) +
                        " >= object_count " + std::to_string(object_count));
      if (!mesh.triangle_objects) break;
    }
    for (size_t i = 0; i < 3 * mesh.triangle_count; ++i)
      if (mesh.indices[i] >= mesh.vertex_count)
        return fail(PVS_RT_INVALID_ARGUMENT, where + "index " + std::to_string(mesh.indices[i]) +
                                                 " of triangle " + std::to_string(i / 3) +
                                                 " >= vertex_count " +
                                                 std::to_string(mesh.vertex_count));
    vertices += mesh.vertex_count;
    triangles += mesh.triangle_count;
  }
  if (vertices + triangles > 0 && vertices + mesh_count > (uint64_t(1) << 32))
    return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_scene_fingerprint: more than 2^32 vertices");
  return guarded([&] {
    // A scene without vertices has no state (vislib::Scene::positions is empty).
    pvs::SceneFingerprint f(vertices ? state_count : 0, vertices, triangles, object_count);
    for (uint32_t s = 0; vertices && s < state_count; ++s)
      for (size_t m = 0; m < mesh_count; ++m) {
        const pvs_rt_mesh& mesh = meshes[m];
        const size_t base = 3 * size_t(s) * mesh.vertex_count;
        for (size_t i = 0; i < mesh.vertex_count; ++i) {
          double p[3];
          for (int k = 0; k < 3; ++k)
            p[k] = mesh.positions_f64 ? mesh.positions_f64[base + 3 * i + k]
                                      : double(mesh.positions_f32[base + 3 * i + k]);
          f.add_position(p[0], p[1], p[2]);
        }
      }
    uint32_t offset = 0;
    for (size_t m = 0; m < mesh_count; ++m) {
      const pvs_rt_mesh& mesh = meshes[m];
      for (size_t t = 0; t < mesh.triangle_count; ++t)
        f.add_triangle(offset + mesh.indices[3 * t], offset + mesh.indices[3 * t + 1],
                       offset + mesh.indices[3 * t + 2],
                       mesh.triangle_objects ? mesh.triangle_objects[t] : mesh.object_id);
      offset += uint32_t(mesh.vertex_count);
    }
    *fingerprint = f.value();
    return PVS_RT_OK;
  });
}

const char* pvs_rt_last_error(void) {
  return g_last_error.c_str();
}

const char* pvs_rt_status_name(int status) {
  // Compared as an int: loading an out-of-range value as the enum type is undefined behaviour.
  if (status < PVS_RT_OK || status > PVS_RT_INTERNAL) return "unknown";
  switch (static_cast<pvs_rt_status>(status)) {
    case PVS_RT_OK:
      return "ok";
    case PVS_RT_INVALID_ARGUMENT:
      return "invalid argument";
    case PVS_RT_IO:
      return "i/o";
    case PVS_RT_FORMAT:
      return "format";
    case PVS_RT_FINGERPRINT:
      return "fingerprint mismatch";
    case PVS_RT_NOT_FOUND:
      return "not found";
    case PVS_RT_BUFFER_TOO_SMALL:
      return "buffer too small";
    case PVS_RT_ABSENT:
      return "absent";
    case PVS_RT_OUT_OF_MEMORY:
      return "out of memory";
    case PVS_RT_INTERNAL:
      return "internal";
  }
  return "unknown";
}

}  // extern "C"
