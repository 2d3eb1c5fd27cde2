// near_far_c.cpp: the C API of runtime/near_far_c.h over runtime/near_far.h. Checks every
// precondition of the C++ functions and reports a violation as PVS_RT_INVALID_ARGUMENT.
#include "runtime/near_far_c.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "runtime/c_api_support.h"
#include "runtime/near_far.h"
#include "runtime/pvs_runtime.h"

using pvs_runtime::Point3;
using pvs_runtime::detail::fail;
using pvs_runtime::detail::guarded_simple;

namespace {

Point3 point(const double* p) {
  return {p[0], p[1], p[2]};
}
Point3 point(const float* p) {
  return {double(p[0]), double(p[1]), double(p[2])};
}
void store(float* out, const Point3& p) {
  out[0] = float(p.x);
  out[1] = float(p.y);
  out[2] = float(p.z);
}
bool finite3(const double* p) {
  return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
}

pvs_rt_status check_radii(const char* fn, double r1, double r2) {
  if (!(r1 >= 0 && r1 < r2 && std::isfinite(r2)))
    return fail(PVS_RT_INVALID_ARGUMENT, std::string(fn) +
                                             ": need 0 <= r1 < r2 (got r1 = " + std::to_string(r1) +
                                             ", r2 = " + std::to_string(r2) + ")");
  return PVS_RT_OK;
}

pvs_rt_status check_curve(const char* fn, pvs_rt_morph_curve c) {
  if (c != PVS_RT_CURVE_LINEAR && c != PVS_RT_CURVE_QUADRATIC && c != PVS_RT_CURVE_SCURVE)
    return fail(PVS_RT_INVALID_ARGUMENT,
                std::string(fn) + ": unknown curve " + std::to_string(int(c)));
  return PVS_RT_OK;
}

// Checks the geometry's arrays and, for the triangles ids[0..count), their indices.
pvs_rt_status check_geometry(const char* fn, const pvs_rt_geometry* g, const uint32_t* ids,
                             size_t count, bool need_objects) {
  const std::string f = fn;
  if (!g || (g->vertex_count && !g->positions) || (g->triangle_count && !g->indices))
    return fail(PVS_RT_INVALID_ARGUMENT, f + ": null geometry array");
  if (need_objects && g->triangle_count && !g->triangle_object)
    return fail(PVS_RT_INVALID_ARGUMENT, f + ": triangle_object is required");
  for (size_t k = 0; k < count; ++k) {
    const uint32_t t = ids[k];
    if (t >= g->triangle_count)
      return fail(PVS_RT_INVALID_ARGUMENT, f + ": id " + std::to_string(t) + " >= triangle_count " +
                                               std::to_string(g->triangle_count));
    for (int j = 0; j < 3; ++j)
      if (g->indices[3 * size_t(t) + j] >= g->vertex_count)
        return fail(PVS_RT_INVALID_ARGUMENT,
                    f + ": triangle " + std::to_string(t) + " has vertex index " +
                        std::to_string(g->indices[3 * size_t(t) + j]) + " >= vertex_count " +
                        std::to_string(g->vertex_count));
  }
  return PVS_RT_OK;
}

void copy_out(const std::vector<uint32_t>& v, uint32_t* out, size_t* count) {
  if (!v.empty()) std::memcpy(out, v.data(), v.size() * sizeof(uint32_t));
  *count = v.size();
}

}  // namespace

struct pvs_rt_clovr {
  pvs_rt_geometry geometry{};
  pvs_rt_clovr_params params{};
  bool started = false;
  Point3 centre;
  std::vector<uint32_t> ids;      // the visible set, sorted
  std::vector<double> id_radius;  // per id: its object's radius
  std::vector<double> equal, contribution, merged;
  // Frame state.
  uint32_t frame = 0;  // the next frame's number
  size_t ring = 0;     // ring of the next frame (after frame 0)
  uint32_t step = 0;   // frames of `ring` already emitted
  bool emitted_first = false;
  double big_r = 0, ring_radius = 0;
  std::vector<uint32_t> near_ids, environment_ids;
};

extern "C" {

pvs_rt_status pvs_rt_cell_near_far(const pvs_rt* handle, uint32_t cell, double centre[3],
                                   double* r1, double* r2) {
  if (!handle || !centre || !r1 || !r2)
    return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_cell_near_far: null argument");
  double lo[3], hi[3];
  if (pvs_rt_status s = pvs_rt_cell_box(handle, cell, lo, hi)) return s;
  for (int k = 0; k < 3; ++k) centre[k] = 0.5 * (lo[k] + hi[k]);
  const double half_diagonal = 0.5 * std::hypot(hi[0] - lo[0], hi[2] - lo[2]);
  // A degenerate (zero-width) cell still gets a positive r1.
  *r1 = 1.25 * std::max(half_diagonal, 1e-6);
  *r2 = 2.0 * *r1;
  return PVS_RT_OK;
}

pvs_rt_status pvs_rt_partition_near_far(const pvs_rt_geometry* g, const uint32_t* ids,
                                        size_t id_count, const double centre[3], double r1,
                                        double r2, pvs_rt_near_far* out) {
  if (!centre || !out || (id_count && !ids))
    return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_partition_near_far: null argument");
  if (pvs_rt_status s = check_radii("pvs_rt_partition_near_far", r1, r2)) return s;
  if (pvs_rt_status s = check_geometry("pvs_rt_partition_near_far", g, ids, id_count, false))
    return s;
  if (out->capacity < id_count)
    return fail(PVS_RT_BUFFER_TOO_SMALL, "pvs_rt_partition_near_far: capacity " +
                                             std::to_string(out->capacity) + " < id_count " +
                                             std::to_string(id_count));
  if (id_count && (!out->near_ids || !out->intermediate_ids || !out->far_static_ids ||
                   !out->far_dynamic_ids || !out->environment_map_ids || !out->geometry_ids))
    return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_partition_near_far: null output array");
  return guarded_simple([&] {
    pvs_runtime::NearFarPartition p = pvs_runtime::partition_near_far(
        g->positions, g->vertex_count, g->indices, g->triangle_count, g->dynamic, ids, id_count,
        point(centre), r1, r2);
    copy_out(p.near_ids, out->near_ids, &out->near_count);
    copy_out(p.intermediate_ids, out->intermediate_ids, &out->intermediate_count);
    copy_out(p.far_static_ids, out->far_static_ids, &out->far_static_count);
    copy_out(p.far_dynamic_ids, out->far_dynamic_ids, &out->far_dynamic_count);
    copy_out(p.environment_map_ids, out->environment_map_ids, &out->environment_map_count);
    copy_out(p.geometry_ids, out->geometry_ids, &out->geometry_count);
    return PVS_RT_OK;
  });
}

pvs_rt_status pvs_rt_morph_weight(double r, double r1, double r2, pvs_rt_morph_curve curve,
                                  double* weight) {
  if (!weight) return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_morph_weight: null argument");
  if (pvs_rt_status s = check_radii("pvs_rt_morph_weight", r1, r2)) return s;
  if (pvs_rt_status s = check_curve("pvs_rt_morph_weight", curve)) return s;
  *weight = pvs_runtime::morph_user_weight(r, r1, r2, pvs_runtime::MorphCurve(curve));
  return PVS_RT_OK;
}

pvs_rt_status pvs_rt_morph_vertices(const float* in, size_t count, const double eye[3],
                                    const double centre[3], double r1, double r2,
                                    pvs_rt_morph_curve curve, float* out) {
  if (!eye || !centre || (count && (!in || !out)))
    return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_morph_vertices: null argument");
  if (pvs_rt_status s = check_radii("pvs_rt_morph_vertices", r1, r2)) return s;
  if (pvs_rt_status s = check_curve("pvs_rt_morph_vertices", curve)) return s;
  const Point3 u = point(eye), o = point(centre);
  const double eye_r = pvs_runtime::axis_distance(u, o);
  if (!(eye_r < r1) || !finite3(eye))
    return fail(PVS_RT_INVALID_ARGUMENT,
                "pvs_rt_morph_vertices: the eye is " + std::to_string(eye_r) +
                    " from the axis, not inside r1 = " + std::to_string(r1));
  for (size_t i = 0; i < count; ++i) {
    const Point3 p = point(in + 3 * i);
    store(out + 3 * i, pvs_runtime::morph_vertex(p, u, o, r1, r2, pvs_runtime::MorphCurve(curve)));
  }
  return PVS_RT_OK;
}

pvs_rt_status pvs_rt_displace_far(const float* in, size_t count, const double eye[3],
                                  const double centre[3], float* out) {
  if (!eye || !centre || (count && (!in || !out)))
    return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_displace_far: null argument");
  const Point3 u = point(eye), o = point(centre);
  for (size_t i = 0; i < count; ++i)
    store(out + 3 * i, pvs_runtime::displace_far(point(in + 3 * i), u, o));
  return PVS_RT_OK;
}

pvs_rt_status pvs_rt_range_test(const double q[3], const double eye[3], const float* range,
                                int size, int* passes) {
  if (!q || !eye || !range || !passes)
    return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_range_test: null argument");
  if (size < 1) return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_range_test: size must be >= 1");
  if (q[0] == eye[0] && q[1] == eye[1] && q[2] == eye[2])
    return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_range_test: q equals the eye");
  *passes =
      pvs_runtime::passes_range_test(point(q), point(eye), pvs_runtime::RangeCubeMap{size, range})
          ? 1
          : 0;
  return PVS_RT_OK;
}

void pvs_rt_clovr_default_params(double final_radius, pvs_rt_clovr_params* p) {
  if (!p) return;
  p->final_radius = final_radius;
  p->ring_area = 3.14159265358979323846 * final_radius * final_radius / 8.0;
  p->min_contribution = -1;
  p->frames_per_ring = 4;
  p->near_fraction = 0.7;
}

pvs_rt_status pvs_rt_clovr_create(const pvs_rt_geometry* g, const pvs_rt_clovr_params* p,
                                  pvs_rt_clovr** out) {
  if (out) *out = nullptr;
  if (!g || !p || !out) return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_clovr_create: null argument");
  if (pvs_rt_status s = check_geometry("pvs_rt_clovr_create", g, nullptr, 0, true)) return s;
  for (size_t t = 0; t < g->triangle_count; ++t) {
    if (g->triangle_object[t] >= g->object_count)
      return fail(PVS_RT_INVALID_ARGUMENT,
                  "pvs_rt_clovr_create: triangle " + std::to_string(t) + " has object " +
                      std::to_string(g->triangle_object[t]) + " >= object_count " +
                      std::to_string(g->object_count));
    for (int j = 0; j < 3; ++j)
      if (g->indices[3 * t + j] >= g->vertex_count)
        return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_clovr_create: triangle " + std::to_string(t) +
                                                 " has a vertex index >= vertex_count");
  }
  if (!(p->final_radius > 0 && std::isfinite(p->final_radius)))
    return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_clovr_create: final_radius must be > 0");
  if (p->frames_per_ring < 1)
    return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_clovr_create: frames_per_ring must be >= 1");
  if (!(p->near_fraction > 0 && p->near_fraction < 1))
    return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_clovr_create: near_fraction must be in (0, 1)");
  if (!std::isfinite(p->ring_area) || !(p->min_contribution == p->min_contribution))
    return fail(PVS_RT_INVALID_ARGUMENT,
                "pvs_rt_clovr_create: ring_area and min_contribution must be finite");
  return guarded_simple([&] {
    auto* c = new pvs_rt_clovr;
    c->geometry = *g;
    c->params = *p;
    if (c->params.ring_area <= 0)
      c->params.ring_area = 3.14159265358979323846 * p->final_radius * p->final_radius / 8.0;
    *out = c;
    return PVS_RT_OK;
  });
}

void pvs_rt_clovr_destroy(pvs_rt_clovr* c) {
  delete c;
}

pvs_rt_status pvs_rt_clovr_start(pvs_rt_clovr* c, const uint32_t* ids, size_t count,
                                 const double centre[3]) {
  if (!c || !centre || (count && !ids))
    return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_clovr_start: null argument");
  if (pvs_rt_status s = check_geometry("pvs_rt_clovr_start", &c->geometry, ids, count, true))
    return s;
  return guarded_simple([&] {
    const pvs_rt_geometry& g = c->geometry;
    c->centre = point(centre);
    c->ids.assign(ids, ids + count);
    std::sort(c->ids.begin(), c->ids.end());
    c->ids.erase(std::unique(c->ids.begin(), c->ids.end()), c->ids.end());
    // Objects of the visible set, their radius over all their triangles (partition_progressive's
    // rule), their weight = visible triangles.
    const double inf = std::numeric_limits<double>::infinity();
    std::vector<uint8_t> wanted(g.object_count, 0);
    for (uint32_t t : c->ids) wanted[g.triangle_object[t]] = 1;
    std::vector<double> object_radius(g.object_count, inf);
    for (size_t t = 0; t < g.triangle_count; ++t) {
      const uint32_t ob = g.triangle_object[t];
      if (!wanted[ob]) continue;
      for (int j = 0; j < 3; ++j) {
        const double r = pvs_runtime::axis_distance(
            point(g.positions + 3 * size_t(g.indices[3 * t + j])), c->centre);
        object_radius[ob] = std::min(object_radius[ob], r);
      }
    }
    c->id_radius.resize(c->ids.size());
    std::vector<double> item_radius, item_weight;
    std::vector<double> weight(g.object_count, 0.0);
    for (size_t k = 0; k < c->ids.size(); ++k) {
      const uint32_t ob = g.triangle_object[c->ids[k]];
      c->id_radius[k] = object_radius[ob];
      weight[ob] += 1.0;
    }
    for (size_t ob = 0; ob < g.object_count; ++ob)
      if (wanted[ob]) {
        item_radius.push_back(object_radius[ob]);
        item_weight.push_back(weight[ob]);
      }
    c->equal = pvs_runtime::equal_area_ring_radii(c->params.ring_area, c->params.final_radius);
    c->contribution = pvs_runtime::ring_contributions(c->equal, item_radius, item_weight);
    double total = 0;
    for (double x : c->contribution) total += x;
    const double min_c = c->params.min_contribution < 0 ? total / double(c->equal.size())
                                                        : c->params.min_contribution;
    c->merged = min_c > 0 ? pvs_runtime::merge_rings(c->equal, c->contribution, min_c) : c->equal;
    c->started = true;
    c->frame = 0;
    c->ring = 0;
    c->step = 0;
    c->emitted_first = false;
    c->big_r = c->ring_radius = 0;
    c->near_ids.clear();
    c->environment_ids = c->ids;
    return PVS_RT_OK;
  });
}

pvs_rt_status pvs_rt_clovr_next_frame(pvs_rt_clovr* c, pvs_rt_clovr_frame* out) {
  if (!c || !out) return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_clovr_next_frame: null argument");
  if (!c->started)
    return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_clovr_next_frame: call pvs_rt_clovr_start first");
  return guarded_simple([&] {
    const size_t rings = c->merged.size();
    const double previous_ring_radius = c->ring_radius;
    size_t ring_now = rings;
    if (!c->emitted_first) {
      c->emitted_first = true;  // frame 0: R_0 = 0, nothing near
      c->big_r = c->ring_radius = 0;
      ring_now = 0;
    } else if (c->ring < rings) {
      const double from = c->ring == 0 ? 0.0 : c->merged[c->ring - 1];
      const double to = c->merged[c->ring];
      ++c->step;
      c->ring_radius = to;
      c->big_r = c->step == c->params.frames_per_ring
                     ? to
                     : from + (to - from) * double(c->step) / c->params.frames_per_ring;
      ring_now = c->ring;
      if (c->step == c->params.frames_per_ring) {
        ++c->ring;
        c->step = 0;
      }
    }
    const bool changed = c->ring_radius != previous_ring_radius || c->frame == 0;
    if (changed) {  // objects whose radius is below the ring being injected are drawn from geometry
      c->near_ids.clear();
      c->environment_ids.clear();
      for (size_t k = 0; k < c->ids.size(); ++k)
        (c->id_radius[k] < c->ring_radius ? c->near_ids : c->environment_ids).push_back(c->ids[k]);
    }
    out->frame = c->frame++;
    out->ring = uint32_t(ring_now);
    out->ring_count = uint32_t(rings);
    out->ring_radius = c->ring_radius;
    out->radius = c->big_r;
    out->near_radius = c->params.near_fraction * c->big_r;
    out->near_changed = changed ? 1 : 0;
    out->done = c->ring >= rings && c->emitted_first ? 1 : 0;
    out->near_count = c->near_ids.size();
    out->environment_count = c->environment_ids.size();
    return PVS_RT_OK;
  });
}

static pvs_rt_status copy_ids(const char* fn, const std::vector<uint32_t>& v, uint32_t* out,
                              size_t capacity, size_t* count) {
  if (!count || (capacity && !out))
    return fail(PVS_RT_INVALID_ARGUMENT, std::string(fn) + ": null argument");
  *count = v.size();
  if (v.size() > capacity)
    return fail(PVS_RT_BUFFER_TOO_SMALL, std::string(fn) + ": " + std::to_string(v.size()) +
                                             " ids, capacity " + std::to_string(capacity));
  if (!v.empty()) std::memcpy(out, v.data(), v.size() * sizeof(uint32_t));
  return PVS_RT_OK;
}

pvs_rt_status pvs_rt_clovr_near_ids(const pvs_rt_clovr* c, uint32_t* out, size_t capacity,
                                    size_t* count) {
  if (!c) return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_clovr_near_ids: null argument");
  return copy_ids("pvs_rt_clovr_near_ids", c->near_ids, out, capacity, count);
}

pvs_rt_status pvs_rt_clovr_environment_ids(const pvs_rt_clovr* c, uint32_t* out, size_t capacity,
                                           size_t* count) {
  if (!c) return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_clovr_environment_ids: null argument");
  return copy_ids("pvs_rt_clovr_environment_ids", c->environment_ids, out, capacity, count);
}

pvs_rt_status pvs_rt_clovr_rings(const pvs_rt_clovr* c, double* equal, double* contribution,
                                 size_t capacity, size_t* equal_count, double* merged,
                                 size_t merged_capacity, size_t* merged_count) {
  if (!c || !equal_count || !merged_count || (capacity && (!equal || !contribution)) ||
      (merged_capacity && !merged))
    return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_clovr_rings: null argument");
  if (!c->started)
    return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_clovr_rings: call pvs_rt_clovr_start first");
  *equal_count = c->equal.size();
  *merged_count = c->merged.size();
  if (c->equal.size() > capacity || c->merged.size() > merged_capacity)
    return fail(PVS_RT_BUFFER_TOO_SMALL, "pvs_rt_clovr_rings: " + std::to_string(c->equal.size()) +
                                             " rings, " + std::to_string(c->merged.size()) +
                                             " merged");
  std::copy(c->equal.begin(), c->equal.end(), equal);
  std::copy(c->contribution.begin(), c->contribution.end(), contribution);
  std::copy(c->merged.begin(), c->merged.end(), merged);
  return PVS_RT_OK;
}

pvs_rt_status pvs_rt_clovr_inject_vertices(const pvs_rt_clovr* c, const float* in, size_t count,
                                           const double eye[3], float* out) {
  if (!c || !eye || (count && (!in || !out)))
    return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_clovr_inject_vertices: null argument");
  if (!c->started)
    return fail(PVS_RT_INVALID_ARGUMENT,
                "pvs_rt_clovr_inject_vertices: call pvs_rt_clovr_start first");
  const double big_r = c->big_r, r_n = c->params.near_fraction * big_r;
  const Point3 u = point(eye);
  const double eye_r = pvs_runtime::axis_distance(u, c->centre);
  if (!(eye_r < r_n))
    return fail(PVS_RT_INVALID_ARGUMENT,
                "pvs_rt_clovr_inject_vertices: the eye is " + std::to_string(eye_r) +
                    " from the axis, not inside R_n = " + std::to_string(r_n));
  for (size_t i = 0; i < count; ++i)
    store(out + 3 * i, pvs_runtime::inject_vertex(point(in + 3 * i), u, c->centre, big_r, r_n));
  return PVS_RT_OK;
}

pvs_rt_status pvs_rt_injection_weight(double r, double big_r, double r_n, double* weight) {
  if (!weight) return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_injection_weight: null argument");
  if (!(r_n >= 0 && r_n < big_r))
    return fail(PVS_RT_INVALID_ARGUMENT, "pvs_rt_injection_weight: need 0 <= R_n < R");
  *weight = pvs_runtime::injection_weight(r, big_r, r_n);
  return PVS_RT_OK;
}

}  // extern "C"
