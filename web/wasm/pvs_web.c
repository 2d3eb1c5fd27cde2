/* pvs_web.c: the WebAssembly side of the web client's runtime (compiled by scripts/build-web.sh
 * with the C API of runtime/, never by CMake). It opens a PVS over byte ranges that JavaScript
 * serves (web/src/pvs_worker.js: synchronous HTTP range requests in a Worker), so the file is read
 * by the same C++ reader as natively. */
#include <emscripten.h>
#include <stdint.h>

#include "runtime/pvs_runtime_c.h"

/* Module.readRange(offset, size) returns a Uint8Array of exactly `size` bytes, or null on a
 * failed request. Offsets travel as doubles (exact below 2^53). */
EM_JS(int, pvs_web_read_js, (double offset, double size, void* out), {
  var bytes = Module.readRange(offset, size);
  if (!bytes || bytes.length != size) return 1;  // both numbers: != compares values
  HEAPU8.set(bytes, out);
  return 0;
});

static int read_range(void* user, uint64_t offset, uint64_t size, void* out) {
  (void)user;
  return pvs_web_read_js((double)offset, (double)size, out);
}

/* Opens the file of `file_size` bytes that Module.readRange serves; NULL on failure
 * (pvs_rt_last_error says why). */
EMSCRIPTEN_KEEPALIVE pvs_rt* pvs_web_open(double file_size) {
  pvs_rt* handle = 0;
  if (pvs_rt_open_ranges((uint64_t)file_size, read_range, 0, 0, 0, &handle) != PVS_RT_OK) return 0;
  return handle;
}
