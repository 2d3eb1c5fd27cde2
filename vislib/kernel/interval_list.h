// interval_list.h: per-pixel depth compositing of coverage intervals (math note §7; the paper's
// DepthComposite, Alg. 1 line 9, with the corrections of the note).
//
// A pixel's list is a sorted vector of disjoint pieces [t0, t1) of the segment parameter, each
// holding the id of the front-most primitive there and that primitive's depth function. Inserting
// a coverage interval keeps the lower envelope: closer intervals split farther ones, intersecting
// surfaces split at their depth crossings, depth ties go to the lower id. The resulting list
// depends only on the set of inserted intervals, never on their order.
//
// The list is generic over the depth function D, which must provide `double at(double t) const`
// (view depth lambda at t) and a free function
//   int depth_crossings(const D& lower_id, const D& higher_id, double lo, double hi, double* out)
// writing the ascending crossing times strictly inside (lo, hi) (at most kMaxCrossings) computed
// with the pair in id order, so that the result does not depend on which one is being inserted.
#pragma once

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

namespace vislib {

constexpr int kMaxCrossings = 8;

// Depth along the pixel ray (view-space depth lambda, scene units) as a function of t.
// Static triangles: lambda(t) = (n0 - n1 t) / dn, linear in t (math note §2.4, (I3)), with
// n0 = n.(a - v0), n1 = n.Delta, dn = d.n. Kept as the three numbers (not a slope and offset) so
// that depth crossings come from P = N_i D_j - N_j D_i (§3.4), exact for exact inputs.
struct LinearDepth {
  double n0 = 0, n1 = 0, dn = 1;
  double at(double t) const { return (n0 - n1 * t) / dn; }
};
int depth_crossings(const LinearDepth& i, const LinearDepth& j, double lo, double hi, double* out);

template <class D>
struct PieceT {
  double t0 = 0, t1 = 0;  // 0 <= t0 < t1 <= 1
  uint32_t id = 0;        // primitive id
  D depth;
};

using Piece = PieceT<LinearDepth>;
using PieceList = std::vector<Piece>;

namespace detail {

template <class D>
const PieceT<D>& front(const PieceT<D>& a, const PieceT<D>& b, double t) {
  double da = a.depth.at(t), db = b.depth.at(t);
  if (da < db) return a;
  if (db < da) return b;
  return a.id < b.id ? a : b;
}

template <class D>
int crossings(const PieceT<D>& a, const PieceT<D>& b, double lo, double hi, double* out) {
  return a.id < b.id ? depth_crossings(a.depth, b.depth, lo, hi, out)
                     : depth_crossings(b.depth, a.depth, lo, hi, out);
}

template <class D>
void push(std::vector<PieceT<D>>& out, const PieceT<D>& src, double t0, double t1) {
  if (!(t0 < t1)) return;
  if (!out.empty() && out.back().id == src.id && out.back().t1 == t0) {
    out.back().t1 = t1;
    return;
  }
  PieceT<D> p = src;
  p.t0 = t0;
  p.t1 = t1;
  out.push_back(p);
}

}  // namespace detail

// Inserts the coverage interval `p` (p.t0 < p.t1) into `list` (sorted, disjoint, merged).
// Returns false when the list is unchanged (p is hidden wherever it overlaps the list).
// Not thread-safe for the same list; lists are per pixel.
template <class D>
bool insert_piece(std::vector<PieceT<D>>& list, const PieceT<D>& p) {
  assert(p.t0 < p.t1);
  const double s = p.t0, f = p.t1;
  // First piece ending after s (t1 increases along the list).
  size_t first = size_t(std::upper_bound(list.begin(), list.end(), s,
                                         [](double v, const PieceT<D>& q) { return v < q.t1; }) -
                        list.begin());
  double cuts[kMaxCrossings + 2];
  // Read-only pass first: most insertions (front-to-back order) are hidden everywhere and must
  // leave the list untouched; find that out without rebuilding anything.
  {
    bool changes = false;
    double cur = s;
    for (size_t i = first; i < list.size() && list[i].t0 < f && !changes; ++i) {
      const PieceT<D>& I = list[i];
      if (cur < I.t0) {
        changes = true;  // a gap the new interval fills
        break;
      }
      double lo = std::max(cur, I.t0), hi = std::min(f, I.t1);
      changes =
          detail::crossings(I, p, lo, hi, cuts) > 0 || &detail::front(I, p, 0.5 * (lo + hi)) == &p;
      cur = hi;
    }
    if (!changes && cur >= f) return false;
  }
  size_t count;  // pieces now standing where list[first, i) stood
  if (first == list.size() || list[first].t0 >= f) {
    list.insert(list.begin() + first, p);  // nothing overlaps: insert in the gap
    count = 1;
  } else {
    thread_local std::vector<PieceT<D>> out;
    out.clear();
    size_t i = first;
    double cur = s;
    while (i < list.size() && list[i].t0 < f) {
      const PieceT<D> I = list[i];
      if (I.t0 < cur) detail::push(out, I, I.t0, cur);
      if (cur < I.t0) detail::push(out, p, cur, I.t0);
      double lo = std::max(cur, I.t0), hi = std::min(f, I.t1);
      int n = detail::crossings(I, p, lo, hi, cuts + 1);
      cuts[0] = lo;
      cuts[n + 1] = hi;
      for (int k = 0; k <= n; ++k)
        detail::push(out, detail::front(I, p, 0.5 * (cuts[k] + cuts[k + 1])), cuts[k], cuts[k + 1]);
      if (I.t1 > f) detail::push(out, I, f, I.t1);
      cur = hi;
      ++i;
    }
    if (cur < f) detail::push(out, p, cur, f);
    size_t removed = i - first;
    if (out.size() > removed)
      list.insert(list.begin() + i, out.size() - removed, PieceT<D>{});
    else
      list.erase(list.begin() + first + out.size(), list.begin() + i);
    std::copy(out.begin(), out.end(), list.begin() + first);
    count = out.size();
  }
  // `push` merged inside the new range; merge across its two ends (higher index first).
  auto merge_at = [&list](size_t k) {  // list[k] absorbs list[k+1] if same id and touching
    if (k + 1 < list.size() && list[k].id == list[k + 1].id && list[k].t1 == list[k + 1].t0) {
      list[k].t1 = list[k + 1].t1;
      list.erase(list.begin() + k + 1);
    }
  };
  merge_at(first + count - 1);
  if (first > 0) merge_at(first - 1);
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

// Checks the invariants of §7 (sorted, disjoint, 0 <= t0 < t1 <= 1, touching same-id pieces
// merged). For tests and debug builds.
template <class D>
bool is_valid(const std::vector<PieceT<D>>& list) {
  for (size_t k = 0; k < list.size(); ++k) {
    const PieceT<D>& p = list[k];
    if (!(0.0 <= p.t0 && p.t0 < p.t1 && p.t1 <= 1.0)) return false;
    if (k > 0) {
      if (list[k - 1].t1 > p.t0) return false;
      if (list[k - 1].t1 == p.t0 && list[k - 1].id == p.id) return false;
    }
  }
  return true;
}

}  // namespace vislib
