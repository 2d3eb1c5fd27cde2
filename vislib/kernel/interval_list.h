// interval_list.h: per-pixel depth compositing of coverage intervals (docs/visibility-math.md §7;
// the paper's DepthComposite, Alg. 1 line 9, with the corrections given there).
//
// A pixel's list is a sorted vector of disjoint pieces [t0, t1) of the segment parameter, each
// holding the id of the front-most primitive there and that primitive's depth function. Inserting
// a coverage interval keeps the lower envelope: closer intervals split farther ones, intersecting
// surfaces split at their depth crossings, depth ties go to the lower id. In exact arithmetic the
// resulting list depends only on the set of inserted intervals. In floating point it does not
// quite: where three or more depth functions cross near one t, the rounded crossing times of the
// pairs disagree, and the tiny pieces between them depend on the order of insertion (measured:
// the 20 m city street at N = 256 ends with 5,252,188 final pieces in the kernel's
// order and 5,245,807 in the reverse one, the same visible set and witnesses). The kernel
// therefore always inserts in one fixed order (nearest depth, then id: tile_driver.h), whatever
// the thread count, the tiles, or the BVH.
//
// The list is generic over the depth function D, which must provide `double at(double t) const`
// (view depth lambda at t) and a free function
//   int depth_crossings(const D& lower_id, const D& higher_id, double lo, double hi, double* out)
// writing the ascending crossing times strictly inside (lo, hi) (at most kMaxCrossings) computed
// with the pair in id order, so that the result does not depend on which one is being inserted,
// and a free function `bool same_depth(const D&, const D&)`: true when two pieces of one primitive
// follow the same depth function. Touching pieces are merged only when they have the same id AND
// the same depth function: one primitive can own touching pieces on different surfaces (a
// sphere's entry and exit roots when the eye enters it, docs/visibility-math.md §4), and a merged
// piece would carry the first one's depth over both, so later insertions would be compared with the
// wrong surface.
#pragma once

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <optional>
#include <type_traits>
#include <vector>

namespace vislib {

// Room for the crossings of one depth_crossings call. Every depth function here has fewer: one for
// LinearDepth, at most 6 for GeneralDepth (the roots of a polynomial of degree <= 6,
// dynamic_visibility.cpp, which static_asserts it), so no crossing is ever dropped.
constexpr int kMaxCrossings = 8;

// Depth along the pixel ray (view-space depth lambda, scene units) as a function of t.
// Static triangles: lambda(t) = (n0 - n1 t) / dn, linear in t (docs/visibility-math.md §2.4, (I3)),
// with n0 = n.(a - v0), n1 = n.Delta, dn = d.n. Kept as the three numbers (not a slope and offset)
// so that depth crossings come from P = N_i D_j - N_j D_i (§3.4), exact for exact inputs.
struct LinearDepth {
  double n0 = 0, n1 = 0, dn = 1;
  double at(double t) const { return (n0 - n1 * t) / dn; }
};
int depth_crossings(const LinearDepth& i, const LinearDepth& j, double lo, double hi, double* out);
inline bool same_depth(const LinearDepth& a, const LinearDepth& b) {
  return a.n0 == b.n0 && a.n1 == b.n1 && a.dn == b.dn;
}

template <class D>
struct PieceT {
  double t0 = 0, t1 = 0;  // 0 <= t0 < t1 <= 1
  uint32_t id = 0;        // primitive id
  D depth;
};

using Piece = PieceT<LinearDepth>;
using PieceList = std::vector<Piece>;

// A depth tie (docs/visibility-math.md §7, H9, the option "treat |dlambda| <= eps_z lambda as a
// tie"): over [t0, t1) primitive `hidden` lost the depth test to `front` although their depths
// differed by at most eps_z times the front depth (checked at both ends and the middle of the
// stretch). A z-buffer z-fights there and may show either, so `hidden` counts as visible wherever
// `front` (or anything `front` is tied with) is in the final list over that stretch (see
// for_each_visible).
struct TieRecord {
  double t0 = 0, t1 = 0;
  uint32_t hidden = 0, front = 0;
};

// The tie rule of insert_piece. With `sink` null (the default) nothing is recorded (rule First):
// ties settled by depth and then by the lower id alone. The list itself never depends on the rule.
struct TieRule {
  double eps_z = 0;                        // relative depth tolerance (unitless, >= 0)
  std::vector<TieRecord>* sink = nullptr;  // where ties are appended (one vector per pixel)
};

namespace detail {

template <class D>
const PieceT<D>& front(const PieceT<D>& a, const PieceT<D>& b, double t) {
  double da = a.depth.at(t), db = b.depth.at(t);
  if (da < db) return a;
  if (db < da) return b;
  return a.id < b.id ? a : b;
}

// Records a tie when `loser` is within rule.eps_z (relative to the front depth) of `winner` at t0,
// at the middle and at t1 (for linear depths: over the whole of [t0, t1)).
// True when `loser` lies within eps_z (relative to the front depth) of `winner` at t0, at the
// middle and at t1: the tie test of H9.
template <class D>
bool tied(double eps_z, const PieceT<D>& winner, const PieceT<D>& loser, double t0, double t1) {
  for (double t : {0.5 * (t0 + t1), t0, t1}) {
    double w = winner.depth.at(t), l = loser.depth.at(t);
    if (!(std::fabs(l - w) <= eps_z * std::fabs(w))) return false;
  }
  return true;
}

template <class D>
void record_tie(const TieRule& rule, const PieceT<D>& winner, const PieceT<D>& loser, double t0,
                double t1) {
  if (tied(rule.eps_z, winner, loser, t0, t1))
    rule.sink->push_back(TieRecord{t0, t1, loser.id, winner.id});
}

// ---- Division-free decisions for linear depths ----------------------------------------------
// The read-only pass of insert_piece asks, per overlapped piece, three questions whose answers
// come from rounded quotients: is there a depth crossing in (lo, hi) (depth_crossings), which
// piece is in front at the midpoint (front), and is the loser within eps_z there (record_tie).
// Each quotient q = num/den is compared here through products instead: when the difference is
// large against the rounding of the products (relative 2^-50), the rounded quotients keep the
// same strict order, so the answer is the one the division would give. Otherwise (near-equal,
// tiny or non-finite magnitudes) the answer is "undecided" and the caller divides as before.

// Sign of q - c for q = num/den, den != 0: 1 or -1 when decided with the margin above, else 0.
// When it returns 1, fl(num/den) > c; when -1, fl(num/den) < c (c a double).
inline int quotient_vs(double num, double den, double c) {
  const double cd = c * den, e = num - cd;
  const double mag = std::fabs(num) + std::fabs(cd);
  if (!(mag < INFINITY) || !(mag > 0x1p-900) || !(std::fabs(e) > 0x1p-50 * mag)) return 0;
  return (e > 0) == (den > 0) ? 1 : -1;
}

// depth_crossings(i, j, lo, hi) > 0 for linear depths (i, j in id order): 1 yes, 0 no, -1
// undecided.
inline int linear_crossing(const LinearDepth& i, const LinearDepth& j, double lo, double hi) {
  const double den = i.n1 * j.dn - j.n1 * i.dn;  // as depth_crossings computes them
  if (den == 0) return 0;
  const double num = i.n0 * j.dn - j.n0 * i.dn;
  const int a = quotient_vs(num, den, lo);
  if (a < 0) return 0;
  const int b = quotient_vs(num, den, hi);
  if (b > 0) return 0;
  return a > 0 && b < 0 ? 1 : -1;
}

// Which of a, b is nearer at t (a.at(t) < b.at(t): -1; b.at(t) < a.at(t): 1; 0 undecided, which
// includes equal depths). x and y get the products na*b.dn and nb*a.dn of at()'s numerators, for
// linear_not_tied.
inline int linear_nearer(const LinearDepth& a, const LinearDepth& b, double t, double& x,
                         double& y) {
  const double na = a.n0 - a.n1 * t, nb = b.n0 - b.n1 * t;  // at()'s numerators, bit for bit
  x = na * b.dn;
  y = nb * a.dn;
  const double d = x - y, mag = std::fabs(x) + std::fabs(y);
  if (!(mag < INFINITY) || !(mag > 0x1p-900) || !(std::fabs(d) > 0x1p-50 * mag)) return 0;
  // a.at - b.at = (x - y) / (a.dn b.dn) up to the rounding decided away above.
  return (d < 0) == ((a.dn > 0) == (b.dn > 0)) ? -1 : 1;
}

// True when record_tie's first test (|l - w| <= eps |w| at t) certainly fails for the winner w and
// the loser l whose products linear_nearer returned (x for w, y for l); false: undecided.
inline bool linear_not_tied(double x, double y, double eps) {
  const double mag = std::fabs(x) + std::fabs(y);
  if (!(mag < INFINITY) || !(mag > 0x1p-900)) return false;
  return std::fabs(x - y) > eps * std::fabs(x) * (1 + 0x1p-30) + 0x1p-48 * mag;
}

// record_tie, with its first test decided by products where they decide it (linear depths):
// most stretches are no tie, and then the three divisions of record_tie are skipped.
template <class D>
void record_tie_checked(const TieRule& rule, const PieceT<D>& winner, const PieceT<D>& loser,
                        double t0, double t1) {
  if constexpr (std::is_same_v<D, LinearDepth>) {
    double x, y;
    if (linear_nearer(winner.depth, loser.depth, 0.5 * (t0 + t1), x, y) < 0 &&
        linear_not_tied(x, y, rule.eps_z))
      return;
  }
  record_tie(rule, winner, loser, t0, t1);
}

template <class D>
int crossings(const PieceT<D>& a, const PieceT<D>& b, double lo, double hi, double* out) {
  return a.id < b.id ? depth_crossings(a.depth, b.depth, lo, hi, out)
                     : depth_crossings(b.depth, a.depth, lo, hi, out);
}

// True when b continues a: same primitive, same depth function, touching (a before b).
template <class D>
bool continues(const PieceT<D>& a, const PieceT<D>& b) {
  return a.id == b.id && a.t1 == b.t0 && same_depth(a.depth, b.depth);
}

template <class D>
void push(std::vector<PieceT<D>>& out, const PieceT<D>& src, double t0, double t1) {
  if (!(t0 < t1)) return;
  if (!out.empty() && out.back().id == src.id && out.back().t1 == t0 &&
      same_depth(out.back().depth, src.depth)) {
    out.back().t1 = t1;
    return;
  }
  PieceT<D> p = src;
  p.t0 = t0;
  p.t1 = t1;
  out.push_back(p);
}

// list[k] absorbs list[k + 1] if that continues it.
template <class D>
void merge_at(std::vector<PieceT<D>>& list, size_t k) {
  if (k + 1 < list.size() && continues(list[k], list[k + 1])) {
    list[k].t1 = list[k + 1].t1;
    list.erase(list.begin() + long(k) + 1);
  }
}

// After list[first, first + count) was replaced: merges across the range's two ends (higher index
// first; inside it, the pieces were written merged).
template <class D>
void merge_range_ends(std::vector<PieceT<D>>& list, size_t first, size_t count) {
  merge_at(list, first + count - 1);
  if (first > 0) merge_at(list, first - 1);
}

// insert_piece where p loses to every piece of list[first, end) it overlaps, without a depth
// crossing, so that it only fills the `gaps` stretches of [p.t0, p.t1) that those pieces leave
// uncovered: each becomes a piece of p, in place (the pieces after `end` move once), and every
// old piece stays as it was. This is what insert_piece's full pass makes of such an insertion
// (there each overlapped piece is cut at p's ends, its parts put back and merged again), without
// its depths.
template <class D>
void gap_fill(std::vector<PieceT<D>>& list, const PieceT<D>& p, size_t first, size_t end,
              int gaps) {
  list.insert(list.begin() + long(end), size_t(gaps), p);
  size_t w = end + size_t(gaps);  // one past the next slot to write, from the back
  double next_t0 = p.t1;          // where the stretch after list[j] ends
  auto put_gap = [&](double t0, double t1) {
    PieceT<D>& g = list[--w];
    g = p;
    g.t0 = t0;
    g.t1 = t1;
  };
  for (size_t j = end; j-- > first;) {
    const PieceT<D> I = list[j];
    if (I.t1 < next_t0) put_gap(I.t1, next_t0);
    list[--w] = I;
    next_t0 = I.t0;
  }
  if (p.t0 < next_t0) put_gap(p.t0, next_t0);
  assert(w == first);
}

// The index of the first piece of `list` ending after s (t1 > s; t1 increases along the list), or
// list.size(). Short lists (the common case, a few cache lines) are scanned. Long ones are scanned
// from a guess, the index s would have if the pieces were of equal length (`guess_index`), up to
// kGuessScan pieces either way, and searched by bisection beyond that. In the deep lists of a dense
// diorama (54 pieces on average at insertion, docs/performance.md "Deep lists") the answer lies
// within 8 pieces of the guess for 85% of the insertions into lists of more than 16: a scan there
// costs one mispredicted branch (its exit), where galloping and bisecting cost about one per
// probe. The same index as std::upper_bound in every case.
template <class D>
size_t guess_index(const std::vector<PieceT<D>>& list, double s) {
  const double g = s * double(list.size());
  return g > 0 ? std::min(list.size() - 1, size_t(g)) : 0;  // (NaN and s <= 0: 0)
}

constexpr size_t kGuessScan = 8;  // pieces scanned from the guess before bisecting

template <class D>
size_t first_ending_after(const std::vector<PieceT<D>>& list, double s) {
  const size_t n = list.size();
  if (n <= 16) {
    size_t i = 0;
    while (i < n && !(s < list[i].t1)) ++i;
    return i;
  }
  const auto bisect = [&list, s](size_t lo, size_t hi) {  // upper_bound over [lo, hi)
    return size_t(std::upper_bound(list.begin() + long(lo), list.begin() + long(hi), s,
                                   [](double v, const PieceT<D>& q) { return v < q.t1; }) -
                  list.begin());
  };
  size_t i = guess_index(list, s);
  if (s < list[i].t1) {  // the answer is i or before it
    for (size_t k = 0; k < kGuessScan; ++k, --i)
      if (i == 0 || !(s < list[i - 1].t1)) return i;
    return bisect(0, i);
  }
  ++i;  // the answer is after the guess
  for (size_t k = 0; k < kGuessScan; ++k, ++i)
    if (i == n || s < list[i].t1) return i;
  return bisect(i, n);
}

}  // namespace detail

// Inserts the coverage interval `p` (p.t0 < p.t1) into `list` (sorted, disjoint, merged).
// Returns false when the list is unchanged (p is hidden wherever it overlaps the list).
// With a tie sink in `ties`, appends a TieRecord for every stretch where the loser of a depth
// comparison lies within ties.eps_z of the winner (the list is the same with or without it).
// Not thread-safe for the same list; lists are per pixel.
template <class D>
bool insert_piece(std::vector<PieceT<D>>& list, const PieceT<D>& p,
                  const TieRule& ties = TieRule{}) {
  assert(p.t0 < p.t1);
  const double s = p.t0, f = p.t1;
  const size_t first = detail::first_ending_after(list, s);
  double cuts[kMaxCrossings + 2];
  // Read-only pass first: most insertions (front-to-back order) are hidden everywhere and must
  // leave the list untouched; find that out without rebuilding anything. It goes on past the
  // gaps of [s, f) (stretches no piece covers) and counts them: when p loses everywhere else, the
  // insertion only fills those gaps, which needs no depth and no rebuild (gap_fill below).
  size_t settled = first;  // list[first, settled): pieces p loses to everywhere, no crossing
  {
    bool changes = false, own_id = false;
    int gaps = 0;
    double cur = s;
    size_t i = first;
    for (; i < list.size() && list[i].t0 < f; ++i) {
      const PieceT<D>& I = list[i];
      if (cur < I.t0) ++gaps;
      // A piece of p's own primitive (a sphere's other root, a moving triangle's other
      // interval at this pixel) may merge with p: such insertions take the full pass.
      own_id |= I.id == p.id;
      double lo = std::max(cur, I.t0), hi = std::min(f, I.t1);
      bool tie_checked = false;
      if constexpr (std::is_same_v<D, LinearDepth>) {
        // The same answers without divisions where the products decide them (see above).
        double x, y;
        const int near = detail::linear_nearer(I.depth, p.depth, 0.5 * (lo + hi), x, y);
        if (near > 0) {
          changes = true;  // p in front at the midpoint
        } else {
          const int cross = I.id < p.id ? detail::linear_crossing(I.depth, p.depth, lo, hi)
                                        : detail::linear_crossing(p.depth, I.depth, lo, hi);
          if (cross < 0)
            changes = detail::crossings(I, p, lo, hi, cuts) > 0;
          else
            changes = cross > 0;
          if (!changes && near == 0) changes = &detail::front(I, p, 0.5 * (lo + hi)) == &p;
          // I in front at the midpoint (decided): record_tie's first test, on the same products.
          tie_checked =
              !changes && near < 0 && ties.sink && detail::linear_not_tied(x, y, ties.eps_z);
        }
      } else {
        // The cheap question first (two depth evaluations, where the crossings need a
        // polynomial's roots); `||` gives the same answer in either order.
        changes = &detail::front(I, p, 0.5 * (lo + hi)) == &p ||
                  detail::crossings(I, p, lo, hi, cuts) > 0;
      }
      if (changes) break;
      if (ties.sink && !tie_checked) detail::record_tie(ties, I, p, lo, hi);
      cur = hi;
    }
    if (!changes) {
      if (cur < f) ++gaps;
      if (gaps == 0) return false;
      if (!own_id) {
        // The tie records of the pass stand: the full pass would make the same ones.
        if (i == first)
          list.insert(list.begin() + long(first), p);  // nothing overlaps: one gap, p itself
        else
          detail::gap_fill(list, p, first, i, gaps);
        detail::merge_range_ends(list, first, i - first + size_t(gaps));
        return true;
      }
    }
    settled = i;
  }
  size_t count;  // pieces now standing where list[first, i) stood
  {
    thread_local std::vector<PieceT<D>> out;
    out.clear();
    size_t i = first;
    double cur = s;
    // The settled pieces stand as they are, p in the gaps before them: what the loop below makes
    // of them (a piece cut at s and pushed back merges again), without its depths. Their tie
    // records are the read-only pass's, which come first in the full pass's order too.
    for (; i < settled; ++i) {
      const PieceT<D>& I = list[i];
      if (cur < I.t0) detail::push(out, p, cur, I.t0);
      detail::push(out, I, I.t0, I.t1);
      cur = std::min(f, I.t1);
    }
    while (i < list.size() && list[i].t0 < f) {
      const PieceT<D> I = list[i];
      if (I.t0 < cur) detail::push(out, I, I.t0, cur);
      if (cur < I.t0) detail::push(out, p, cur, I.t0);
      double lo = std::max(cur, I.t0), hi = std::min(f, I.t1);
      int n = detail::crossings(I, p, lo, hi, cuts + 1);
      cuts[0] = lo;
      cuts[n + 1] = hi;
      for (int k = 0; k <= n; ++k) {
        const PieceT<D>& w = detail::front(I, p, 0.5 * (cuts[k] + cuts[k + 1]));
        detail::push(out, w, cuts[k], cuts[k + 1]);
        if (ties.sink && cuts[k] < cuts[k + 1])
          detail::record_tie_checked(ties, w, &w == &p ? I : p, cuts[k], cuts[k + 1]);
      }
      if (I.t1 > f) detail::push(out, I, f, I.t1);
      cur = hi;
      ++i;
    }
    if (cur < f) detail::push(out, p, cur, f);
    // list[first, i) becomes `out`: overwrite what fits, then insert the rest (each piece written
    // once) or erase what is left over.
    const size_t removed = i - first;
    if (out.size() > removed) {
      std::copy(out.begin(), out.begin() + long(removed), list.begin() + long(first));
      list.insert(list.begin() + long(i), out.begin() + long(removed), out.end());
    } else {
      std::copy(out.begin(), out.end(), list.begin() + long(first));
      list.erase(list.begin() + long(first + out.size()), list.begin() + long(i));
    }
    count = out.size();
  }
  detail::merge_range_ends(list, first, count);  // (`push` merged inside the new range)
  return true;
}

// The piece covering t (t0 <= t < t1), if any.
template <class D>
std::optional<PieceT<D>> lookup(const std::vector<PieceT<D>>& list, double t) {
  auto it = std::upper_bound(list.begin(), list.end(), t,
                             [](double v, const PieceT<D>& q) { return v < q.t1; });
  if (it != list.end() && it->t0 <= t) return *it;
  return std::nullopt;
}

// Calls f(id, t0, t1) for every piece of the final `list`, then for every stretch made visible by
// the tie records `ties` of that list: a record (hidden, front, [a, b)) makes `hidden` visible
// over [a, b) intersected with each stretch where `front` is visible, transitively (three coplanar
// copies: each is visible). Stretches are reported once each (exact duplicates skipped).
// `settled(id)` (optional) tells that reporting any stretch of `id` would change nothing for the
// caller (its mark is set and it keeps no witness): a record that hides such an id behind another,
// and whose hidden id is in front in no record, is then skipped whole, as it can add nothing.
template <class D, class F, class Settled>
void for_each_visible(const std::vector<PieceT<D>>& list, const std::vector<TieRecord>& ties, F f,
                      Settled settled) {
  for (const PieceT<D>& p : list) f(p.id, p.t0, p.t1);
  if (ties.empty()) return;
  struct Stretch {
    uint32_t id;
    double t0, t1;
  };
  // Stretches added by the records, kept per thread (this runs for every pixel with ties, millions
  // in a street). Every record is intersected once with every stretch of the list and of `added`
  // (the closure does not depend on the order); the list is sorted and disjoint, so a record meets
  // only the pieces over its own [t0, t1).
  thread_local std::vector<Stretch> added;
  added.clear();
  auto known = [&](uint32_t id, double a, double b) {
    for (const PieceT<D>& p : list) {  // only one piece can start at a (they are disjoint)
      if (p.t0 > a) break;
      if (p.t0 == a) {
        if (p.id == id && p.t1 == b) return true;
        break;  // (and the same stretch may have been added: not reported twice)
      }
    }
    for (const Stretch& v : added)
      if (v.id == id && v.t0 == a && v.t1 == b) return true;
    return false;
  };
  auto meet = [&](const TieRecord& tr, uint32_t id, double t0, double t1) {
    if (id != tr.front) return;
    const double a = std::max(tr.t0, t0), b = std::min(tr.t1, t1);
    if (!(a < b) || known(tr.hidden, a, b)) return;
    // Field by field: a braced temporary is built on the stack in two stores and copied with
    // one wider load, which stalls (store forwarding; 3% of the 2 m street's run).
    Stretch& s = added.emplace_back();
    s.id = tr.hidden;
    s.t0 = a;
    s.t1 = b;
    f(tr.hidden, a, b);
  };
  // The records' front ids, a bit per id modulo 64 (a set bit may be another id's).
  uint64_t fronts = 0;
  for (const TieRecord& tr : ties) fronts |= uint64_t(1) << (tr.front & 63u);
  auto skipped = [&](const TieRecord& tr) {
    return !(fronts >> (tr.hidden & 63u) & 1u) && settled(tr.hidden);
  };
  for (const TieRecord& tr : ties) {
    if (skipped(tr)) continue;
    size_t e = 0;
    while (e < list.size() && !(tr.t0 < list[e].t1)) ++e;
    for (; e < list.size() && list[e].t0 < tr.t1; ++e) meet(tr, list[e].id, list[e].t0, list[e].t1);
  }
  // Then each added stretch meets every record (the closure is the same in any order, and so
  // are the marks its callers make: their reductions are order-free). Most added stretches are
  // in front of no record (measured on the 20 m street: 11.7 added stretches and 12 records per
  // pixel with ties, 750K such pixels); the bits of the front ids find those without the records.
  for (size_t e = 0; e < added.size(); ++e) {
    if (!(fronts >> (added[e].id & 63u) & 1u)) continue;
    const Stretch v = added[e];  // a copy: meet() may grow `added`
    for (const TieRecord& tr : ties)
      if (tr.front == v.id && !skipped(tr)) meet(tr, v.id, v.t0, v.t1);
  }
}

// for_each_visible reporting every stretch (nothing settled).
template <class D, class F>
void for_each_visible(const std::vector<PieceT<D>>& list, const std::vector<TieRecord>& ties, F f) {
  for_each_visible(list, ties, f, [](uint32_t) { return false; });
}

// See-through primitives (Object::see_through, docs/visibility.md "See-through
// triangles") are never inserted into a list: they hide nothing. Calls f(t0, t1) for each
// maximal stretch of [p.t0, p.t1) where the see-through coverage interval `p` is visible over the
// final `list` of opaque pieces: where no piece covers, where p's depth is at most the piece's (an
// exact tie counts as visible, whatever the ids), and, when `ties` is true, where the piece is in
// front but p lies within eps_z of it (detail::tied, the H9 test insert_piece records). The
// stretches are split at the depth crossings of p with each piece (computed with the pair in id
// order, as insert_piece does) and merged where they touch, so they are the stretches a caller
// measures against eps_len.
template <class D, class F>
void for_each_see_through_stretch(const std::vector<PieceT<D>>& list, const PieceT<D>& p, bool ties,
                                  double eps_z, F f) {
  double run0 = 0, run1 = -1;  // the current run [run0, run1) (empty while run1 < run0)
  auto visible = [&](double a, double b) {
    if (!(a < b)) return;
    if (run1 == a) {
      run1 = b;
      return;
    }
    if (run0 < run1) f(run0, run1);
    run0 = a;
    run1 = b;
  };
  double cur = p.t0;
  double cuts[kMaxCrossings + 2];
  for (size_t i = 0; i < list.size() && list[i].t0 < p.t1; ++i) {
    const PieceT<D>& I = list[i];
    if (!(cur < I.t1)) continue;
    if (cur < I.t0) visible(cur, I.t0);
    const double lo = std::max(cur, I.t0), hi = std::min(p.t1, I.t1);
    const int n = detail::crossings(I, p, lo, hi, cuts + 1);
    cuts[0] = lo;
    cuts[n + 1] = hi;
    for (int k = 0; k <= n; ++k) {
      const double a = cuts[k], b = cuts[k + 1], m = 0.5 * (a + b);
      if (!(a < b)) continue;
      if (p.depth.at(m) <= I.depth.at(m) || (ties && detail::tied(eps_z, I, p, a, b)))
        visible(a, b);
    }
    cur = hi;
  }
  if (cur < p.t1) visible(cur, p.t1);
  if (run0 < run1) f(run0, run1);
}

// True when the pieces cover [0, 1] without gap.
template <class D>
bool covers_segment(const std::vector<PieceT<D>>& list) {
  if (list.empty() || list.front().t0 != 0.0 || list.back().t1 != 1.0) return false;
  for (size_t k = 1; k < list.size(); ++k)
    if (list[k].t0 != list[k - 1].t1) return false;
  return true;
}

// Largest depth over all pieces of a list of linear depths (at the piece ends); -inf if empty.
double farthest_depth(const PieceList& list);

// Checks the invariants of §7 (sorted, disjoint, 0 <= t0 < t1 <= 1, touching pieces with the same
// id and the same depth function merged). For tests and debug builds.
template <class D>
bool is_valid(const std::vector<PieceT<D>>& list) {
  for (size_t k = 0; k < list.size(); ++k) {
    const PieceT<D>& p = list[k];
    if (!(0.0 <= p.t0 && p.t0 < p.t1 && p.t1 <= 1.0)) return false;
    if (k > 0) {
      if (list[k - 1].t1 > p.t0) return false;
      if (detail::continues(list[k - 1], p)) return false;
    }
  }
  return true;
}

}  // namespace vislib
