// Tests of vislib/eval/benchmark_compare.h: test views, the equal-quality comparison and its
// extrapolation, and one small run of the whole comparison.
#include "vislib/eval/benchmark_compare.h"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "vislib/eval/bench_report.h"
#include "vislib/scene/generate.h"

using namespace vislib;

namespace {

Box3 box(Vec3 a, Vec3 b) {
  Box3 r;
  r.extend(a);
  r.extend(b);
  return r;
}

bool inside(const Box3& b, Vec3 p) {
  for (int k = 0; k < 3; ++k)
    if (p[k] < b.min[k] || p[k] > b.max[k]) return false;
  return true;
}

}  // namespace

TEST(BenchmarkCompare, TestViewsLieInsideTheBoxAndCoverManyHeadings) {
  for (ViewPath path : {ViewPath::Walk, ViewPath::Random}) {
    BenchOptions o;
    o.box = box({-3, 1.5, -20}, {3, 1.9, 20});
    o.views = 12;
    o.path = path;
    const auto views = bench_views(o);
    ASSERT_EQ(views.size(), 12u);
    int positive_x = 0, positive_z = 0;
    for (const Camera& c : views) {
      EXPECT_TRUE(inside(o.box, c.eye));
      EXPECT_NEAR(length(c.forward), 1.0, 1e-12);
      EXPECT_LE(std::fabs(c.forward.y), std::sin(15.0 * M_PI / 180) + 1e-12);  // pitch <= 15 deg
      positive_x += c.forward.x > 0, positive_z += c.forward.z > 0;
    }
    EXPECT_GT(positive_x, 2);
    EXPECT_LT(positive_x, 10);
    EXPECT_GT(positive_z, 2);
    EXPECT_LT(positive_z, 10);
    EXPECT_EQ(bench_views(o)[5].eye, views[5].eye);  // deterministic
  }
}

TEST(BenchmarkCompare, WalkFollowsTheLongerHorizontalAxis) {
  BenchOptions o;
  o.box = box({-10, 1.7, -1}, {10, 1.7, 1});
  o.views = 5;
  const auto views = bench_views(o);
  for (size_t i = 1; i < views.size(); ++i) EXPECT_GT(views[i].eye.x, views[i - 1].eye.x);
  EXPECT_DOUBLE_EQ(views[0].eye.y, 1.7);
}

TEST(BenchmarkCompare, EqualQualityMeasuredWhenReached) {
  const std::vector<size_t> found = {10, 15, 18, 20, 21};
  const std::vector<double> t = {0.1, 0.2, 0.3, 0.4, 0.5};
  const EqualQuality q = equal_quality(found, t, 19, 2.0);
  EXPECT_TRUE(q.reached);
  EXPECT_FALSE(q.extrapolated);
  EXPECT_EQ(q.point_runs, 4.0);
  EXPECT_DOUBLE_EQ(q.point_seconds, 0.4);
  EXPECT_DOUBLE_EQ(q.time_ratio, 0.2);
}

TEST(BenchmarkCompare, EqualQualityExtrapolatesAPowerLawGrowth) {
  // f(n) = A - B n^-0.5: discovery rate 0.5 B n^-1.5 (exponent 1.5), levelling off at A.
  const double A = 100000, B = 50000;
  const int m = 4000;
  std::vector<size_t> found;
  std::vector<double> t;
  for (int n = 1; n <= m; ++n) {
    found.push_back(size_t(std::llround(A - B / std::sqrt(double(n)))));
    t.push_back(0.01 * n);
  }
  const size_t target = 99500;  // reached at n = (B / 500)^2 = 10000
  const EqualQuality q = equal_quality(found, t, target, 5.0);
  EXPECT_FALSE(q.reached);
  EXPECT_TRUE(q.extrapolated);
  EXPECT_TRUE(q.finite);
  EXPECT_NEAR(q.rate_exponent, 1.5, 0.02);
  EXPECT_NEAR(q.point_runs, 10000, 300);
  EXPECT_NEAR(q.point_seconds, 0.01 * q.point_runs, 1e-9);
  EXPECT_NEAR(q.time_ratio, q.point_seconds / 5.0, 1e-12);
  EXPECT_FALSE(q.note.empty());
  EXPECT_DOUBLE_EQ(q.time_ratio_lower_bound, 0.01 * m / 5.0);
  // An exact power law: every fit window gives about the same answer.
  EXPECT_LE(q.time_ratio_low, q.time_ratio);
  EXPECT_GE(q.time_ratio_high, q.time_ratio);
  EXPECT_LT(q.time_ratio_high / q.time_ratio_low, 1.1);
  // Beyond the asymptote the fit never gets there.
  const EqualQuality never = equal_quality(found, t, size_t(A + 1000), 5.0);
  EXPECT_FALSE(never.finite);
  EXPECT_TRUE(std::isinf(never.time_ratio));
}

TEST(BenchmarkCompare, EqualQualityWithoutGrowthCannotBeExtrapolated) {
  const EqualQuality q = equal_quality({5, 5, 5, 5}, {1, 2, 3, 4}, 6, 1.0);
  EXPECT_TRUE(q.extrapolated);
  EXPECT_TRUE(std::isnan(q.time_ratio));
  EXPECT_FALSE(q.note.empty());
}

TEST(BenchmarkCompare, SmallRunIsConsistent) {
  CityOptions co;
  co.blocks_x = co.blocks_z = 2;
  const Scene s = generate_city(co);
  BenchOptions o;
  o.box = box({-3, 1.7, -20}, {3, 1.7, 20});
  o.segment_runs = 2;
  o.point_runs = 12;
  o.resolution = 48;
  o.views = 3;
  o.width = 48, o.height = 36;
  const BenchResult r = run_bench(s, o);
  ASSERT_EQ(r.segments.size(), 4u);  // a view rectangle: four sides
  ASSERT_EQ(r.segment.growth.size(), 8u);
  ASSERT_EQ(r.point.growth.size(), 12u);
  for (const auto* m : {&r.segment, &r.point}) {
    for (size_t i = 1; i < m->growth.size(); ++i) {
      EXPECT_GE(m->growth[i].found, m->growth[i - 1].found);
      EXPECT_GE(m->growth[i].seconds, m->growth[i - 1].seconds);
    }
    EXPECT_EQ(m->growth.back().found, m->set.size());
    // Checkpoint sets are the growth curve's sets; frame quality does not get worse with more runs.
    for (size_t i = 0; i < m->checkpoints.size(); ++i) {
      const QualityCheckpoint& c = m->checkpoints[i];
      EXPECT_EQ(c.set_size, c.runs ? m->growth[size_t(c.runs) - 1].found : 0u);
      EXPECT_EQ(c.views.size(), 3u);
      if (i) {
        EXPECT_LE(c.quality.missed_pixels, m->checkpoints[i - 1].quality.missed_pixels);
      }
    }
  }
  // Every id: almost every id of the set re-casts from its witness (a float ray at a grazing or
  // tied pixel may not); the every-id count never exceeds the set or what from-point found.
  EXPECT_LE(r.equal_quality.confirmed, r.segment.set.size());
  EXPECT_GE(double(r.equal_quality.confirmed), 0.95 * double(r.segment.set.size()));
  EXPECT_LE(r.equal_quality.confirmed_found, r.equal_quality.confirmed);
  EXPECT_LE(r.equal_quality.confirmed_found, r.point.set.size());
  // Every missed pixel of the equal-time frames is a frame triangle the set lacks.
  EXPECT_EQ(r.equal_time.segment.runs, 8);
  EXPECT_EQ(r.equal_time.segment_found, r.segment.set.size());
  EXPECT_DOUBLE_EQ(r.equal_time.share,
                   double(r.equal_time.point_found) / double(r.equal_time.segment_found));
  if (r.equal_time.segment.vs_frames.missed == 0) {
    EXPECT_EQ(r.equal_time.segment.quality.missed_pixels, 0u);
  }
  ASSERT_EQ(r.truth_frames.size(), 3u);
  ASSERT_EQ(r.segment_missed.size(), 3u);
  // Both sets are contained in the dense reference.
  EXPECT_EQ(r.segment_vs_reference.extra, 0u);
  EXPECT_EQ(r.point_vs_reference.extra, 0u);
}

TEST(BenchmarkCompare, RepeatedRunGivesTheSameSetsAndQuality) {
  CityOptions co;
  co.blocks_x = co.blocks_z = 2;
  const Scene s = generate_city(co);
  BenchOptions o;
  o.box = box({-3, 1.5, -10}, {3, 1.9, 10});
  o.segment_runs = 1;
  o.point_runs = 6;
  o.resolution = 32;
  o.views = 2;
  o.width = 32, o.height = 24;
  o.keep_frames = false;
  const BenchResult a = run_bench(s, o), b = run_bench(s, o);
  EXPECT_EQ(a.segment.set, b.segment.set);
  EXPECT_EQ(a.point.set, b.point.set);
  EXPECT_EQ(a.point.first_run, b.point.first_run);
  ASSERT_EQ(a.segment.checkpoints.size(), b.segment.checkpoints.size());
  for (size_t i = 0; i < a.segment.checkpoints.size(); ++i) {
    EXPECT_EQ(a.segment.checkpoints[i].quality.missed_pixels,
              b.segment.checkpoints[i].quality.missed_pixels);
    EXPECT_EQ(a.segment.checkpoints[i].quality.ssim_mean,
              b.segment.checkpoints[i].quality.ssim_mean);
  }
  EXPECT_EQ(a.segments.size(), 12u);  // a box with a height band: twelve edges
}

TEST(BenchJson, RecordsTheRunAsGivenTheResultAndNullForNonFiniteNumbers) {
  using nlohmann::json;
  CityOptions co;
  co.blocks_x = co.blocks_z = 2;
  const Scene s = generate_city(co);
  BenchOptions o;
  o.box = box({-3, 1.7, -20}, {3, 1.7, 20});
  o.point_runs = 6;
  o.resolution = 32;
  o.views = 2;
  o.width = 32, o.height = 24;
  o.path = ViewPath::Random;
  BenchResult r = run_bench(s, o);
  BenchRunInfo info;
  info.scene = "city.glb";
  info.scene_triangles = s.triangle_count();
  info.given = o;
  info.threads = 3;
  info.load_seconds = 0.25;
  info.total_seconds = 2;
  info.frames = {"frames/view0_*.png"};
  r.equal_quality.time_ratio = INFINITY;  // JSON has no infinities
  const std::string text = bench_json(info, r);
  ASSERT_EQ(text.back(), '\n');
  const json j = json::parse(text);
  EXPECT_EQ(j["scene"], "city.glb");
  EXPECT_EQ(j["scene_triangles"], s.triangle_count());
  EXPECT_EQ(j["settings"]["view_path"], "random");
  EXPECT_EQ(j["settings"]["threads"], 3);
  EXPECT_EQ(j["settings"]["point_runs"], 6);
  EXPECT_EQ(j["settings"]["point_runs_automatic"], false);
  EXPECT_EQ(j["settings"]["perimeter_segments"], r.segments.size());
  EXPECT_EQ(j["box"]["min"], json::array({-3, 1.7, -20}));
  EXPECT_TRUE(j["equal_quality"]["time_ratio"].is_null());
  EXPECT_TRUE(j["equal_quality_time_ratio"].is_null());
  EXPECT_EQ(j["equal_time"]["segment_found"], r.equal_time.segment_found);
  EXPECT_EQ(j["segment"]["found"], r.equal_time.segment.set_size);
  EXPECT_EQ(j["timings"]["load_seconds"], 0.25);
  EXPECT_EQ(j["timings"]["total_seconds"], 2.0);
  EXPECT_EQ(j["files"]["frames"], json::array({"frames/view0_*.png"}));
  EXPECT_EQ(j["files"]["plots"], json::array());
  EXPECT_EQ(j["files"]["csv"].size(), 5u);
  // The automatic point runs are recorded as such.
  info.given.point_runs = 0;
  EXPECT_EQ(json::parse(bench_json(info, r))["settings"]["point_runs_automatic"], true);
}

// Every id: the run that found the last confirmed id, or the share found at the cap with the
// ratio as a bound.
TEST(BenchmarkCompare, EveryIdIsTheRunThatFoundTheLastConfirmedIdOrABoundAtTheCap) {
  const uint32_t never = MethodRun::kNever;
  const std::vector<uint32_t> first_run = {never, 0, never, 2, never, 1};
  const std::vector<double> elapsed = {1.0, 2.0, 3.0};
  EqualQuality q;
  q.segment_seconds = 0.5;
  equal_quality_every_id({1, 3, 5}, first_run, elapsed, q);
  EXPECT_TRUE(q.all_found);
  EXPECT_EQ(q.confirmed, 3u);
  EXPECT_EQ(q.confirmed_found, 3u);
  EXPECT_DOUBLE_EQ(q.all_point_runs, 3.0);  // id 3, found in run 2 (0-based)
  EXPECT_DOUBLE_EQ(q.all_point_seconds, 3.0);
  EXPECT_DOUBLE_EQ(q.all_time_ratio, 6.0);
  EXPECT_TRUE(std::isnan(q.all_time_ratio_bound));

  equal_quality_every_id({1, 2, 5}, first_run, elapsed, q);  // id 2 never found
  EXPECT_FALSE(q.all_found);
  EXPECT_EQ(q.confirmed_found, 2u);
  EXPECT_DOUBLE_EQ(q.confirmed_share, 2.0 / 3.0);
  EXPECT_TRUE(std::isnan(q.all_time_ratio));
  EXPECT_DOUBLE_EQ(q.all_time_ratio_bound, 6.0);  // all 3 runs' seconds over 0.5 s
}
