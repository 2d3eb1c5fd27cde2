/* pvs_runtime_c.h: the C API of the PVS runtime loader (runtime/pvs_runtime.h), for engines that
 * are not written in C++. Same functions, an opaque handle, error codes; no exception ever
 * crosses this boundary. docs/runtime.md documents it; examples/engine_loop.c uses it.
 *
 * Errors: every function returns a pvs_rt_status. On failure, pvs_rt_last_error() returns a
 * message naming the file and the problem (for a malformed file, "byte N: ..."). The message is
 * per thread and stays valid until the next failing call of this API on the same thread.
 *
 * Thread-safety: a handle must not be used by two threads at once; distinct handles may. */
#ifndef PVS_RUNTIME_C_H
#define PVS_RUNTIME_C_H

#include <stddef.h>
#include <stdint.h>

#include "runtime/vislib_version.h"

/* PVS_RT_API marks the exported C functions. libvislib_runtime.so is built with every other
 * symbol hidden (-fvisibility=hidden plus a version script), so its ABI is this C API alone. */
#if defined(VISLIB_RT_BUILDING_SHARED) && defined(__GNUC__)
#define PVS_RT_API __attribute__((visibility("default")))
#else
#define PVS_RT_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

typedef struct pvs_rt pvs_rt; /* an open PVS file (memory-mapped, or read by byte range) */

typedef enum pvs_rt_status {
  PVS_RT_OK = 0,
  PVS_RT_INVALID_ARGUMENT = 1, /* a null pointer, a cell id >= cell_count, margin < 0 */
  PVS_RT_IO = 2,               /* the file cannot be opened, sized or memory-mapped */
  PVS_RT_FORMAT = 3,           /* not a PVS file, truncated, corrupt (checksum), too new, ... */
  PVS_RT_FINGERPRINT = 4,      /* a valid PVS, but baked for another scene */
  PVS_RT_NOT_FOUND = 5,        /* no cell contains the position */
  PVS_RT_BUFFER_TOO_SMALL = 6, /* *count holds the capacity needed */
  PVS_RT_ABSENT = 7,           /* the cell has no data in this (partial) file */
  PVS_RT_OUT_OF_MEMORY = 8,
  PVS_RT_INTERNAL = 9
} pvs_rt_status;

typedef struct pvs_rt_info {
  uint32_t format_version;
  uint32_t cell_count;
  uint32_t universe;    /* ids are < universe */
  uint32_t granularity; /* 0: triangle ids, 1: object ids */
  uint32_t layout;      /* 0: grid, 1: box list, 2: BSP tree */
  uint32_t partial;     /* 1 if some cells may be absent */
  uint64_t scene_fingerprint;
  uint64_t file_size;
} pvs_rt_info;

/* Opens `path` memory-mapped and checks header, layout and index. If check_fingerprint is
 * nonzero, a file whose scene fingerprint differs from expected_fingerprint is rejected with
 * PVS_RT_FINGERPRINT. On success *out is a handle to release with pvs_rt_close; on failure *out
 * is set to NULL. */
PVS_RT_API pvs_rt_status pvs_rt_open(const char* path, int check_fingerprint,
                                     uint64_t expected_fingerprint, pvs_rt** out);
/* Reads `size` bytes at byte `offset` of the file into `out` (offset + size <= the file size,
 * size > 0); returns 0 on success, anything else on failure. `user` is pvs_rt_open_ranges's. */
typedef int (*pvs_rt_read_fn)(void* user, uint64_t offset, uint64_t size, void* out);

/* Opens a PVS file of `file_size` bytes that `read` serves by byte range instead of a path (a file
 * fetched over HTTP range requests, as the web client does): the open asks for the header, the
 * layout section and the index; pvs_rt_visible_ids for the cell's block and the blocks of its
 * Delta chain (at most pvs_rt_info's max delta depth more), every time (no cache: the caller may
 * keep one); nothing else ever. pvs_rt_prefetch does nothing on such a handle
 * (pvs_rt_block_range names what to fetch ahead). `read` and `user` must stay valid until
 * pvs_rt_close. A failing read makes the call that needed it return PVS_RT_IO. Otherwise as
 * pvs_rt_open. */
PVS_RT_API pvs_rt_status pvs_rt_open_ranges(uint64_t file_size, pvs_rt_read_fn read, void* user,
                                            int check_fingerprint, uint64_t expected_fingerprint,
                                            pvs_rt** out);

/* Releases the handle (NULL is allowed). */
PVS_RT_API void pvs_rt_close(pvs_rt* handle);

/* The file's header fields. */
PVS_RT_API pvs_rt_status pvs_rt_get_info(const pvs_rt* handle, pvs_rt_info* out);

/* The cell containing position (x, y, z; y up; boundaries inclusive, lowest id wins), or
 * PVS_RT_NOT_FOUND. A NaN or infinite coordinate is PVS_RT_INVALID_ARGUMENT. */
PVS_RT_API pvs_rt_status pvs_rt_find_cell(const pvs_rt* handle, const double position[3],
                                          uint32_t* cell);

/* The lookup box of the cell (min and max corners, scene units, y up). */
PVS_RT_API pvs_rt_status pvs_rt_cell_box(const pvs_rt* handle, uint32_t cell, double min[3],
                                         double max[3]);

/* The cells whose boxes come within `margin` (>= 0, +INFINITY for all cells; NaN is
 * PVS_RT_INVALID_ARGUMENT) of cell's box, sorted, without `cell`.
 * Writes at most `capacity` ids to `out`; *count receives the number of neighbours. If it
 * exceeds capacity, returns PVS_RT_BUFFER_TOO_SMALL (27 is always enough for margin 0 on a grid).
 */
PVS_RT_API pvs_rt_status pvs_rt_neighbours(const pvs_rt* handle, uint32_t cell, double margin,
                                           uint32_t* out, size_t capacity, size_t* count);

/* Number of visible ids of the cell, from the index (no block read): the capacity that
 * pvs_rt_visible_ids needs. */
PVS_RT_API pvs_rt_status pvs_rt_visible_count(const pvs_rt* handle, uint32_t cell, uint32_t* count);

/* The cell's visible ids (triangle or object ids, as pvs_rt_info.granularity says), sorted.
 * *count receives their number; PVS_RT_BUFFER_TOO_SMALL if it exceeds capacity (nothing
 * written). PVS_RT_FORMAT if the block is corrupt, PVS_RT_ABSENT for an absent cell. */
PVS_RT_API pvs_rt_status pvs_rt_visible_ids(pvs_rt* handle, uint32_t cell, uint32_t* out,
                                            size_t capacity, size_t* count);

/* The byte range of the cell's block (*offset from the start of the file, *size bytes), from the
 * index: what a client streaming the file fetches ahead for a cell it may enter. */
PVS_RT_API pvs_rt_status pvs_rt_block_range(const pvs_rt* handle, uint32_t cell, uint64_t* offset,
                                            uint32_t* size);

/* The cells whose blocks pvs_rt_visible_ids(cell) reads: `cell` first, then the cell each Delta
 * block refers to (at most pvs_rt_info's max delta depth more). Reads those blocks (on a
 * pvs_rt_open_ranges handle: asks the callback for each, and for nothing else), decodes no ids:
 * what a streaming client calls to fetch a neighbour's whole chain ahead, then
 * pvs_rt_block_range names each block's bytes. Writes at most `capacity` cells to `out`; *count
 * receives their number (PVS_RT_BUFFER_TOO_SMALL if it exceeds capacity; 1 + the max delta depth
 * is always enough). PVS_RT_FORMAT on a corrupt block or too long a chain. */
PVS_RT_API pvs_rt_status pvs_rt_delta_chain(pvs_rt* handle, uint32_t cell, uint32_t* out,
                                            size_t capacity, size_t* count);

/* Asks the OS to page in the cell's block (returns immediately). */
PVS_RT_API pvs_rt_status pvs_rt_prefetch(pvs_rt* handle, uint32_t cell);

/* The message of the last failing call on this thread ("" if none). */
PVS_RT_API const char* pvs_rt_last_error(void);

/* A short name of a status code ("ok", "format", ...); "unknown" for any other value. Takes an
 * int (a pvs_rt_status converts to it) so that any value can be passed safely. */
PVS_RT_API const char* pvs_rt_status_name(int status);

/* ---- Version -------------------------------------------------------------------------------- */

/* The version of the linked library as MAJOR * 10000 + MINOR * 100 + PATCH (compare it with
 * VISLIB_VERSION of the header the engine compiled against), and as "MAJOR.MINOR.PATCH". */
PVS_RT_API uint32_t pvs_rt_version(void);
PVS_RT_API const char* pvs_rt_version_string(void);

/* ---- Scene fingerprint from an engine's own buffers ------------------------------------------ */

/* One mesh of the engine's scene, as the engine holds it (docs/runtime.md, "Binding a PVS to the
 * assets"). Vertices: vertex_count of them per key state, state-major: state s, vertex v at
 * positions[3 * (s * vertex_count + v)] (x, y, z; y up, scene units). Give either float positions
 * (positions_f32) or double ones (positions_f64), not both. They are the world-space positions
 * vislib hashes (glTF node transforms applied in double): float buffers reproduce the bake's
 * fingerprint only where those are float-exact (docs/runtime.md, "Binding a PVS"). Triangles:
 * triangle_count triples of indices local to this mesh (each < vertex_count), all of object
 * object_id, or, if triangle_objects is not NULL, of object triangle_objects[t] each. */
typedef struct pvs_rt_mesh {
  const float* positions_f32;
  const double* positions_f64;
  size_t vertex_count;
  const uint32_t* indices;
  size_t triangle_count;
  uint32_t object_id;
  const uint32_t* triangle_objects;
} pvs_rt_mesh;

/* The scene fingerprint a PVS file stores (docs/pvs-format.md, "The scene fingerprint"), of the
 * scene made of meshes[0..mesh_count) in that order: the scene's vertices are those of mesh 0, then
 * mesh 1, ...; its triangles (the PVS triangle ids) likewise, with indices offset by the vertex
 * count of the meshes before. This is vislib's id order when the meshes are given in the order
 * `pvs export --id-map` lists them. object_count is the scene's object count (every object_id must
 * be below it); state_count >= 1 the number of key states (1 for a static scene). Compare the
 * result with pvs_rt_info.scene_fingerprint, or pass it to pvs_rt_open. Errors:
 * PVS_RT_INVALID_ARGUMENT for a null pointer, both or neither position arrays, an index >=
 * vertex_count or an object_id >= object_count (the message names the mesh). */
PVS_RT_API pvs_rt_status pvs_rt_scene_fingerprint(const pvs_rt_mesh* meshes, size_t mesh_count,
                                                  uint32_t state_count, uint32_t object_count,
                                                  uint64_t* fingerprint);

#ifdef __cplusplus
}
#endif

#endif /* PVS_RUNTIME_C_H */
