// stereo.cpp: single-render stereo by reprojection (YORO, MobiSys '25, §6-7, Alg. 1-3, Eq. 6;
// ../shared/papers/yoro-single-render-stereo.txt), with exact world-space reprojection and the
// fixes of docs/stereo.md. Contracts in stereo.h.
#include "vislib/render/stereo.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

#include "vislib/base/ray_triangle.h"

namespace vislib {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Rec. 601 luminance of an 8-bit RGB pixel.
double luminance(const uint8_t* c) {
  return 0.299 * c[0] + 0.587 * c[1] + 0.114 * c[2];
}

uint8_t to_byte(double v) {
  const double s = std::round(v);
  return uint8_t(s < 0 ? 0 : (s > 255 ? 255 : s));
}

// Where each source sample lands (slot i = source pixel index).
struct Landing {
  uint32_t target = kNoSource;                           // target pixel index
  double view_depth = kInf;                              // target view depth (inf: background)
  float range = std::numeric_limits<float>::infinity();  // |P - target eye|
};

Landing land(const Frame& src, const Camera& sc, const CameraBasis& sb, const Camera& tc,
             const CameraBasis& tb, int x, int y) {
  Landing l;
  const size_t i = size_t(y) * size_t(src.width) + size_t(x);
  const Vec3 d = camera_ray(sb, sc, x, y);
  std::optional<PixelPosition> p;
  Vec3 world;
  const bool background = src.tri[i] == kNoHit || !std::isfinite(src.depth[i]);
  if (background) {
    p = camera_project_direction(tb, tc, d);
  } else {
    world = sc.eye + d * (double(src.depth[i]) / length(d));
    p = camera_project(tb, tc, world);
    if (p && !(p->view_depth > tc.z_near)) p.reset();
  }
  if (!p || !in_image(tc, *p)) return l;
  const int tx = int(std::floor(p->x + 0.5)), ty = int(std::floor(p->y + 0.5));
  if (tx < 0 || tx >= tc.width || ty < 0 || ty >= tc.height) return l;
  l.target = uint32_t(size_t(ty) * size_t(tc.width) + size_t(tx));
  l.view_depth = p->view_depth;
  l.range = background ? std::numeric_limits<float>::infinity() : float(length(world - tc.eye));
  return l;
}

Reprojection empty_reprojection(int w, int h) {
  Reprojection r;
  r.width = w;
  r.height = h;
  const size_t n = size_t(w) * size_t(h);
  r.rgb.assign(3 * n, 0);
  for (size_t p = 0; p < n; ++p)
    for (int k = 0; k < 3; ++k) r.rgb[3 * p + size_t(k)] = kStereoHoleColour[size_t(k)];
  r.depth.assign(n, std::numeric_limits<float>::infinity());
  r.tri.assign(n, kNoHit);
  r.source.assign(n, kNoSource);
  r.hole.assign(n, HoleKind::Disocclusion);
  return r;
}

void write_sample(Reprojection& r, const Frame& src, size_t p, uint32_t s, float range) {
  r.source[p] = s;
  r.hole[p] = HoleKind::Filled;
  r.depth[p] = range;
  r.tri[p] = src.tri[s];
  for (int k = 0; k < 3; ++k) r.rgb[3 * p + size_t(k)] = src.rgb[3 * size_t(s) + size_t(k)];
}

// Crack / outside / disocclusion for every hole of `r` (see stereo.h); `vdepth` is the target view
// depth per pixel (inf at background and holes).
void classify_holes(Reprojection& r, const std::vector<float>& vdepth, const Frame& src,
                    const Camera& sc, const Camera& tc) {
  const int w = r.width, h = r.height;
  const CameraBasis sb = camera_basis(sc), tb = camera_basis(tc);
  auto filled = [&](int x, int y) {
    return r.source[size_t(y) * size_t(w) + size_t(x)] != kNoSource;
  };
  auto same_surface = [&](size_t a, size_t b) {
    const long sa = long(r.source[a]), sbi = long(r.source[b]);
    const long ax = sa % src.width, ay = sa / src.width, bx = sbi % src.width, by = sbi / src.width;
    if (std::max(std::labs(ax - bx), std::labs(ay - by)) > kStereoCrackSourceSpan) return false;
    const double da = double(vdepth[a]), db = double(vdepth[b]);
    if (std::isinf(da) || std::isinf(db)) return std::isinf(da) && std::isinf(db);
    return std::max(da, db) <= kStereoSurfaceDepthRatio * std::min(da, db);
  };
  // Outside the source view when the target pixel's ray at `range` from the target eye (inf: its
  // direction) does not project into the source image.
  auto outside = [&](int x, int y, double range) {
    const Vec3 d = camera_ray(tb, tc, x, y);
    std::optional<PixelPosition> p;
    if (std::isinf(range)) {
      p = camera_project_direction(sb, sc, d);
    } else {
      p = camera_project(sb, sc, tc.eye + d * (range / length(d)));
      if (p && !(p->view_depth > sc.z_near)) p.reset();
    }
    return !p || !in_image(sc, *p);
  };
  std::vector<HoleKind>& kind = r.hole;  // classification reads r.source and r.depth only
  tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& rows) {
    std::vector<int> left(static_cast<size_t>(w)), right(static_cast<size_t>(w));
    for (int y = rows.begin(); y != rows.end(); ++y) {
      const size_t row = size_t(y) * size_t(w);
      int last = -1;
      for (int x = 0; x < w; ++x) {
        if (filled(x, y)) last = x;
        left[size_t(x)] = last;
      }
      last = -1;
      for (int x = w - 1; x >= 0; --x) {
        if (filled(x, y)) last = x;
        right[size_t(x)] = last;
      }
      for (int x = 0; x < w; ++x) {
        const size_t p = row + size_t(x);
        if (r.source[p] != kNoSource) continue;
        if (x > 0 && x + 1 < w && filled(x - 1, y) && filled(x + 1, y) &&
            same_surface(p - 1, p + 1)) {
          kind[p] = HoleKind::Crack;
          continue;
        }
        if (y > 0 && y + 1 < h && filled(x, y - 1) && filled(x, y + 1) &&
            same_surface(p - size_t(w), p + size_t(w))) {
          kind[p] = HoleKind::Crack;
          continue;
        }
        double range = -1;
        const int l = left[size_t(x)], rr = right[size_t(x)];
        if (l >= 0) range = std::max(range, double(r.depth[row + size_t(l)]));
        if (rr >= 0) range = std::max(range, double(r.depth[row + size_t(rr)]));
        if (range < 0) {  // nothing landed in this row: the column's nearest filled pixels
          for (int yy = y - 1; yy >= 0; --yy)
            if (filled(x, yy)) {
              range = std::max(range, double(r.depth[size_t(yy) * size_t(w) + size_t(x)]));
              break;
            }
          for (int yy = y + 1; yy < h; ++yy)
            if (filled(x, yy)) {
              range = std::max(range, double(r.depth[size_t(yy) * size_t(w) + size_t(x)]));
              break;
            }
        }
        kind[p] =
            range < 0 || outside(x, y, range) ? HoleKind::OutsideView : HoleKind::Disocclusion;
      }
    }
  });
}

Reprojection reproject_exact(const Frame& src, const Camera& sc, const Camera& tc) {
  const CameraBasis sb = camera_basis(sc), tb = camera_basis(tc);
  const size_t n = src.pixel_count();
  // Where each source sample lands (slot i): target pixel and target view depth (float: only
  // compared, ties go to the smaller source index).
  std::vector<uint32_t> target(n);
  std::vector<float> depth(n);
  tbb::parallel_for(tbb::blocked_range<int>(0, src.height),
                    [&](const tbb::blocked_range<int>& rows) {
                      for (int y = rows.begin(); y != rows.end(); ++y)
                        for (int x = 0; x < src.width; ++x) {
                          const size_t i = size_t(y) * size_t(src.width) + size_t(x);
                          const Landing l = land(src, sc, sb, tc, tb, x, y);
                          target[i] = l.target;
                          depth[i] = float(l.view_depth);
                        }
                    });
  // Bucket the samples by target row, in source order (a sequential counting sort).
  const size_t tw = size_t(tc.width);
  std::vector<uint32_t> start(size_t(tc.height) + 1, 0);
  for (uint32_t t : target)
    if (t != kNoSource) ++start[t / tw + 1];
  for (size_t y = 0; y < size_t(tc.height); ++y) start[y + 1] += start[y];
  std::vector<uint32_t> order(start.back());
  {
    std::vector<uint32_t> fill(start.begin(), start.end() - 1);
    for (size_t i = 0; i < n; ++i)
      if (target[i] != kNoSource) order[fill[target[i] / tw]++] = uint32_t(i);
  }
  Reprojection r = empty_reprojection(tc.width, tc.height);
  std::vector<float> vdepth(r.pixel_count(), std::numeric_limits<float>::infinity());
  tbb::parallel_for(tbb::blocked_range<int>(0, tc.height),
                    [&](const tbb::blocked_range<int>& rows) {
                      for (int y = rows.begin(); y != rows.end(); ++y) {
                        for (uint32_t k = start[size_t(y)]; k < start[size_t(y) + 1]; ++k) {
                          const uint32_t s = order[k];
                          const size_t p = target[s];
                          // Nearest wins; on equal depth the earlier (smaller) source index stays.
                          if (r.source[p] != kNoSource && !(depth[s] < vdepth[p])) continue;
                          vdepth[p] = depth[s];
                          r.source[p] = s;
                        }
                        for (size_t p = size_t(y) * tw; p < size_t(y + 1) * tw; ++p) {
                          const uint32_t s = r.source[p];
                          if (s == kNoSource) continue;
                          const Landing l = land(src, sc, sb, tc, tb, int(s % uint32_t(src.width)),
                                                 int(s / uint32_t(src.width)));
                          write_sample(r, src, p, s, l.range);
                        }
                      }
                    });
  classify_holes(r, vdepth, src, sc, tc);
  return r;
}

bool same_vec(Vec3 a, Vec3 b, double tol) {
  return length(a - b) <= tol;
}

// Alg. 2 as printed (one row per task), on the exact landing positions (for parallel eyes with
// identical projections, Alg. 1 without a perspective divide gives the same columns).
Reprojection reproject_alg2(const Frame& src, const Camera& sc, const Camera& tc) {
  const CameraBasis sb = camera_basis(sc), tb = camera_basis(tc);
  const Vec3 offset = tc.eye - sc.eye;
  const double tol = 1e-12;
  if (!(same_vec(sb.f, tb.f, tol) && same_vec(sb.u, tb.u, tol) &&
        sc.vfov_degrees == tc.vfov_degrees && sc.width == tc.width && sc.height == tc.height &&
        sc.shift_x == tc.shift_x && sc.shift_y == tc.shift_y && sc.z_near == tc.z_near &&
        std::fabs(dot(offset, sb.f)) <= 1e-12 * (1 + length(offset)) &&
        std::fabs(dot(offset, sb.u)) <= 1e-12 * (1 + length(offset))))
    throw std::invalid_argument(
        "Alg. 2 as printed needs parallel eyes with identical projections (an eye offset along the "
        "right "
        "vector only)");
  // Target left of the source: samples move to +x, the paper's scan direction. Else mirror x.
  const bool mirror = dot(offset, sb.r) > 0;
  const int w = sc.width;
  Reprojection r = empty_reprojection(tc.width, tc.height);
  std::vector<float> vdepth(r.pixel_count(), std::numeric_limits<float>::infinity());
  tbb::parallel_for(
      tbb::blocked_range<int>(0, sc.height), [&](const tbb::blocked_range<int>& rows) {
        // S-hat of the row: (x0 or source column, reversed depth d, width w); w == 0 = a sample.
        std::vector<int> from(static_cast<size_t>(w)), width(static_cast<size_t>(w));
        std::vector<double> rdepth(static_cast<size_t>(w));
        for (int y = rows.begin(); y != rows.end(); ++y) {
          std::fill(from.begin(), from.end(), -1);
          std::fill(width.begin(), width.end(), -1);
          std::fill(rdepth.begin(), rdepth.end(), -kInf);  // below every depth, background included
          int x0 = 0;
          for (int xm = 0; xm < w; ++xm) {
            const int x = mirror ? w - 1 - xm : xm;
            const Landing l = land(src, sc, sb, tc, tb, x, y);
            if (l.target == kNoSource || l.target / size_t(w) != size_t(y)) continue;
            const int xt = int(l.target % size_t(w));
            const int xh = mirror ? w - 1 - xt : xt;  // line 4, in scan coordinates
            const double d =
                std::isinf(l.view_depth) ? 0.0 : 1.0 / l.view_depth;  // line 5 (reversed Z)
            if (rdepth[size_t(xh)] < d) {                             // line 6
              const int ww = xh - x0;                                 // line 7
              for (int i = x0 + 1; i <= xh; ++i) {                    // lines 8-10
                from[size_t(i)] = x0, rdepth[size_t(i)] = d, width[size_t(i)] = ww;
              }
              from[size_t(xh)] = xm, rdepth[size_t(xh)] = d, width[size_t(xh)] = 0;  // line 11
            }
            x0 = xh;  // line 13
          }
          for (int xh = 0; xh < w; ++xh) {
            if (width[size_t(xh)] != 0) continue;  // never written, or a hole span entry
            const int xs = mirror ? w - 1 - from[size_t(xh)] : from[size_t(xh)];
            const int xt = mirror ? w - 1 - xh : xh;
            const uint32_t s = uint32_t(size_t(y) * size_t(w) + size_t(xs));
            const Landing l = land(src, sc, sb, tc, tb, xs, y);
            const size_t p = size_t(y) * size_t(w) + size_t(xt);
            vdepth[p] = float(l.view_depth);
            write_sample(r, src, p, s, l.range);
          }
        }
      });
  classify_holes(r, vdepth, src, sc, tc);
  return r;
}

Frame frame_of(const Reprojection& r) {
  Frame f;
  f.width = r.width;
  f.height = r.height;
  f.rgb = r.rgb;
  f.depth = r.depth;
  f.tri = r.tri;
  return f;
}

// patch_median on a frame whose holes are the pixels with open[p] != 0.
size_t median_fill(Frame& f, std::vector<uint8_t> open) {
  const int w = f.width, h = f.height;
  size_t patched = 0;
  for (int pass = 0; pass < 64; ++pass) {
    Frame next = f;
    std::vector<uint8_t> next_open = open;
    std::vector<size_t> row_count(size_t(h), 0);
    tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& rows) {
      std::vector<std::pair<double, size_t>> cand;
      for (int y = rows.begin(); y != rows.end(); ++y)
        for (int x = 0; x < w; ++x) {
          const size_t p = size_t(y) * size_t(w) + size_t(x);
          if (!open[p]) continue;
          cand.clear();
          for (int yy = std::max(0, y - 2); yy <= std::min(h - 1, y + 2); ++yy)
            for (int xx = std::max(0, x - 2); xx <= std::min(w - 1, x + 2); ++xx) {
              const size_t q = size_t(yy) * size_t(w) + size_t(xx);
              if (!open[q]) cand.push_back({luminance(&f.rgb[3 * q]), q});
            }
          if (cand.empty()) continue;
          std::sort(cand.begin(), cand.end());
          const size_t q = cand[(cand.size() - 1) / 2].second;
          for (int k = 0; k < 3; ++k) next.rgb[3 * p + size_t(k)] = f.rgb[3 * q + size_t(k)];
          next.depth[p] = f.depth[q];
          next.tri[p] = f.tri[q];
          next_open[p] = 0;
          ++row_count[size_t(y)];
        }
    });
    size_t changed = 0;
    for (size_t c : row_count) changed += c;
    f = std::move(next);
    open = std::move(next_open);
    patched += changed;
    if (changed == 0) break;
  }
  return patched;
}

}  // namespace

size_t Reprojection::count(HoleKind kind) const {
  return size_t(std::count(hole.begin(), hole.end(), kind));
}

StereoPair stereo_pair(const Camera& centre, double ipd, double toe_in_degrees, double shift) {
  assert(ipd >= 0);
  const CameraBasis b = camera_basis(centre);
  StereoPair s{centre, centre};
  s.left.eye = centre.eye - b.r * (ipd / 2);
  s.right.eye = centre.eye + b.r * (ipd / 2);
  if (toe_in_degrees != 0) {
    const double a = toe_in_degrees * (M_PI / 180.0);
    s.left.forward = b.f * std::cos(a) + b.r * std::sin(a);
    s.right.forward = b.f * std::cos(a) - b.r * std::sin(a);
  }
  s.left.shift_x = shift;
  s.right.shift_x = -shift;
  return s;
}

Reprojection reproject(const Frame& source, const Camera& source_camera,
                       const Camera& target_camera, Splatting splatting) {
  assert(source.width == source_camera.width && source.height == source_camera.height);
  if (splatting == Splatting::Alg2AsPrinted)
    return reproject_alg2(source, source_camera, target_camera);
  return reproject_exact(source, source_camera, target_camera);
}

Frame patch_none(const Reprojection& r, size_t* patched) {
  if (patched) *patched = 0;
  return frame_of(r);
}

Frame patch_median(const Reprojection& r, size_t* patched) {
  Frame f = frame_of(r);
  std::vector<uint8_t> open(r.pixel_count());
  for (size_t p = 0; p < open.size(); ++p) open[p] = r.hole[p] != HoleKind::Filled;
  const size_t n = median_fill(f, std::move(open));
  if (patched) *patched = n;
  return f;
}

std::vector<double> yoro_kernel_weights(int width, double t) {
  assert(width >= 1 && t > 0 && t <= 1);
  std::vector<double> wts(static_cast<size_t>(width));
  double rem = 1;
  for (int k = 0; k < width; ++k) {
    const double wk = rem * (0.5 + 0.3 * t);
    wts[size_t(k)] = wk;
    rem -= wk;
  }
  for (double& v : wts) v /= (1 - rem);
  return wts;
}

Frame patch_yoro(const Reprojection& r, bool as_printed, size_t* patched) {
  const int w = r.width, h = r.height;
  Frame f = frame_of(r);
  std::vector<uint8_t> open(r.pixel_count(), 0);
  std::vector<size_t> row_count(size_t(h), 0);
  auto is_filled = [&](int x, int y) {
    return r.hole[size_t(y) * size_t(w) + size_t(x)] == HoleKind::Filled;
  };
  tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y != rows.end(); ++y) {
      int x = 0;
      while (x < w) {
        if (is_filled(x, y)) {
          ++x;
          continue;
        }
        const int a = x;
        while (x < w && !is_filled(x, y)) ++x;
        const int b = x - 1;  // hole run [a, b]
        const int hw = b - a + 1;
        const bool has_l = a > 0, has_r = b + 1 < w;
        int e = -1;
        if (has_l && has_r) {
          const float dl = r.depth[size_t(y) * size_t(w) + size_t(a - 1)];
          const float dr = r.depth[size_t(y) * size_t(w) + size_t(b + 1)];
          e = dr > dl ? b + 1
                      : a - 1;  // the farther edge; on a tie the left one (the paper's side)
        } else if (has_l) {
          e = a - 1;
        } else if (has_r) {
          e = b + 1;
        }
        for (int u = a; u <= b; ++u) {
          const size_t p = size_t(y) * size_t(w) + size_t(u);
          if (e < 0) {
            open[p] = 1;
            continue;
          }
          const int s = e < a ? -1 : 1;
          const double de = double(r.depth[size_t(y) * size_t(w) + size_t(e)]);
          const double t = double(std::abs(u - e)) / double(hw);
          double acc[3] = {0, 0, 0}, rem = 1;
          bool any = false;
          uint32_t tri = kNoHit;
          float depth = std::numeric_limits<float>::infinity();
          for (int k = 0; k < hw; ++k) {
            const int kk = as_printed ? hw - 1 - k : k;
            const int col = e + s * kk;
            if (col < 0 || col >= w) continue;
            double sum[3] = {0, 0, 0};
            int kept = 0;
            for (int dy : {0, -1, 1}) {
              if (as_printed && dy != 0) continue;
              const int yy = y + dy;
              if (yy < 0 || yy >= h || !is_filled(col, yy)) continue;
              const size_t q = size_t(yy) * size_t(w) + size_t(col);
              if (double(r.depth[q]) * kStereoSurfaceDepthRatio < de) continue;  // foreground (O2)
              for (int c = 0; c < 3; ++c) sum[c] += r.rgb[3 * q + size_t(c)];
              if (!any && kept == 0) tri = r.tri[q], depth = r.depth[q];
              ++kept;
            }
            if (kept == 0) continue;
            const double wk = rem * (0.5 + 0.3 * t);  // Eq. 6, t in pixels / pixels
            for (int c = 0; c < 3; ++c) acc[c] += sum[c] / kept * wk;
            rem -= wk;
            any = true;
          }
          if (!any) {
            open[p] = 1;
            continue;
          }
          for (int c = 0; c < 3; ++c) f.rgb[3 * p + size_t(c)] = to_byte(acc[c] / (1 - rem));
          f.tri[p] = tri;
          f.depth[p] = depth;
          ++row_count[size_t(y)];
        }
      }
    }
  });
  size_t n = 0;
  for (size_t c : row_count) n += c;
  n += median_fill(f, std::move(open));
  if (patched) *patched = n;
  return f;
}

Frame patch_rays(const Reprojection& r, const Scene& scene, const EmbreeScene& rt,
                 const Camera& target, const uint8_t* allowed, size_t* rays) {
  assert(r.width == target.width && r.height == target.height);
  const CameraBasis b = camera_basis(target);
  Frame f = frame_of(r);
  const int w = r.width;
  std::vector<size_t> row_rays(size_t(r.height), 0);
  tbb::parallel_for(tbb::blocked_range<int>(0, r.height), [&](const tbb::blocked_range<int>& rows) {
    std::vector<Vec3> dirs;
    std::vector<Hit> hits;
    std::vector<int> xs;
    for (int y = rows.begin(); y != rows.end(); ++y) {
      dirs.clear();
      xs.clear();
      for (int x = 0; x < w; ++x)
        if (r.hole[size_t(y) * size_t(w) + size_t(x)] != HoleKind::Filled) {
          dirs.push_back(camera_ray(b, target, x, y));
          xs.push_back(x);
        }
      if (dirs.empty()) continue;
      hits.resize(dirs.size());
      rt.first_hits_among(target.eye, dirs.data(), dirs.size(), target.z_near, allowed,
                          hits.data());
      for (size_t i = 0; i < dirs.size(); ++i) {
        const size_t p = size_t(y) * size_t(w) + size_t(xs[i]);
        uint8_t* out = &f.rgb[3 * p];
        if (hits[i].tri == kNoHit) {
          out[0] = kRenderBackground[0], out[1] = kRenderBackground[1],
          out[2] = kRenderBackground[2];
          f.depth[p] = std::numeric_limits<float>::infinity();
          f.tri[p] = kNoHit;
          continue;
        }
        f.tri[p] = hits[i].tri;
        f.depth[p] = float(hits[i].lambda * length(dirs[i]));
        const auto c = shade_triangle(scene, hits[i].tri, dirs[i]);
        out[0] = c[0], out[1] = c[1], out[2] = c[2];
      }
      row_rays[size_t(y)] = dirs.size();
    }
  });
  if (rays) {
    *rays = 0;
    for (size_t c : row_rays) *rays += c;
  }
  return f;
}

ReshadeStats reshade(Reprojection& r, const Scene& scene, const Camera& target) {
  assert(r.width == target.width && r.height == target.height);
  const CameraBasis b = camera_basis(target);
  const int w = r.width, h = r.height;
  const Reprojection in = r;  // candidates come from the unmodified reprojection
  std::vector<size_t> row_resolved(size_t(h), 0), row_unresolved(size_t(h), 0);
  tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& rows) {
    std::vector<std::pair<uint32_t, size_t>> cand;  // (triangle, pixel it came from)
    for (int y = rows.begin(); y != rows.end(); ++y)
      for (int x = 0; x < w; ++x) {
        const size_t p = size_t(y) * size_t(w) + size_t(x);
        const HoleKind k = in.hole[p];
        if (k != HoleKind::Filled && k != HoleKind::Crack) continue;
        cand.clear();
        for (int yy = std::max(0, y - 1); yy <= std::min(h - 1, y + 1); ++yy)
          for (int xx = std::max(0, x - 1); xx <= std::min(w - 1, x + 1); ++xx) {
            const size_t q = size_t(yy) * size_t(w) + size_t(xx);
            if (in.hole[q] == HoleKind::Filled && in.tri[q] != kNoHit)
              cand.push_back({in.tri[q], q});
          }
        std::sort(cand.begin(), cand.end());
        const Vec3 d = camera_ray(b, target, x, y);
        double best = kInf;
        size_t best_q = 0;
        uint32_t best_tri = kNoHit;
        for (size_t i = 0; i < cand.size(); ++i) {
          if (i > 0 && cand[i].first == cand[i - 1].first) continue;
          const auto t = ray_triangle(target.eye, d, scene.corners(cand[i].first, 0));
          if (t && *t > target.z_near && *t < best) {
            best = *t;
            best_tri = cand[i].first;
            best_q = cand[i].second;
          }
        }
        uint8_t* out = &r.rgb[3 * p];
        if (best_tri != kNoHit) {
          r.tri[p] = best_tri;
          r.depth[p] = float(best * length(d));
          const auto c = shade_triangle(scene, best_tri, d);
          out[0] = c[0], out[1] = c[1], out[2] = c[2];
          if (k == HoleKind::Crack) {
            r.hole[p] = HoleKind::Filled;
            r.source[p] = in.source[best_q];
            ++row_resolved[size_t(y)];
          }
        } else if (k == HoleKind::Filled && in.tri[p] != kNoHit) {
          r.hole[p] = HoleKind::Disocclusion;
          r.source[p] = kNoSource;
          r.tri[p] = kNoHit;
          r.depth[p] = std::numeric_limits<float>::infinity();
          out[0] = kStereoHoleColour[0], out[1] = kStereoHoleColour[1],
          out[2] = kStereoHoleColour[2];
          ++row_unresolved[size_t(y)];
        }
      }
  });
  ReshadeStats st;
  for (size_t c : row_resolved) st.cracks_resolved += c;
  for (size_t c : row_unresolved) st.unresolved += c;
  return st;
}

std::vector<uint8_t> hole_mask_image(const Frame& frame, const std::vector<HoleKind>& hole) {
  assert(hole.size() == frame.pixel_count());
  std::vector<uint8_t> out(frame.rgb.size());
  for (size_t p = 0; p < hole.size(); ++p) {
    uint8_t* o = &out[3 * p];
    switch (hole[p]) {
      case HoleKind::Filled:
        for (int k = 0; k < 3; ++k) o[k] = uint8_t(std::floor(0.3 * frame.rgb[3 * p + size_t(k)]));
        break;
      case HoleKind::Disocclusion:
        o[0] = 255, o[1] = 0, o[2] = 0;
        break;
      case HoleKind::Crack:
        o[0] = 255, o[1] = 255, o[2] = 0;
        break;
      case HoleKind::OutsideView:
        o[0] = 0, o[1] = 96, o[2] = 255;
        break;
    }
  }
  return out;
}

std::vector<uint8_t> side_by_side(int width, int height, const std::vector<uint8_t>& left,
                                  const std::vector<uint8_t>& right) {
  assert(left.size() == size_t(3 * width * height) && right.size() == left.size());
  std::vector<uint8_t> out(2 * left.size());
  const size_t row = 3 * size_t(width);
  for (int y = 0; y < height; ++y) {
    std::copy_n(&left[size_t(y) * row], row, &out[size_t(y) * 2 * row]);
    std::copy_n(&right[size_t(y) * row], row, &out[size_t(y) * 2 * row + row]);
  }
  return out;
}

}  // namespace vislib
