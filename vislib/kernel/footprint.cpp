// footprint.cpp: docs/visibility-math.md §5.1 (clipped convex hull of the six eye-relative points).
#include "vislib/kernel/footprint.h"

#include <algorithm>
#include <cmath>

#include "vislib/base/tolerances.h"

namespace vislib {
namespace {

double cross2(Vec2 o, Vec2 a, Vec2 b) {
  return (a.u - o.u) * (b.w - o.w) - (a.w - o.w) * (b.u - o.u);
}

// Andrew's monotone chain over pts[0, n) (reordered in place); writes the CCW hull (collinear
// points dropped) to `out` and returns its size.
int convex_hull(Vec2* pts, int n, Vec2* out) {
  std::sort(pts, pts + n, [](Vec2 a, Vec2 b) { return a.u < b.u || (a.u == b.u && a.w < b.w); });
  n = int(std::unique(pts, pts + n, [](Vec2 a, Vec2 b) { return a.u == b.u && a.w == b.w; }) - pts);
  if (n <= 2) {
    std::copy(pts, pts + n, out);
    return n;
  }
  Vec2 h[2 * kMaxFootprintPoints];
  int k = 0;
  for (int i = 0; i < n; ++i) {
    while (k >= 2 && cross2(h[k - 2], h[k - 1], pts[i]) <= 0) --k;
    h[k++] = pts[i];
  }
  for (int i = n - 1, lo = k + 1; i-- > 0;) {
    while (k >= lo && cross2(h[k - 2], h[k - 1], pts[i]) <= 0) --k;
    h[k++] = pts[i];
  }
  std::copy(h, h + k - 1, out);
  return k - 1;
}

// Margin in face coordinates: absolute plus relative to the polygon's magnitude (points near the
// near plane project far out; their rounding grows with them).
double margin_of(const Vec2* hull, int size) {
  double m = 0;
  for (int i = 0; i < size; ++i) m = std::max({m, std::fabs(hull[i].u), std::fabs(hull[i].w)});
  return kFootprintMargin + kFootprintRelativeMargin * m;
}
double margin_of(const Footprint& fp) {
  return margin_of(fp.hull.data(), fp.size);
}

}  // namespace

namespace {

// Quick reject: the face-frame points q (x = S.p, y = T.p, z = F.p) all lie on the outer side of
// one plane of the face's frustum (near plane, or one of |u| <= 1, |w| <= 1 widened by
// kFrustumRejectWidening), so their clipped hull misses the face.
bool frustum_reject(const Vec3* q, int count, double near) {
  const double g = 1.0 + kFrustumRejectWidening;
  bool behind = true, right = true, left = true, up = true, down = true;
  for (int i = 0; i < count; ++i) {
    const double z = std::fabs(q[i].z) * g;
    behind = behind && q[i].z < near;
    right = right && q[i].x > z;
    left = left && q[i].x < -z;
    up = up && q[i].y > z;
    down = down && q[i].y < -z;
  }
  return behind || right || left || up || down;
}

// The projected, clipped points of §5.1 (before the hull): at most kMaxFootprintPoints. Returns
// -1 when the quick frustum reject applies (the footprint is empty), else the point count; zmin
// (if given) gets the smallest view depth F.rel[i].
int projected_points(const Vec3* rel, int count, const FaceAxes& axes, double near, Vec2* pts,
                     double* zmin) {
  Vec3 q[12];
  count = std::min(count, 12);
  for (int i = 0; i < count; ++i)
    q[i] = {dot(axes.S, rel[i]), dot(axes.T, rel[i]), dot(axes.F, rel[i])};
  if (zmin) {
    double z = INFINITY;
    for (int i = 0; i < count; ++i) z = std::min(z, q[i].z);
    *zmin = z;
  }
  if (frustum_reject(q, count, near)) return -1;
  int n = 0;
  for (int i = 0; i < count; ++i)
    if (q[i].z >= near) pts[n++] = {q[i].x / q[i].z, q[i].y / q[i].z};
  // Edges of the point set crossing the near plane: their crossing points (all pairs).
  for (int i = 0; i < count; ++i)
    for (int j = i + 1; j < count; ++j) {
      double zi = q[i].z - near, zj = q[j].z - near;
      if ((zi < 0 && zj > 0) || (zi > 0 && zj < 0)) {
        double s = (near - q[i].z) / (q[j].z - q[i].z);
        double x = q[i].x + s * (q[j].x - q[i].x), y = q[i].y + s * (q[j].y - q[i].y);
        pts[n++] = {x / near, y / near};
      }
    }
  return n;
}

// Pixel rectangle of the points pts[0, count) (non-empty) with margin m.
bool bounds_of(const Vec2* pts, int count, double m, int n, int& x0, int& x1, int& y0, int& y1) {
  double umin = INFINITY, umax = -INFINITY, wmin = INFINITY, wmax = -INFINITY;
  for (int i = 0; i < count; ++i) {
    Vec2 p = pts[i];
    umin = std::min(umin, p.u);
    umax = std::max(umax, p.u);
    wmin = std::min(wmin, p.w);
    wmax = std::max(wmax, p.w);
  }
  return face_box_pixels(umin, umax, wmin, wmax, m, n, x0, x1, y0, y1);
}

}  // namespace

bool face_box_pixels(double umin, double umax, double wmin, double wmax, double m, int n, int& x0,
                     int& x1, int& y0, int& y1) {
  if (umax < -1 - m || umin > 1 + m || wmax < -1 - m || wmin > 1 + m) return false;
  auto lo = [n](double c) {
    return std::max(0, int(std::ceil(std::max(-2.0, pixel_coord(c, n)))));
  };
  auto hi = [n](double c) {
    return std::min(n - 1, int(std::floor(std::min(double(n) + 1, pixel_coord(c, n)))));
  };
  x0 = lo(umin - m);
  x1 = hi(umax + m);
  y0 = lo(wmin - m);
  y1 = hi(wmax + m);
  return x0 <= x1 && y0 <= y1;
}

Footprint compute_footprint(const Vec3* rel, int count, const FaceAxes& axes, double near) {
  Footprint fp;
  double margin;
  fp.size = compute_footprint_hull(rel, count, axes, near, fp.hull.data(), margin);
  return fp;
}

int compute_footprint_hull(const Vec3* rel, int count, const FaceAxes& axes, double near,
                           Vec2* hull, double& margin) {
  Vec2 pts[kMaxFootprintPoints];
  int n = projected_points(rel, count, axes, near, pts, nullptr);
  const int size = n > 0 ? convex_hull(pts, n, hull) : 0;
  margin = margin_of(hull, size);
  return size;
}

bool footprint_bounds(const Vec3* rel, int count, const FaceAxes& axes, double near, int n, int& x0,
                      int& x1, int& y0, int& y1, double& zmin) {
  Vec2 pts[kMaxFootprintPoints];
  int k = projected_points(rel, count, axes, near, pts, &zmin);
  if (k <= 0) return false;
  // The hull keeps every extreme point (its vertices are a subset of the points that includes
  // the extremes in u and w), so the margin and the bounds equal those of the hull exactly.
  double m = 0;
  for (int i = 0; i < k; ++i) m = std::max({m, std::fabs(pts[i].u), std::fabs(pts[i].w)});
  return bounds_of(pts, k, kFootprintMargin + kFootprintRelativeMargin * m, n, x0, x1, y0, y1);
}

bool box_footprint_bounds(const float lo[3], const float hi[3], Vec3 v0, Vec3 v1,
                          const FaceAxes& axes, double near, int n, int& x0, int& x1, int& y0,
                          int& y1, double& zmin) {
  Vec3 q[16];
  double mag = 0;
  for (int c = 0; c < 8; ++c) {
    const Vec3 corner{(c & 1) ? hi[0] : lo[0], (c & 2) ? hi[1] : lo[1], (c & 4) ? hi[2] : lo[2]};
    for (int e = 0; e < 2; ++e) {
      const Vec3 rel = corner - (e ? v1 : v0);
      Vec3& p = q[2 * c + e];
      p = {dot(axes.S, rel), dot(axes.T, rel), dot(axes.F, rel)};
      mag = std::max({mag, std::fabs(rel.x), std::fabs(rel.y), std::fabs(rel.z)});
    }
  }
  // delta: far more than the rounding of any of these dot products, or of a contained
  // triangle's (a few units in the last place of mag), so that every test below is decided the
  // conservative way for every triangle inside the box.
  const double delta = 1e-9 * mag + 1e-300;
  const double g = 1.0 + 2 * kFrustumRejectWidening;
  bool behind = true, right = true, left = true, up = true, down = true, straddles = false;
  double z_low = INFINITY;
  for (const Vec3& p : q) {
    const double z = (std::fabs(p.z) + delta) * g;
    behind = behind && p.z < near - delta;
    right = right && p.x - delta > z;
    left = left && p.x + delta < -z;
    up = up && p.y - delta > z;
    down = down && p.y + delta < -z;
    straddles = straddles || p.z < near + delta;
    z_low = std::min(z_low, p.z);
  }
  zmin = z_low - delta;
  if (behind || right || left || up || down) return false;
  // Clip the box's swept hull at z = near_c, a little nearer than near so that every point of a
  // contained triangle at z >= near (as its own test computes it) is inside; its projection's
  // extremes are those of the points in front and of the crossings of all pairs of points with
  // the clipping plane (a superset of the clipped hull's vertices, inside the hull).
  const double near_c = near - delta;
  if (!(near_c > 0.5 * near)) {  // the margin swamps near: the whole face (conservative)
    x0 = y0 = 0;
    x1 = y1 = n - 1;
    return true;
  }
  Vec2 pts[16 + 64];
  int k = 0;
  for (const Vec3& p : q)
    if (p.z >= near_c) pts[k++] = {p.x / p.z, p.y / p.z};
  if (straddles)
    for (int i = 0; i < 16; ++i)
      for (int j = i + 1; j < 16; ++j) {
        const double zi = q[i].z - near_c, zj = q[j].z - near_c;
        if (!((zi < 0 && zj > 0) || (zi > 0 && zj < 0))) continue;
        const double s = (near_c - q[i].z) / (q[j].z - q[i].z);
        const double x = q[i].x + s * (q[j].x - q[i].x), y = q[i].y + s * (q[j].y - q[i].y);
        pts[k++] = {x / near_c, y / near_c};  // at most 8 x 8 pairs cross
      }
  if (k == 0) return false;  // nothing at z >= near_c (then nothing at z >= near either)
  // The projected triangle points lie inside the hull of these up to rounding, which the margin
  // (amplified by 1/z, z >= near_c) covers.
  double m = 0;
  for (int i = 0; i < k; ++i) m = std::max({m, std::fabs(pts[i].u), std::fabs(pts[i].w)});
  const double margin =
      2 * (kFootprintMargin + kFootprintRelativeMargin * m) + 1e-9 * (1 + m) * (mag / near_c + 1);
  if (!bounds_of(pts, k, margin, n, x0, x1, y0, y1)) return false;
  x0 = std::max(0, x0 - 1);  // one pixel more on each side
  y0 = std::max(0, y0 - 1);
  x1 = std::min(n - 1, x1 + 1);
  y1 = std::min(n - 1, y1 + 1);
  return true;
}

unsigned reachable_faces(const Vec3* rel, int count, const Mat3& R, double near) {
  // World axes A_j = R e_j. Every face axis R a (a = +-e_j, face_axes) equals +-A_j component by
  // component (up to the sign of zero components), so dot(R a, p) = +-dot(A_j, p) bit for bit
  // (negation is exact and rounding symmetric), and frustum_reject's tests become tests on the
  // coordinates c_j = dot(A_j, p): for a face with F = +-A_f and S or T = +-A_j, "all points right
  // of (or all left of) the side plane" is all c_j > |c_f| g or all c_j < -|c_f| g whatever the
  // signs, and "all behind" is all +-c_f < near.
  const Vec3 A[3] = {R * Vec3{1, 0, 0}, R * Vec3{0, 1, 0}, R * Vec3{0, 0, 1}};
  const double g = 1.0 + kFrustumRejectWidening;
  bool above[3][3], below[3][3];      // [j][f]: every point has c_j > |c_f| g, resp. c_j < -|c_f| g
  bool behind_pos[3], behind_neg[3];  // every point has c_f < near, resp. -c_f < near
  for (int a = 0; a < 3; ++a) {
    behind_pos[a] = behind_neg[a] = true;
    for (int b = 0; b < 3; ++b) above[a][b] = below[a][b] = true;
  }
  count = std::min(count, 12);
  for (int i = 0; i < count; ++i) {
    const double c[3] = {dot(A[0], rel[i]), dot(A[1], rel[i]), dot(A[2], rel[i])};
    for (int f = 0; f < 3; ++f) {
      const double z = std::fabs(c[f]) * g;
      behind_pos[f] = behind_pos[f] && c[f] < near;
      behind_neg[f] = behind_neg[f] && -c[f] < near;
      for (int j = 0; j < 3; ++j) {
        above[j][f] = above[j][f] && c[j] > z;
        below[j][f] = below[j][f] && c[j] < -z;
      }
    }
  }
  auto axis = [](Vec3 a, int& sign) {  // index and sign of a signed unit axis
    sign = (a.x + a.y + a.z) > 0 ? 1 : -1;
    return a.x != 0 ? 0 : a.y != 0 ? 1 : 2;
  };
  unsigned mask = 0;
  for (int k = 0; k < kCubeFaces; ++k) {
    const FaceAxes ax = face_axes_local(k);
    int sf, ss, st;
    const int f = axis(ax.F, sf), js = axis(ax.S, ss), jt = axis(ax.T, st);
    const bool rejected = (sf > 0 ? behind_pos[f] : behind_neg[f]) || above[js][f] ||
                          below[js][f] || above[jt][f] || below[jt][f];
    if (!rejected) mask |= 1u << k;
  }
  return mask;
}

bool footprint_pixel_bounds(const Footprint& fp, int n, int& x0, int& x1, int& y0, int& y1) {
  if (fp.empty()) return false;
  return bounds_of(fp.hull.data(), fp.size, margin_of(fp), n, x0, x1, y0, y1);
}

bool footprint_row_span(const Footprint& fp, int n, int y, int& x0, int& x1) {
  if (fp.empty()) return false;
  return footprint_row_span(fp.hull.data(), fp.size, margin_of(fp), n, y, x0, x1);
}

bool footprint_row_span(const Vec2* hull, int k, double m, int n, int y, int& x0, int& x1) {
  if (k == 0) return false;
  double wc = pixel_center(y, n), wlo = wc - m, whi = wc + m;
  double umin = INFINITY, umax = -INFINITY;
  for (int i = 0; i < k; ++i) {
    Vec2 a = hull[i];
    if (a.w >= wlo && a.w <= whi) {
      umin = std::min(umin, a.u);
      umax = std::max(umax, a.u);
    }
    if (k == 1) break;
    Vec2 b = hull[i + 1 == k ? 0 : i + 1];  // (no integer division: this runs per triangle and row)
    for (double wl : {wlo, whi}) {
      if ((a.w < wl && b.w > wl) || (a.w > wl && b.w < wl)) {
        double u = a.u + (wl - a.w) / (b.w - a.w) * (b.u - a.u);
        umin = std::min(umin, u);
        umax = std::max(umax, u);
      }
    }
  }
  if (!(umin <= umax)) return false;
  if (umax < -1 - m || umin > 1 + m) return false;
  x0 = std::max(0, int(std::ceil(std::max(-2.0, pixel_coord(umin - m, n)))));
  x1 = std::min(n - 1, int(std::floor(std::min(double(n) + 1, pixel_coord(umax + m, n)))));
  return x0 <= x1;
}

}  // namespace vislib
