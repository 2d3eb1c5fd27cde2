// The dynamic kernel (moving triangles, spheres, the two modes) against a double-precision
// brute-force ray caster at sampled times (docs/visibility-math.md §8 with §3-4), plus the hard
// cases H14, H15 and the sphere cases of docs/visibility-math.md §4.
#include "vislib/kernel/dynamic_visibility.h"

#include <gtest/gtest.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <cmath>
#include <memory>
#include <mutex>

#include "tests/scene_builders.h"
#include "tests/support/ray_oracle.h"
#include "tests/test_support.h"
#include "vislib/base/polynomial.h"
#include "vislib/eval/embree_scene.h"
#include "vislib/kernel/general_depth.h"
#include "vislib/kernel/segment_visibility.h"
#include "vislib/kernel/static_coverage.h"
#include "vislib/scene/generate.h"
#include "vislib/scene/import.h"

using namespace vislib;

namespace {

struct RefHit {
  uint32_t id = kNoHit;  // triangle id, or triangle_count + sphere index
  bool ambiguous = false;
};

// First hit over triangles (brute_force_first_hit, double) and spheres (analytic, double) of the
// scene at animation time tau, from `eye` along d, lambda > near.
RefHit reference(const Scene& s, double tau, Vec3 eye, Vec3 d, double near) {
  RefHit r;
  OracleSample tri =
      s.triangle_count() ? brute_force_first_hit(s, tau, eye, d, near) : OracleSample{};
  double best = tri.tri == kNoHit ? INFINITY : tri.lambda;
  r.id = tri.tri;
  r.ambiguous = tri.ambiguous;
  const double dd = dot(d, d);
  for (size_t k = 0; k < s.sphere_count(); ++k) {
    Vec3 w = eye - s.sphere_center_at(uint32_t(k), tau);
    double rr = s.sphere_radius[k];
    double h = dot(d, w), m = dot(w, w) - rr * rr;
    Vec3 c = cross(d, w);
    double g = rr * rr * dd - dot(c, c);
    if (g <= 0) {
      if (g > -1e-9 * rr * rr * dd) r.ambiguous = r.ambiguous || true;  // grazing
      continue;
    }
    if (g < 1e-9 * rr * rr * dd) r.ambiguous = true;  // grazing
    double sq = std::sqrt(g);
    double l1 = h < 0 ? m / (-h + sq) : (-h - sq) / dd, l2 = (-h + sq) / dd;
    double lam = l1 > near ? l1 : (l2 > near ? l2 : INFINITY);
    if (std::fabs(l1 - near) < 1e-9 * near + 1e-12 || std::fabs(l2 - near) < 1e-9 * near + 1e-12)
      r.ambiguous = true;
    if (!std::isfinite(lam)) continue;
    if (std::fabs(lam - best) <= 1e-7 * std::max(lam, best)) r.ambiguous = true;
    if (lam < best) {
      best = lam;
      r.id = uint32_t(s.triangle_count() + k);
    }
  }
  return r;
}

struct Counts {
  uint64_t forward = 0, ambiguous = 0, misses = 0, converse = 0, false_positives = 0;
  std::string first;
};

// Diagonal mode (tau = t): forward check at random t and converse check at every piece middle.
// With `embree`, the forward check first asks Embree rebuilt at each sampled time (triangles only)
// and consults the brute-force reference only where Embree disagrees (float vs double).
Counts check_diagonal(const Scene& s, Vec3 v0, Vec3 v1, const Mat3& R, int n, double near,
                      int samples, uint64_t seed, bool embree = false) {
  SegmentOptions o;
  o.resolution = n;
  o.near = near;
  o.orientation = R;
  o.want_pieces = true;
  SegmentResult r = dynamic_segment_visibility(s, v0, v1, o);
  std::vector<double> ts;
  Rng rng(seed);
  for (int k = 0; k < samples; ++k) ts.push_back(rng.uniform());
  std::vector<std::unique_ptr<EmbreeScene>> at_time;
  if (embree)
    for (double t : ts) at_time.push_back(std::make_unique<EmbreeScene>(s, t, lerp(v0, v1, t)));
  // The converse check re-casts at most ~30000 pieces (every stride-th piece, in pixel order), so
  // that dense scenes stay affordable with the brute-force reference.
  size_t total_pieces = 0;
  std::vector<size_t> first_piece(r.general_pieces.size() + 1, 0);
  for (size_t p = 0; p < r.general_pieces.size(); ++p) {
    first_piece[p] = total_pieces;
    total_pieces += r.general_pieces[p].size();
  }
  const size_t stride = std::max<size_t>(1, total_pieces / 30000);
  std::atomic<uint64_t> fwd{0}, amb{0}, miss{0}, conv{0}, fp{0};
  std::string first;
  std::mutex mu;
  tbb::parallel_for(size_t(0), size_t(6) * n * n, [&](size_t p) {
    int face = int(p / (size_t(n) * n)), y = int(p / n % n), x = int(p % n);
    Vec3 d = pixel_direction(face_axes(face, R), x, y, n);
    const auto& list = r.general_pieces[p];
    auto judge = [&](double t, uint32_t ours, bool converse) {
      RefHit ref = reference(s, t, lerp(v0, v1, t), d, near);
      if (ref.id == ours) return;
      if (ref.ambiguous) {
        ++amb;
        return;
      }
      (converse ? fp : miss)++;
      std::lock_guard<std::mutex> g(mu);
      if (first.empty())
        first = std::string(converse ? "false positive" : "miss") + " face " +
                std::to_string(face) + " x " + std::to_string(x) + " y " + std::to_string(y) +
                " t " + std::to_string(t) + " kernel " + std::to_string(int(ours)) + " reference " +
                std::to_string(int(ref.id));
    };
    for (size_t ti = 0; ti < ts.size(); ++ti) {
      const double t = ts[ti];
      bool near_boundary = false;
      for (const auto& pc : list)
        if (std::fabs(t - pc.t0) < 1e-9 || std::fabs(t - pc.t1) < 1e-9) near_boundary = true;
      if (near_boundary) continue;
      auto pc = lookup(list, t);
      ++fwd;
      uint32_t ours = pc ? pc->id : kNoHit;
      if (embree && at_time[ti]->first_hit(lerp(v0, v1, t), d, near).tri == ours) continue;
      judge(t, ours, false);
    }
    for (size_t k = 0; k < list.size(); ++k) {
      const auto& pc = list[k];
      if ((first_piece[p] + k) % stride != 0) continue;
      if (!(pc.t1 - pc.t0 > 1e-9)) continue;
      ++conv;
      judge(0.5 * (pc.t0 + pc.t1), pc.id, true);
    }
  });
  return {fwd, amb, miss, conv, fp, first};
}

// Zero misses and false positives among unambiguous samples; the ambiguous share must stay below
// `max_ambiguous` so that the check means something.
void expect_clean(const Counts& c, const char* what, double max_ambiguous = 0.01) {
  EXPECT_EQ(c.misses, 0u) << what << ": " << c.first;
  EXPECT_EQ(c.false_positives, 0u) << what << ": " << c.first;
  EXPECT_GT(c.forward, 1000u) << what;
  EXPECT_LT(double(c.ambiguous), max_ambiguous * double(c.forward + c.converse) + 5) << what;
  std::printf(
      "[dynamic oracle] %s: forward %llu, converse %llu, ambiguous %llu, misses %llu, false "
      "positives %llu\n",
      what, (unsigned long long)c.forward, (unsigned long long)c.converse,
      (unsigned long long)c.ambiguous, (unsigned long long)c.misses,
      (unsigned long long)c.false_positives);
}

// A soup of triangles each moving (and turning) linearly over `states` key states.
Scene moving_soup(int count, int states, uint64_t seed, double extent, double size, double motion) {
  Rng rng(seed);
  Scene s;
  s.positions.resize(states);
  for (int i = 0; i < count; ++i) {
    Vec3 c{rng.uniform(-extent, extent), rng.uniform(-extent, extent),
           rng.uniform(-extent, extent)};
    uint32_t b = uint32_t(s.positions[0].size());
    for (int v = 0; v < 3; ++v) {
      Vec3 p =
          c + Vec3{rng.uniform(-size, size), rng.uniform(-size, size), rng.uniform(-size, size)};
      for (int k = 0; k < states; ++k) {
        s.positions[k].push_back(p);
        p = p + Vec3{rng.uniform(-motion, motion), rng.uniform(-motion, motion),
                     rng.uniform(-motion, motion)};
      }
    }
    s.triangles.push_back({b, b + 1, b + 2});
    s.triangle_object.push_back(uint32_t(i));
    s.objects.push_back({"t" + std::to_string(i)});
  }
  return s;
}

}  // namespace

TEST(DynamicVisibility, StaticSceneThroughTheDynamicKernelMatchesTheLinearKernel) {
  Scene s = moving_soup(300, 1, 5, 8, 1.5, 0);
  SegmentOptions o;
  o.resolution = 32;
  o.want_pieces = true;
  o.orientation = random_orientation(2);
  auto a = segment_visibility(s, {0, 0, 0}, {1.5, -0.5, 0.7}, o);
  auto b = dynamic_segment_visibility(s, {0, 0, 0}, {1.5, -0.5, 0.7}, o);
  EXPECT_EQ(a.visible, b.visible);
  ASSERT_EQ(a.pieces.size(), b.general_pieces.size());
  for (size_t p = 0; p < a.pieces.size(); ++p) {
    ASSERT_EQ(a.pieces[p].size(), b.general_pieces[p].size()) << p;
    for (size_t k = 0; k < a.pieces[p].size(); ++k) {
      EXPECT_EQ(a.pieces[p][k].id, b.general_pieces[p][k].id);
      EXPECT_NEAR(a.pieces[p][k].t0, b.general_pieces[p][k].t0, 1e-12);
      EXPECT_NEAR(a.pieces[p][k].t1, b.general_pieces[p][k].t1, 1e-12);
    }
  }
}

TEST(DynamicVisibility, MovingAndTurningTrianglesMatchTheReferenceAtSampledTimes) {
  // Vertices move independently, so triangles turn through edge-on (H14: sigma flips).
  Scene s = moving_soup(250, 3, 7, 6, 1.5, 2.0);
  expect_clean(check_diagonal(s, {0, 0, 0}, {2, 1, -1}, random_orientation(3), 40, 0.01, 6, 1),
               "moving soup");
}

TEST(DynamicVisibility, H14_TriangleTurningThroughEdgeOnIsCoveredExactlyWhenFacingTheRay) {
  // One triangle spinning about the x axis in front of a fixed eye: edge-on at tau = 0.5.
  Scene s;
  s.positions = {{{-1, -1, 5}, {1, -1, 5}, {0, 1, 5}},
                 {{-1, -1, 5}, {1, -1, 5}, {0, -1, 7}},
                 {{-1, -1, 5}, {1, -1, 5}, {0, -3, 5}}};
  s.triangles = {{0, 1, 2}};
  s.triangle_object = {0};
  s.objects = {{"spinner"}};
  expect_clean(check_diagonal(s, {0, 0, 0}, {0, 0, 0}, Mat3{}, 48, 0.01, 20, 2), "spinner");
}

TEST(DynamicVisibility, H15_FourCoverageIntervalsOfOneMovingTriangleAtOnePixel) {
  // The witness of search_intervals.py: z = 10, eye fixed at the origin, d = +z (N = 1 on +Z).
  double V0[3][2] = {{0.4576821423384487, 0.24706675268238376},
                     {-0.688258553731099, 0.7557804641488242},
                     {-0.8985668004318588, -0.5328682352724976}};
  double V1[3][2] = {{-25.563507330937078, -15.818740074503603},
                     {29.312488846201276, -28.37074709207861},
                     {-28.028873885457422, 28.82514057563443}};
  Scene s;
  s.positions.resize(2);
  for (int k = 0; k < 3; ++k) {
    // +Z face: d = (sc, -tc, 1); the witness's 2D frame is (x, y) with the ray at the origin.
    s.positions[0].push_back({V0[k][0], V0[k][1], 10});
    s.positions[1].push_back({V0[k][0] + V1[k][0], V0[k][1] + V1[k][1], 10});
  }
  s.triangles = {{0, 1, 2}};
  s.triangle_object = {0};
  s.objects = {{"w"}};
  SegmentOptions o;
  o.resolution = 1;
  o.want_pieces = true;
  auto r = dynamic_segment_visibility(s, {0, 0, 0}, {0, 0, 0}, o);
  const auto& l = r.general_pieces[4];  // face +Z, pixel (0,0): d = (0,0,1)
  ASSERT_EQ(l.size(), 4u);
  const double expect[4][2] = {{0.0, 0.0012088241478774916},
                               {0.015334695445606497, 0.017222377573659204},
                               {0.02519742889223435, 0.02722625191932012},
                               {0.7723508078604829, 1.0}};
  for (int k = 0; k < 4; ++k) {
    EXPECT_NEAR(l[k].t0, expect[k][0], 1e-12);
    EXPECT_NEAR(l[k].t1, expect[k][1], 1e-12);
  }
}

TEST(DynamicVisibility, BouncingSpheresOverAGroundMatchTheReference) {
  Scene s;
  vislib_test::add_quad(s, {-30, -1, -30}, {30, -1, -30}, {30, -1, 30}, {-30, -1, 30});
  Rng rng(9);
  const int K = 4, n = 120;
  s.sphere_centers.resize(K);
  while (s.positions.size() < K) s.positions.push_back(s.positions[0]);
  for (int i = 0; i < n; ++i) {
    double r = rng.uniform(0.3, 1.5);
    Vec3 c{rng.uniform(-15, 15), rng.uniform(0, 6), rng.uniform(-15, 15)};
    for (int k = 0; k < K; ++k) {
      s.sphere_centers[k].push_back(c);
      c = c +
          Vec3{rng.uniform(-3, 3), rng.uniform(-2, 2), rng.uniform(-3, 3)};  // may interpenetrate
    }
    s.sphere_radius.push_back(r);
    s.sphere_object.push_back(uint32_t(s.objects.size()));
    s.objects.push_back({"sphere" + std::to_string(i)});
  }
  expect_clean(check_diagonal(s, {-2, 1, -1}, {3, 1.5, 2}, random_orientation(4), 40, 0.01, 5, 3),
               "spheres");
}

TEST(DynamicVisibility, EyeInsideASphereSeesItsInsideAndGrazingRaysDoNotBreakAnything) {
  Scene s;
  s.sphere_centers = {{{0, 0, 0}, {0, 0.5, 8}, {3, 0, 6}}};  // one state
  s.sphere_radius = {1.0, 1.0, 2.0};
  s.sphere_object = {0, 1, 2};
  s.objects = {{"a"}, {"b"}, {"c"}};
  // The eye starts inside sphere a and leaves it (the inside is seen through the far root); b is
  // grazed by rays near its silhouette and hidden by a; c and b interpenetrate.
  expect_clean(check_diagonal(s, {0.2, 0, -0.3}, {0, 0, -3}, Mat3{}, 48, 0.01, 8, 4),
               "inside/grazing");
  SegmentOptions o;
  o.resolution = 16;
  auto r = dynamic_segment_visibility(s, {0.2, 0, -0.3}, {0, 0, -3}, o);
  EXPECT_EQ(r.visible_spheres, (std::vector<uint32_t>{0, 2}));
}

TEST(DynamicVisibility, DecoupledModeFindsWhatTheDiagonalMissesAndKeepsEverythingElse) {
  // The eye walks from v0 (behind a wall) to v1 (with a view of the target). An occluder arrives
  // in front of the target by mid-animation: on the diagonal the target is never seen; with the
  // eye at v1 early in the animation it is.
  Scene s;
  vislib_test::add_quad(s, {-1, -1, 10}, {1, -1, 10}, {1, 1, 10}, {-1, 1, 10});  // target 0-1
  vislib_test::add_quad(s, {-40, -20, 5}, {-0.5, -20, 5}, {-0.5, 20, 5}, {-40, 20, 5});  // wall 2-3
  size_t occ = s.positions[0].size();
  vislib_test::add_quad(s, {20, -3, 8}, {26, -3, 8}, {26, 3, 8}, {20, 3, 8});  // occluder 4-5
  s.positions.resize(3, s.positions[0]);
  for (int k = 0; k < 4; ++k) {
    s.positions[1][occ + k].x -= 23;  // at tau = 0.5 and 1: x in [-3, 3]
    s.positions[2][occ + k].x -= 23;
  }
  SegmentOptions o;
  o.resolution = 64;
  auto a = dynamic_segment_visibility(s, {-5, 0, 0}, {0, 0, 0}, o);
  o.mode = DynamicMode::Decoupled;
  auto b = dynamic_segment_visibility(s, {-5, 0, 0}, {0, 0, 0}, o);
  auto has = [](const std::vector<uint32_t>& v, uint32_t id) {
    return std::find(v.begin(), v.end(), id) != v.end();
  };
  EXPECT_FALSE(has(a.visible, 0) || has(a.visible, 1));
  EXPECT_TRUE(has(b.visible, 0) || has(b.visible, 1));
  for (uint32_t id : a.visible) EXPECT_TRUE(has(b.visible, id));
}

TEST(DynamicVisibility, BoxAnimatedMatchesTheReferenceAtSampledTimes) {
  VISLIB_REQUIRE_SHARED(shared);
  LoadOptions lo;
  lo.states = 9;
  Scene s = load_scene(shared + "/scenes/khronos_boxanimated/BoxAnimated.gltf", lo);
  ASSERT_TRUE(s.is_dynamic());
  Box3 b = s.bounds();
  Vec3 c = (b.min + b.max) * 0.5, e = b.max - b.min;
  // A segment passing beside the box, looking at it from all around. BoxAnimated contains
  // overlapping coplanar triangles within one face (e.g. ids 246 and 247 both contain the same
  // points at the same depth): the kernel gives such ties to the lower id, the reference cannot
  // judge them and calls them ambiguous (measured: ~6% of samples), hence the 10% budget.
  expect_clean(check_diagonal(s, c + Vec3{-1.5 * e.x, 0.3 * e.y, 1.2 * e.z},
                              c + Vec3{1.5 * e.x, 0.1 * e.y, 1.0 * e.z}, Mat3{}, 48, 0.01, 6, 5),
               "BoxAnimated", 0.10);
}

TEST(DynamicVisibility, SwayingGrassMatchesEmbreeRebuiltAtSampledTimes) {
  GrassOptions g;
  g.size = 6;
  g.target_triangles = 4000;
  g.states = 5;
  g.seed = 3;
  Scene s = generate_grass(g);
  ASSERT_TRUE(s.is_dynamic());
  // Eye low over the grass, walking through it.
  Counts c =
      check_diagonal(s, {-2, 0.4, -1}, {2, 0.6, 1.5}, random_orientation(6), 48, 0.01, 4, 7, true);
  expect_clean(c, "grass");
}

// The dynamic kernel's lists hold 32-byte pieces pointing into a per-tile pool of depth
// functions (reused from tile to tile, the last entry dropped when an insertion changes nothing),
// and its default tile side is its own. Neither may change a result: every tile side gives the
// same visible sets, witnesses and final pieces, bit for bit, with both tie rules.
TEST(DynamicVisibility, EveryTileSideGivesTheSamePiecesWitnessesAndSetsBitForBit) {
  GrassOptions g;
  g.size = 4;
  g.target_triangles = 1500;
  g.states = 3;
  g.seed = 11;
  Scene s = generate_grass(g);
  SphereOptions so;
  so.count = 30;
  so.radius = 0.5;
  so.area = 6;
  so.states = 3;
  so.max_height = 2;
  so.seed = 4;
  append_scene(s, generate_spheres(so));
  ASSERT_TRUE(s.is_dynamic());
  ASSERT_GT(s.sphere_count(), 0u);
  auto digest = [&](int tile, CoplanarRule rule, uint64_t* pieces) {
    SegmentOptions o;
    o.resolution = 40;
    o.orientation = random_orientation(12);
    o.tile_size = tile;
    o.coplanar = rule;
    o.want_pieces = true;
    o.want_witnesses = true;
    SegmentResult r = dynamic_segment_visibility(s, {-1.5, 0.3, -1}, {1.5, 0.5, 1.2}, o);
    uint64_t h = 1469598103934665603ull;
    auto mix = [&h](const void* data, size_t n) {
      const unsigned char* b = static_cast<const unsigned char*>(data);
      for (size_t k = 0; k < n; ++k) h = (h ^ b[k]) * 1099511628211ull;
    };
    for (uint32_t id : r.visible) mix(&id, 4);
    for (uint32_t id : r.visible_spheres) mix(&id, 4);
    for (const Witness& w : r.witnesses) {
      mix(&w.tri, 4);
      mix(&w.is_sphere, 1);
      mix(&w.face, 4);
      mix(&w.x, 4);
      mix(&w.y, 4);
      mix(&w.t, 8);
      mix(&w.tau, 8);
    }
    *pieces = 0;
    for (const auto& list : r.general_pieces)
      for (const GeneralPiece& pc : list) {
        mix(&pc.t0, 8);
        mix(&pc.t1, 8);
        mix(&pc.id, 4);
        mix(&pc.depth.kind, 1);
        mix(pc.depth.c, sizeof(pc.depth.c));
        ++*pieces;
      }
    return h;
  };
  for (CoplanarRule rule : {CoplanarRule::Both, CoplanarRule::First}) {
    uint64_t n0 = 0;
    const uint64_t h0 = digest(0, rule, &n0);
    EXPECT_GT(n0, 10000u);  // dense enough that lists grow, split and merge
    for (int tile : {3, 16, 32, 64}) {
      uint64_t n = 0;
      EXPECT_EQ(digest(tile, rule, &n), h0) << "tile " << tile;
      EXPECT_EQ(n, n0) << "tile " << tile;
    }
  }
}

TEST(DynamicVisibility, GeneratedBouncingSpheresOverAGroundMatchTheReference) {
  SphereOptions so;
  so.count = 150;
  so.radius = 1.5;
  so.area = 40;
  so.states = 6;
  so.seed = 5;
  Scene s = generate_spheres(so);
  Scene ground;
  vislib_test::add_quad(ground, {-25, 0, -25}, {-25, 0, 25}, {25, 0, 25}, {25, 0, -25});
  append_scene(s, ground);
  expect_clean(check_diagonal(s, {-3, 1.7, -2}, {4, 1.7, 3}, random_orientation(8), 40, 0.01, 5, 9),
               "bouncing spheres");
}

namespace {

// View depth of primitive `id` (triangle id, or triangle_count + sphere) along eye + lambda d at
// animation time tau, lambda > near, in double; inf when the ray misses it.
double depth_of(const Scene& s, uint32_t id, double tau, Vec3 eye, Vec3 d, double near) {
  if (id < s.triangle_count()) {
    const auto& ix = s.triangles[id];
    Vec3 a = s.position_at(ix[0], tau) - eye, b = s.position_at(ix[1], tau) - eye,
         c = s.position_at(ix[2], tau) - eye;
    Vec3 e1 = b - a, e2 = c - a, pv = cross(d, e2);
    double det = dot(e1, pv);
    if (det == 0) return INFINITY;
    double u = dot(-a, pv) / det;
    Vec3 qv = cross(-a, e1);
    double v = dot(d, qv) / det, lam = dot(e2, qv) / det;
    if (u < 0 || v < 0 || u + v > 1 || !(lam > near)) return INFINITY;
    return lam;
  }
  uint32_t k = uint32_t(id - s.triangle_count());
  Vec3 w = eye - s.sphere_center_at(k, tau);
  double rr = s.sphere_radius[k], dd = dot(d, d), h = dot(d, w), m = dot(w, w) - rr * rr;
  Vec3 c = cross(d, w);
  double g = rr * rr * dd - dot(c, c);
  if (g <= 0) return INFINITY;
  double sq = std::sqrt(g);
  double l1 = h < 0 ? m / (-h + sq) : (-h - sq) / dd, l2 = (-h + sq) / dd;
  return l1 > near ? l1 : (l2 > near ? l2 : INFINITY);
}

struct WitnessCounts {
  size_t witnesses = 0, ambiguous = 0, failures = 0;
  std::string first;
};

// Re-casts every witness of `r` (both kinds of primitive) with the double-precision reference at
// the witness's eye position v0 + t (v1 - v0) and animation time tau. A witness holds when the
// reference's first hit is its primitive, or when its primitive lies within eps_z of the first
// hit's depth (a coplanar tie, CoplanarRule::Both); ambiguous references are skipped.
WitnessCounts recast_witnesses(const Scene& s, const SegmentResult& r, Vec3 v0, Vec3 v1,
                               const SegmentOptions& o) {
  WitnessCounts c;
  for (const Witness& w : r.witnesses) {
    ++c.witnesses;
    uint32_t id = w.is_sphere ? uint32_t(s.triangle_count() + w.tri) : w.tri;
    Vec3 eye = lerp(v0, v1, w.t),
         d = pixel_direction(face_axes(w.face, o.orientation), w.x, w.y, o.resolution);
    RefHit ref = reference(s, w.tau, eye, d, o.near);
    if (ref.id == id) continue;
    if (ref.ambiguous) {
      ++c.ambiguous;
      continue;
    }
    if (o.coplanar == CoplanarRule::Both && ref.id != kNoHit) {
      double mine = depth_of(s, id, w.tau, eye, d, o.near),
             front = depth_of(s, ref.id, w.tau, eye, d, o.near);
      if (std::fabs(mine - front) <= 2 * o.eps_z * front) continue;
    }
    ++c.failures;
    if (c.first.empty())
      c.first = std::string(w.is_sphere ? "sphere " : "triangle ") + std::to_string(w.tri) +
                " face " + std::to_string(w.face) + " x " + std::to_string(w.x) + " y " +
                std::to_string(w.y) + " t " + std::to_string(w.t) + " tau " +
                std::to_string(w.tau) + ": reference " + std::to_string(int(ref.id));
  }
  return c;
}

// Dense overlapping moving spheres around a segment that passes through several of them.
Scene dense_spheres(int count, double extent, uint64_t seed) {
  Rng rng(seed);
  Scene s;
  const int K = 4;
  s.sphere_centers.resize(K);
  for (int i = 0; i < count; ++i) {
    double r = rng.uniform(0.6, 1.8);
    Vec3 c{rng.uniform(-extent, extent), rng.uniform(-2, 2), rng.uniform(-extent, extent)};
    Vec3 v{rng.uniform(-1.5, 1.5), rng.uniform(-0.5, 0.5), rng.uniform(-1.5, 1.5)};
    for (int k = 0; k < K; ++k) s.sphere_centers[k].push_back(c + v * double(k));
    s.sphere_radius.push_back(r);
    s.sphere_object.push_back(uint32_t(i));
    s.objects.push_back({"sphere" + std::to_string(i)});
  }
  return s;
}

}  // namespace

// With the eye inside overlapping spheres, a sphere's pixel list holds touching
// pieces of the same sphere on its entry root and then on its exit root; joining them by id alone
// kept the entry depth over both, so a sphere behind another's exit surface won (witness of sphere
// 0 in the repro at t = 0.7162, face 1, pixel (15, 31), where sphere 1's exit lies in front).
TEST(DynamicVisibility, WitnessesOfOverlappingSpheresAroundTheEyeRecastToTheirSphere) {
  Scene s = dense_spheres(220, 7, 21);
  const Vec3 v0{-6, 0.3, -5}, v1{6, -0.2, 5.5};
  // The segment must run inside several spheres at once somewhere, or the test means nothing.
  int most_inside = 0;
  for (int k = 0; k <= 100; ++k) {
    double t = k / 100.0;
    int inside = 0;
    for (size_t i = 0; i < s.sphere_count(); ++i)
      inside += length(lerp(v0, v1, t) - s.sphere_center_at(uint32_t(i), t)) < s.sphere_radius[i];
    most_inside = std::max(most_inside, inside);
  }
  EXPECT_GE(most_inside, 3);
  for (DynamicMode mode : {DynamicMode::Diagonal, DynamicMode::Decoupled}) {
    SegmentOptions o;
    o.resolution = 40;
    o.orientation = random_orientation(12);
    o.want_witnesses = true;
    o.mode = mode;
    SegmentResult r = dynamic_segment_visibility(s, v0, v1, o);
    WitnessCounts c = recast_witnesses(s, r, v0, v1, o);
    const char* name = mode == DynamicMode::Diagonal ? "diagonal" : "decoupled";
    EXPECT_GT(c.witnesses, 50u) << name;
    EXPECT_EQ(c.failures, 0u) << name << ": " << c.first;
    EXPECT_LE(c.ambiguous, c.witnesses / 100 + 2) << name;
    std::printf(
        "[sphere witnesses] %s: %zu witnesses, %zu ambiguous, %zu failures (eye inside up to %d "
        "spheres)\n",
        name, c.witnesses, c.ambiguous, c.failures, most_inside);
  }
}

TEST(DynamicVisibility, EyeInsideOverlappingSpheresReproHasOnlyTrueWitnesses) {
  VISLIB_REQUIRE_SHARED(shared);
  Scene s = load_scene(shared + "/repros/eye-inside-overlapping-spheres.spheres");
  const Vec3 v0{7.6, 4.6, 2.8}, v1{-5, 1.7, -3};
  for (DynamicMode mode : {DynamicMode::Diagonal, DynamicMode::Decoupled}) {
    SegmentOptions o;
    o.resolution = 32;
    o.want_witnesses = true;
    o.mode = mode;
    SegmentResult r = dynamic_segment_visibility(s, v0, v1, o);
    WitnessCounts c = recast_witnesses(s, r, v0, v1, o);
    EXPECT_EQ(c.failures, 0u) << c.first;
    EXPECT_GT(c.witnesses, 0u);
  }
}

// A 300-sphere scene (generate spheres --count 300 --radius 1.5 --area 40 --states 6
// --max-height 6 --speed 4, the repro's segment): merging by id alone made 5 of 136 (diagonal)
// and 5 of 295 (decoupled) witnesses fail.
TEST(DynamicVisibility, GeneratedThreeHundredSpheresHaveOnlyTrueWitnesses) {
  SphereOptions so;
  so.count = 300;
  so.radius = 1.5;
  so.area = 40;
  so.states = 6;
  so.max_height = 6;
  so.speed = 4;
  Scene s = generate_spheres(so);
  const Vec3 v0{7.6, 4.6, 2.8}, v1{-5, 1.7, -3};
  for (DynamicMode mode : {DynamicMode::Diagonal, DynamicMode::Decoupled}) {
    SegmentOptions o;
    o.resolution = 32;
    o.want_witnesses = true;
    o.mode = mode;
    SegmentResult r = dynamic_segment_visibility(s, v0, v1, o);
    WitnessCounts c = recast_witnesses(s, r, v0, v1, o);
    EXPECT_EQ(c.failures, 0u) << c.first;
    std::printf("[300 spheres] %s: %zu witnesses, %zu ambiguous, %zu failures\n",
                mode == DynamicMode::Diagonal ? "diagonal" : "decoupled", c.witnesses, c.ambiguous,
                c.failures);
  }
}

// The decoupled mode checked like the diagonal one, at random (eye position s,
// animation time tau) pairs on moving triangles and spheres. Pairs on what the mode computes (the
// diagonal s = tau, the eye fixed at either end while the scene animates, the scene frozen at a
// key state while the eye moves): every unambiguous first hit of every pixel is in the set.
// Witnesses re-cast to their primitive. Pairs inside the (s, tau) square, which the mode
// approximates by its boundary (docs/visibility.md), are measured: a first hit outside the set is
// allowed there, at most 2% of the rays.
TEST(DynamicVisibility, DecoupledModeHoldsEveryFirstHitOnItsRunsAndOnlyTrueWitnesses) {
  Scene s = moving_soup(160, 3, 31, 6, 1.2, 1.5);
  Scene balls = dense_spheres(40, 6, 32);
  balls.sphere_centers.resize(3);  // three key states, as the soup
  append_scene(s, balls);
  const Vec3 v0{-1.5, 0.2, -1}, v1{1.5, -0.3, 1.2};
  SegmentOptions o;
  o.resolution = 32;
  o.orientation = random_orientation(14);
  o.want_witnesses = true;
  o.mode = DynamicMode::Decoupled;
  SegmentResult r = dynamic_segment_visibility(s, v0, v1, o);
  std::vector<uint8_t> in_set(s.triangle_count() + s.sphere_count(), 0);
  for (uint32_t t : r.visible) in_set[t] = 1;
  for (uint32_t k : r.visible_spheres) in_set[s.triangle_count() + k] = 1;
  const int K = int(s.state_count()), n = o.resolution;
  Rng rng(15);
  struct Pair {
    double s, tau;
    bool on_runs;
  };
  std::vector<Pair> pairs;
  for (int k = 0; k < 6; ++k) {
    double u = rng.uniform();
    pairs.push_back({u, u, true});                // diagonal
    pairs.push_back({0.0, rng.uniform(), true});  // eye at v0
    pairs.push_back({1.0, rng.uniform(), true});  // eye at v1
    pairs.push_back(
        {rng.uniform(), std::min(K - 1, int(rng.uniform() * K)) / double(K - 1), true});  // frozen
    pairs.push_back({rng.uniform(), rng.uniform(), false});  // inside the square
    pairs.push_back({rng.uniform(), rng.uniform(), false});
  }
  std::atomic<uint64_t> rays{0}, ambiguous{0}, misses{0}, inner_rays{0}, inner_out{0};
  std::string first;
  std::mutex mu;
  for (const Pair& pr : pairs) {
    const Vec3 eye = lerp(v0, v1, pr.s);
    tbb::parallel_for(size_t(0), size_t(6) * n * n, [&](size_t p) {
      int face = int(p / (size_t(n) * n)), y = int(p / n % n), x = int(p % n);
      RefHit ref = reference(s, pr.tau, eye,
                             pixel_direction(face_axes(face, o.orientation), x, y, n), o.near);
      if (ref.id == kNoHit) return;
      if (!pr.on_runs) {
        ++inner_rays;
        if (!ref.ambiguous && !in_set[ref.id]) ++inner_out;
        return;
      }
      ++rays;
      if (in_set[ref.id]) return;
      if (ref.ambiguous) {
        ++ambiguous;
        return;
      }
      ++misses;
      std::lock_guard<std::mutex> g(mu);
      if (first.empty())
        first = "miss at s " + std::to_string(pr.s) + " tau " + std::to_string(pr.tau) + " face " +
                std::to_string(face) + " x " + std::to_string(x) + " y " + std::to_string(y) +
                ": reference " + std::to_string(int(ref.id));
    });
  }
  EXPECT_GT(rays.load(), 10000u);
  EXPECT_EQ(misses.load(), 0u) << first;
  EXPECT_LT(double(ambiguous.load()), 0.01 * double(rays.load()));
  EXPECT_LT(double(inner_out.load()), 0.02 * double(inner_rays.load()));
  WitnessCounts c = recast_witnesses(s, r, v0, v1, o);
  EXPECT_EQ(c.failures, 0u) << c.first;
  EXPECT_GT(c.witnesses, 50u);
  std::printf(
      "[decoupled oracle] %zu ids; on its runs: %llu rays, %llu ambiguous, %llu misses; inside the "
      "square: %llu "
      "rays, %llu first hits outside the set; witnesses %zu (%zu ambiguous, %zu failures)\n",
      r.visible.size() + r.visible_spheres.size(), (unsigned long long)rays.load(),
      (unsigned long long)ambiguous.load(), (unsigned long long)misses.load(),
      (unsigned long long)inner_rays.load(), (unsigned long long)inner_out.load(), c.witnesses,
      c.ambiguous, c.failures);
}

// kMaxCrossings (interval_list.h) bounds the crossings of one depth_crossings call; the kernels'
// polynomials reach degree 6, and every root must come back (none dropped at the buffer's end).
TEST(DepthCrossings, PolynomialOfDegreeSixReturnsAllSixRootsInsideTheRange) {
  // (t - 0.05)(t - 0.2)(t - 0.35)(t - 0.5)(t - 0.65)(t - 0.8), expanded.
  const double roots[6] = {0.05, 0.2, 0.35, 0.5, 0.65, 0.8};
  double c[7] = {1, 0, 0, 0, 0, 0, 0};
  for (double r : roots) {
    for (int k = 6; k >= 1; --k) c[k] = c[k - 1] - r * c[k];
    c[0] = -r * c[0];
  }
  double out[kMaxCrossings];
  ASSERT_EQ(poly_roots_in(c, 6, 0.0, 1.0, out), 6);
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(out[k], roots[k], 1e-12) << k;
  // A range holding only some of them returns those.
  EXPECT_EQ(poly_roots_in(c, 6, 0.3, 0.7, out), 3);
}

TEST(DepthCrossings, TwoRationalDepthsCrossingFiveTimesReturnAllFiveCrossings) {
  // i: N = (t - 0.1)(t - 0.3)(t - 0.5), D = 1; j: N = 0, D = (t - 0.7)(t - 0.9). The crossing
  // polynomial P = N_i D_j - N_j D_i has the five roots, each a sign change of lambda_i - lambda_j.
  GeneralDepth i, j;
  i.c[0] = -0.015, i.c[1] = 0.23, i.c[2] = -0.9, i.c[3] = 1;  // N_i
  i.c[4] = 1;                                                 // D_i
  j.c[4] = 0.63, j.c[5] = -1.6, j.c[6] = 1;                   // D_j
  double out[kMaxCrossings];
  const int n = depth_crossings(i, j, 0.0, 1.0, out);
  ASSERT_EQ(n, 5);
  const double expected[5] = {0.1, 0.3, 0.5, 0.7, 0.9};
  for (int k = 0; k < 5; ++k) EXPECT_NEAR(out[k], expected[k], 1e-9) << k;
}
