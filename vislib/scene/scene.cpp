#include "vislib/scene/scene.h"

#include <fnmatch.h>

#include <cassert>
#include <cmath>

namespace vislib {

bool Scene::is_dynamic() const {
  for (size_t k = 1; k < positions.size(); ++k)
    if (positions[k] != positions[0]) return true;
  for (size_t k = 1; k < sphere_centers.size(); ++k)
    if (sphere_centers[k] != sphere_centers[0]) return true;
  return false;
}

bool Scene::has_see_through() const {
  for (const Object& o : objects)
    if (o.see_through) return true;
  return false;
}

size_t Scene::see_through_triangle_count() const {
  if (!has_see_through()) return 0;
  size_t n = 0;
  for (uint32_t o : triangle_object) n += objects[o].see_through ? 1 : 0;
  return n;
}

size_t mark_see_through(Scene& scene, const std::vector<std::string>& patterns) {
  size_t marked = 0;
  for (Object& o : scene.objects)
    for (const std::string& p : patterns)
      if (fnmatch(p.c_str(), o.name.c_str(), 0) == 0) {
        o.see_through = true;
        ++marked;
        break;
      }
  return marked;
}

std::vector<size_t> keep_opaque(Scene& scene, const std::vector<std::string>& patterns) {
  std::vector<size_t> matched(patterns.size(), 0);
  auto matches = [&](const std::string& name) {
    bool any = false;
    for (size_t p = 0; p < patterns.size(); ++p)
      if (fnmatch(patterns[p].c_str(), name.c_str(), 0) == 0) {
        ++matched[p];
        any = true;
      }
    return any;
  };
  for (Object& o : scene.objects) {
    const bool by_name = matches(o.name);
    const bool by_material = !o.alpha_materials.empty();
    std::vector<std::string> kept;
    for (const std::string& m : o.alpha_materials)
      if (!matches(m)) kept.push_back(m);
    o.alpha_materials = std::move(kept);
    if (by_name || (by_material && o.alpha_materials.empty())) {
      o.see_through = false;
      o.alpha_materials.clear();
    }
  }
  return matched;
}

namespace {
// Maps tau in [0,1] to (state interval k, local parameter s).
void locate(size_t states, double tau, size_t& k, double& s) {
  if (states <= 1) {
    k = 0;
    s = 0;
    return;
  }
  double x = std::fmin(std::fmax(tau, 0.0), 1.0) * double(states - 1);
  k = size_t(x);
  if (k >= states - 1) k = states - 2;
  s = x - double(k);
}
}  // namespace

Vec3 Scene::position_at(uint32_t vertex, double tau) const {
  size_t k;
  double s;
  locate(positions.size(), tau, k, s);
  if (positions.size() <= 1) return positions[0][vertex];
  return lerp(positions[k][vertex], positions[k + 1][vertex], s);
}

Vec3 Scene::sphere_center_at(uint32_t sphere, double tau) const {
  size_t k;
  double s;
  locate(sphere_centers.size(), tau, k, s);
  if (sphere_centers.size() <= 1) return sphere_centers[0][sphere];
  return lerp(sphere_centers[k][sphere], sphere_centers[k + 1][sphere], s);
}

Box3 Scene::bounds() const {
  Box3 b;
  for (const auto& state : positions)
    for (const auto& p : state) b.extend(p);
  for (const auto& state : sphere_centers)
    for (size_t i = 0; i < state.size(); ++i) {
      Vec3 r{sphere_radius[i], sphere_radius[i], sphere_radius[i]};
      b.extend(state[i] - r);
      b.extend(state[i] + r);
    }
  return b;
}

void append_scene(Scene& scene, const Scene& other) {
  size_t ks = scene.state_count(), ko = other.state_count();
  assert(ks == ko || ks <= 1 || ko <= 1);
  size_t k = ks > ko ? ks : ko;
  if (k == 0) k = 1;
  auto widen = [k](std::vector<std::vector<Vec3>>& states, size_t count) {
    if (states.empty()) states.resize(1);
    states[0].resize(count);
    while (states.size() < k) states.push_back(states[0]);
  };
  size_t vbase = scene.vertex_count(), sbase = scene.sphere_count();
  uint32_t obase = uint32_t(scene.objects.size());
  widen(scene.positions, vbase);
  widen(scene.sphere_centers, sbase);
  for (size_t s = 0; s < k; ++s) {
    const auto& op = other.positions.empty() ? std::vector<Vec3>{}
                                             : other.positions[other.positions.size() == 1 ? 0 : s];
    scene.positions[s].insert(scene.positions[s].end(), op.begin(), op.end());
    const auto& oc = other.sphere_centers.empty()
                         ? std::vector<Vec3>{}
                         : other.sphere_centers[other.sphere_centers.size() == 1 ? 0 : s];
    scene.sphere_centers[s].insert(scene.sphere_centers[s].end(), oc.begin(), oc.end());
  }
  for (auto t : other.triangles)
    scene.triangles.push_back(
        {uint32_t(t[0] + vbase), uint32_t(t[1] + vbase), uint32_t(t[2] + vbase)});
  for (auto o : other.triangle_object) scene.triangle_object.push_back(o + obase);
  for (auto o : other.sphere_object) scene.sphere_object.push_back(o + obase);
  scene.sphere_radius.insert(scene.sphere_radius.end(), other.sphere_radius.begin(),
                             other.sphere_radius.end());
  scene.objects.insert(scene.objects.end(), other.objects.begin(), other.objects.end());
  if (scene.positions.size() == 1 && scene.positions[0].empty() &&
      scene.sphere_centers[0].empty()) {
    scene.positions.clear();
    scene.sphere_centers.clear();
  }
}

}  // namespace vislib
