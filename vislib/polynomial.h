// polynomial.h: numerically careful real roots of low-degree polynomials (math note §6), for the
// quadratic events of moving triangles and spheres.
#pragma once

#include <cmath>

namespace vislib {

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
  r[0] = std::fmin(x0, x1);
  r[1] = std::fmax(x0, x1);
  return 2;
}

}  // namespace vislib
