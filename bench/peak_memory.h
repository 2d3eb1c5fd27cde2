// peak_memory.h: peak resident memory of this process, for the benchmarks' "peak MB" columns.
#pragma once

#include <fstream>
#include <string>

namespace vislib_bench {

// Resets the peak (VmHWM) to the current resident size (Linux; no effect elsewhere).
inline void reset_peak() {
  std::ofstream f("/proc/self/clear_refs");
  if (f) f << "5";
}

// Peak resident memory in MB since the last reset_peak() (Linux; 0 elsewhere).
inline double peak_mb() {
  std::ifstream f("/proc/self/status");
  std::string line;
  while (std::getline(f, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  return 0;
}

}  // namespace vislib_bench
