// The consumer side of the C API (runtime/near_far_c.h): the near-far partition, the
// Eq. 1/4/5 morph, Eq. 2/3, the CloVR scheduler, version and fingerprint argument checks. Every
// call goes through the C functions; expectations are computed here from the papers' formulas.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "pvs_format/pvs_format.h"
#include "runtime/near_far_c.h"
#include "runtime/pvs_runtime_c.h"

namespace {

// A random soup: `objects` objects of `per_object` triangles each, within [-extent, extent] in x
// and z, y in [0, 3].
struct Soup {
  std::vector<float> positions;
  std::vector<uint32_t> indices, triangle_object;
  std::vector<uint8_t> dynamic;
  size_t objects = 0;
  pvs_rt_geometry geometry() const {
    return {positions.data(),
            positions.size() / 3,
            indices.data(),
            indices.size() / 3,
            triangle_object.data(),
            objects,
            dynamic.empty() ? nullptr : dynamic.data()};
  }
};

Soup make_soup(int objects, int per_object, double extent, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> c(-extent, extent), d(-1.0, 1.0), h(0.0, 3.0);
  Soup s;
  s.objects = size_t(objects);
  for (int ob = 0; ob < objects; ++ob) {
    const double cx = c(rng), cz = c(rng);
    for (int k = 0; k < per_object; ++k) {
      const uint32_t base = uint32_t(s.positions.size() / 3);
      for (int j = 0; j < 3; ++j) {
        s.positions.push_back(float(cx + d(rng)));
        s.positions.push_back(float(h(rng)));
        s.positions.push_back(float(cz + d(rng)));
        s.indices.push_back(base + uint32_t(j));
      }
      s.triangle_object.push_back(uint32_t(ob));
      s.dynamic.push_back(uint8_t(ob % 5 == 0));
    }
  }
  return s;
}

double axis_r(const float* p, const double o[3]) {
  return std::hypot(double(p[0]) - o[0], double(p[2]) - o[2]);
}

}  // namespace

TEST(RuntimeCApi, VersionQueryMatchesTheHeaderMacros) {
  EXPECT_EQ(pvs_rt_version(), uint32_t(VISLIB_VERSION));
  EXPECT_STREQ(pvs_rt_version_string(), VISLIB_VERSION_STRING);
  EXPECT_EQ(VISLIB_VERSION,
            VISLIB_VERSION_MAJOR * 10000 + VISLIB_VERSION_MINOR * 100 + VISLIB_VERSION_PATCH);
}

TEST(RuntimeCApi, NearFarPartitionClassifiesTrianglesByTheirVertexRadii) {
  const Soup s = make_soup(60, 5, 30, 1);
  const pvs_rt_geometry g = s.geometry();
  std::vector<uint32_t> ids;
  for (uint32_t t = 0; t < g.triangle_count; t += 2) ids.push_back(t);
  const double o[3] = {1, 0, -2}, r1 = 8, r2 = 17;
  std::vector<uint32_t> a(ids.size()), b(ids.size()), c(ids.size()), d(ids.size()), e(ids.size()),
      f(ids.size());
  pvs_rt_near_far out{a.data(), b.data(), c.data(), d.data(), e.data(), f.data(), ids.size(),
                      0,        0,        0,        0,        0,        0};
  ASSERT_EQ(pvs_rt_partition_near_far(&g, ids.data(), ids.size(), o, r1, r2, &out), PVS_RT_OK)
      << pvs_rt_last_error();
  std::vector<uint32_t> near, inter, far_s, far_d, env, geo;
  for (uint32_t t : ids) {
    int n = 0, fa = 0, beyond = 0;
    for (int j = 0; j < 3; ++j) {
      const double r = axis_r(&s.positions[3 * s.indices[3 * t + j]], o);
      n += r <= r1;
      fa += r >= r2;
      beyond += r > r2;
    }
    const bool moves = s.dynamic[t];
    if (n == 3)
      near.push_back(t);
    else if (fa == 3)
      (moves ? far_d : far_s).push_back(t);
    else
      inter.push_back(t);
    if (!(fa == 3 && !moves)) geo.push_back(t);
    if (!moves && beyond) env.push_back(t);
  }
  EXPECT_EQ(std::vector<uint32_t>(a.begin(), a.begin() + out.near_count), near);
  EXPECT_EQ(std::vector<uint32_t>(b.begin(), b.begin() + out.intermediate_count), inter);
  EXPECT_EQ(std::vector<uint32_t>(c.begin(), c.begin() + out.far_static_count), far_s);
  EXPECT_EQ(std::vector<uint32_t>(d.begin(), d.begin() + out.far_dynamic_count), far_d);
  EXPECT_EQ(std::vector<uint32_t>(e.begin(), e.begin() + out.environment_map_count), env);
  EXPECT_EQ(std::vector<uint32_t>(f.begin(), f.begin() + out.geometry_count), geo);
  EXPECT_GT(near.size(), 0u);
  EXPECT_GT(inter.size(), 0u);
  EXPECT_GT(far_s.size(), 0u);
  EXPECT_GT(far_d.size(), 0u);
  // A short buffer and a bad id are reported, not written.
  out.capacity = ids.size() - 1;
  EXPECT_EQ(pvs_rt_partition_near_far(&g, ids.data(), ids.size(), o, r1, r2, &out),
            PVS_RT_BUFFER_TOO_SMALL);
  out.capacity = ids.size();
  const uint32_t bad = uint32_t(g.triangle_count);
  EXPECT_EQ(pvs_rt_partition_near_far(&g, &bad, 1, o, r1, r2, &out), PVS_RT_INVALID_ARGUMENT);
  EXPECT_NE(std::string(pvs_rt_last_error()).find("id 300 >= triangle_count 300"),
            std::string::npos)
      << pvs_rt_last_error();
  EXPECT_EQ(pvs_rt_partition_near_far(&g, ids.data(), ids.size(), o, r2, r1, &out),
            PVS_RT_INVALID_ARGUMENT);
}

TEST(RuntimeCApi, MorphCurvesFollowEquations1To5) {
  // x = (r2 - r)/(r2 - r1): linear x, quadratic x^2, S-curve 2x^2 below 1/2, 1 - 2(x-1)^2 above.
  const double r1 = 10, r2 = 20;
  for (double r : {10.0, 12.5, 15.0, 17.5, 20.0}) {
    const double x = (r2 - r) / (r2 - r1);
    double w[3];
    for (int c = 0; c < 3; ++c)
      ASSERT_EQ(pvs_rt_morph_weight(r, r1, r2, pvs_rt_morph_curve(c), &w[c]), PVS_RT_OK);
    EXPECT_DOUBLE_EQ(w[0], x);
    EXPECT_DOUBLE_EQ(w[1], x * x);
    EXPECT_DOUBLE_EQ(w[2], x < 0.5 ? 2 * x * x : 1 - 2 * (x - 1) * (x - 1));
  }
  double w;
  EXPECT_EQ(pvs_rt_morph_weight(15, r1, r2, pvs_rt_morph_curve(7), &w), PVS_RT_INVALID_ARGUMENT);
}

TEST(RuntimeCApi, MorphKeepsNearVerticesAndSendsR2VerticesAlongTheCentresRay) {
  const double u[3] = {1.0, 1.6, 0.5}, o[3] = {0, 1.6, 0}, r1 = 5, r2 = 12;
  // near (r = 3), at r1, at r2, beyond (Eq. 2), intermediate
  const float in[15] = {3, 0, 0, 0, 2, 5, 12, 0.5f, 0, 0, 3, -20, 6, 1, 6};
  float out[15];
  for (int c = 0; c < 3; ++c) {
    ASSERT_EQ(pvs_rt_morph_vertices(in, 5, u, o, r1, r2, pvs_rt_morph_curve(c), out), PVS_RT_OK)
        << pvs_rt_last_error();
    for (int k = 0; k < 6; ++k) EXPECT_FLOAT_EQ(out[k], in[k]);  // r <= r1: unchanged
    // r = r2: Q = U + |OP| d_O, i.e. Q - U parallel to P - O with the same length.
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(out[6 + k] - u[k], in[6 + k] - o[k], 1e-5);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(out[9 + k], u[k] + in[9 + k] - o[k], 1e-5);  // Eq. 2
  }
  float far_out[3];
  ASSERT_EQ(pvs_rt_displace_far(in + 9, 1, u, o, far_out), PVS_RT_OK);
  for (int k = 0; k < 3; ++k) EXPECT_FLOAT_EQ(far_out[k], float(u[k] + in[9 + k] - o[k]));
  const double outside[3] = {6, 1.6, 0};  // the eye beyond r1: Eq. 1 is undefined
  EXPECT_EQ(pvs_rt_morph_vertices(in, 5, outside, o, r1, r2, PVS_RT_CURVE_LINEAR, out),
            PVS_RT_INVALID_ARGUMENT);
  EXPECT_NE(std::string(pvs_rt_last_error()).find("not inside r1"), std::string::npos);
}

TEST(RuntimeCApi, RangeTestHidesFragmentsBehindTheFarSurface) {
  const int size = 4;
  std::vector<float> range(6 * size * size, 10.0f);
  const double u[3] = {0, 0, 0};
  int pass = -1;
  const double in_front[3] = {0, 0, 9.5}, behind[3] = {0, 0, 10.5}, on[3] = {6, 0, 8};
  ASSERT_EQ(pvs_rt_range_test(in_front, u, range.data(), size, &pass), PVS_RT_OK);
  EXPECT_EQ(pass, 1);
  ASSERT_EQ(pvs_rt_range_test(behind, u, range.data(), size, &pass), PVS_RT_OK);
  EXPECT_EQ(pass, 0);
  ASSERT_EQ(pvs_rt_range_test(on, u, range.data(), size, &pass),
            PVS_RT_OK);  // |on| = 10: equal range passes
  EXPECT_EQ(pass, 1);
  EXPECT_EQ(pvs_rt_range_test(u, u, range.data(), size, &pass), PVS_RT_INVALID_ARGUMENT);
}

// The scheduler: frame 0 has R = 0 and nothing near; R then rises ring by ring over F frames per
// ring to the final radius; the near set only grows, is exactly the visible triangles of objects
// with a vertex inside the ring being injected, and with the environment set partitions the ids.
TEST(RuntimeCApi, ClovrSchedulerGrowsFromZeroThroughMergedRings) {
  const Soup s = make_soup(80, 4, 25, 2);
  const pvs_rt_geometry g = s.geometry();
  std::vector<uint32_t> ids;
  for (uint32_t t = 0; t < g.triangle_count; ++t)
    if (t % 3 != 1) ids.push_back(t);
  pvs_rt_clovr_params p;
  pvs_rt_clovr_default_params(20.0, &p);
  p.frames_per_ring = 3;
  pvs_rt_clovr* c = nullptr;
  ASSERT_EQ(pvs_rt_clovr_create(&g, &p, &c), PVS_RT_OK) << pvs_rt_last_error();
  const double o[3] = {0, 0, 0};
  ASSERT_EQ(pvs_rt_clovr_start(c, ids.data(), ids.size(), o), PVS_RT_OK) << pvs_rt_last_error();

  std::vector<double> equal(64), contribution(64), merged(64);
  size_t ne = 0, nm = 0;
  ASSERT_EQ(
      pvs_rt_clovr_rings(c, equal.data(), contribution.data(), 64, &ne, merged.data(), 64, &nm),
      PVS_RT_OK);
  ASSERT_EQ(ne, 8u);
  for (size_t k = 0; k < ne; ++k)  // equal-area: R_k = sqrt(k A / pi), A = pi 20^2 / 8
    EXPECT_NEAR(equal[k], std::sqrt(double(k + 1) * 400.0 / 8.0), 1e-9);
  ASSERT_GE(nm, 1u);
  EXPECT_LE(nm, ne);
  EXPECT_EQ(merged[nm - 1], 20.0);
  for (size_t k = 0; k < nm; ++k)
    EXPECT_NE(std::find(equal.begin(), equal.begin() + ne, merged[k]), equal.begin() + ne);

  // Object radius: smallest vertex axis distance over all its triangles.
  std::vector<double> obj_r(s.objects, 1e300);
  for (size_t t = 0; t < g.triangle_count; ++t)
    for (int j = 0; j < 3; ++j)
      obj_r[s.triangle_object[t]] =
          std::min(obj_r[s.triangle_object[t]], axis_r(&s.positions[3 * s.indices[3 * t + j]], o));

  std::vector<uint32_t> near(ids.size()), env(ids.size()), previous;
  double last_r = -1, last_ring_radius = 0;
  int frames = 0;
  pvs_rt_clovr_frame f{};
  for (;; ++frames) {
    ASSERT_EQ(pvs_rt_clovr_next_frame(c, &f), PVS_RT_OK);
    ASSERT_EQ(f.frame, uint32_t(frames));
    size_t nn = 0, nv = 0;
    ASSERT_EQ(pvs_rt_clovr_near_ids(c, near.data(), near.size(), &nn), PVS_RT_OK);
    ASSERT_EQ(pvs_rt_clovr_environment_ids(c, env.data(), env.size(), &nv), PVS_RT_OK);
    EXPECT_EQ(nn, f.near_count);
    EXPECT_EQ(nn + nv, ids.size());
    if (frames == 0) {
      EXPECT_EQ(f.radius, 0.0);
      EXPECT_EQ(nn, 0u);
    }
    EXPECT_GE(f.radius, last_r);
    EXPECT_DOUBLE_EQ(f.near_radius, 0.7 * f.radius);
    std::vector<uint32_t> expect_near;
    for (uint32_t t : ids)
      if (obj_r[s.triangle_object[t]] < f.ring_radius) expect_near.push_back(t);
    EXPECT_EQ(std::vector<uint32_t>(near.begin(), near.begin() + nn), expect_near)
        << "frame " << frames;
    EXPECT_TRUE(
        std::includes(expect_near.begin(), expect_near.end(), previous.begin(), previous.end()));
    EXPECT_EQ(f.near_changed != 0, frames == 0 || f.ring_radius != last_ring_radius)
        << "frame " << frames;
    previous = expect_near;
    last_ring_radius = f.ring_radius;
    last_r = f.radius;
    if (f.done) break;
    ASSERT_LT(frames, 1000);
  }
  EXPECT_EQ(frames, int(nm * 3));  // frame 0 plus F frames per merged ring, the last one done
  EXPECT_EQ(f.radius, 20.0);
  ASSERT_EQ(pvs_rt_clovr_next_frame(c, &f), PVS_RT_OK);  // stays final
  EXPECT_EQ(f.radius, 20.0);
  EXPECT_EQ(f.done, 1);
  pvs_rt_clovr_destroy(c);
}

TEST(RuntimeCApi, ClovrInjectionFollowsAlgorithm1) {
  const Soup s = make_soup(10, 2, 10, 3);
  const pvs_rt_geometry g = s.geometry();
  pvs_rt_clovr_params p;
  pvs_rt_clovr_default_params(10.0, &p);
  p.min_contribution = 0;  // no merging: 8 equal-area rings
  p.frames_per_ring = 2;
  pvs_rt_clovr* c = nullptr;
  ASSERT_EQ(pvs_rt_clovr_create(&g, &p, &c), PVS_RT_OK);
  std::vector<uint32_t> ids(g.triangle_count);
  for (uint32_t t = 0; t < ids.size(); ++t) ids[t] = t;
  const double o[3] = {0, 1.5, 0}, u[3] = {0.2, 1.5, 0.1};
  ASSERT_EQ(pvs_rt_clovr_start(c, ids.data(), ids.size(), o), PVS_RT_OK);
  pvs_rt_clovr_frame f;
  ASSERT_EQ(pvs_rt_clovr_next_frame(c, &f), PVS_RT_OK);  // frame 0: R = 0, no injection possible
  const float v[3] = {1, 1, 1};
  float q[3];
  EXPECT_EQ(pvs_rt_clovr_inject_vertices(c, v, 1, u, q), PVS_RT_INVALID_ARGUMENT);
  for (int k = 0; k < 6; ++k) ASSERT_EQ(pvs_rt_clovr_next_frame(c, &f), PVS_RT_OK);
  const double big_r = f.radius, r_n = f.near_radius;
  ASSERT_GT(big_r, 0.0);
  // Inside R_n: unchanged. Beyond R: w = 0, Q on P's own cylinder in P - O's direction from U.
  const float pts[9] = {float(0.5 * r_n),           1, 0,   float(big_r + 3), 2, 1,
                        float(0.5 * (r_n + big_r)), 0, 0.3f};
  float out[9];
  ASSERT_EQ(pvs_rt_clovr_inject_vertices(c, pts, 3, u, out), PVS_RT_OK) << pvs_rt_last_error();
  for (int k = 0; k < 3; ++k) EXPECT_FLOAT_EQ(out[k], pts[k]);
  const double rp = std::hypot(pts[3] - o[0], pts[5] - o[2]),
               rq = std::hypot(out[3] - o[0], out[5] - o[2]);
  EXPECT_NEAR(rq, rp, 1e-4);
  double dq[3], dp[3];
  for (int k = 0; k < 3; ++k) {
    dq[k] = out[3 + k] - u[k];
    dp[k] = pts[3 + k] - o[k];
  }
  const double cross =
      std::hypot(std::hypot(dq[1] * dp[2] - dq[2] * dp[1], dq[2] * dp[0] - dq[0] * dp[2]),
                 dq[0] * dp[1] - dq[1] * dp[0]);
  EXPECT_NEAR(cross / (std::hypot(std::hypot(dq[0], dq[1]), dq[2]) *
                       std::hypot(std::hypot(dp[0], dp[1]), dp[2])),
              0, 1e-5);
  // In between: on its own cylinder too; the Alg. 1 weight is (R - r)/(R - R_n).
  const double rm = std::hypot(pts[6] - o[0], pts[8] - o[2]);
  EXPECT_NEAR(std::hypot(out[6] - o[0], out[8] - o[2]), rm, 1e-4);
  double w;
  ASSERT_EQ(pvs_rt_injection_weight(rm, big_r, r_n, &w), PVS_RT_OK);
  EXPECT_DOUBLE_EQ(w, (big_r - rm) / (big_r - r_n));
  pvs_rt_clovr_destroy(c);
}

TEST(RuntimeCApi, SchedulerAndFingerprintRejectBadArguments) {
  const Soup s = make_soup(3, 1, 5, 4);
  pvs_rt_geometry g = s.geometry();
  pvs_rt_clovr_params p;
  pvs_rt_clovr_default_params(10.0, &p);
  pvs_rt_clovr* c = nullptr;
  p.near_fraction = 1.0;
  EXPECT_EQ(pvs_rt_clovr_create(&g, &p, &c), PVS_RT_INVALID_ARGUMENT);
  EXPECT_EQ(c, nullptr);
  p.near_fraction = 0.7;
  g.triangle_object = nullptr;
  EXPECT_EQ(pvs_rt_clovr_create(&g, &p, &c), PVS_RT_INVALID_ARGUMENT);
  EXPECT_NE(std::string(pvs_rt_last_error()).find("triangle_object"), std::string::npos);

  const uint32_t bad_index[3] = {0, 1, 9};
  pvs_rt_mesh m{s.positions.data(), nullptr, 3, bad_index, 1, 0, nullptr};
  uint64_t fp = 0;
  EXPECT_EQ(pvs_rt_scene_fingerprint(&m, 1, 1, 1, &fp), PVS_RT_INVALID_ARGUMENT);
  EXPECT_NE(std::string(pvs_rt_last_error()).find("mesh 0: index 9"), std::string::npos)
      << pvs_rt_last_error();
  const uint32_t ok_index[3] = {0, 1, 2};
  m.indices = ok_index;
  m.object_id = 1;
  EXPECT_EQ(pvs_rt_scene_fingerprint(&m, 1, 1, 1, &fp),
            PVS_RT_INVALID_ARGUMENT);  // object 1 >= 1 object
  m.object_id = 0;
  EXPECT_EQ(pvs_rt_scene_fingerprint(&m, 1, 1, 1, &fp), PVS_RT_OK);
  // Float and double buffers of the same values give the same fingerprint.
  std::vector<double> d(s.positions.begin(), s.positions.begin() + 9);
  pvs_rt_mesh md{nullptr, d.data(), 3, ok_index, 1, 0, nullptr};
  uint64_t fd = 1;
  EXPECT_EQ(pvs_rt_scene_fingerprint(&md, 1, 1, 1, &fd), PVS_RT_OK);
  EXPECT_EQ(fd, fp);
}

namespace {

// A file in memory served by byte range, recording every range asked for.
struct RangeLog {
  std::string bytes;
  std::vector<std::pair<uint64_t, uint64_t>> ranges;  // [begin, end)
  bool fail = false;
};

int read_range(void* user, uint64_t offset, uint64_t size, void* out) {
  auto* log = static_cast<RangeLog*>(user);
  if (log->fail || offset + size > log->bytes.size()) return 1;
  log->ranges.emplace_back(offset, offset + size);
  std::memcpy(out, log->bytes.data() + offset, size_t(size));
  return 0;
}

// A 6 x 1 x 5 grid of nested random sets (neighbouring cells alike, so the writer picks Delta
// blocks), written to a temporary file.
struct RangeCase {
  std::string path;
  pvs::FileInfo info;
  std::string bytes;
};

RangeCase make_range_case() {
  RangeCase rc;
  rc.info.scene_fingerprint = 0x5eedf00dull;
  rc.info.universe = 5000;
  rc.info.layout.grid_box = {{-30, 0, -25}, {30, 3, 25}};
  rc.info.layout.nx = 6;
  rc.info.layout.nz = 5;
  rc.info.layout.eye_hi = 2;
  std::mt19937 rng(7);
  std::vector<pvs::CellSet> cells;
  std::vector<uint32_t> base;
  for (uint32_t i = 0; i < rc.info.universe; ++i)
    if (rng() % 3 == 0) base.push_back(i);
  for (uint32_t c = 0; c < 30; ++c) {
    std::vector<uint32_t> ids;
    for (uint32_t id : base)
      if (rng() % 50 != 0) ids.push_back(id);
    cells.emplace_back(ids);
  }
  rc.bytes = pvs::write_pvs(rc.info, cells);
  // One file per process: ctest runs each test in its own process, in parallel, and rewriting a
  // file another test has mapped would fault it.
  rc.path = (std::filesystem::temp_directory_path() /
             ("vislib_range_case_" + std::to_string(::getpid()) + ".pvs"))
                .string();
  std::ofstream(rc.path, std::ios::binary).write(rc.bytes.data(), std::streamsize(rc.bytes.size()));
  return rc;
}

std::vector<uint32_t> ids_of(pvs_rt* h, uint32_t cell) {
  uint32_t n = 0;
  EXPECT_EQ(pvs_rt_visible_count(h, cell, &n), PVS_RT_OK);
  std::vector<uint32_t> ids(n);
  size_t count = 0;
  EXPECT_EQ(pvs_rt_visible_ids(h, cell, ids.data(), ids.size(), &count), PVS_RT_OK)
      << pvs_rt_last_error();
  ids.resize(count);
  return ids;
}

}  // namespace

TEST(RuntimeCApi, OpenRangesAnswersLikeOpenByPath) {
  const RangeCase rc = make_range_case();
  RangeLog log{rc.bytes, {}, false};
  pvs_rt *by_path = nullptr, *by_ranges = nullptr;
  ASSERT_EQ(pvs_rt_open(rc.path.c_str(), 1, rc.info.scene_fingerprint, &by_path), PVS_RT_OK);
  ASSERT_EQ(pvs_rt_open_ranges(rc.bytes.size(), read_range, &log, 1, rc.info.scene_fingerprint,
                               &by_ranges),
            PVS_RT_OK)
      << pvs_rt_last_error();
  pvs_rt_info a{}, b{};
  ASSERT_EQ(pvs_rt_get_info(by_path, &a), PVS_RT_OK);
  ASSERT_EQ(pvs_rt_get_info(by_ranges, &b), PVS_RT_OK);
  EXPECT_EQ(std::memcmp(&a, &b, sizeof a), 0);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> x(-31, 31), z(-26, 26);
  for (int i = 0; i < 200; ++i) {
    const double p[3] = {x(rng), 1.0, z(rng)};
    uint32_t ca = 99, cb = 98;
    const pvs_rt_status sa = pvs_rt_find_cell(by_path, p, &ca);
    ASSERT_EQ(sa, pvs_rt_find_cell(by_ranges, p, &cb));
    if (sa == PVS_RT_OK) {
      EXPECT_EQ(ca, cb);
    }
  }
  for (uint32_t c = 0; c < a.cell_count; ++c) EXPECT_EQ(ids_of(by_path, c), ids_of(by_ranges, c));
  pvs_rt_close(by_path);
  pvs_rt_close(by_ranges);
  std::filesystem::remove(rc.path);
}

TEST(RuntimeCApi, OpenRangesAsksForHeaderIndexAndTheQueriedCellsBlocksOnly) {
  const RangeCase rc = make_range_case();
  pvs::Reader reader = pvs::Reader::from_memory(rc.bytes);
  RangeLog log{rc.bytes, {}, false};
  pvs_rt* h = nullptr;
  ASSERT_EQ(pvs_rt_open_ranges(rc.bytes.size(), read_range, &log, 0, 0, &h), PVS_RT_OK);
  // Opening: the header, the layout section and the index, in that order, nothing else.
  const std::vector<std::pair<uint64_t, uint64_t>> open_ranges = {
      {0, pvs::kHeaderSize},
      {pvs::kHeaderSize, reader.index_offset()},
      {reader.index_offset(), reader.blocks_offset()}};
  EXPECT_EQ(log.ranges, open_ranges);
  log.ranges.clear();
  // Queries: each cell's block, then the blocks of its Delta chain (from the reader's own view of
  // the blocks), and nothing of any other cell.
  int deltas = 0;
  for (uint32_t cell : {17u, 4u, 29u, 12u}) {
    std::vector<std::pair<uint64_t, uint64_t>> expected;
    for (uint32_t c = cell;;) {
      const pvs::IndexEntry& e = reader.entry(c);
      expected.emplace_back(e.offset, e.offset + e.size);
      const pvs::BlockInfo bi = reader.block_info(c);
      if (bi.encoding != pvs::Encoding::Delta) break;
      ++deltas;
      c = bi.reference;
    }
    log.ranges.clear();
    uint64_t off = 0;
    uint32_t size = 0;
    ASSERT_EQ(pvs_rt_block_range(h, cell, &off, &size), PVS_RT_OK);
    EXPECT_EQ(off, expected[0].first);
    EXPECT_EQ(off + size, expected[0].second);
    EXPECT_EQ(ids_of(h, cell), reader.read_cell(cell));
    EXPECT_EQ(log.ranges, expected) << "cell " << cell;
  }
  EXPECT_GT(deltas, 0) << "the case should exercise Delta chains";
  // The index answers without reading: counts, lookups and neighbours ask for nothing.
  log.ranges.clear();
  uint32_t n = 0, cell = 0;
  const double p[3] = {0, 1, 0};
  size_t count = 0;
  uint32_t nb[27];
  EXPECT_EQ(pvs_rt_visible_count(h, 5, &n), PVS_RT_OK);
  EXPECT_EQ(pvs_rt_find_cell(h, p, &cell), PVS_RT_OK);
  EXPECT_EQ(pvs_rt_neighbours(h, cell, 0, nb, 27, &count), PVS_RT_OK);
  EXPECT_EQ(pvs_rt_prefetch(h, cell), PVS_RT_OK);
  EXPECT_TRUE(log.ranges.empty());
  // A failing read is an i/o error naming the range.
  log.fail = true;
  size_t got = 0;
  std::vector<uint32_t> out(rc.info.universe);
  EXPECT_EQ(pvs_rt_visible_ids(h, 3, out.data(), out.size(), &got), PVS_RT_IO);
  EXPECT_NE(std::string(pvs_rt_last_error()).find("read callback failed"), std::string::npos);
  pvs_rt_close(h);
  pvs_rt* h2 = reinterpret_cast<pvs_rt*>(&log);
  EXPECT_EQ(pvs_rt_open_ranges(rc.bytes.size(), read_range, &log, 0, 0, &h2), PVS_RT_IO);
  EXPECT_EQ(h2, nullptr);
  EXPECT_EQ(pvs_rt_open_ranges(rc.bytes.size(), nullptr, &log, 0, 0, &h2), PVS_RT_INVALID_ARGUMENT);
  // A file size that disagrees with the header is a format error, like a truncated file.
  log.fail = false;
  EXPECT_EQ(pvs_rt_open_ranges(rc.bytes.size() - 1, read_range, &log, 0, 0, &h2), PVS_RT_FORMAT);
  std::filesystem::remove(rc.path);
}

TEST(RuntimeCApi, DeltaChainNamesAndReadsExactlyTheBlocksVisibleIdsNeeds) {
  const RangeCase rc = make_range_case();
  pvs::Reader reader = pvs::Reader::from_memory(rc.bytes);
  RangeLog log{rc.bytes, {}, false};
  pvs_rt* h = nullptr;
  ASSERT_EQ(pvs_rt_open_ranges(rc.bytes.size(), read_range, &log, 0, 0, &h), PVS_RT_OK);
  size_t longest = 0;
  for (uint32_t cell = 0; cell < 30; ++cell) {
    // Oracle: the blocks visible_ids asks for (the callback's log), in order.
    log.ranges.clear();
    EXPECT_EQ(ids_of(h, cell), reader.read_cell(cell));
    const auto read_by_ids = log.ranges;
    log.ranges.clear();
    uint32_t chain[16];
    size_t count = 0;
    ASSERT_EQ(pvs_rt_delta_chain(h, cell, chain, 16, &count), PVS_RT_OK) << pvs_rt_last_error();
    ASSERT_GE(count, 1u);
    EXPECT_EQ(chain[0], cell);
    std::vector<std::pair<uint64_t, uint64_t>> named;
    for (size_t k = 0; k < count; ++k) {
      uint64_t off = 0;
      uint32_t size = 0;
      ASSERT_EQ(pvs_rt_block_range(h, chain[k], &off, &size), PVS_RT_OK);
      named.emplace_back(off, off + size);
    }
    EXPECT_EQ(named, read_by_ids) << "cell " << cell;
    EXPECT_EQ(log.ranges, read_by_ids) << "cell " << cell << ": the chain reads its blocks only";
    longest = std::max(longest, size_t(count));
    if (count > 1) {
      size_t small = 0;
      EXPECT_EQ(pvs_rt_delta_chain(h, cell, chain, count - 1, &small), PVS_RT_BUFFER_TOO_SMALL);
      EXPECT_EQ(small, count);
    }
  }
  EXPECT_GT(longest, 1u) << "the case should exercise Delta chains";
  size_t count = 0;
  uint32_t one = 0;
  EXPECT_EQ(pvs_rt_delta_chain(h, 30, &one, 1, &count), PVS_RT_INVALID_ARGUMENT);
  EXPECT_EQ(pvs_rt_delta_chain(nullptr, 0, &one, 1, &count), PVS_RT_INVALID_ARGUMENT);
  pvs_rt_close(h);
  std::filesystem::remove(rc.path);
}
