// polynomial.h: numerically careful real roots of low-degree polynomials (docs/visibility-math.md
// §6), for the quadratic events of moving triangles and spheres.
#pragma once

#include <cmath>

namespace vislib {

// std::fmin and std::fmax without the call into libm (GCC inlines those only with
// -ffinite-math-only; the calls were 6% of the grass field's kernel): the same value for every
// input. A NaN operand is ignored (IEEE minNum/maxNum); of two equal values (+0 and -0) the first
// is returned, as x86-64 glibc does (tested against it).
inline double min_num(double x, double y) {
  return y < x ? y : (x == x ? x : y);
}
inline double max_num(double x, double y) {
  return y > x ? y : (x == x ? x : y);
}

// Real roots of a t^2 + b t + c, ascending, written to r[0..count). Discriminant with Kahan's FMA
// trick (exact products), roots by q = -(b + sign(b) sqrt(disc))/2, t = q/a and c/q (no
// cancellation). a == 0: the linear root; a == b == 0: none. A double root is reported twice
// (r[0] == r[1]); callers classify the pieces between roots by their midpoints, never by
// multiplicity.
inline int solve_quadratic(double a, double b, double c, double r[2]) {
  if (a == 0) {
    if (b == 0) return 0;
    r[0] = -c / b;
    return 1;
  }
  double p = b * b, dp = std::fma(b, b, -p);
  double q4 = 4 * a * c, dq = std::fma(4 * a, c, -q4);
  double disc = (p - q4) + (dp - dq);
  if (disc < 0) return 0;
  double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
  if (q == 0) {  // b == 0 and c == 0: double root at 0
    r[0] = r[1] = 0;
    return 2;
  }
  double x0 = q / a, x1 = c / q;
  r[0] = min_num(x0, x1);
  r[1] = max_num(x0, x1);
  return 2;
}

}  // namespace vislib

namespace vislib {

// c[0] + c[1] t + ... + c[deg] t^deg (Horner).
inline double poly_eval(const double* c, int deg, double t) {
  double r = c[deg];
  for (int k = deg - 1; k >= 0; --k) r = r * t + c[k];
  return r;
}

// Roots of c[0..deg] (deg <= 6) strictly inside (lo, hi), ascending, written to out (at most
// deg). Degree <= 2: closed form (solve_quadratic; may include a double root). Higher: the roots
// of the derivative cut (lo, hi) into monotone pieces, and each piece whose ends differ in sign is
// bisected to the last bit (Yuksel, HPG 2022, docs/visibility-math.md §3.4). Leading zero
// coefficients are dropped. Callers classify the pieces between roots by their midpoints. False
// when c[0..deg] certainly has no root in [lo, hi] (0 <= lo <= hi): interval Horner.
inline bool poly_may_vanish(const double* c, int deg, double lo, double hi) {
  double a = c[deg], b = c[deg];
  for (int k = deg - 1; k >= 0; --k) {
    double p0 = a * lo, p1 = a * hi, p2 = b * lo, p3 = b * hi;
    a = min_num(min_num(p0, p1), min_num(p2, p3)) + c[k];
    b = max_num(max_num(p0, p1), max_num(p2, p3)) + c[k];
    // Widen by the rounding of this step (relative 4 ulp of the magnitudes involved).
    double e = 4 * 2.2e-16 * (std::fabs(a) + std::fabs(b) + std::fabs(c[k]));
    a -= e;
    b += e;
  }
  return a <= 0 && b >= 0;
}

inline int poly_roots_in(const double* c_in, int deg, double lo, double hi, double* out) {
  double c[7];
  for (int k = 0; k <= deg; ++k) c[k] = c_in[k];
  while (deg > 0 && c[deg] == 0) --deg;
  if (deg <= 0) return 0;
  if (deg > 2 && lo >= 0 && !poly_may_vanish(c, deg, lo, hi)) return 0;
  int n = 0;
  if (deg <= 2) {
    double r[2];
    int m = deg == 2 ? solve_quadratic(c[2], c[1], c[0], r) : solve_quadratic(0, c[1], c[0], r);
    for (int k = 0; k < m; ++k)
      if (r[k] > lo && r[k] < hi && (n == 0 || r[k] != out[n - 1])) out[n++] = r[k];
    return n;
  }
  double d[6];
  for (int k = 1; k <= deg; ++k) d[k - 1] = double(k) * c[k];
  double pts[8];
  int np = 0;
  pts[np++] = lo;
  np += poly_roots_in(d, deg - 1, lo, hi, pts + np);
  pts[np++] = hi;
  for (int k = 0; k + 1 < np; ++k) {
    double a = pts[k], b = pts[k + 1];
    double fa = poly_eval(c, deg, a), fb = poly_eval(c, deg, b);
    if (fa == 0 && k > 0) {  // a critical point that is a root
      if (n == 0 || out[n - 1] != a) out[n++] = a;
      continue;
    }
    if (!((fa < 0 && fb > 0) || (fa > 0 && fb < 0))) continue;
    // Safeguarded Newton: a Newton step from the bracket's better end when it stays inside the
    // bracket, else bisection; the bracket shrinks every step, down to adjacent doubles.
    double x = 0.5 * (a + b);
    for (int it = 0; it < 200; ++it) {
      double fx = poly_eval(c, deg, x);
      if (fx == 0) {
        a = b = x;
        break;
      }
      if ((fx < 0) == (fa < 0)) {
        a = x;
        fa = fx;
      } else {
        b = x;
      }
      double mid = 0.5 * (a + b);
      if (mid <= a || mid >= b) break;
      double dx = poly_eval(d, deg - 1, x);
      double xn = dx != 0 ? x - fx / dx : mid;
      x = (xn > a && xn < b) ? xn : mid;
      if (it > 4 && !(xn > a && xn < b)) x = mid;
      if (x == a || x == b) x = mid;
    }
    double r = 0.5 * (a + b);
    if (r > lo && r < hi && (n == 0 || out[n - 1] != r)) out[n++] = r;
  }
  return n;
}

}  // namespace vislib
