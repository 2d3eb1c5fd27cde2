// bake_progress.h: the progress output of `pvs bake` on stderr.
#pragma once

#include <string>

#include "vislib/bake/bake.h"

namespace pvs_cli {

// "m:ss" or "h:mm:ss"; "?" for a negative or non-finite number of seconds.
std::string format_duration(double s);

// A bar with cells done / total and the ETA on a terminal (redrawn in place); plain lines
// otherwise, every 5% of the cells or every 10 s, whichever comes first.
vislib::BakeProgressFn progress_printer();

}  // namespace pvs_cli
