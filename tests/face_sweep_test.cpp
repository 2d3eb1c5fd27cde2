// Tests of the face sweeps (vislib/bake/face_sweep.h): the even chords are the ones the BSP leaf
// bake always ran, and the adaptive sweep inserts chords only where the set changes, down to its
// floor, and finds what only a chord between two coarse ones sees.
#include "vislib/bake/face_sweep.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "tests/scene_builders.h"
#include "vislib/base/cubemap.h"

namespace vislib {
namespace {

// A 100 x 10 rectangle in the z = 0 plane, swept across y (chords parallel to x, its long edge).
FaceSweep rectangle() {
  const std::vector<Vec3> face = {{0, 0, 0}, {100, 0, 0}, {100, 10, 0}, {0, 10, 0}};
  auto s = face_sweep_of(face, {0, 0, 1}, kSweepMinChord);
  EXPECT_TRUE(s.has_value());
  return *s;
}

// A 10 x 100 rectangle swept across x: chords parallel to y at x = h.
FaceSweep wide() {
  const std::vector<Vec3> face = {{0, 0, 0}, {0, 100, 0}, {100, 100, 0}, {100, 0, 0}};
  auto s = face_sweep_of(face, {0, 0, -1}, kSweepMinChord);
  EXPECT_TRUE(s.has_value());
  return *s;
}

TEST(FaceSweep, EvenChordsLieAcrossTheFaceAtMostTheSpacingApart) {
  const FaceSweep s = rectangle();
  EXPECT_NEAR(std::fabs(s.along.x), 1, 1e-15);
  EXPECT_NEAR(s.hi - s.lo, 10, 1e-12);
  const std::vector<Segment> c = even_chords(s, 4, kSweepMinChord);
  ASSERT_EQ(c.size(), 2u);  // ceil(10 / 4) = 3 steps: y = 10/3, 20/3
  for (const Segment& seg : c) {
    EXPECT_NEAR(std::fabs(seg.to.x - seg.from.x), 100, 1e-9);
    EXPECT_NEAR(seg.from.y, seg.to.y, 1e-12);
  }
  EXPECT_TRUE(even_chords(s, 10, kSweepMinChord).empty());  // not wider than the spacing
}

// A strip's chords are the pieces of the face's chords over its stretch: the strips of a
// triangle cover each chord whole, piece after piece, and a chord that does not reach a strip
// gives it none.
TEST(FaceSweep, StripsCutEveryChordIntoPiecesThatMeetEndToEnd) {
  const std::vector<Vec3> face = {{0, 0, 0}, {100, 0, 0}, {100, 50, 0}};
  auto s = face_sweep_of(face, {0, 0, 1}, kSweepMinChord);  // chords along the hypotenuse
  ASSERT_TRUE(s.has_value());
  auto t_of = [&](Vec3 p) { return dot(s->along, p); };
  const std::vector<FaceSweep> strips = sweep_strips(*s, 30);
  ASSERT_EQ(strips.size(), 4u);  // about 111.8 units along the chords: 4 strips
  EXPECT_EQ(strips.front().t_lo, -INFINITY);
  EXPECT_EQ(strips.back().t_hi, INFINITY);
  for (size_t k = 0; k + 1 < strips.size(); ++k) EXPECT_EQ(strips[k].t_hi, strips[k + 1].t_lo);
  for (double f : {0.01, 0.2, 0.5, 0.75, 0.98}) {
    const double h = s->lo + f * (s->hi - s->lo);
    const auto whole = face_chord(*s, h, kSweepMinChord);
    ASSERT_TRUE(whole.has_value());
    const double t0 = std::min(t_of(whole->from), t_of(whole->to));
    const double t1 = std::max(t_of(whole->from), t_of(whole->to));
    double reached = t0;
    size_t pieces = 0;
    for (const FaceSweep& strip : strips) {
      const auto piece = face_chord(strip, h, kSweepMinChord);
      if (!piece) {  // the chord does not reach this strip
        EXPECT_TRUE(t1 <= strip.t_lo + 1e-9 || t0 >= strip.t_hi - 1e-9) << h;
        continue;
      }
      ++pieces;
      const double p0 = std::min(t_of(piece->from), t_of(piece->to));
      const double p1 = std::max(t_of(piece->from), t_of(piece->to));
      EXPECT_NEAR(p0, reached, 1e-9) << h;
      EXPECT_LE(p1 - p0, 30) << h;
      EXPECT_NEAR(dot(s->across, piece->from), h, 1e-9);
      EXPECT_NEAR(dot(s->across, piece->to), h, 1e-9);
      reached = p1;
    }
    EXPECT_NEAR(reached, t1, 1e-9) << h;
    EXPECT_GE(pieces, 1u);
  }
  // Not longer than the length: the sweep itself, and its chords bit for bit.
  const std::vector<FaceSweep> one = sweep_strips(*s, 120);
  ASSERT_EQ(one.size(), 1u);
  const double h = s->lo + 0.5 * (s->hi - s->lo);
  EXPECT_EQ(face_chord(one[0], h, kSweepMinChord)->to.x, face_chord(*s, h, kSweepMinChord)->to.x);
}

// The chord position of a segment of wide(): its x.
double position(const Segment& s) {
  return s.from.x;
}

// A fake round: what a chord at x sees is `see(x)`; records every position run, by round, and
// the new ids of its parent that the sweep handed it.
struct FakeScene {
  std::function<std::vector<uint32_t>(double)> see;
  std::vector<std::vector<double>> rounds;
  std::map<double, std::vector<uint32_t>> fresh_at;
  ChordRound round() {
    return [this](const std::vector<Segment>& chords, const std::vector<size_t>&,
                  const std::vector<std::vector<uint32_t>>& fresh) {
      EXPECT_EQ(fresh.size(), chords.size());
      rounds.emplace_back();
      std::vector<std::vector<uint32_t>> out;
      for (size_t i = 0; i < chords.size(); ++i) {
        const double x = position(chords[i]);
        rounds.back().push_back(x);
        fresh_at[x] = fresh.at(i);
        out.push_back(see(x));
      }
      return out;
    };
  }
};

// Over a flat wall (every chord sees what the edges see) the sweep runs the coarse chords and one
// probe between each two neighbours, and stops: far fewer than an even sweep at the floor.
TEST(FaceSweep, AdaptiveSweepOverAFlatWallStopsAfterTheFirstProbes) {
  FakeScene flat{[](double) { return std::vector<uint32_t>{1, 2}; }, {}, {}};
  const size_t run = adaptive_sweep({wide()}, {32, 4}, {{1, 2}}, kSweepMinChord, flat.round());
  ASSERT_EQ(flat.rounds.size(), 2u);
  EXPECT_EQ(flat.rounds[0].size(), 3u);  // ceil(100 / 32) = 4 intervals: 3 coarse chords
  EXPECT_EQ(flat.rounds[1].size(), 4u);  // one probe in each interval
  EXPECT_EQ(run, 7u);
  EXPECT_LT(run, even_chords(wide(), 4, kSweepMinChord).size());
}

// A slit seen only from 44.5 < x < 45.5, inside a stretch 20 < x < 60 where every chord sees an id
// of its own (the view changes there): the sweep keeps inserting chords around the change and
// finds the slit once its floor allows a chord there; the coarse chords alone, and a floor too
// wide, do not.
TEST(FaceSweep, AdaptiveSweepInsertsChordsWhereTheSetChangesAndFindsASlit) {
  auto see = [](double x) {
    std::vector<uint32_t> ids = {1};
    if (x > 20 && x < 60) ids.push_back(100 + uint32_t(std::lround(x)));
    if (x > 44.5 && x < 45.5) ids.push_back(2);
    return ids;
  };
  auto found_slit = [&](const AdaptiveSpacing& spacing, size_t* runs) {
    FakeScene scene{see, {}, {}};
    *runs = adaptive_sweep({wide()}, spacing, {{1}}, kSweepMinChord, scene.round());
    std::set<double> all;
    for (const auto& r : scene.rounds) all.insert(r.begin(), r.end());
    bool slit = false;
    for (double x : all) slit = slit || (x > 44.5 && x < 45.5);
    return slit;
  };
  size_t fine = 0, coarse_only = 0;
  EXPECT_TRUE(found_slit({64, 1}, &fine));
  EXPECT_FALSE(found_slit({64, 4}, &coarse_only));
  // Fewer chords than an even sweep fine enough to hit the slit (1 apart), though the view
  // changes over 40 of the 100 units.
  EXPECT_LT(fine, even_chords(wide(), 1, kSweepMinChord).size());
  // Deterministic.
  size_t again = 0;
  found_slit({64, 1}, &again);
  EXPECT_EQ(again, fine);
}

// Each chord is handed what made the sweep insert it: the ids its parent probe saw that neither
// of the parent's neighbours saw (the caller may look only toward them). The coarse chords and the
// first probes between them have no parent; a slit's id 2, seen from 44.5 < x < 45.5 only, reaches
// the chords inserted on both sides of the probe that saw it.
TEST(FaceSweep, AdaptiveSweepHandsEachInsertedChordItsParentsNewIds) {
  auto see = [](double x) {
    std::vector<uint32_t> ids = {1};
    if (x > 20 && x < 60) ids.push_back(100 + uint32_t(std::lround(x)));
    if (x > 44.5 && x < 45.5) ids.push_back(2);
    std::sort(ids.begin(), ids.end());  // a round's sets are sorted
    return ids;
  };
  FakeScene scene{see, {}, {}};
  adaptive_sweep({wide()}, {64, 1}, {{1}}, kSweepMinChord, scene.round());
  ASSERT_GE(scene.rounds.size(), 3u);
  for (size_t r = 0; r < 2; ++r)
    for (double x : scene.rounds[r]) EXPECT_TRUE(scene.fresh_at.at(x).empty()) << x;
  size_t with_slit = 0;
  for (size_t r = 2; r < scene.rounds.size(); ++r)
    for (double x : scene.rounds[r]) {
      const std::vector<uint32_t>& f = scene.fresh_at.at(x);
      EXPECT_FALSE(f.empty()) << x;  // only refined intervals are probed again
      EXPECT_TRUE(std::find(f.begin(), f.end(), 1u) == f.end()) << x;  // the base: never new
      EXPECT_TRUE(std::is_sorted(f.begin(), f.end()));
      if (std::find(f.begin(), f.end(), 2u) != f.end()) {
        ++with_slit;
        EXPECT_GT(x, 44.5 - 2) << "a child of the probe that saw the slit lies beside it";
        EXPECT_LT(x, 45.5 + 2);
      }
    }
  EXPECT_GE(with_slit, 2u);
}

// With new_to_family a probe's ids are judged against everything its family ran before it, not
// only its two neighbours: id 7, seen from the first probe at x = 50, is seen again at 87.5,
// where neither neighbour (75, which sees an id 8 of its own, and the face's end) sees it. Judged
// by the neighbours, 87.5 opens two intervals, probed at 81.25 and 93.75, which look toward 7;
// judged by the family, 7 is not new there and the sweep stops. Strips of one face are one
// family: the same holds when 50 and 87.5 lie on two strips of the face.
TEST(FaceSweep, ProbesJudgedByTheirFamilyRefineOnlyWhereTheFamilySeesSomethingNew) {
  auto see = [](double x) {
    std::vector<uint32_t> ids = {1};
    if (std::abs(x - 50) < 5 || std::abs(x - 87.5) < 1) ids.push_back(7);
    if (std::abs(x - 75) < 1) ids.push_back(8);
    return ids;
  };
  AdaptiveSpacing spacing{100, 1};
  FakeScene by_neighbours{see, {}, {}};
  EXPECT_EQ(adaptive_sweep({wide()}, spacing, {{1}}, kSweepMinChord, by_neighbours.round()), 7u);
  EXPECT_EQ(by_neighbours.fresh_at.at(81.25), std::vector<uint32_t>{7});
  spacing.new_to_family = true;
  FakeScene by_family{see, {}, {}};
  EXPECT_EQ(adaptive_sweep({wide()}, spacing, {{1}}, kSweepMinChord, by_family.round()), 5u);
  EXPECT_EQ(by_family.fresh_at.count(81.25), 0u);
  EXPECT_EQ(by_family.fresh_at.at(62.5), std::vector<uint32_t>{8});  // 75's own id stays new

  // Two strips of the face (y below and above 50): the first sees 7 at x = 50, the second an id
  // 9 of its own there, then 8 at 75 and 7 at 87.5.
  const std::vector<FaceSweep> strips = sweep_strips(wide(), 50);
  ASSERT_EQ(strips.size(), 2u);
  auto strip_round = [&](size_t* runs) {
    return [&see, runs](const std::vector<Segment>& chords, const std::vector<size_t>& of,
                        const std::vector<std::vector<uint32_t>>&) {
      std::vector<std::vector<uint32_t>> out;
      for (size_t i = 0; i < chords.size(); ++i) {
        const double x = position(chords[i]);
        std::vector<uint32_t> ids = see(x);
        if (of[i] == 0 && std::abs(x - 50) >= 5) ids.resize(1);  // 7 at 50 only
        if (of[i] == 1 && std::abs(x - 50) < 5) ids = {1, 9};    // an id of its own at 50
        out.push_back(ids);
        ++*runs;
      }
      return out;
    };
  };
  size_t strip_runs = 0;
  spacing.new_to_family = false;
  adaptive_sweep(strips, spacing, {{1}, {1}}, kSweepMinChord, strip_round(&strip_runs));
  EXPECT_EQ(strip_runs, 2u + 4u + 2u + 2u);  // 87.5 on the second strip refines
  strip_runs = 0;
  spacing.new_to_family = true;
  adaptive_sweep(strips, spacing, {{1}, {1}}, kSweepMinChord, strip_round(&strip_runs));
  EXPECT_EQ(strip_runs, 2u + 4u + 2u);
}

// The tiles toward some triangles hold every pixel where one of them can appear from an eye of
// the chord (sampled: eyes along it, points of the triangles), on every face it spans, and a run
// on those tiles sees every one of them that the whole run sees; the whole cube (none) only for
// a triangle that meets the chord.
TEST(FaceSweep, ChordTilesTowardTrianglesHoldEveryPixelTheyCoverFromTheChord) {
  const Scene s = vislib_test::random_soup(400, 5);
  const Segment chord{{-1, 0, 0}, {1, 0.5, 0.3}};
  const int n = 64, ts = 8, tiles = tiles_per_side(n, ts);
  Rng rng(11);
  size_t flagged = 0, across = 0;
  for (uint32_t t = 0; t < s.triangle_count(); ++t) {
    const auto m = chord_tiles_toward(s, 0, chord, {t}, n, ts, 0, true);
    ASSERT_TRUE(m.has_value()) << "triangle " << t << " does not meet the chord";
    ASSERT_EQ(m->size(), size_t(6 * tiles * tiles));
    flagged += size_t(std::count(m->begin(), m->end(), 1));
    int faces = 0;
    for (int f = 0; f < 6; ++f)
      faces += std::any_of(m->begin() + f * tiles * tiles, m->begin() + (f + 1) * tiles * tiles,
                           [](uint8_t b) { return b != 0; });
    across += faces > 1;
    const auto c = s.corners(t);
    for (int k = 0; k < 200; ++k) {
      const Vec3 eye = chord.from + (chord.to - chord.from) * rng.uniform();
      double u = rng.uniform(), v = rng.uniform();
      if (u + v > 1) u = 1 - u, v = 1 - v;
      const Vec3 d = c[0] + (c[1] - c[0]) * u + (c[2] - c[0]) * v - eye;
      int f = 0;
      for (int g = 1; g < 6; ++g)
        if (dot(d, face_axes(g, Mat3{}).F) > dot(d, face_axes(f, Mat3{}).F)) f = g;
      const FaceAxes a = face_axes(f, Mat3{});
      const double depth = dot(d, a.F);
      const int x =
          std::clamp(int(std::floor(pixel_coord(dot(d, a.S) / depth, n) + 0.5)), 0, n - 1);
      const int y =
          std::clamp(int(std::floor(pixel_coord(dot(d, a.T) / depth, n) + 0.5)), 0, n - 1);
      ASSERT_TRUE((*m)[tile_mask_index(f, x / ts, y / ts, tiles)])
          << "triangle " << t << " face " << f << " pixel " << x << "," << y;
    }
  }
  EXPECT_GT(across, 50u);  // of 400: seen from the chord across a face's edge
  // One face: the same tiles where every corner lies in front of one face from both ends, the
  // whole cube for the others.
  size_t one_face = 0, whole = 0;
  for (uint32_t t = 0; t < s.triangle_count(); ++t) {
    const auto m = chord_tiles_toward(s, 0, chord, {t}, n, ts, 0, false);
    if (!m) {
      ++whole;
      continue;
    }
    ++one_face;
    EXPECT_EQ(*m, *chord_tiles_toward(s, 0, chord, {t}, n, ts, 0, true)) << t;
  }
  EXPECT_GT(one_face, 150u);
  EXPECT_GE(whole, across);
  EXPECT_LT(flagged, s.triangle_count() * size_t(6 * tiles * tiles) / 10);  // a small part
  EXPECT_FALSE(chord_tiles_toward(s, 0, chord, {}, n, ts, 0, true).has_value());
  // A triangle through the chord is seen in every direction around it: the whole cube.
  const Scene through = vislib_test::soup({{Vec3{0, -1, -1}, Vec3{0, 2, -1}, Vec3{0, -1, 2}}});
  EXPECT_FALSE(chord_tiles_toward(through, 0, chord, {0}, n, ts, 0, true).has_value());
  // A triangle that fills a face's whole view holds none of its corners' images there: the face's
  // corner rays pass through it, and every tile of the face counts.
  const Scene wall =
      vislib_test::soup({{Vec3{-100, -100, 5}, Vec3{100, -100, 5}, Vec3{0, 200, 5}}});
  const auto w = chord_tiles_toward(wall, 0, Segment{{0, 0, 0}, {0.1, 0, 0}}, {0}, n, ts, 0, true);
  ASSERT_TRUE(w.has_value());
  for (int f = 0; f < 6; ++f) {
    const double z = face_axes(f, Mat3{}).F.z;
    if (std::abs(z) < 0.5) continue;  // the sides see its far parts
    for (int y = 0; y < tiles; ++y)
      for (int x = 0; x < tiles; ++x)
        EXPECT_EQ((*w)[tile_mask_index(f, x, y, tiles)], z > 0 ? 1 : 0)
            << f << " " << x << "," << y;
  }

  // A run on the tiles toward 30 triangles sees each of them that the whole run sees.
  std::vector<uint32_t> some;
  for (uint32_t t = 0; t < s.triangle_count() && some.size() < 30; t += 7) some.push_back(t);
  SegmentOptions o;
  o.resolution = n;
  o.tile_size = ts;
  const SegmentResult all = segment_visibility(s, chord.from, chord.to, o);
  o.tile_mask = *chord_tiles_toward(s, 0, chord, some, n, ts, 0, true);
  const SegmentResult toward = segment_visibility(s, chord.from, chord.to, o);
  std::vector<uint32_t> in_all, in_toward;
  std::set_intersection(all.visible.begin(), all.visible.end(), some.begin(), some.end(),
                        std::back_inserter(in_all));
  std::set_intersection(toward.visible.begin(), toward.visible.end(), some.begin(), some.end(),
                        std::back_inserter(in_toward));
  EXPECT_GT(in_all.size(), 5u);
  EXPECT_EQ(in_toward, in_all);
  EXPECT_LT(toward.visible.size(), all.visible.size());
}

// The crossed sweep of a face runs its chords perpendicular to the first family's, over the same
// face from one extreme to the other, on the same side.
TEST(FaceSweep, CrossedSweepChordsArePerpendicularAndSpanTheFace) {
  const std::vector<Vec3> face = {{0, 0, 0}, {8, 0, 0}, {8, 0, 2}, {0, 0, 2}};
  std::optional<FaceSweep> s = face_sweep_of(face, {0, 1, 0}, kSweepMinChord);
  ASSERT_TRUE(s.has_value());
  s->side_normal = {0, 1, 0};
  s->side = 1;
  const FaceSweep x = crossed_sweep(*s);
  EXPECT_NEAR(std::abs(dot(x.along, s->along)), 0, 1e-12);
  EXPECT_NEAR(std::abs(dot(x.along, s->across)), 1, 1e-12);
  EXPECT_EQ(x.side_normal, s->side_normal);
  EXPECT_EQ(x.side, 1);
  EXPECT_NEAR(x.hi - x.lo, 8, 1e-12);  // the first chords run along the long edge, 8
  EXPECT_NEAR(s->hi - s->lo, 2, 1e-12);
  for (double h : {x.lo + 1, x.lo + 4, x.hi - 1}) {
    std::optional<Segment> c = face_chord(x, h, kSweepMinChord);
    ASSERT_TRUE(c.has_value()) << h;
    EXPECT_NEAR(length(c->to - c->from), 2, 1e-12) << h;  // across the face's short side
    EXPECT_NEAR(dot(c->to - c->from, s->along), 0, 1e-12) << h;
    EXPECT_EQ(c->side, 1);
  }
}

// The crossed family stops at its own floor: over a face where every probe sees a new id, the
// first family's chords reach the floor (4) and the crossed family's stop at 16, each foreseen by
// the estimate; with crossed_floor 0 both reach 4.
TEST(FaceSweep, CrossedChordsAreInsertedDownToTheCrossedFloorOnly) {
  uint32_t next_id = 10;
  std::vector<std::pair<int, Vec3>> runs;  // the family and the first end of every chord run
  const ChordRound round = [&](const std::vector<Segment>& chords, const std::vector<size_t>& of,
                               const std::vector<std::vector<uint32_t>>&) {
    std::vector<std::vector<uint32_t>> out;
    for (size_t i = 0; i < chords.size(); ++i) {
      runs.push_back({int(of[i]), chords[i].from});
      out.push_back({next_id++});
    }
    return out;
  };
  const std::vector<FaceSweep> families = {wide(), crossed_sweep(wide())};
  ASSERT_FALSE(families[0].crossed);
  ASSERT_TRUE(families[1].crossed);
  AdaptiveSpacing spacing{32, 4};
  spacing.crossed = true;
  spacing.crossed_floor = 16;
  const size_t run = adaptive_sweep(families, spacing, {{1}, {1}}, kSweepMinChord, round);
  // The first family: 3 coarse chords and 1 + 2 + 4 probes in each of 4 intervals of 25 (31);
  // the crossed one: 3 coarse chords and one probe in each (7), its halves of 12.5 not wider
  // than 16.
  EXPECT_EQ(run, 38u);
  EXPECT_EQ(double(run), expected_adaptive_probes(families, spacing, 1.0));
  std::vector<double> crossed_at;
  for (const auto& [family, from] : runs)
    if (family == 1) crossed_at.push_back(dot(families[1].across, from));
  ASSERT_EQ(crossed_at.size(), 7u);
  std::sort(crossed_at.begin(), crossed_at.end());
  for (size_t k = 0; k + 1 < crossed_at.size(); ++k)
    EXPECT_NEAR(crossed_at[k + 1] - crossed_at[k], 12.5, 1e-9);
  spacing.crossed_floor = 0;  // the floor
  runs.clear();
  EXPECT_EQ(adaptive_sweep(families, spacing, {{1}, {1}}, kSweepMinChord, round), 62u);
}

// --chord-tiles and a bake's metadata name each value; a file is read back by the same names, and
// a name from elsewhere is refused, not taken for a default.
TEST(FaceSweep, ChordTilesNamesReadBackAsTheirValuesAndNoOtherNameIsOne) {
  const std::vector<ChordTiles> values = {ChordTiles::All, ChordTiles::New,
                                          ChordTiles::NewEveryFace};
  const std::vector<std::string_view> names = chord_tiles_names();
  ASSERT_EQ(names.size(), values.size());
  for (size_t i = 0; i < values.size(); ++i) {
    EXPECT_EQ(names[i], chord_tiles_name(values[i]));
    EXPECT_EQ(chord_tiles_named(names[i]), values[i]) << names[i];
  }
  EXPECT_STREQ(chord_tiles_name(ChordTiles::NewEveryFace), "new-every-face");
  for (const char* other : {"", "New", "new ", "every-face", "none"})
    EXPECT_FALSE(chord_tiles_named(other).has_value()) << other;
}

// The sweep's estimate of what it runs, which the bake's progress and ETA use: exact at both
// ends of the refine rate (an interval of 128 over a floor of 8 holds 15 positions of the even
// grid at 8, one when nothing refines), and, over a face where every probe sees a new id, exact
// from the first round judged on.
TEST(FaceSweep, AdaptiveSweepEstimatesTheChordsItRunsFromTheRefineRateItSees) {
  EXPECT_EQ(expected_probes(128, 8, 1.0), 15.0);
  EXPECT_EQ(expected_probes(128, 8, 0.0), 1.0);
  EXPECT_EQ(expected_probes(8, 8, 1.0), 0.0);  // not wider than the floor: closed
  EXPECT_EQ(expected_probes(128, 8, 0.5), 4.0);
  uint32_t next_id = 10;
  FakeScene changing{[&](double) { return std::vector<uint32_t>{next_id++}; }, {}, {}};
  std::vector<std::pair<size_t, double>> told;
  const AdaptiveSpacing spacing{32, 4};
  const size_t run = adaptive_sweep({wide()}, spacing, {{1}}, kSweepMinChord, changing.round(),
                                    [&](size_t r, double expected) {
                                      told.push_back({r, expected});
                                    });
  ASSERT_EQ(told.size(), changing.rounds.size());
  EXPECT_EQ(told[0].first, 0u);
  EXPECT_EQ(told[0].second, expected_adaptive_probes({wide()}, spacing, kRefinePrior));
  // Every probe refined: the even grid at the floor (25 intervals of 4), every round after the
  // first judged one foreseeing it.
  EXPECT_EQ(run, 31u);  // 4 intervals of 25 units: 3 coarse chords, 1 + 2 + 4 probes in each
  EXPECT_EQ(double(run), expected_adaptive_probes({wide()}, spacing, 1.0));
  for (size_t k = 2; k < told.size(); ++k) EXPECT_EQ(told[k].second, double(run)) << k;
  // A flat wall: the coarse chords and one probe an interval, foreseen at a refine rate of 0.
  FakeScene flat{[](double) { return std::vector<uint32_t>{1}; }, {}, {}};
  EXPECT_EQ(double(adaptive_sweep({wide()}, spacing, {{1}}, kSweepMinChord, flat.round())),
            expected_adaptive_probes({wide()}, spacing, 0.0));
}

}  // namespace
}  // namespace vislib
