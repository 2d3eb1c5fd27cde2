// Per-pixel compositing of coverage intervals (interval_list.h, docs/visibility-math.md §7):
// insertion-order independence with crossings and ties, interpenetrating surfaces, merging, hidden
// insertions and lists far longer than any pixel holds in practice.
#include "vislib/kernel/interval_list.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <tuple>
#include <vector>

#include "vislib/base/random.h"

using namespace vislib;

namespace {

// depth(t) = a + b t
LinearDepth line(double a, double b) {
  return LinearDepth{a, -b, 1.0};
}

PieceList insert_all(const std::vector<Piece>& in) {
  PieceList l;
  for (const Piece& p : in) insert_piece(l, p);
  return l;
}

void expect_same(const PieceList& a, const PieceList& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].id, b[i].id) << i;
    EXPECT_EQ(a[i].t0, b[i].t0) << i;
    EXPECT_EQ(a[i].t1, b[i].t1) << i;
  }
}

}  // namespace

TEST(IntervalList, InsertionOrderDoesNotChangeTheListWithCrossingsAndTies) {
  Rng rng(21);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<Piece> in;
    for (uint32_t id = 0; id < 30; ++id) {
      // Few distinct ends and depths, so that pieces share ends, tie in depth and cross.
      double a = rng.below(9) / 8.0, b = rng.below(9) / 8.0;
      if (a > b) std::swap(a, b);
      if (a == b) continue;
      in.push_back(Piece{a, b, id, line(double(1 + rng.below(4)), double(rng.below(5)) - 2.0)});
    }
    const PieceList ref = insert_all(in);
    ASSERT_TRUE(is_valid(ref));
    ASSERT_FALSE(ref.empty());
    for (int k = 0; k < 8; ++k) {
      for (size_t i = in.size(); i > 1; --i) std::swap(in[i - 1], in[rng.below(i)]);
      expect_same(insert_all(in), ref);
    }
  }
}

TEST(IntervalList, InterpenetratingSurfacesSplitAtTheirCrossing) {
  // id 0: depth 1 + 2t, id 1: depth 2: they cross at t = 0.5; in front: id 0 before, id 1 after.
  const Piece a{0, 1, 0, line(1, 2)}, b{0, 1, 1, line(2, 0)};
  for (const PieceList& l : {insert_all({a, b}), insert_all({b, a})}) {
    ASSERT_EQ(l.size(), 2u);
    EXPECT_EQ(l[0].id, 0u);
    EXPECT_EQ(l[0].t0, 0.0);
    EXPECT_DOUBLE_EQ(l[0].t1, 0.5);
    EXPECT_EQ(l[1].id, 1u);
    EXPECT_DOUBLE_EQ(l[1].t0, 0.5);
    EXPECT_EQ(l[1].t1, 1.0);
  }
}

TEST(IntervalList, DepthTiesGoToTheLowerId) {
  const Piece a{0.25, 0.75, 7, line(3, 0)}, b{0, 1, 4, line(3, 0)};
  for (const PieceList& l : {insert_all({a, b}), insert_all({b, a})}) {
    ASSERT_EQ(l.size(), 1u);
    EXPECT_EQ(l[0].id, 4u);
    EXPECT_EQ(l[0].t0, 0.0);
    EXPECT_EQ(l[0].t1, 1.0);
  }
}

TEST(IntervalList, TouchingPiecesOfOneIdMerge) {
  PieceList l;
  EXPECT_TRUE(insert_piece(l, Piece{0, 0.25, 3, line(5, 0)}));
  EXPECT_TRUE(insert_piece(l, Piece{0.25, 0.5, 3, line(5, 0)}));
  ASSERT_EQ(l.size(), 1u);
  EXPECT_EQ(l[0].t0, 0.0);
  EXPECT_EQ(l[0].t1, 0.5);
  // A closer piece in the middle splits it in three; one more touching piece of id 3 beyond.
  EXPECT_TRUE(insert_piece(l, Piece{0.1, 0.2, 9, line(1, 0)}));
  EXPECT_TRUE(insert_piece(l, Piece{0.5, 0.75, 3, line(5, 0)}));
  ASSERT_EQ(l.size(), 3u);
  EXPECT_EQ(l[0].id, 3u);
  EXPECT_EQ(l[1].id, 9u);
  EXPECT_EQ(l[2].id, 3u);
  EXPECT_EQ(l[2].t0, 0.2);
  EXPECT_EQ(l[2].t1, 0.75);
  EXPECT_TRUE(is_valid(l));
}

TEST(IntervalList, HiddenInsertionLeavesTheListUnchanged) {
  PieceList l;
  insert_piece(l, Piece{0, 1, 2, line(1, 0)});
  const PieceList before = l;
  EXPECT_FALSE(insert_piece(l, Piece{0.2, 0.9, 1, line(4, 1)}));
  expect_same(l, before);
}

TEST(IntervalList, InsertionBehindEveryPieceFillsExactlyTheGapsItSpans) {
  // insert_piece's gap fill: an interval behind every piece it overlaps (no crossing) keeps every
  // old piece as it was and owns exactly the stretches of [t0, t1) that no piece covered, with
  // the tie records of a full rebuild (none here: the depths are far apart).
  Rng rng(77);
  for (int trial = 0; trial < 300; ++trial) {
    PieceList l;
    const int n = 1 + int(rng.below(40));  // short lists (linear search) and long ones
    for (int i = 0; i < n; ++i) {
      const double a = (2 * i + rng.below(2)) / double(2 * n), b = (2 * i + 1) / double(2 * n);
      if (a < b) l.push_back(Piece{a, b, uint32_t(i), line(1 + 0.01 * i, 0)});
    }
    if (l.empty()) continue;
    const PieceList before = l;
    double s = rng.below(1000) / 1000.0, f = rng.below(1000) / 1000.0;
    if (s > f) std::swap(s, f);
    if (!(s < f)) continue;
    const uint32_t id = 1000;
    std::vector<TieRecord> ties;
    const bool changed = insert_piece(l, Piece{s, f, id, line(5, 0.5)}, TieRule{1e-6, &ties});
    EXPECT_TRUE(ties.empty());
    // The expected list: the old pieces, and the uncovered stretches of [s, f) as pieces of id.
    PieceList want;
    double cur = s;
    for (const Piece& q : before) {
      if (q.t0 > cur && cur < f) want.push_back(Piece{cur, std::min(q.t0, f), id, line(5, 0.5)});
      want.push_back(q);
      cur = std::max(cur, q.t1);
    }
    if (cur < f) want.push_back(Piece{cur, f, id, line(5, 0.5)});
    EXPECT_EQ(changed, want.size() != before.size());
    ASSERT_TRUE(is_valid(l));
    expect_same(l, want);
    for (const Piece& q : l) {
      if (q.id != id) {
        EXPECT_TRUE(same_depth(q.depth, line(1 + 0.01 * q.id, 0)));
      }
    }
  }
}

TEST(IntervalList, ThousandsOfDisjointPiecesAreAllKeptInOrder) {
  // No capacity limit: a list holds as many pieces as the pixel needs (the vector grows).
  const int n = 5000;
  std::vector<Piece> in;
  for (int i = 0; i < n; ++i)
    in.push_back(Piece{i / double(n), (i + 0.5) / double(n), uint32_t(i), line(1 + i % 7, 0)});
  Rng rng(5);
  for (size_t i = in.size(); i > 1; --i) std::swap(in[i - 1], in[rng.below(i)]);
  PieceList l = insert_all(in);
  ASSERT_EQ(l.size(), size_t(n));
  ASSERT_TRUE(is_valid(l));
  for (int i = 0; i < n; ++i) {
    auto p = lookup(l, (i + 0.25) / double(n));
    ASSERT_TRUE(p.has_value()) << i;
    EXPECT_EQ(p->id, uint32_t(i));
    EXPECT_FALSE(lookup(l, (i + 0.75) / double(n)).has_value()) << i;
  }
  EXPECT_FALSE(covers_segment(l));
}

TEST(IntervalList, SearchFromTheGuessFindsTheIndexOfABinarySearch) {
  // detail::first_ending_after scans from the index s would have in equal pieces and bisects
  // beyond kGuessScan pieces; the oracle is std::upper_bound over the whole list. Lists of every
  // length around the scan/search switch up to deep ones, with pieces bunched at one end (the
  // guess far off) or even, queried at every piece end, inside pieces, in gaps and outside [0, 1].
  Rng rng(11);
  for (int n : {0, 1, 15, 16, 17, 18, 31, 64, 200, 1000}) {
    for (int shape = 0; shape < 3; ++shape) {
      std::vector<double> cuts;  // 2n increasing values in [0, 1]: t0, t1 of each piece
      for (int k = 0; k < 2 * n; ++k) {
        const double u = rng.uniform();
        cuts.push_back(shape == 0 ? u : shape == 1 ? u * u * u * u : 1 - u * u * u * u);
      }
      std::sort(cuts.begin(), cuts.end());
      cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
      PieceList l;
      for (size_t k = 0; k + 1 < cuts.size(); k += 2)
        l.push_back(Piece{cuts[k], cuts[k + 1], uint32_t(k), line(1, 0)});
      std::vector<double> queries = {-1, 0, 1, 2, std::nan("")};
      for (const Piece& p : l) {
        queries.push_back(p.t0);
        queries.push_back(p.t1);
        queries.push_back(0.5 * (p.t0 + p.t1));
        queries.push_back(std::nextafter(p.t1, 2.0));
      }
      for (int k = 0; k < 200; ++k) queries.push_back(rng.uniform());
      for (double s : queries) {
        const size_t want =
            size_t(std::upper_bound(l.begin(), l.end(), s,
                                    [](double v, const Piece& q) { return v < q.t1; }) -
                   l.begin());
        ASSERT_EQ(detail::first_ending_after(l, s), want) << "n " << l.size() << " s " << s;
      }
    }
  }
}

TEST(IntervalList, ValidityCheckRejectsOverlapsUnmergedNeighboursAndEmptyPieces) {
  EXPECT_TRUE(is_valid(PieceList{}));
  EXPECT_FALSE(is_valid(PieceList{Piece{0, 0.5, 1, {}}, Piece{0.4, 1, 2, {}}}));
  EXPECT_FALSE(is_valid(PieceList{Piece{0, 0.5, 1, {}}, Piece{0.5, 1, 1, {}}}));
  EXPECT_FALSE(is_valid(PieceList{Piece{0.5, 0.5, 1, {}}}));
  EXPECT_TRUE(is_valid(PieceList{Piece{0, 0.5, 1, {}}, Piece{0.5, 1, 2, {}}}));
}

// The read-only pass of insert_piece decides crossings, the nearer piece and the tie test for
// linear depths from products instead of quotients. Wherever those decide, the answer
// must be the one the divisions give; checked on random depths and on near-equal ones (the same
// plane scaled, depths one rounding apart, crossings at the interval ends), where they must mostly
// stay undecided rather than guess.
TEST(IntervalList, DivisionFreeDecisionsAgreeWithTheQuotients) {
  Rng rng(41);
  auto random_depth = [&rng]() {
    return LinearDepth{rng.uniform(-50, 50), rng.uniform(-50, 50),
                       (rng.uniform() < 0.5 ? -1 : 1) * rng.uniform(0.01, 3)};
  };
  int decided_near = 0, decided_cross = 0, decided_tie = 0, undecided = 0;
  for (int trial = 0; trial < 200000; ++trial) {
    LinearDepth a = random_depth(), b = random_depth();
    const int kind = trial % 4;
    if (kind == 1) {  // the same depth function scaled: equal quotients up to rounding
      const double s = rng.uniform(0.5, 2);
      b = LinearDepth{a.n0 * s, a.n1 * s, a.dn * s};
    } else if (kind == 2) {  // within the tie tolerance
      b = LinearDepth{a.n0 * (1 + rng.uniform(-2e-6, 2e-6)), a.n1, a.dn};
    }
    double lo = rng.uniform(0, 1), hi = rng.uniform(0, 1);
    if (lo > hi) std::swap(lo, hi);
    if (kind == 3) {  // an interval end at the crossing of a and b
      double c[kMaxCrossings];
      if (depth_crossings(a, b, 0, 1, c) == 1) (rng.uniform() < 0.5 ? lo : hi) = c[0];
    }
    if (!(lo < hi)) continue;
    const double t = 0.5 * (lo + hi);
    double x, y;
    const int near = detail::linear_nearer(a, b, t, x, y);
    const double da = a.at(t), db = b.at(t);
    if (near != 0) {
      ++decided_near;
      ASSERT_EQ(near < 0, da < db) << trial;
      ASSERT_EQ(near > 0, db < da) << trial;
    }
    const int cross = detail::linear_crossing(a, b, lo, hi);
    double c[kMaxCrossings];
    const int n = depth_crossings(a, b, lo, hi, c);
    if (cross >= 0) {
      ++decided_cross;
      ASSERT_EQ(cross, n > 0 ? 1 : 0) << trial;
    } else {
      ++undecided;
    }
    if (near < 0) {  // a wins: the tie test is record_tie's first one, at t
      const double eps = trial % 8 < 4 ? 1e-6 : 0.0;
      if (detail::linear_not_tied(x, y, eps)) {
        ++decided_tie;
        ASSERT_FALSE(std::fabs(db - da) <= eps * std::fabs(da)) << trial;
      }
    }
  }
  EXPECT_GT(decided_near, 100000);
  EXPECT_GT(decided_cross, 100000);
  EXPECT_GT(decided_tie, 50000);
  EXPECT_GT(undecided, 100);  // the constructed near-ties do reach the fallback
}

// The tie closure reports each stretch once, also when one is reached twice and begins where a
// different piece of the list begins: 3 is tied behind 1 directly, and behind 4 (itself tied
// behind 1) over the same stretch [0, 0.5) that piece 1 starts at.
TEST(IntervalList, TieClosureReportsAStretchReachedTwiceOnce) {
  PieceList list{Piece{0.0, 0.5, 1, line(1, 0)}, Piece{0.5, 1.0, 2, line(1, 0)}};
  std::vector<TieRecord> ties{{0.0, 0.5, 4, 1}, {0.0, 0.5, 3, 4}, {0.0, 0.5, 3, 1}};
  for (int order = 0; order < 2; ++order) {
    std::vector<std::tuple<uint32_t, double, double>> seen;
    for_each_visible(list, ties,
                     [&](uint32_t id, double t0, double t1) { seen.emplace_back(id, t0, t1); });
    std::sort(seen.begin(), seen.end());
    using S = std::tuple<uint32_t, double, double>;
    EXPECT_EQ(seen,
              (std::vector<S>{S{1, 0.0, 0.5}, S{2, 0.5, 1.0}, S{3, 0.0, 0.5}, S{4, 0.0, 0.5}}))
        << "order " << order;
    std::reverse(ties.begin(), ties.end());
  }
}

// A caller that keeps only marks can say which ids are settled (already marked): records that hide
// a settled id are skipped, unless that id is in front in another record (the closure still needs
// its stretches to reach the ids tied behind it).
TEST(IntervalList, TieClosureSkipsSettledIdsButStillFollowsThemToOthers) {
  PieceList list{Piece{0.0, 0.5, 1, line(1, 0)}, Piece{0.5, 1.0, 2, line(1, 0)}};
  const std::vector<TieRecord> ties{{0.0, 0.5, 4, 1}, {0.0, 0.5, 3, 4}, {0.5, 1.0, 5, 2}};
  auto ids = [&](auto settled) {
    std::vector<uint32_t> seen;
    for_each_visible(
        list, ties, [&](uint32_t id, double, double) { seen.push_back(id); }, settled);
    std::sort(seen.begin(), seen.end());
    return seen;
  };
  EXPECT_EQ(ids([](uint32_t) { return false; }), (std::vector<uint32_t>{1, 2, 3, 4, 5}));
  // 4 is settled but in front of 3: followed, so 3 is still reported.
  EXPECT_EQ(ids([](uint32_t id) { return id == 4; }), (std::vector<uint32_t>{1, 2, 3, 4, 5}));
  // 3 and 5 are settled and in front of nothing: their records are skipped.
  EXPECT_EQ(ids([](uint32_t id) { return id == 3 || id == 5; }), (std::vector<uint32_t>{1, 2, 4}));
}
