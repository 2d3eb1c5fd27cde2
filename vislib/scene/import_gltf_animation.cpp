// import_gltf_animation.cpp: a glTF file's animation channels and their sampling (gltf_reader.h).
#include <algorithm>
#include <cmath>

#include "vislib/scene/gltf_reader.h"

namespace vislib {
namespace gltf_reader {

// Reads the animation channels of the selected animations. `node_targets[n]` is the morph target
// count of node n's mesh (0 without a mesh), the number of weights a "weights" channel animates.
std::vector<Channel> read_channels(Ctx& ctx, int which, const std::vector<size_t>& node_targets) {
  std::vector<Channel> out;
  const auto& anims = ctx.model.animations;
  if (which >= int(anims.size()))
    ctx.fail("animation " + std::to_string(which) + " does not exist (the file has " +
             std::to_string(anims.size()) + ")");
  for (size_t ai = 0; ai < anims.size(); ++ai) {
    if (which >= 0 && size_t(which) != ai) continue;
    const auto& an = anims[ai];
    for (size_t ci = 0; ci < an.channels.size(); ++ci) {
      const auto& ch = an.channels[ci];
      std::string where = "animation " + std::to_string(ai) + " channel " + std::to_string(ci);
      Channel c;
      if (ch.target_path == "translation")
        c.path = 0;
      else if (ch.target_path == "rotation")
        c.path = 1;
      else if (ch.target_path == "scale")
        c.path = 2;
      else if (ch.target_path == "weights")
        c.path = 3;
      else {
        ctx.warnings->push_back(ctx.path + ": " + where + ": target path '" + ch.target_path +
                                "' is not supported; channel ignored");
        continue;
      }
      if (ch.target_node < 0 || size_t(ch.target_node) >= ctx.model.nodes.size())
        ctx.fail(where + ": target node " + std::to_string(ch.target_node) + " does not exist");
      if (c.path == 3) {
        c.ncomp = node_targets[size_t(ch.target_node)];
        if (c.ncomp == 0)
          ctx.fail(where + ": animates the morph weights of node " +
                   std::to_string(ch.target_node) + ", which has no mesh with morph targets");
      } else {
        c.ncomp = c.path == 1 ? 4 : 3;
      }
      if (ch.sampler < 0 || size_t(ch.sampler) >= an.samplers.size())
        ctx.fail(where + ": sampler " + std::to_string(ch.sampler) + " does not exist");
      const auto& s = an.samplers[ch.sampler];
      c.node = ch.target_node;
      c.interp = s.interpolation == "STEP" ? 1 : s.interpolation == "CUBICSPLINE" ? 2 : 0;
      int nc;
      c.times = read_accessor(ctx, s.input, "input of " + where, nc, {1});
      c.values =
          read_accessor(ctx, s.output, "output of " + where, nc, {c.path == 3 ? 1 : int(c.ncomp)});
      size_t per_key = c.ncomp * (c.interp == 2 ? 3 : 1);
      if (c.times.empty() || c.values.size() != c.times.size() * per_key)
        ctx.fail("accessor " + std::to_string(s.output) + " (output of " + where +
                 "): " + std::to_string(c.values.size()) + " values, but " +
                 std::to_string(c.times.size()) + " keys (accessor " + std::to_string(s.input) +
                 ") need " + std::to_string(c.times.size() * per_key) +
                 (c.path == 3 ? " (" + std::to_string(c.ncomp) + " morph weights per key" +
                                    (c.interp == 2 ? ", times 3 for CUBICSPLINE)" : ")")
                              : std::string()));
      for (double t : c.times)
        if (!std::isfinite(t)) ctx.fail(where + ": non-finite key time");
      c.node = ch.target_node;
      out.push_back(std::move(c));
    }
  }
  return out;
}

// Value of channel `c` at time t (c.ncomp components).
void sample(const Channel& c, double t, double* v) {
  const size_t n = c.ncomp;
  size_t keys = c.times.size();
  size_t stride = n * (c.interp == 2 ? 3 : 1), voff = c.interp == 2 ? n : 0;
  auto val = [&](size_t k, size_t i) { return c.values[k * stride + voff + i]; };
  size_t k = size_t(std::upper_bound(c.times.begin(), c.times.end(), t) - c.times.begin());
  if (k == 0 || k == keys) {
    size_t at = k == 0 ? 0 : keys - 1;
    for (size_t i = 0; i < n; ++i) v[i] = val(at, i);
    return;
  }
  size_t k0 = k - 1;
  double t0 = c.times[k0], t1 = c.times[k], dt = t1 - t0;
  double s = dt > 0 ? (t - t0) / dt : 0;
  if (c.interp == 1) {
    for (size_t i = 0; i < n; ++i) v[i] = val(k0, i);
  } else if (c.interp == 2) {
    double s2 = s * s, s3 = s2 * s;
    for (size_t i = 0; i < n; ++i) {
      double p0 = val(k0, i), p1 = val(k, i);
      double m0 = dt * c.values[k0 * stride + 2 * n + i];  // out-tangent of k0
      double m1 = dt * c.values[k * stride + i];           // in-tangent of k
      v[i] = (2 * s3 - 3 * s2 + 1) * p0 + (s3 - 2 * s2 + s) * m0 + (-2 * s3 + 3 * s2) * p1 +
             (s3 - s2) * m1;
    }
  } else if (c.path == 1) {  // slerp
    double a[4], b[4], d = 0;
    for (size_t i = 0; i < 4; ++i) a[i] = val(k0, i), b[i] = val(k, i), d += a[i] * b[i];
    if (d < 0) {
      d = -d;
      for (double& x : b) x = -x;
    }
    double wa = 1 - s, wb = s;
    if (d < 0.9995) {
      double th = std::acos(std::min(d, 1.0)), sn = std::sin(th);
      wa = std::sin((1 - s) * th) / sn;
      wb = std::sin(s * th) / sn;
    }
    for (size_t i = 0; i < 4; ++i) v[i] = wa * a[i] + wb * b[i];
  } else {
    for (size_t i = 0; i < n; ++i) v[i] = val(k0, i) + (val(k, i) - val(k0, i)) * s;
  }
}

}  // namespace gltf_reader
}  // namespace vislib
