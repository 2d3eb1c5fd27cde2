// interval_list.cpp: the linear depth of static triangles (docs/visibility-math.md §2.4, §7).
#include "vislib/kernel/interval_list.h"

namespace vislib {

int depth_crossings(const LinearDepth& i, const LinearDepth& j, double lo, double hi, double* out) {
  // lambda_i - lambda_j has the sign of P(t) D_i D_j with P = N_i D_j - N_j D_i, linear here.
  double den = i.n1 * j.dn - j.n1 * i.dn;
  if (den == 0) return 0;
  double t = (i.n0 * j.dn - j.n0 * i.dn) / den;
  if (!(t > lo && t < hi)) return 0;
  out[0] = t;
  return 1;
}

double farthest_depth(const PieceList& list) {
  double far = -INFINITY;
  for (const Piece& p : list) far = std::max({far, p.depth.at(p.t0), p.depth.at(p.t1)});
  return far;
}

}  // namespace vislib
