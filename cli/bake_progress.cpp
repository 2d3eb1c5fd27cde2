// bake_progress.cpp: the progress output of `pvs bake`.
#include "cli/bake_progress.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "cli/options.h"
#include "vislib/bake/bake_eta.h"

namespace pvs_cli {

std::string format_duration(double s) {
  if (!std::isfinite(s) || s < 0) return "?";
  long t = long(s + 0.5);
  char buf[32];
  if (t >= 3600)
    std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", t / 3600, (t / 60) % 60, t % 60);
  else
    std::snprintf(buf, sizeof buf, "%ld:%02ld", t / 60, t % 60);
  return buf;
}

vislib::BakeProgressFn progress_printer() {
  struct State {
    bool tty = isatty(fileno(stderr));
    double last_line = -1;
    double last_done = 0;
  };
  auto st = std::make_shared<State>();
  return [st](const vislib::BakeProgress& p) {
    if (!show_progress()) return;
    // The cells left weighted by their expected work (bake_eta.h), the running ones' finished
    // share counted as done (a long cell shows progress).
    const double eta = vislib::eta_seconds(p.elapsed, p.work_done, p.work_total - p.work_done);
    if (st->tty) {
      const int width = 30;
      int fill = p.total ? int(double(width) * (p.done + p.running) / p.total) : width;
      std::string bar(size_t(fill), '#');
      bar.resize(width, '.');
      std::fprintf(stderr, "\rpvs bake: [%s] %u/%u cells", bar.c_str(), p.done, p.total);
      if (p.resumed) std::fprintf(stderr, " (%u resumed)", p.resumed);
      if (p.running > 0) std::fprintf(stderr, " + %.2f of running cells", p.running);
      std::fprintf(stderr, "  %s elapsed  ETA %s   ", format_duration(p.elapsed).c_str(),
                   p.done == p.total ? "0:00" : format_duration(eta).c_str());
      if (p.done == p.total) std::fprintf(stderr, "\n");
      std::fflush(stderr);
      return;
    }
    bool first = st->last_line < 0, last = p.done == p.total;
    // A line every 5% of the work (cells, and runs inside the running cells) or every 10 s.
    const double at = p.done + p.running;
    bool step = at >= st->last_done + p.total / 20.0;
    if (!first && !last && !step && p.elapsed - st->last_line < 10) return;
    st->last_line = p.elapsed;
    st->last_done = at;
    if (p.running > 0 && !last)
      std::fprintf(
          stderr,
          "pvs bake: %u/%u cells + %.2f of running cells (%u resumed), %s elapsed, ETA %s\n",
          p.done, p.total, p.running, p.resumed, format_duration(p.elapsed).c_str(),
          format_duration(eta).c_str());
    else
      std::fprintf(stderr, "pvs bake: %u/%u cells (%u resumed), %s elapsed, ETA %s\n", p.done,
                   p.total, p.resumed, format_duration(p.elapsed).c_str(),
                   last ? "0:00" : format_duration(eta).c_str());
  };
}

}  // namespace pvs_cli
