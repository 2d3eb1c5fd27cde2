// interval_list.cpp: lower-envelope insertion of math note §7.
#include "vislib/interval_list.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace vislib {
namespace {

// Crossing of two linear depths inside (lo, hi), computed with the pair in canonical order
// (lower id first) so that it does not depend on which one is being inserted.
bool crossing(const Piece& a, const Piece& b, double lo, double hi, double& t) {
  const Piece& i = a.id < b.id ? a : b;
  const Piece& j = a.id < b.id ? b : a;
  // lambda_i - lambda_j has the sign of P(t) D_i D_j with P = N_i D_j - N_j D_i, linear here.
  const LinearDepth &di = i.depth, &dj = j.depth;
  double den = di.n1 * dj.dn - dj.n1 * di.dn;
  if (den == 0) return false;
  t = (di.n0 * dj.dn - dj.n0 * di.dn) / den;
  return t > lo && t < hi;
}

// Front-most of two pieces at t; depth tie goes to the lower id.
const Piece& front(const Piece& a, const Piece& b, double t) {
  double da = a.depth.at(t), db = b.depth.at(t);
  if (da < db) return a;
  if (db < da) return b;
  return a.id < b.id ? a : b;
}

void push(PieceList& out, const Piece& src, double t0, double t1) {
  if (!(t0 < t1)) return;
  if (!out.empty() && out.back().id == src.id && out.back().t1 == t0) {
    out.back().t1 = t1;
    return;
  }
  Piece p = src;
  p.t0 = t0;
  p.t1 = t1;
  out.push_back(p);
}

}  // namespace

bool insert_piece(PieceList& list, const Piece& p) {
  assert(p.t0 < p.t1);
  const double s = p.t0, f = p.t1;
  // First piece ending after s (t1 increases along the list).
  size_t first = size_t(std::upper_bound(list.begin(), list.end(), s,
                                         [](double v, const Piece& q) { return v < q.t1; }) -
                        list.begin());
  // Read-only pass first: most insertions (front-to-back order) are hidden everywhere and must
  // leave the list untouched; find that out without rebuilding anything.
  {
    bool changes = false;
    double cur = s;
    for (size_t i = first; i < list.size() && list[i].t0 < f && !changes; ++i) {
      const Piece& I = list[i];
      if (cur < I.t0) {
        changes = true;  // a gap the new interval fills
        break;
      }
      double lo = std::max(cur, I.t0), hi = std::min(f, I.t1), tc;
      changes = crossing(I, p, lo, hi, tc) || &front(I, p, 0.5 * (lo + hi)) == &p;
      cur = hi;
    }
    if (!changes && cur >= f) return false;
  }
  size_t count;  // pieces now standing where list[first, i) stood
  if (first == list.size() || list[first].t0 >= f) {
    // Fast path: nothing overlaps; insert in the gap.
    list.insert(list.begin() + first, p);
    count = 1;
  } else {
    thread_local PieceList out;
    out.clear();
    size_t i = first;
    double cur = s;
    while (i < list.size() && list[i].t0 < f) {
      const Piece I = list[i];
      if (I.t0 < cur) push(out, I, I.t0, cur);
      if (cur < I.t0) push(out, p, cur, I.t0);
      double lo = std::max(cur, I.t0), hi = std::min(f, I.t1);
      double tc;
      if (crossing(I, p, lo, hi, tc)) {
        push(out, front(I, p, 0.5 * (lo + tc)), lo, tc);
        push(out, front(I, p, 0.5 * (tc + hi)), tc, hi);
      } else {
        push(out, front(I, p, 0.5 * (lo + hi)), lo, hi);
      }
      if (I.t1 > f) push(out, I, f, I.t1);
      cur = hi;
      ++i;
    }
    if (cur < f) push(out, p, cur, f);
    size_t removed = i - first;
    if (out.size() > removed)
      list.insert(list.begin() + i, out.size() - removed, Piece{});
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

std::optional<Piece> lookup(const PieceList& list, double t) {
  auto it = std::upper_bound(list.begin(), list.end(), t,
                             [](double v, const Piece& q) { return v < q.t1; });
  if (it != list.end() && it->t0 <= t) return *it;
  return std::nullopt;
}

bool covers_segment(const PieceList& list) {
  if (list.empty() || list.front().t0 != 0.0 || list.back().t1 != 1.0) return false;
  for (size_t k = 1; k < list.size(); ++k)
    if (list[k].t0 != list[k - 1].t1) return false;
  return true;
}

double farthest_depth(const PieceList& list) {
  double far = -INFINITY;
  for (const Piece& p : list) far = std::max({far, p.depth.at(p.t0), p.depth.at(p.t1)});
  return far;
}

bool is_valid(const PieceList& list) {
  for (size_t k = 0; k < list.size(); ++k) {
    const Piece& p = list[k];
    if (!(0.0 <= p.t0 && p.t0 < p.t1 && p.t1 <= 1.0)) return false;
    if (k > 0) {
      if (list[k - 1].t1 > p.t0) return false;
      if (list[k - 1].t1 == p.t0 && list[k - 1].id == p.id) return false;
    }
  }
  return true;
}

}  // namespace vislib
