// benchmark_compare.h: from-segment against from-point visibility on one view region, measured as
// in §4.5 of "Complex VEs on All-In-One VR Headsets Through Continuous From-Segment Visibility
// Computation", with the frame-quality metrics of its §4.3 over test views inside the region.
//
// On the same region, same cube resolution and near plane, same machine and process:
//  - from-segment: region_visibility with K cube orientations per perimeter segment. Its runs are
//    taken in pass-major order (pass 0 = every segment world-aligned, pass 1 = every segment with
//    its first random orientation, ...); the growth curve is the union size after each run
//    against the cumulative kernel seconds (SegmentStats::seconds).
//  - from-point: sample_box with M viewpoints uniform in the box and a random cube orientation
//    each; the growth curve is the union after each run against the wall-clock seconds since the
//    first run (the one-off Embree BVH build is not included; it is reported separately).
//  - test views (bench_views): ground-truth frames of the full scene with the reference renderer;
//    at checkpoints of both growth curves, frames of the set found so far against them (epsilon,
//    PSNR, SSIM, metrics.h).
//  - equal time: from-point's union after the last run that ended within the from-segment total
//    seconds, over the from-segment set size (the paper's 24,000/29,000 = 83%).
//  - equal quality: the from-point seconds until its union holds as many triangles as the
//    from-segment set, over the from-segment seconds (the paper's 30 min vs 3.84 s); extrapolated
//    (and flagged) when from-point does not get there within its M runs.
// Timings are wall clock and vary between runs; everything else is a deterministic function of
// the options (seed included) and M. The scene is taken as +Y up (glTF's convention and that of
// the generators).
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "vislib/eval/metrics.h"
#include "vislib/eval/render.h"
#include "vislib/kernel/region_visibility.h"

namespace vislib {

enum class ViewPath {
  Walk,    // a walking path through the box (see bench_views)
  Random,  // random positions in the box
};

struct BenchOptions {
  Box3 box;                      // view region; must not be empty (flat along y = view rectangle)
  int segment_runs = 2;          // K cube orientations per perimeter segment, >= 1
  int point_runs = 0;            // M from-point viewpoints, >= 0; 0 = automatic (below)
  double point_time_factor = 3;  // automatic M: this multiple of from-segment's seconds, >= 1
  int max_point_runs = 100000;   // upper bound of the automatic M, >= 1
  int calibration_runs = 5;      // automatic M: from-point runs timed first (discarded), >= 2
  int resolution = 512;          // cube face resolution N of both methods, >= 1
  double near = kDefaultNear;    // near plane (view depth) of both methods and of the frames, > 0
  int views = 8;                 // test views, >= 1
  ViewPath path = ViewPath::Walk;
  int width = 640, height = 480;  // test frame size; each >= kSsimWindow
  double vfov_degrees = 90;       // vertical field of view of the test frames, in (0, 180)
  uint64_t seed = 1;              // cube orientations, viewpoints and test views
  bool keep_frames = true;        // keep the equal-time frames in BenchResult
};

// The test views. Walk: the path runs along the horizontal axis a (x or z) on which the box is
// longer (x on ties), b being the other; view i of V, s = (i + 0.5)/V, stands at
//   a = min_a + (0.1 + 0.8 s) ext_a,  b = mid_b + 0.3 ext_b sin(2 pi s),
//   y = mid_y + 0.25 ext_y sin(4 pi s)
// (inside the box) and looks at yaw i * 137.5 degrees (the golden angle, so the views cover all
// headings) from +a towards +b, pitch uniform in [-15, 15] degrees. Random: position uniform in
// the box, yaw uniform, pitch uniform in [-15, 15] degrees. Up is +Y; frame size, field of view
// and near plane from `options`. Deterministic in options.seed.
std::vector<Camera> bench_views(const BenchOptions& options);

struct GrowthPoint {
  int runs = 0;        // runs done (from-segment: pass-major order)
  double seconds = 0;  // cumulative seconds after those runs
  size_t found = 0;    // triangles in the union
};

// Frame quality of one set over all test views.
struct QualitySummary {
  double epsilon_mean = 0, epsilon_max = 0;  // pixel error epsilon, fraction in [0, 1]
  // PSNR of the MSE pooled over all views (10 log10(255^2 / mean MSE)); +inf when every frame is
  // identical to its ground truth. psnr_min: the worst view (+inf likewise).
  double psnr = 0, psnr_min = 0;
  double ssim_mean = 1, ssim_min = 1;
  size_t missed_pixels = 0;  // over all views
};
QualitySummary summarize(const std::vector<FrameQuality>& views);

// A measured point of a growth curve with the frame quality of its set (named apart from the
// bake's vislib::Checkpoint file class, checkpoint.h: two classes of one name broke the
// one-definition rule).
struct QualityCheckpoint {
  int runs = 0;
  double seconds = 0;
  size_t set_size = 0;
  std::vector<FrameQuality> views;  // per test view
  QualitySummary quality;
  SetComparison vs_frames;  // against the triangles seen in the ground-truth test frames
};

struct MethodRun {
  std::vector<GrowthPoint> growth;             // after every run
  std::vector<QualityCheckpoint> checkpoints;  // in increasing runs
  std::vector<uint32_t> set;                   // final union, sorted
  // Per triangle: the run index (0-based, in growth order) that first found it, or kNever.
  std::vector<uint32_t> first_run;
  static constexpr uint32_t kNever = std::numeric_limits<uint32_t>::max();
};

struct EqualTime {
  double seconds = 0;                 // the from-segment total seconds
  int point_runs = 0;                 // from-point runs finished within `seconds` (0: none)
  double point_seconds = 0;           // their elapsed seconds
  size_t segment_found = 0;           // |S|
  size_t point_found = 0;             // |P|
  size_t point_found_of_segment = 0;  // |P ∩ S|
  double share = 0;                   // |P| / |S| (the paper's 83%)
  double overlap_share = 0;           // |P ∩ S| / |S|
  // False when from-point stopped before `seconds` (then P is its final set: a lower bound).
  bool within_measured = true;
  QualityCheckpoint segment, point;  // frame quality of S and P
};

struct EqualQuality {
  size_t target = 0;           // |S|, the from-segment set size
  double segment_seconds = 0;  // its seconds
  bool reached = false;        // from-point's union reached `target` within its runs
  bool extrapolated = false;   // not reached: runs and seconds below come from the fit
  bool finite = true;          // false: the fitted growth levels off below `target`
  double point_runs = 0;       // runs needed (measured: an integer; extrapolated: real)
  double point_seconds = 0;    // seconds needed (extrapolated: point_runs * mean seconds per run)
  double time_ratio = 0;       // point_seconds / segment_seconds (+inf when not finite)
  // Not reached: the measured bound time_ratio > (seconds of all M runs) / segment_seconds.
  double time_ratio_lower_bound = 0;
  // Extrapolated: the smallest and largest ratio from fits over the upper 3/4, 1/2 and 1/4 (log
  // scale) of the runs, a measure of how much the estimate depends on the fit window.
  double time_ratio_low = 0, time_ratio_high = 0;
  // Extrapolation: new triangles per run ~ rate_coefficient * runs^(-rate_exponent), fitted by
  // least squares in log-log space to the discovery rates between log-spaced run counts over the
  // upper half (in log scale) of the measured runs; `fit_points` rates entered the fit.
  double rate_coefficient = 0, rate_exponent = 0;
  int fit_points = 0;
  std::string note;  // why a value is missing or extrapolated; empty when measured

  // Every id, measured (equal_quality_every_id): S_c, the ids of the from-segment set whose
  // witness re-casts to them (one Embree ray from the witness's eye through its pixel centre), and
  // the from-point runs until its union holds every one of them. Not found within the runs: the
  // share found is reported, and the ratio only as a bound.
  size_t confirmed = 0;             // |S_c|
  size_t confirmed_found = 0;       // |P ∩ S_c| after the last from-point run
  double confirmed_share = 0;       // confirmed_found / confirmed
  bool all_found = false;           // P ⊇ S_c within the runs
  double all_point_runs = 0;        // runs until P ⊇ S_c (all_found; NaN otherwise)
  double all_point_seconds = 0;     // their seconds (all_found; NaN otherwise)
  double all_time_ratio = 0;        // all_point_seconds / segment_seconds (NaN otherwise)
  double all_time_ratio_bound = 0;  // not all_found: the ratio exceeds this (all runs' seconds)
};

// The equal-quality comparison from a from-point growth curve (union_size[i] and
// elapsed_seconds[i] after run i, i = 0..M-1, M >= 1; union sizes non-decreasing). `target` >= 1,
// `segment_seconds` > 0. Deterministic.
EqualQuality equal_quality(const std::vector<size_t>& union_size,
                           const std::vector<double>& elapsed_seconds, size_t target,
                           double segment_seconds);

// Fills the every-id fields of `q` (q.segment_seconds > 0 set): `confirmed` sorted ids,
// `point_first_run` the from-point run (0-based) that first found each triangle or
// MethodRun::kNever, `elapsed_seconds[i]` the seconds after run i (at least one run).
void equal_quality_every_id(const std::vector<uint32_t>& confirmed,
                            const std::vector<uint32_t>& point_first_run,
                            const std::vector<double>& elapsed_seconds, EqualQuality& q);

struct BenchResult {
  BenchOptions options;  // as run (point_runs = the M actually used)
  std::vector<Camera> views;
  std::vector<uint32_t> frame_triangles;  // union of the triangle ids of the ground-truth frames
  std::vector<Segment> segments;          // perimeter segments
  MethodRun segment, point;
  std::vector<Vec3> point_viewpoints;
  EqualTime equal_time;
  EqualQuality equal_quality;
  // Dense reference: the union of both final sets and the frame triangles (every one of them is
  // visible from the region, as far as float ray casts and pixel-centre sampling tell).
  std::vector<uint32_t> reference;
  SetComparison segment_vs_reference, point_vs_reference, point_equal_time_vs_reference;
  double bvh_build_seconds = 0;            // Embree scene build (used by from-point and the frames)
  double truth_seconds = 0;                // rendering the ground-truth frames
  double point_seconds_per_run = 0;        // mean over the M runs
  double calibration_seconds_per_run = 0;  // automatic M only
  double quality_seconds = 0;              // rendering and comparing the checkpoint frames
  // Equal-time frames per view (when keep_frames): ground truth, from S, from P, missed masks.
  std::vector<Frame> truth_frames, segment_frames, point_frames;
  std::vector<std::vector<uint8_t>> segment_missed, point_missed;
};

// Reports progress: stage name, done, total. Called from the calling thread; may be empty.
using BenchProgress = std::function<void(const std::string& stage, size_t done, size_t total)>;

// Runs the whole comparison on key state 0 of `scene` (spheres ignored). Throws
// std::runtime_error if Embree fails. TBB-parallel inside each step.
BenchResult run_bench(const Scene& scene, const BenchOptions& options,
                      const BenchProgress& progress = {});

}  // namespace vislib
