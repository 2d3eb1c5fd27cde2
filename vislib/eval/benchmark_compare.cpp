// benchmark_compare.cpp: from-segment vs from-point on one region (paper §4.5) with the frame
// quality metrics of §4.3.
#include "vislib/eval/benchmark_compare.h"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <iterator>
#include <limits>

#include "vislib/base/cubemap.h"
#include "vislib/base/random.h"
#include "vislib/eval/embree_scene.h"
#include "vislib/eval/point_visibility.h"

namespace vislib {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

constexpr double kPi = 3.14159265358979323846;
constexpr double kGoldenAngle = 137.50776405003785;  // degrees
constexpr double kMaxPitch = 15.0;                   // degrees

Vec3 view_direction(int a, int b, double yaw_deg, double pitch_deg) {
  const double yaw = yaw_deg * kPi / 180.0, pitch = pitch_deg * kPi / 180.0;
  Vec3 d;
  d[a] = std::cos(pitch) * std::cos(yaw);
  d[b] = std::cos(pitch) * std::sin(yaw);
  d[1] = std::sin(pitch);
  return d;
}

// Sorted ids of the triangles with first_run < runs.
std::vector<uint32_t> set_after(const std::vector<uint32_t>& first_run, int runs) {
  std::vector<uint32_t> ids;
  for (size_t t = 0; t < first_run.size(); ++t)
    if (first_run[t] != MethodRun::kNever && first_run[t] < uint32_t(runs))
      ids.push_back(uint32_t(t));
  return ids;
}

struct Evaluator {
  const Scene& scene;
  const EmbreeScene& rt;
  const std::vector<Camera>& views;
  const std::vector<Frame>& truth;
  const std::vector<uint32_t>& frame_triangles;

  QualityCheckpoint evaluate(const std::vector<uint32_t>& first_run, int runs, double seconds,
                             std::vector<Frame>* frames = nullptr,
                             std::vector<std::vector<uint8_t>>* missed = nullptr) const {
    QualityCheckpoint c;
    c.runs = runs;
    c.seconds = seconds;
    const std::vector<uint32_t> ids = set_after(first_run, runs);
    c.set_size = ids.size();
    c.vs_frames = compare_sets(ids, frame_triangles);
    const std::vector<uint8_t> mask = triangle_mask(scene.triangle_count(), ids);
    for (size_t v = 0; v < views.size(); ++v) {
      Frame f = render_frame(scene, rt, views[v], mask.data());
      c.views.push_back(frame_quality(truth[v], f));
      if (missed) missed->push_back(missed_pixels(truth[v], f));
      if (frames) frames->push_back(std::move(f));
    }
    c.quality = summarize(c.views);
    return c;
  }
};

// Index of the last growth point with seconds <= t, or -1.
int last_within(const std::vector<GrowthPoint>& g, double t) {
  int best = -1;
  for (size_t i = 0; i < g.size(); ++i)
    if (g[i].seconds <= t) best = int(i);
  return best;
}

}  // namespace

std::vector<Camera> bench_views(const BenchOptions& o) {
  assert(!o.box.empty() && o.views >= 1);
  const Box3& box = o.box;
  const Vec3 ext = box.max - box.min, mid = (box.min + box.max) * 0.5;
  const int a = ext.z > ext.x ? 2 : 0, b = 2 - a;
  Rng rng(Rng::derive(o.seed, 0x76696577ull));  // "view"
  std::vector<Camera> views;
  for (int i = 0; i < o.views; ++i) {
    Camera c;
    c.width = o.width;
    c.height = o.height;
    c.vfov_degrees = o.vfov_degrees;
    c.z_near = o.near;
    c.up = {0, 1, 0};
    double yaw;
    if (o.path == ViewPath::Walk) {
      const double s = (double(i) + 0.5) / double(o.views);
      c.eye[a] = box.min[a] + (0.1 + 0.8 * s) * ext[a];
      c.eye[b] = mid[b] + 0.3 * ext[b] * std::sin(2 * kPi * s);
      c.eye[1] = mid[1] + 0.25 * ext[1] * std::sin(4 * kPi * s);
      yaw = std::fmod(double(i) * kGoldenAngle, 360.0);
    } else {
      for (int k = 0; k < 3; ++k) c.eye[k] = rng.uniform(box.min[k], box.max[k]);
      yaw = rng.uniform(0, 360);
    }
    const double pitch = rng.uniform(-kMaxPitch, kMaxPitch);
    c.forward = view_direction(a, b, yaw, pitch);
    views.push_back(c);
  }
  return views;
}

QualitySummary summarize(const std::vector<FrameQuality>& views) {
  QualitySummary s;
  if (views.empty()) return s;
  double eps = 0, ssim = 0, mse = 0;
  s.psnr_min = std::numeric_limits<double>::infinity();
  s.ssim_min = 1;
  for (const FrameQuality& q : views) {
    eps += q.epsilon;
    s.epsilon_max = std::max(s.epsilon_max, q.epsilon);
    ssim += q.ssim;
    s.ssim_min = std::min(s.ssim_min, q.ssim);
    s.psnr_min = std::min(s.psnr_min, q.psnr);
    mse += q.mse;
    s.missed_pixels += q.missed_pixels;
  }
  const double n = double(views.size());
  s.epsilon_mean = eps / n;
  s.ssim_mean = ssim / n;
  mse /= n;
  s.psnr =
      mse == 0 ? std::numeric_limits<double>::infinity() : 10.0 * std::log10(255.0 * 255.0 / mse);
  return s;
}

namespace {

struct RateFit {
  bool ok = false;
  double c = 0, p = 0;  // new triangles per run ~ c * runs^-p
  int points = 0;
};

// Least-squares fit of log(rate) against log(runs) for the discovery rates between 9 log-spaced
// run counts over [m^lower, m] (m = union_size.size()); rates of zero are left out.
RateFit fit_discovery_rate(const std::vector<size_t>& union_size, double lower) {
  const size_t m = union_size.size();
  std::vector<size_t> ns;
  const int steps = 8;
  for (int j = 0; j <= steps; ++j) {
    const double e = lower + (1 - lower) * double(j) / steps;
    const size_t n = std::min(size_t(std::llround(std::pow(double(m), e))), m);
    if (n >= 1 && (ns.empty() || n > ns.back())) ns.push_back(n);
  }
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  RateFit f;
  for (size_t j = 0; j + 1 < ns.size(); ++j) {
    const double gain = double(union_size[ns[j + 1] - 1]) - double(union_size[ns[j] - 1]);
    if (gain <= 0) continue;
    const double rate = gain / double(ns[j + 1] - ns[j]);
    const double x = std::log(std::sqrt(double(ns[j]) * double(ns[j + 1]))), y = std::log(rate);
    sx += x, sy += y, sxx += x * x, sxy += x * y, ++f.points;
  }
  const double k = double(f.points), det = k * sxx - sx * sx;
  if (f.points < 2 || !(det > 0)) return f;
  const double slope = (k * sxy - sx * sy) / det;
  f.c = std::exp((sy - slope * sx) / k);
  f.p = -slope;
  f.ok = true;
  return f;
}

// Runs n at which f(n) = f(m) + integral_m^n c x^-p dx reaches `target`; +inf when the fitted
// growth levels off below it.
double runs_to_reach(const std::vector<size_t>& union_size, size_t target, const RateFit& f) {
  const double dm = double(union_size.size());
  const double need = double(target) - double(union_size.back());
  if (std::fabs(1 - f.p) < 1e-9) return dm * std::exp(need / f.c);
  if (f.p < 1) return std::pow(std::pow(dm, 1 - f.p) + need * (1 - f.p) / f.c, 1 / (1 - f.p));
  const double base = std::pow(dm, 1 - f.p) - need * (f.p - 1) / f.c;
  if (!(base > 0)) return std::numeric_limits<double>::infinity();
  return std::pow(base, -1 / (f.p - 1));
}

}  // namespace

EqualQuality equal_quality(const std::vector<size_t>& union_size,
                           const std::vector<double>& elapsed_seconds, size_t target,
                           double segment_seconds) {
  assert(!union_size.empty() && union_size.size() == elapsed_seconds.size());
  assert(target >= 1 && segment_seconds > 0);
  EqualQuality q;
  q.target = target;
  q.segment_seconds = segment_seconds;
  const size_t m = union_size.size();
  for (size_t i = 0; i < m; ++i)
    if (union_size[i] >= target) {
      q.reached = true;
      q.point_runs = double(i + 1);
      q.point_seconds = elapsed_seconds[i];
      q.time_ratio = q.point_seconds / segment_seconds;
      return q;
    }
  q.extrapolated = true;
  q.time_ratio_lower_bound = elapsed_seconds[m - 1] / segment_seconds;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  q.point_runs = q.point_seconds = q.time_ratio = nan;
  const double per_run = elapsed_seconds[m - 1] / double(m);
  const RateFit fit = fit_discovery_rate(union_size, 0.5);
  q.fit_points = fit.points;
  if (!fit.ok) {
    q.note = "from-point did not reach the from-segment set size in " + std::to_string(m) +
             " runs, and its growth has fewer than two positive rates to extrapolate from";
    return q;
  }
  q.rate_coefficient = fit.c;
  q.rate_exponent = fit.p;
  const double n = runs_to_reach(union_size, target, fit);
  q.point_runs = n;
  q.point_seconds = n * per_run;
  q.time_ratio = q.point_seconds / segment_seconds;
  q.finite = std::isfinite(q.time_ratio);
  // Sensitivity: the same extrapolation from fits over the upper 3/4 and upper 1/4 (log scale).
  q.time_ratio_low = q.time_ratio_high = q.time_ratio;
  for (double lower : {0.25, 0.75}) {
    const RateFit f = fit_discovery_rate(union_size, lower);
    const double r = f.ok ? runs_to_reach(union_size, target, f) * per_run / segment_seconds
                          : std::numeric_limits<double>::quiet_NaN();
    if (std::isnan(r)) continue;
    q.time_ratio_low = std::min(q.time_ratio_low, r);
    q.time_ratio_high = std::max(q.time_ratio_high, r);
  }
  if (!q.finite) {
    q.note = "extrapolated: the fitted from-point growth levels off at " +
             std::to_string(double(union_size[m - 1]) +
                            fit.c / (fit.p - 1) * std::pow(double(m), 1 - fit.p)) +
             " triangles, below the from-segment set size";
    return q;
  }
  q.note = "extrapolated: from-point did not reach the from-segment set size in " +
           std::to_string(m) + " runs; runs needed from a power-law fit of its discovery rate, " +
           "seconds = runs x mean seconds per run";
  return q;
}

void equal_quality_every_id(const std::vector<uint32_t>& confirmed,
                            const std::vector<uint32_t>& point_first_run,
                            const std::vector<double>& elapsed_seconds, EqualQuality& q) {
  assert(!elapsed_seconds.empty() && q.segment_seconds > 0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  q.confirmed = confirmed.size();
  q.confirmed_found = 0;
  uint32_t last = 0;  // the run that found the last of them
  for (uint32_t id : confirmed) {
    const uint32_t f = point_first_run[id];
    if (f == MethodRun::kNever || f >= elapsed_seconds.size()) continue;
    ++q.confirmed_found;
    last = std::max(last, f);
  }
  q.confirmed_share = q.confirmed ? double(q.confirmed_found) / double(q.confirmed) : 1.0;
  q.all_found = q.confirmed_found == q.confirmed;
  q.all_point_runs = q.all_point_seconds = q.all_time_ratio = nan;
  q.all_time_ratio_bound = nan;
  if (q.all_found) {
    q.all_point_runs = q.confirmed ? double(last) + 1 : 0.0;
    q.all_point_seconds = q.confirmed ? elapsed_seconds[last] : 0.0;
    q.all_time_ratio = q.all_point_seconds / q.segment_seconds;
  } else {
    q.all_time_ratio_bound = elapsed_seconds.back() / q.segment_seconds;
  }
}

BenchResult run_bench(const Scene& scene, const BenchOptions& options,
                      const BenchProgress& progress) {
  assert(!options.box.empty() && options.segment_runs >= 1 && options.point_runs >= 0);
  assert(options.point_time_factor >= 1 && options.calibration_runs >= 2);
  auto report = [&](const std::string& stage, size_t done, size_t total) {
    if (progress) progress(stage, done, total);
  };
  BenchResult r;
  r.options = options;
  const size_t nt = scene.triangle_count();
  const Vec3 centre = (options.box.min + options.box.max) * 0.5;

  // Embree scene (from-point and frames) and the ground truth.
  auto t0 = Clock::now();
  const EmbreeScene rt(scene, 0.0, centre);
  r.bvh_build_seconds = seconds_since(t0);
  r.views = bench_views(options);
  t0 = Clock::now();
  std::vector<Frame> truth;
  for (size_t v = 0; v < r.views.size(); ++v) {
    truth.push_back(render_frame(scene, rt, r.views[v]));
    std::vector<uint32_t> ids = visible_set(truth.back().tri);
    std::vector<uint32_t> merged;
    std::set_union(r.frame_triangles.begin(), r.frame_triangles.end(), ids.begin(), ids.end(),
                   std::back_inserter(merged));
    r.frame_triangles.swap(merged);
    report("ground-truth frames", v + 1, r.views.size());
  }
  r.truth_seconds = seconds_since(t0);
  const Evaluator eval{scene, rt, r.views, truth, r.frame_triangles};

  // From-segment: K runs per perimeter segment, reordered pass-major.
  RegionOptions ro;
  ro.segment.resolution = options.resolution;
  ro.segment.near = options.near;
  ro.runs = options.segment_runs;
  ro.seed = options.seed;
  // Witnesses, to confirm each id of the set by a re-cast (equal quality, every id); included in
  // the from-segment seconds.
  ro.segment.want_witnesses = true;
  RegionResult region = region_visibility(scene, options.box, ro, [&](size_t done, size_t total) {
    report("from-segment runs", done, total);
  });
  r.segments = region.segments;
  const size_t S = region.segments.size(), K = size_t(options.segment_runs);
  r.segment.first_run.assign(nt, MethodRun::kNever);
  {
    double seconds = 0;
    size_t found = 0;
    for (size_t k = 0; k < K; ++k)
      for (size_t s = 0; s < S; ++s) {
        const RunRecord& rec = region.runs[s * K + k];
        assert(rec.segment == s && rec.run == int(k));
        const uint32_t order = uint32_t(k * S + s);
        for (uint32_t id : rec.visible)
          if (r.segment.first_run[id] == MethodRun::kNever)
            r.segment.first_run[id] = order, ++found;
        seconds += rec.stats.seconds;
        r.segment.growth.push_back({int(order) + 1, seconds, found});
      }
  }
  r.segment.set = region.visible;
  const double seg_seconds = r.segment.growth.back().seconds;

  // From-point: M random viewpoints with random orientations in the box.
  PointSampling ps;
  ps.n = options.resolution;
  ps.z_near = options.near;
  ps.random_orientation = true;
  ps.seed = options.seed;
  int m = options.point_runs;
  if (m == 0) {
    ps.runs = options.calibration_runs;
    SampledVisibility cal = sample_box(rt, options.box, ps);
    // The first run also warms up caches and the thread pool: time the others.
    const double per_run = (cal.elapsed_seconds.back() - cal.elapsed_seconds.front()) /
                           double(options.calibration_runs - 1);
    r.calibration_seconds_per_run = per_run;
    const double want = options.point_time_factor * seg_seconds / std::max(per_run, 1e-9);
    m = int(std::min(double(options.max_point_runs), std::max(2.0, std::ceil(want))));
    report("from-point calibration", 1, 1);
  }
  r.options.point_runs = m;
  ps.runs = m;
  SampledVisibility pv = sample_box(rt, options.box, ps, [&](size_t done, size_t total) {
    report("from-point runs", done, total);
  });
  r.point.first_run.assign(nt, MethodRun::kNever);
  for (size_t j = 0; j < pv.ids.size(); ++j) r.point.first_run[pv.ids[j]] = pv.first_run[j];
  for (int i = 0; i < m; ++i)
    r.point.growth.push_back({i + 1, pv.elapsed_seconds[size_t(i)], pv.union_size[size_t(i)]});
  r.point.set = pv.ids;
  r.point_viewpoints = pv.viewpoints;
  r.point_seconds_per_run = pv.elapsed_seconds.back() / double(m);

  // Checkpoints. From-segment: after each run of the first pass, then after every full pass
  // (at most 16 passes, log-spaced, the last included).
  std::vector<int> seg_cp;
  for (size_t s = 1; s < S; ++s) seg_cp.push_back(int(s));
  for (int j = 0; j < 16; ++j) {
    const double e = K == 1 ? 1.0 : double(j) / 15.0;
    seg_cp.push_back(int(S) * int(std::llround(std::pow(double(K), e))));
  }
  std::sort(seg_cp.begin(), seg_cp.end());
  seg_cp.erase(std::unique(seg_cp.begin(), seg_cp.end()), seg_cp.end());
  // From-point: powers of two, M, and the last run within each from-segment checkpoint's seconds.
  std::vector<int> pt_cp;
  for (int n = 1; n < m; n *= 2) pt_cp.push_back(n);
  pt_cp.push_back(m);
  for (int c : seg_cp) {
    const int i = last_within(r.point.growth, r.segment.growth[size_t(c) - 1].seconds);
    pt_cp.push_back(i + 1);  // 0 when no from-point run ended in that time
  }
  std::sort(pt_cp.begin(), pt_cp.end());
  pt_cp.erase(std::unique(pt_cp.begin(), pt_cp.end()), pt_cp.end());

  t0 = Clock::now();
  const size_t total_cp = seg_cp.size() + pt_cp.size();
  size_t done_cp = 0;
  for (int c : seg_cp) {
    r.segment.checkpoints.push_back(
        eval.evaluate(r.segment.first_run, c, r.segment.growth[size_t(c) - 1].seconds));
    report("frame quality checkpoints", ++done_cp, total_cp);
  }
  for (int c : pt_cp) {
    r.point.checkpoints.push_back(
        eval.evaluate(r.point.first_run, c, c == 0 ? 0.0 : r.point.growth[size_t(c) - 1].seconds));
    report("frame quality checkpoints", ++done_cp, total_cp);
  }
  r.quality_seconds = seconds_since(t0);

  // Equal time.
  EqualTime& et = r.equal_time;
  et.seconds = seg_seconds;
  const int within = last_within(r.point.growth, seg_seconds);
  et.point_runs = within + 1;
  et.within_measured = r.point.growth.back().seconds >= seg_seconds;
  et.point_seconds = within >= 0 ? r.point.growth[size_t(within)].seconds : 0.0;
  const std::vector<uint32_t> p_eq = set_after(r.point.first_run, et.point_runs);
  et.segment_found = r.segment.set.size();
  et.point_found = p_eq.size();
  et.point_found_of_segment = compare_sets(p_eq, r.segment.set).common;
  et.share = et.segment_found ? double(et.point_found) / double(et.segment_found) : 0.0;
  et.overlap_share =
      et.segment_found ? double(et.point_found_of_segment) / double(et.segment_found) : 0.0;
  for (const QualityCheckpoint& c : r.segment.checkpoints)
    if (c.runs == int(S * K)) et.segment = c;
  for (const QualityCheckpoint& c : r.point.checkpoints)
    if (c.runs == et.point_runs) et.point = c;
  if (options.keep_frames) {
    r.truth_frames = truth;
    eval.evaluate(r.segment.first_run, int(S * K), seg_seconds, &r.segment_frames,
                  &r.segment_missed);
    eval.evaluate(r.point.first_run, et.point_runs, et.point_seconds, &r.point_frames,
                  &r.point_missed);
  }

  // Equal quality.
  if (!r.segment.set.empty())
    r.equal_quality = equal_quality(pv.union_size, pv.elapsed_seconds, r.segment.set.size(),
                                    std::max(seg_seconds, 1e-12));
  else
    r.equal_quality.note = "the from-segment set is empty";
  // Every id: the ids whose witness re-casts to them, and the from-point runs until it holds all.
  {
    std::vector<uint32_t> confirmed;
    for (size_t i = 0; i < region.visible.size() && i < region.witnesses.size(); ++i) {
      const RegionWitness& w = region.witnesses[i];
      const Segment& seg = region.segments[w.segment];
      const Mat3& R = region.runs[w.segment * K + size_t(w.run)].orientation;
      const Vec3 eye = lerp(seg.from, seg.to, w.witness.t);
      const Vec3 dir = pixel_direction(face_axes(w.witness.face, R), w.witness.x, w.witness.y,
                                       options.resolution);
      if (rt.first_hit(eye, dir, options.near).tri == w.witness.tri)
        confirmed.push_back(w.witness.tri);
    }
    std::sort(confirmed.begin(), confirmed.end());
    r.equal_quality.segment_seconds = std::max(seg_seconds, 1e-12);
    equal_quality_every_id(confirmed, r.point.first_run, pv.elapsed_seconds, r.equal_quality);
  }

  // Dense reference.
  std::vector<uint32_t> both;
  std::set_union(r.segment.set.begin(), r.segment.set.end(), r.point.set.begin(), r.point.set.end(),
                 std::back_inserter(both));
  std::set_union(both.begin(), both.end(), r.frame_triangles.begin(), r.frame_triangles.end(),
                 std::back_inserter(r.reference));
  r.segment_vs_reference = compare_sets(r.segment.set, r.reference);
  r.point_vs_reference = compare_sets(r.point.set, r.reference);
  r.point_equal_time_vs_reference = compare_sets(p_eq, r.reference);
  return r;
}

}  // namespace vislib
