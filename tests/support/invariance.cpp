// invariance.cpp: invariance.h.
#include "tests/support/invariance.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "vislib/base/cubemap.h"

namespace vislib {
namespace {

constexpr double kUlp = 0x1p-53;

// Distance between the segments p0 + s u and q0 + r v, s, r in [0, 1] (Ericson, Real-Time Collision
// Detection, 5.1.9); also the parameter s of the closest point on the first.
double segment_distance(Vec3 p0, Vec3 u, Vec3 q0, Vec3 v, double* s_out) {
  const Vec3 w = p0 - q0;
  const double a = dot(u, u), e = dot(v, v), f = dot(v, w);
  double s = 0, r = 0;
  if (a <= 0 && e <= 0) {
    s = r = 0;
  } else if (a <= 0) {
    r = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = dot(u, w);
    if (e <= 0) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = dot(u, v), den = a * e - b * b;
      s = den > 0 ? std::clamp((b * f - c * e) / den, 0.0, 1.0) : 0.0;
      r = (b * s + f) / e;
      if (r < 0) {
        r = 0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (r > 1) {
        r = 1;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  *s_out = s;
  const Vec3 d = (p0 + u * s) - (q0 + v * r);
  return std::sqrt(dot(d, d));
}

double max_abs_coordinate(const Scene& s) {
  double m = 0;
  for (const auto& state : s.positions)
    for (Vec3 p : state) m = std::max({m, std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)});
  return m;
}

// One triangle against one ray (eye + lambda d, lambda in [lo, hi]).
struct TriangleOnRay {
  bool inside = false;     // the ray's line crosses the interior (Moller-Trumbore, double)
  double lambda = 0;       // depth of the plane crossing (inf when parallel)
  double edge = 0;         // nearest edge to the ray segment
  double edge_lambda = 0;  // depth of the ray's closest point to that edge
};

TriangleOnRay on_ray(const std::array<Vec3, 3>& c, Vec3 eye, Vec3 d, double lo, double hi) {
  TriangleOnRay r;
  const Vec3 e1 = c[1] - c[0], e2 = c[2] - c[0], p = cross(d, e2);
  const double det = dot(e1, p);
  r.lambda = INFINITY;
  if (det != 0) {
    const Vec3 s = eye - c[0], q = cross(s, e1);
    const double b1 = dot(s, p) / det, b2 = dot(d, q) / det;
    r.lambda = dot(e2, q) / det;
    r.inside = b1 > 0 && b2 > 0 && b1 + b2 < 1;
  }
  r.edge = INFINITY;
  const Vec3 a0 = eye + d * lo, ad = d * (hi - lo);
  for (int k = 0; k < 3; ++k) {
    double s = 0;
    const double dist = segment_distance(a0, ad, c[k], c[(k + 1) % 3] - c[k], &s);
    if (dist < r.edge) {
      r.edge = dist;
      r.edge_lambda = lo + s * (hi - lo);
    }
  }
  return r;
}

struct RayVerdict {
  InvarianceClass cls = InvarianceClass::Defect;
  double edge_distance = INFINITY, depth_gap = INFINITY;
  double bound = 0;  // the grazing bound on this ray
  std::string why;
};

// The id `x` against the ray (eye, d) in scene `a`, `unit` = 2^-53 * magnitudes without the
// lambda term, which is added here.
RayVerdict judge_ray(const Scene& a, uint32_t x, Vec3 eye, Vec3 d, double z_near, double eps_z,
                     double unit) {
  RayVerdict v;
  const auto cx = a.corners(x);
  // The id's own plane depth (or its nearest point when the ray runs parallel to it).
  TriangleOnRay own = on_ray(cx, eye, d, z_near, 1e30);
  double lx = std::isfinite(own.lambda) && own.lambda > z_near ? own.lambda : own.edge_lambda;
  const double dl = std::sqrt(dot(d, d));
  const double bound = kInvarianceUlps * (unit + kUlp * lx * dl);
  const double hi = lx * (1 + 4 * kTieBandFactor * eps_z) + 2 * bound / dl;
  v.bound = bound;
  own = on_ray(cx, eye, d, z_near, hi);
  v.edge_distance = own.edge;
  const bool x_grazed = own.edge <= bound;
  if (!x_grazed && !own.inside) {
    v.why = "the ray misses the triangle by more than the bound";
    return v;
  }
  // Triangles in front of (or tied with) the id along this ray.
  double front_robust = INFINITY;  // nearest robust hit of another triangle
  bool other_grazed = false;
  const double r_limit = hi;  // farther than this cannot hide or tie
  for (uint32_t t = 0; t < a.triangle_count(); ++t) {
    if (t == x) continue;
    const auto c = a.corners(t);
    // Bounding-sphere reject against the ray segment [z_near, hi].
    const Vec3 m = (c[0] + c[1] + c[2]) * (1.0 / 3.0);
    double rad2 = 0;
    for (const Vec3& p : c) rad2 = std::max(rad2, dot(p - m, p - m));
    const Vec3 w = m - eye;
    const double s = std::clamp(dot(w, d) / (dl * dl), z_near, r_limit);
    const Vec3 off = w - d * s;
    const double rad = std::sqrt(rad2) + bound;
    if (dot(off, off) > rad * rad) continue;
    const TriangleOnRay o = on_ray(c, eye, d, z_near, r_limit);
    if (o.edge <= bound) {
      other_grazed = true;
      v.edge_distance = std::min(v.edge_distance, o.edge);
    } else if (o.inside && o.lambda > z_near && o.lambda < front_robust) {
      front_robust = o.lambda;
    }
  }
  if (std::isfinite(front_robust))
    v.depth_gap = std::fabs(lx - front_robust) / std::min(lx, front_robust);
  if (!x_grazed && std::isfinite(front_robust) &&
      front_robust < lx * (1 - kTieBandFactor * eps_z)) {
    v.why = "a triangle hit away from its edges hides it by more than the tie band";
    return v;
  }
  if (x_grazed || other_grazed) {
    v.cls = InvarianceClass::Grazing;
    v.why = x_grazed ? "the ray grazes an edge of the triangle" : "the ray grazes an edge in front";
    return v;
  }
  if (std::isfinite(front_robust) && v.depth_gap <= kTieBandFactor * eps_z) {
    v.cls = InvarianceClass::DepthTie;
    v.why = "hit within the tie band of another surface";
    return v;
  }
  v.why = "the first hit, away from every edge and tie: the other set misses it";
  return v;
}

struct EvidenceRay {
  int face, x, y;
  double t, len;
};

}  // namespace

const char* invariance_class_name(InvarianceClass c) {
  switch (c) {
    case InvarianceClass::Grazing:
      return "grazing";
    case InvarianceClass::DepthTie:
      return "depth tie";
    case InvarianceClass::Defect:
      return "defect";
  }
  return "?";
}

size_t InvarianceReport::count(InvarianceClass c) const {
  return size_t(std::count_if(diffs.begin(), diffs.end(),
                              [c](const InvarianceEvidence& e) { return e.cls == c; }));
}

InvarianceReport classify_invariance(const Scene& a, const Scene& b, const Similarity& sim, Vec3 v0,
                                     Vec3 v1, const SegmentOptions& options) {
  SegmentOptions oa = options;
  oa.want_pieces = true;
  oa.want_witnesses = true;
  SegmentOptions ob = oa;
  ob.orientation = multiply(sim.rotation, options.orientation);
  ob.near = options.near * sim.scale;
  const SegmentResult ra = segment_visibility(a, v0, v1, oa);
  const SegmentResult rb = segment_visibility(b, apply(sim, v0), apply(sim, v1), ob);
  InvarianceReport rep;
  rep.visible_a = ra.visible.size();
  rep.visible_b = rb.visible.size();
  const double unit = kUlp * (max_abs_coordinate(a) + max_abs_coordinate(b) / sim.scale +
                              std::sqrt(dot(v1 - v0, v1 - v0)));
  const int n = options.resolution;
  FaceAxes axes[kCubeFaces];
  for (int f = 0; f < kCubeFaces; ++f) axes[f] = face_axes(f, options.orientation);

  std::vector<uint32_t> only;
  std::set_symmetric_difference(ra.visible.begin(), ra.visible.end(), rb.visible.begin(),
                                rb.visible.end(), std::back_inserter(only));
  rep.diffs.resize(only.size());
  tbb::parallel_for(size_t(0), only.size(), [&](size_t k) {  // ids are independent: deterministic
    const uint32_t id = only[k];
    const bool in_a = std::binary_search(ra.visible.begin(), ra.visible.end(), id);
    const SegmentResult& r = in_a ? ra : rb;
    std::vector<EvidenceRay> rays;
    for (size_t p = 0; p < r.pieces.size(); ++p)
      for (const Piece& pc : r.pieces[p])
        if (pc.id == id && pc.t1 - pc.t0 > options.eps_len) {
          const int f = int(p / (size_t(n) * n)), y = int(p / n % n), x = int(p % n);
          rays.push_back({f, x, y, 0.5 * (pc.t0 + pc.t1), pc.t1 - pc.t0});
        }
    if (rays.empty())  // visible through a depth tie only: its witness
      for (const Witness& w : r.witnesses)
        if (w.tri == id && !w.is_sphere) rays.push_back({w.face, w.x, w.y, w.t, 0});
    std::stable_sort(rays.begin(), rays.end(),
                     [](const EvidenceRay& l, const EvidenceRay& r2) { return l.len > r2.len; });
    if (rays.size() > kMaxEvidenceRays) rays.resize(kMaxEvidenceRays);
    InvarianceEvidence ev;
    ev.id = id;
    ev.in_original = in_a;
    ev.rays = rays.size();
    bool have = false;
    for (const EvidenceRay& er : rays) {
      const Vec3 eye = lerp(v0, v1, er.t), d = pixel_direction(axes[er.face], er.x, er.y, n);
      const RayVerdict v = judge_ray(a, id, eye, d, options.near, options.eps_z, unit);
      // The worst class wins: defect, then grazing, then tie.
      auto rank = [](InvarianceClass c) {
        return c == InvarianceClass::Defect ? 2 : c == InvarianceClass::Grazing ? 1 : 0;
      };
      if (!have || rank(v.cls) > rank(ev.cls)) {
        have = true;
        ev.cls = v.cls;
        ev.face = er.face;
        ev.x = er.x;
        ev.y = er.y;
        ev.t = er.t;
        ev.piece_length = er.len;
        ev.edge_distance = v.edge_distance;
        ev.ulps_needed = v.edge_distance / (v.bound / kInvarianceUlps);
        ev.depth_gap = v.depth_gap;
        ev.why = v.why;
      }
      if (ev.cls == InvarianceClass::Defect) break;
    }
    if (!have) ev.why = "no evidence ray (no piece and no witness)";
    rep.diffs[k] = ev;
  });
  return rep;
}

}  // namespace vislib
