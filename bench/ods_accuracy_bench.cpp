// ods_accuracy_bench: the ODS raster method's error against the ray-cast reference by distance
// and the paper formula (Eq. 5) against the exact tangent-ray projection.
// A plain program (no Google Benchmark timing): prints a Markdown table.
//
//   build/bench/ods_accuracy_bench [width]      (default 3840; height = width / 2)
//
// Scene: at each distance d, 12 square cards facing the centre, 10 degrees wide, at longitudes
// -165, -135, ..., 165 and elevations 0, 30, 60 degrees (alternating). Per card and method: the
// distance in pixels between the card's coverage centroid in the raster panorama and in the
// ray-cast one (right eye, IPD 6.4 cm, no pole merging), and the share of pixels whose triangle
// differs. Also the pure formula error: the largest distance between the paper's and the exact
// projection of the card corners.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>

#include "runtime/ods.h"
#include "vislib/eval/embree_scene.h"
#include "vislib/render/ods_render.h"

namespace {

using vislib::Vec3;

void add_card(vislib::Scene& s, Vec3 c, Vec3 right, Vec3 up, double half) {
  const uint32_t base = uint32_t(s.positions[0].size());
  for (Vec3 p : {c - right * half - up * half, c + right * half - up * half,
                 c + right * half + up * half, c - right * half + up * half})
    s.positions[0].push_back(p);
  const uint32_t obj = uint32_t(s.objects.size());
  s.objects.push_back({"card" + std::to_string(obj)});
  s.triangles.push_back({base, base + 1, base + 2});
  s.triangles.push_back({base, base + 2, base + 3});
  s.triangle_object.push_back(obj);
  s.triangle_object.push_back(obj);
}

// Centroid (u, v, count) per object.
std::map<uint32_t, std::array<double, 3>> centroids(const vislib::Scene& s,
                                                    const vislib::Frame& f) {
  std::map<uint32_t, std::array<double, 3>> c;
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x) {
      const uint32_t t = f.tri[size_t(y) * f.width + x];
      if (t == vislib::kNoHit) continue;
      auto& a = c[s.triangle_object[t]];
      a[0] += x + 0.5, a[1] += y + 0.5, a[2] += 1;
    }
  return c;
}

}  // namespace

int main(int argc, char** argv) {
  const int width = argc > 1 ? std::atoi(argv[1]) : 3840;
  const double pi = pvs_runtime::kOdsPi, deg = pi / 180, ipd = 0.064;
  const Vec3 centre{0.25, 1.6, -0.4};
  std::printf("ODS raster error against rays, %dx%d, right eye, IPD %.3f m, no pole merging\n\n",
              width, width / 2, ipd);
  std::printf(
      "| distance (m) | Eq. 5 formula max (px) | raster-paper centroid max / mean (px) | "
      "raster-exact centroid "
      "max / mean (px) | paper tri mismatch | exact tri mismatch |\n|---|---|---|---|---|---|\n");
  for (double d : {0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0}) {
    vislib::Scene s;
    s.positions.resize(1);
    double formula_max = 0;
    for (int k = 0; k < 12; ++k) {
      const double lon = (-165 + 30 * k) * deg, el = (k % 3) * 30 * deg;
      const Vec3 dir{-std::sin(lon) * std::cos(el), std::sin(el), std::cos(lon) * std::cos(el)};
      Vec3 right = cross(dir, Vec3{0, 1, 0});
      right = right * (1.0 / length(right));
      const Vec3 up = cross(right, dir);
      const double half = d * std::tan(5 * deg);
      add_card(s, centre + dir * d, right, up, half);
      for (int q = 0; q < 4; ++q) {
        const Vec3 p = s.positions[0][s.positions[0].size() - 4 + size_t(q)];
        const pvs_runtime::Point3 pp{p.x, p.y, p.z}, cc{centre.x, centre.y, centre.z};
        const auto e = pvs_runtime::ods_project_exact(pp, cc, ipd, pvs_runtime::Eye::Right, {});
        const auto a = pvs_runtime::ods_project_paper(pp, cc, ipd, pvs_runtime::Eye::Right, {});
        if (!e.visible) continue;
        formula_max = std::max(
            formula_max,
            std::hypot(pvs_runtime::wrap_longitude(e.ll.lon - a.ll.lon), e.ll.lat - a.ll.lat) *
                width / (2 * pi));
      }
    }
    vislib::EmbreeScene rt(s, 0.0, centre);
    vislib::OdsSettings set;
    set.centre = centre;
    set.ipd = ipd;
    set.width = width, set.height = width / 2;
    const vislib::Frame ref = vislib::render_ods_rays(s, rt, set, pvs_runtime::Eye::Right);
    std::vector<uint32_t> ids(s.triangle_count());
    for (uint32_t t = 0; t < ids.size(); ++t) ids[t] = t;
    const auto cref = centroids(s, ref);
    double out[2][3];
    for (int m = 0; m < 2; ++m) {
      vislib::OdsRasterSettings r;
      r.formula = m == 0 ? vislib::OdsFormula::Paper : vislib::OdsFormula::Exact;
      const vislib::Frame f = vislib::render_ods_raster(s, ids, set, pvs_runtime::Eye::Right, r);
      const auto c = centroids(s, f);
      double worst = 0, sum = 0;
      int n = 0;
      for (const auto& [o, a] : cref) {
        auto it = c.find(o);
        if (it == c.end()) {
          worst = INFINITY;
          continue;
        }
        const double e = std::hypot(a[0] / a[2] - it->second[0] / it->second[2],
                                    a[1] / a[2] - it->second[1] / it->second[2]);
        worst = std::max(worst, e), sum += e, ++n;
      }
      size_t other = 0;
      for (size_t p = 0; p < ref.pixel_count(); ++p) other += ref.tri[p] != f.tri[p];
      size_t shown = 0;
      for (size_t p = 0; p < ref.pixel_count(); ++p) shown += ref.tri[p] != vislib::kNoHit;
      out[m][0] = worst, out[m][1] = n ? sum / n : 0,
      out[m][2] = double(other) / double(std::max<size_t>(shown, 1));
    }
    std::printf("| %.1f | %.3f | %.3f / %.3f | %.3f / %.3f | %.4f | %.4f |\n", d, formula_max,
                out[0][0], out[0][1], out[1][0], out[1][1], out[0][2], out[1][2]);
  }
  std::printf(
      "\n(tri mismatch: pixels whose triangle differs from the rays', per pixel showing a card)\n");
  return 0;
}
