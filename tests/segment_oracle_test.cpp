// The independent oracle of docs/visibility-math.md §8 for the from-segment kernel: Embree ray
// casts at random t through every pixel centre (forward check: nothing missed) and a re-cast at the
// middle of every final piece (converse check: nothing extra, so every witness holds). Samples the
// oracle calls ambiguous (float vs double, edges, coplanar surfaces, the near plane) are skipped
// and counted; everything else must agree exactly.
#include <gtest/gtest.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <cstdio>
#include <mutex>

#include "tests/scene_builders.h"
#include "tests/support/ray_oracle.h"
#include "tests/test_support.h"
#include "vislib/kernel/segment_visibility.h"
#include "vislib/scene/import.h"

using namespace vislib;
using vislib_test::random_soup;

namespace {

struct OracleCounts {
  uint64_t forward = 0, forward_ambiguous = 0, misses = 0;
  uint64_t settled_by_double = 0;  // Embree (float) disagreed, the double reference agreed
  uint64_t converse = 0, converse_ambiguous = 0, false_positives = 0;
  uint64_t witnesses = 0, witness_failures = 0;
  uint64_t witness_ties = 0;  // the first hit is another surface within eps_z (coplanar tie)
  std::string first_failure;
};

// Runs the kernel on one segment and checks it with `samples` random t per pixel.
OracleCounts check_segment(const Scene& scene, const EmbreeScene& embree, Vec3 v0, Vec3 v1,
                           const Mat3& R, int n, double near, int samples, uint64_t seed) {
  SegmentOptions o;
  o.resolution = n;
  o.near = near;
  o.orientation = R;
  o.want_pieces = true;
  o.want_witnesses = true;
  SegmentResult r = segment_visibility(scene, v0, v1, o);
  RayOracle oracle(embree, v0, v1, R, n, near);
  std::vector<double> ts;
  Rng rng(seed);
  for (int k = 0; k < samples; ++k) ts.push_back(rng.uniform());

  std::atomic<uint64_t> fwd{0}, fwd_amb{0}, miss{0}, conv{0}, conv_amb{0}, fp{0}, settled{0};
  // On a disagreement with Embree (float): the double-precision brute-force reference decides.
  // 0 = the kernel is right (float error), 1 = ambiguous (skip), 2 = the kernel is wrong.
  auto resolve = [&](int face, int x, int y, double t, uint32_t ours) {
    OracleSample ref =
        brute_force_first_hit(scene, 0.0, oracle.eye(t), oracle.direction(face, x, y), near);
    if (!ref.ambiguous && ref.tri == ours) {
      ++settled;
      return 0;
    }
    if (ref.ambiguous || oracle.is_ambiguous(face, x, y, t)) return 1;
    return 2;
  };
  std::mutex m;
  std::string first;
  auto fail = [&](const char* kind, int face, int x, int y, double t, uint32_t ours,
                  uint32_t theirs) {
    std::lock_guard<std::mutex> g(m);
    if (!first.empty()) return;
    char buf[256];
    std::snprintf(buf, sizeof buf, "%s at face %d x %d y %d t %.17g: kernel %d, Embree %d", kind,
                  face, x, y, t, int(ours), int(theirs));
    first = buf;
  };
  const size_t pixels = size_t(6) * n * n;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, pixels, 256),
                    [&](const tbb::blocked_range<size_t>& br) {
                      uint64_t f = 0, fa = 0, mi = 0, c = 0, ca = 0, fpos = 0;
                      for (size_t p = br.begin(); p != br.end(); ++p) {
                        int face = int(p / (size_t(n) * n)), y = int(p / n % n), x = int(p % n);
                        const PieceList& list = r.pieces[p];
                        // Forward: at random t (away from piece boundaries) the first hit is the
                        // piece's id.
                        for (double t : ts) {
                          bool near_boundary = false;
                          for (const Piece& pc : list)
                            if (std::fabs(t - pc.t0) < 1e-9 || std::fabs(t - pc.t1) < 1e-9)
                              near_boundary = true;
                          if (near_boundary) continue;
                          auto piece = lookup(list, t);
                          uint32_t ours = piece ? piece->id : kNoHit;
                          Hit h = oracle.first_hit(face, x, y, t);
                          ++f;
                          if (h.tri == ours) continue;
                          int verdict = resolve(face, x, y, t, ours);
                          if (verdict == 0) continue;
                          if (verdict == 1) {
                            ++fa;
                            continue;
                          }
                          ++mi;
                          fail("miss", face, x, y, t, ours, h.tri);
                        }
                        // Converse: the middle of every final piece that counts (longer than
                        // eps_len, so it puts its triangle in the set) shows that piece's triangle.
                        // Shorter pieces are rounding slivers at shared vertices (~1e-16 in t) that
                        // make nothing visible.
                        for (const Piece& pc : list) {
                          if (!(pc.t1 - pc.t0 > o.eps_len)) continue;
                          double t = 0.5 * (pc.t0 + pc.t1);
                          Hit h = oracle.first_hit(face, x, y, t);
                          ++c;
                          if (h.tri == pc.id) continue;
                          int verdict = resolve(face, x, y, t, pc.id);
                          if (verdict == 0) continue;
                          if (verdict == 1) {
                            ++ca;
                            continue;
                          }
                          ++fpos;
                          fail("false positive", face, x, y, t, pc.id, h.tri);
                        }
                      }
                      fwd += f;
                      fwd_amb += fa;
                      miss += mi;
                      conv += c;
                      conv_amb += ca;
                      fp += fpos;
                    });
  OracleCounts out;
  out.forward = fwd;
  out.forward_ambiguous = fwd_amb;
  out.misses = miss;
  out.converse = conv;
  out.converse_ambiguous = conv_amb;
  out.false_positives = fp;
  out.settled_by_double = settled;
  out.first_failure = first;
  // Every visible triangle's witness re-casts to it (unless ambiguous), or (CoplanarRule::Both) to
  // a surface whose depth is within eps_z of the witness triangle's along that ray.
  for (const Witness& w : r.witnesses) {
    ++out.witnesses;
    Hit h = oracle.first_hit(w.face, w.x, w.y, w.t);
    if (h.tri == w.tri || resolve(w.face, w.x, w.y, w.t, w.tri) != 2) continue;
    OracleSample ref = brute_force_first_hit(scene, 0.0, oracle.eye(w.t),
                                             oracle.direction(w.face, w.x, w.y), near);
    double mine =
        triangle_depth(scene, w.tri, oracle.eye(w.t), oracle.direction(w.face, w.x, w.y), near);
    if (ref.tri != kNoHit && std::fabs(mine - ref.lambda) <= 2 * o.eps_z * ref.lambda) {
      ++out.witness_ties;
      continue;
    }
    ++out.witness_failures;
  }
  return out;
}

// Random segments inside the scene's bounding box (a tenth of its diagonal long at most).
void check_scene(const std::string& name, const Scene& scene, int segments, int n, int samples,
                 uint64_t seed) {
  Box3 b = scene.bounds();
  Vec3 ext = b.max - b.min;
  double diag = length(ext);
  Rng rng(seed);
  OracleCounts total;
  for (int s = 0; s < segments; ++s) {
    Vec3 v0{rng.uniform(b.min.x, b.max.x), rng.uniform(b.min.y, b.max.y),
            rng.uniform(b.min.z, b.max.z)};
    Vec3 dir{rng.normal(), rng.normal(), rng.normal()};
    Vec3 v1 = v0 + dir * (0.1 * diag * rng.uniform() / length(dir));
    Mat3 R = s == 0 ? Mat3{} : random_orientation(Rng::derive(seed, s));
    double near = 1e-4 * diag;
    EmbreeScene embree(scene, 0.0, v0);
    OracleCounts c =
        check_segment(scene, embree, v0, v1, R, n, near, samples, Rng::derive(seed, 100 + s));
    EXPECT_EQ(c.misses, 0u) << name << " segment " << s << ": " << c.first_failure;
    EXPECT_EQ(c.false_positives, 0u) << name << " segment " << s << ": " << c.first_failure;
    EXPECT_EQ(c.witness_failures, 0u) << name << " segment " << s;
    total.forward += c.forward;
    total.forward_ambiguous += c.forward_ambiguous;
    total.converse += c.converse;
    total.converse_ambiguous += c.converse_ambiguous;
    total.witnesses += c.witnesses;
    total.misses += c.misses;
    total.false_positives += c.false_positives;
    total.settled_by_double += c.settled_by_double;
  }
  // Sampled checks need enough unambiguous samples to mean something.
  EXPECT_GT(total.forward, 0u);
  EXPECT_LT(double(total.forward_ambiguous), 0.01 * double(total.forward)) << name;
  EXPECT_LT(double(total.converse_ambiguous), 0.01 * double(total.converse) + 10) << name;
  std::printf(
      "[oracle] %s: %d segments N=%d: forward %llu (ambiguous %llu, misses %llu), converse %llu "
      "(ambiguous %llu, false positives %llu), witnesses %llu, Embree disagreements settled by the "
      "double "
      "reference %llu\n",
      name.c_str(), segments, n, (unsigned long long)total.forward,
      (unsigned long long)total.forward_ambiguous, (unsigned long long)total.misses,
      (unsigned long long)total.converse, (unsigned long long)total.converse_ambiguous,
      (unsigned long long)total.false_positives, (unsigned long long)total.witnesses,
      (unsigned long long)total.settled_by_double);
}

}  // namespace

TEST(SegmentOracle, RandomSoupHasNoMissAndNoFalsePositive) {
  check_scene("soup", random_soup(2000, 1, 10, 1.5), 4, 64, 6, 1);
}

TEST(SegmentOracle, ClosedWavyGridsWithBackgroundHaveNoMissAndNoFalsePositive) {
  Scene s;
  vislib_test::add_grid(
      s, 40, -20, 20, -20, 20,
      [](double x, double y) { return 3 + std::sin(x) * std::cos(0.7 * y); }, 3, 0.7);
  vislib_test::add_grid(
      s, 20, -20, 20, -20, 20, [](double x, double y) { return -4 + 0.5 * std::cos(x + y); }, 4,
      0.7);
  vislib_test::add_quad(s, {-30, -30, 12}, {30, -30, 12}, {30, 30, 12}, {-30, 30, 12});
  check_scene("grids", s, 4, 64, 6, 2);
}

// The oracle on real scenes: every static scene of ../shared at N = 256.
class SharedSceneOracle : public ::testing::TestWithParam<const char*> {};

TEST_P(SharedSceneOracle, HasNoMissAndNoFalsePositiveAtN256) {
  VISLIB_REQUIRE_SHARED(shared);
  std::string path = shared + "/scenes/" + GetParam();
  Scene scene = load_scene(path);
  check_scene(GetParam(), scene, 2, 256, 2, 7);
}

INSTANTIATE_TEST_SUITE_P(StaticScenes, SharedSceneOracle,
                         ::testing::Values("sauer_fdm6/fdm6.obj",
                                           "godot_truck_town/town_model.gltf",
                                           "sauer_pandora/pandora.obj",
                                           "godot_occlusion_room/room.glb",
                                           "gk_dream_apartment/dream-apartment.glb",
                                           "khronos_boxanimated/BoxAnimated.gltf"),
                         [](const auto& param_info) {
                           std::string s = param_info.param;
                           std::string out;
                           for (char c : s.substr(0, s.find('/')))
                             out += std::isalnum((unsigned char)c) ? c : '_';
                           return out;
                         });
