// c_api_support.h: internal to the runtime's C API sources (not installed). One per-thread error
// message for every pvs_rt_* function (pvs_rt_last_error).
#pragma once

#include <string>

#include "runtime/pvs_runtime_c.h"

namespace pvs_runtime::detail {

// Stores `message` as this thread's last error and returns `s`.
pvs_rt_status fail(pvs_rt_status s, const std::string& message);

}  // namespace pvs_runtime::detail

#include <new>
#include <stdexcept>

namespace pvs_runtime::detail {

// Runs f() (returning a pvs_rt_status) and maps a std::bad_alloc or another exception to a status.
template <class F>
pvs_rt_status guarded_simple(F&& f) {
  try {
    return f();
  } catch (const std::bad_alloc&) {
    return fail(PVS_RT_OUT_OF_MEMORY, "out of memory");
  } catch (const std::exception& e) {
    return fail(PVS_RT_INTERNAL, e.what());
  } catch (...) {
    return fail(PVS_RT_INTERNAL, "unknown error");
  }
}

}  // namespace pvs_runtime::detail
