// stereo.js: the page's single-render stereo mode (`mode=stereo`), on WebGL2: the dominant eye is
// rendered from the PVS of the cells holding the eyes, every one of its pixels is reprojected to
// the other eye, and the holes are patched (the YORO paper, ../shared/papers/yoro-single-render-
// stereo.txt, with the corrections of vislib/render/stereo.h, which `pvs view --stereo yoro` runs
// on the CPU):
//  - eyes: at -+ IPD/2 along the view's right vector, parallel, the same symmetric frustum
//    (stereo_pair without toe-in or shift); vertical field of view `fov` (default 90, as pvs
//    view), near plane 0.01 (kDefaultNear);
//  - reprojection (reproject_exact's splatting): each source sample goes to the target pixel whose
//    centre is nearest, the nearest view depth wins (a z-buffer), nothing is written into a hole,
//    so a background sample landing in a gap is kept (holes not poisoned); `reproject=mesh`
//    (default; parallel eyes) warps the source as a grid of cells and gathers exactly only around
//    the edges between surfaces (MESH_VS), `gather` (parallel eyes) gathers every pixel
//    (GATHER_FS), `points` splats one point per source pixel, its world point from the depth
//    buffer through the inverse view-projection (a background pixel is a direction), projected
//    with the full perspective divide into the other eye (any pair of cameras);
//  - patchers (`patch=`): `yoro` (patch_yoro: Alg. 3 with Eq. 6 fixed: the kernel starts at the
//    hole run's farther filled end and walks away from the hole, nearest column first, 3 rows,
//    skipping foreground samples nearer than the edge by more than 5%; weights rem (1/2 + 0.3 t),
//    t = |u - e| / run width, stopped once the weight left is below 2^-10 (the columns after it
//    move no channel by a quarter step); runs longer than kMaxRun or with no filled end are left
//    to `median`'s rule: the nearest filled pixel of the row), `render` (the holes only, drawn from the
//    target eye under a stencil of the filled pixels: the GPU counterpart of `rays`, which re-casts
//    only the hole pixels), `none` (holes stay black).
// Per frame (window.viewer.step(i)) the page also renders both eyes (two renders) and both eyes in
// one OVR_multiview2 pass, and times the three, each `reps` times (the record's ms_* are medians),
// the passes of single-render stereo alone (one render, reprojection, patch) and a full-screen copy
// (the least a pass writing every target pixel costs), and measures the produced eye against the
// true render of that eye: PSNR, pixels off by more than 8 steps, hole pixels before patching.
//
// URL parameters: size=WxH (an eye), fov, ipd (metres, default 0.064), upm, dominant=left|right
// (default left), patch=yoro|render|none (default yoro), reproject=mesh|gather|points (default
// mesh), reps=N, plus scene, pvs, path (points
// EYE@LOOK: EYE is the point between the eyes) and overlay=0.
import {parsePath, vec3} from "./path.js";
import {loadScene, diagonal} from "./scene_load.js";
import {triangleColours} from "./ods.js";

const NEAR = 0.01;  // kDefaultNear
const MAX_RUN = 256;  // kMaxRun: hole runs the yoro patcher walks (pixels)
const BACKGROUND = [150, 170, 195];

const SCENE_VS = `#version 300 es
#ifdef MULTIVIEW
#extension GL_OVR_multiview2 : require
layout(num_views = 2) in;
uniform mat4 viewProjs[2];
uniform vec3 eyes[2];
#else
uniform mat4 viewProj;
uniform vec3 eye;
#endif
in vec3 position; in vec3 normal; in vec3 colour;
out vec3 vV; flat out vec3 vN; flat out vec3 vC;
void main() {
#ifdef MULTIVIEW
  mat4 m = viewProjs[gl_ViewID_OVR]; vec3 e = eyes[gl_ViewID_OVR];
#else
  mat4 m = viewProj; vec3 e = eye;
#endif
  vV = position - e; vN = normal; vC = colour;
  gl_Position = m * vec4(position, 1.0);
}`;
// The CPU renderer's shading (shade_triangle, render.h): albedo * (0.35 + 0.65 min(max(|n . v|,
// 0.6 |n_y|), 1)), v from the eye (kRenderAmbient, kRenderSky).
const SCENE_FS = `#version 300 es
precision highp float;
in vec3 vV; flat in vec3 vN; flat in vec3 vC;
out vec4 o;
void main() {
  float nl = length(vN), vl = length(vV);
  float l = nl > 0.0 && vl > 0.0 ? abs(dot(vN, vV)) / (nl * vl) : 0.0;
  float sky = nl > 0.0 ? 0.6 * abs(vN.y) / nl : 0.0;
  o = vec4(vC * (0.35 + 0.65 * min(max(l, sky), 1.0)), 1.0);
}`;
// One point per source pixel, to the other eye.
const SPLAT_VS = `#version 300 es
precision highp float;
uniform highp sampler2D srcColour, srcDepth;
uniform mat4 srcInverse, dstViewProj;
uniform vec3 srcEye;
uniform int width;
flat out vec4 vC;
void main() {
  ivec2 p = ivec2(gl_VertexID % width, gl_VertexID / width);
  ivec2 size = textureSize(srcDepth, 0);
  float z = texelFetch(srcDepth, p, 0).r;
  vC = texelFetch(srcColour, p, 0);
  vec2 ndc = (vec2(p) + 0.5) / vec2(size) * 2.0 - 1.0;
  gl_PointSize = 1.0;
  if (z >= 1.0) {  // background: a direction, which parallel eyes see at the same place
    vec4 f = srcInverse * vec4(ndc, 1.0, 1.0);
    vec4 c = dstViewProj * vec4(f.xyz / f.w - srcEye, 0.0);
    gl_Position = vec4(c.xy / c.w, 1.0, 1.0);
    return;
  }
  vec4 w = srcInverse * vec4(ndc, 2.0 * z - 1.0, 1.0);
  gl_Position = dstViewProj * vec4(w.xyz / w.w, 1.0);
}`;
const SPLAT_FS = `#version 300 es
precision highp float;
flat in vec4 vC;
out vec4 o;
void main() { o = vec4(vC.rgb, 1.0); }`;
// The same splatting as a gather, for parallel eyes with one projection (the eyes here): a source
// pixel of view depth z moves by d = D / z pixels along the row (D = f_px * IPD), towards -x in
// the right eye; target pixel xt takes, of the source pixels xs = xt + s k (k = 0..R) whose
// landing point xs + 1/2 - s d lies in it, the one of largest disparity (the nearest: as the
// z-buffer of the points), k between the smallest and the largest disparity of the source blocks
// it can come from (BLOCK_FS, at most MAX_DISPARITY pixels: nearer surfaces are lost to the
// holes); a row of a level view through a horizontal floor has one depth, so k spans little.
const BLOCK = 64, MAX_DISPARITY = 255;
const DEPTH_GLSL = `
uniform float near, far, D;
float viewDepth(highp sampler2D depth, ivec2 p) {
  float z = texelFetch(depth, p, 0).r;
  if (z >= 1.0) return 1e30;
  float n = 2.0 * z - 1.0;
  return 2.0 * near * far / (far + near - n * (far - near));
}`;
const BLOCK_FS = `#version 300 es
precision highp float;
uniform highp sampler2D srcDepth;
${DEPTH_GLSL}
out vec4 o;
void main() {
  ivec2 b = ivec2(gl_FragCoord.xy);
  int w = textureSize(srcDepth, 0).x;
  float m = 0.0, l = 1e30;
  for (int x = b.x * ${BLOCK}; x < min(w, (b.x + 1) * ${BLOCK}); ++x) {
    float d = D / viewDepth(srcDepth, ivec2(x, b.y));
    m = max(m, d);
    l = min(l, d);
  }
  o = vec4(min(ceil(m) + 1.0, ${MAX_DISPARITY}.0) / 255.0, max(floor(l) - 1.0, 0.0) / 255.0, 0.0, 1.0);
}`;
const GATHER_FS = `#version 300 es
precision highp float;
uniform highp sampler2D srcColour, srcDepth, blocks;
uniform float side;  // +1: the target is right of the source, -1: left
${DEPTH_GLSL}
out vec4 o;
void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  int w = textureSize(srcDepth, 0).x;
  int s = int(side);
  int lo = s > 0 ? p.x : max(0, p.x - ${MAX_DISPARITY});
  int hi = s > 0 ? min(w - 1, p.x + ${MAX_DISPARITY}) : p.x;
  // Per source block, the pixels whose offset |xs - xt| lies within the block's disparity
  // bounds (the pre-pass's, widened by one): only they can land in pixel xt.
  float best = -1.0;
  int bx = -1;
  for (int b = lo / ${BLOCK}; b <= hi / ${BLOCK}; ++b) {
    vec2 m = texelFetch(blocks, ivec2(b, p.y), 0).rg * 255.0;
    int kmax = int(round(m.r)), kmin = int(round(m.g));
    int b0 = b * ${BLOCK}, b1 = min(w, b0 + ${BLOCK}) - 1;
    int x0 = s > 0 ? max(b0, p.x + kmin) : max(b0, p.x - kmax);
    int x1 = s > 0 ? min(b1, p.x + kmax) : min(b1, p.x - kmin);
    for (int xs = x0; xs <= x1; ++xs) {
      float d = D / viewDepth(srcDepth, ivec2(xs, p.y));
      if (d > best && int(floor(float(xs) + 0.5 - side * d)) == p.x) { best = d; bx = xs; }
    }
  }
  if (bx >= 0) {  // the largest disparity landing here: the nearest sample
    o = vec4(texelFetch(srcColour, ivec2(bx, p.y), 0).rgb, 1.0);
    gl_FragDepth = texelFetch(srcDepth, ivec2(bx, p.y), 0).r;
    return;
  }
  discard;
}`;
// reproject=mesh (parallel eyes, as the gather): the source eye as a grid of CELL x CELL pixel
// cells, vertices at pixel centres (the image's borders at its edges). Where the disparity
// over a cell's (CELL + 1)^2 pixels is the cell's two triangles' linear interpolation of its
// corners' to within MESH_TOLERANCE pixels (a plane is exactly: d = D / z is affine on the
// screen over a plane), the cell is drawn warped to the other eye (each vertex moved by its
// disparity, the colour fetched at the interpolated source position: the splat's pixel to
// within the tolerance, a magnified surface without the splat's cracks); elsewhere (an edge
// between surfaces) the target pixels the cell's samples can reach, [x0 - dmax - 1, x1 - dmin +
// 1] on its rows, are marked (stencil 2) and computed by the exact gather, which sees every
// source sample, warped cells' included. The warped cells draw outside the marks only.
const CELL = 8, MESH_TOLERANCE = 0.25;
const CELL_FS = `#version 300 es
precision highp float;
uniform highp sampler2D srcDepth;
${DEPTH_GLSL}
out vec4 o;
void main() {
  ivec2 c = ivec2(gl_FragCoord.xy), size = textureSize(srcDepth, 0);
  ivec2 p0 = c * ${CELL}, p1 = min(p0 + ${CELL}, size - 1);
  vec2 span = vec2(p1 - p0);
  float d00 = D / viewDepth(srcDepth, p0), d10 = D / viewDepth(srcDepth, ivec2(p1.x, p0.y));
  float d01 = D / viewDepth(srcDepth, ivec2(p0.x, p1.y)), d11 = D / viewDepth(srcDepth, p1);
  float lo = 1e30, hi = 0.0, err = 0.0;
  for (int v = 0; v <= ${CELL}; ++v)
    for (int u = 0; u <= ${CELL}; ++u) {
      ivec2 q = min(p0 + ivec2(u, v), p1);
      float d = D / viewDepth(srcDepth, q);
      vec2 t = vec2(q - p0) / max(span, vec2(1.0));
      float pred = t.x >= t.y ? d00 + (d10 - d00) * t.x + (d11 - d10) * t.y
                              : d00 + (d01 - d00) * t.y + (d11 - d01) * t.x;
      err = max(err, abs(d - pred));
      lo = min(lo, d);
      hi = max(hi, d);
    }
  o = vec4(err <= ${MESH_TOLERANCE} ? 1.0 : 0.0, max(floor(lo) - 1.0, 0.0) / 255.0,
           min(ceil(hi) + 1.0, 255.0) / 255.0, 1.0);
}`;
// Six vertices a cell (its two triangles); `marks` 1: the marks of the cells that are not
// drawn warped, 0: the warped cells. A cell of the other kind goes outside the clip volume.
const MESH_VS = `#version 300 es
precision highp float;
uniform highp sampler2D srcDepth, cells;
uniform float side;
uniform int marks;
${DEPTH_GLSL}
out vec2 vSrc;
float edge(int i, int n) {  // a vertex's position along an axis of n pixels (grid index i)
  int p = min(i * ${CELL}, n - 1);
  return i == 0 ? 0.0 : p == n - 1 ? float(n) : float(p) + 0.5;
}
void main() {
  int id = gl_VertexID / 6, k = gl_VertexID % 6;
  ivec2 size = textureSize(srcDepth, 0), n = textureSize(cells, 0);
  ivec2 c = ivec2(id % n.x, id / n.x);
  ivec2 q = ivec2(k == 1 || k == 2 || k == 4 ? 1 : 0, k == 2 || k == 4 || k == 5 ? 1 : 0);
  vec4 f = texelFetch(cells, c, 0);
  if ((f.r > 0.5) == (marks == 1)) { gl_Position = vec4(2.0, 2.0, 2.0, 1.0); return; }
  ivec2 g = c + q;
  vec2 v = vec2(edge(g.x, size.x), edge(g.y, size.y));
  if (marks == 1) {
    float lo = f.g * 255.0, hi = f.b * 255.0;
    float x = q.x == 0 ? edge(c.x, size.x) - 1.0 - (side > 0.0 ? hi : -lo)
                       : edge(c.x + 1, size.x) + 1.0 - (side > 0.0 ? lo : -hi);
    float y = q.y == 0 ? v.y - 0.5 : v.y + 0.5;
    gl_Position = vec4(2.0 * x / float(size.x) - 1.0, 2.0 * y / float(size.y) - 1.0, 0.0, 1.0);
    vSrc = v;
    return;
  }
  ivec2 p = min(g * ${CELL}, size - 1);
  float z = texelFetch(srcDepth, p, 0).r;
  float x = v.x - side * D / viewDepth(srcDepth, p);
  gl_Position = vec4(2.0 * x / float(size.x) - 1.0, 2.0 * v.y / float(size.y) - 1.0, 2.0 * z - 1.0, 1.0);
  vSrc = v;
}`;
const MESH_FS = `#version 300 es
precision highp float;
uniform highp sampler2D srcColour;
in vec2 vSrc;
out vec4 o;
void main() {
  ivec2 size = textureSize(srcColour, 0);
  o = vec4(texelFetch(srcColour, min(ivec2(floor(vSrc)), size - 1), 0).rgb, 1.0);
}`;
// The least a full-screen pass over the target can cost: each pixel one fetch of the source.
const COPY_FS = `#version 300 es
precision highp float;
uniform highp sampler2D img;
out vec4 o;
void main() { o = texelFetch(img, ivec2(gl_FragCoord.xy), 0); }`;
const FILL_FS = `#version 300 es
precision highp float;
uniform vec3 colour;
out vec4 o;
void main() { o = vec4(colour, 1.0); }`;
const QUAD_VS = `#version 300 es
void main() { gl_Position = vec4(float((gl_VertexID << 1) & 2) * 2.0 - 1.0, float(gl_VertexID & 2) * 2.0 - 1.0, 0.0, 1.0); }`;
// patch_yoro on the splat (alpha 0: a hole; depth: the splat's depth buffer, linearised).
const PATCH_FS = `#version 300 es
precision highp float;
uniform highp sampler2D img, depth;
uniform float near, far;
uniform int patchMode;
out vec4 o;
float viewDepth(ivec2 p) {
  float z = texelFetch(depth, p, 0).r;
  if (z >= 1.0) return 1e30;
  float n = 2.0 * z - 1.0;
  return 2.0 * near * far / (far + near - n * (far - near));
}
bool filled(ivec2 p) { return texelFetch(img, p, 0).a > 0.5; }
vec4 patchHole(ivec2 p, ivec2 size) {
  int a = p.x, b = p.x;
  while (a > 0 && p.x - a < ${MAX_RUN} && !filled(ivec2(a - 1, p.y))) a--;
  while (b + 1 < size.x && b - p.x < ${MAX_RUN} && !filled(ivec2(b + 1, p.y))) b++;
  bool hasL = a > 0 && filled(ivec2(a - 1, p.y)), hasR = b + 1 < size.x && filled(ivec2(b + 1, p.y));
  int hw = b - a + 1;
  int e = -1;
  if (hasL && hasR) e = viewDepth(ivec2(b + 1, p.y)) > viewDepth(ivec2(a - 1, p.y)) ? b + 1 : a - 1;
  else if (hasL) e = a - 1;
  else if (hasR) e = b + 1;
  if (e >= 0 && hw <= ${MAX_RUN}) {
    int s = e < a ? -1 : 1;
    float de = viewDepth(ivec2(e, p.y));
    float t = float(abs(p.x - e)) / float(hw);
    vec3 acc = vec3(0.0);
    float rem = 1.0;
    bool any = false;
    for (int k = 0; k < hw; ++k) {
      int col = e + s * k;
      if (col < 0 || col >= size.x) continue;
      vec3 sum = vec3(0.0);
      int kept = 0;
      for (int dy = -1; dy <= 1; ++dy) {
        ivec2 q = ivec2(col, p.y + dy);
        if (q.y < 0 || q.y >= size.y || !filled(q)) continue;
        if (viewDepth(q) * 1.05 < de) continue;  // foreground (kStereoSurfaceDepthRatio)
        sum += texelFetch(img, q, 0).rgb;
        ++kept;
      }
      if (kept == 0) continue;
      float wk = rem * (0.5 + 0.3 * t);
      acc += sum / float(kept) * wk;
      rem -= wk;
      any = true;
      // The columns left weigh at most rem: below 2^-10 they move no channel by a quarter step.
      if (rem < ${1 / 1024}) break;
    }
    if (any) return vec4(acc / (1.0 - rem), 1.0);
  }
  // Left to the nearest filled pixel of the row.
  for (int k = 1; k < ${4 * MAX_RUN}; ++k) {
    if (p.x - k >= 0 && filled(ivec2(p.x - k, p.y))) return vec4(texelFetch(img, ivec2(p.x - k, p.y), 0).rgb, 1.0);
    if (p.x + k < size.x && filled(ivec2(p.x + k, p.y))) return vec4(texelFetch(img, ivec2(p.x + k, p.y), 0).rgb, 1.0);
  }
  return vec4(0.0, 0.0, 0.0, 1.0);
}
void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  ivec2 size = textureSize(img, 0);
  vec4 c = texelFetch(img, p, 0);
  o = vec4(c.rgb, 1.0);
  // A hole's work inside a loop: SwiftShader runs a branch's code for the whole group of lanes
  // (a 2 x 2 quad) with the others masked, but leaves a loop as soon as no lane is in it, so the
  // filled pixels (99%) pay one test.
  for (int k = c.a > 0.5 || patchMode == 0 ? 1 : 0; k < 1; ++k) o = patchHole(p, size);
}`;

function compile(gl, vs, fs, defines = "") {
  const sh = (type, src) => {
    const s = gl.createShader(type);
    gl.shaderSource(s, defines ? src.replace("#version 300 es\n", `#version 300 es\n${defines}\n`) : src);
    gl.compileShader(s);
    if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(`shader: ${gl.getShaderInfoLog(s)}`);
    return s;
  };
  const p = gl.createProgram();
  gl.attachShader(p, sh(gl.VERTEX_SHADER, vs));
  gl.attachShader(p, sh(gl.FRAGMENT_SHADER, fs));
  gl.bindAttribLocation(p, 0, "position");
  gl.bindAttribLocation(p, 1, "normal");
  gl.bindAttribLocation(p, 2, "colour");
  gl.linkProgram(p);
  if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(`program: ${gl.getProgramInfoLog(p)}`);
  const u = {};
  for (let i = 0; i < gl.getProgramParameter(p, gl.ACTIVE_UNIFORMS); ++i) {
    const name = gl.getActiveUniform(p, i).name.replace(/\[0\]$/, "");
    u[name] = gl.getUniformLocation(p, name);
  }
  return {p, u};
}

// Column-major 4x4 helpers.
function mul(a, b) {
  const o = new Float32Array(16);
  for (let c = 0; c < 4; ++c)
    for (let r = 0; r < 4; ++r) {
      let s = 0;
      for (let k = 0; k < 4; ++k) s += a[4 * k + r] * b[4 * c + k];
      o[4 * c + r] = s;
    }
  return o;
}
function invert(m) {
  const a = Array.from(m), inv = new Array(16).fill(0);
  for (let i = 0; i < 4; ++i) inv[5 * i] = 1;
  for (let c = 0; c < 4; ++c) {  // Gauss-Jordan on columns (m is column-major: a[4 c + r])
    let piv = c;
    for (let r = c + 1; r < 4; ++r) if (Math.abs(a[4 * c + r]) > Math.abs(a[4 * c + piv])) piv = r;
    for (let k = 0; k < 4; ++k) {
      [a[4 * k + c], a[4 * k + piv]] = [a[4 * k + piv], a[4 * k + c]];
      [inv[4 * k + c], inv[4 * k + piv]] = [inv[4 * k + piv], inv[4 * k + c]];
    }
    const d = a[4 * c + c];
    for (let k = 0; k < 4; ++k) { a[4 * k + c] /= d; inv[4 * k + c] /= d; }
    for (let r = 0; r < 4; ++r) {
      if (r === c) continue;
      const f = a[4 * c + r];
      for (let k = 0; k < 4; ++k) { a[4 * k + r] -= f * a[4 * k + c]; inv[4 * k + r] -= f * inv[4 * k + c]; }
    }
  }
  return new Float32Array(inv);
}
const sub3 = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const cross3 = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const norm3 = (a) => { const l = Math.hypot(...a); return a.map((v) => v / l); };
const dot3 = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];

// The camera of render.h: forward f, right r = f x up, up u = r x f; vertical fov; symmetric.
function camera(eye, f, vfovDeg, aspect, far) {
  const r = norm3(cross3(f, [0, 1, 0])), u = cross3(r, f);
  const view = new Float32Array([r[0], u[0], -f[0], 0, r[1], u[1], -f[1], 0, r[2], u[2], -f[2], 0,
                                 -dot3(r, eye), -dot3(u, eye), dot3(f, eye), 1]);
  const t = 1 / Math.tan((vfovDeg * Math.PI) / 360);
  const proj = new Float32Array([t / aspect, 0, 0, 0, 0, t, 0, 0, 0, 0, -(far + NEAR) / (far - NEAR), -1,
                                 0, 0, (-2 * far * NEAR) / (far - NEAR), 0]);
  return {eye, r, viewProj: mul(proj, view)};
}

export class StereoViewer {
  constructor(params, overlay, canvas) {
    this.params = params;
    this.overlayEl = overlay;
    this.canvas = canvas;
  }

  async init() {
    const params = this.params;
    for (const id of params.get("overlay") === "0" ? ["overlay", "map", "help"] : ["map"])
      document.getElementById(id).style.display = "none";
    const [w, h] = (params.get("size") || "640x480").split("x").map(Number);
    this.W = w;
    this.H = h;
    this.fov = Number(params.get("fov") || 90);
    this.ipd = Number(params.get("ipd") || 0.064) * Number(params.get("upm") || 1);
    this.dominant = params.get("dominant") || "left";
    if (!["left", "right"].includes(this.dominant)) throw new Error(`dominant=${this.dominant}: left or right`);
    this.patch = params.get("patch") || "yoro";
    if (!["yoro", "render", "none"].includes(this.patch)) throw new Error(`patch=${this.patch}: yoro, render or none`);
    this.reps = Number(params.get("reps") || 0);
    this.reproject = params.get("reproject") || "mesh";
    if (!["mesh", "gather", "points"].includes(this.reproject)) throw new Error(`reproject=${this.reproject}: mesh, gather or points`);
    Object.assign(this, await loadScene(params));
    this.setup();
    this.path = params.get("path") ? parsePath(params.get("path")) : null;
    return this;
  }

  // The GL side, once this.scene, this.W and this.H are set.
  setup() {
    const w = this.W, h = this.H;
    this.canvas.width = 2 * w;
    this.canvas.height = h;
    this.canvas.style.width = `${2 * w}px`;
    this.canvas.style.height = `${h}px`;
    const gl = this.canvas.getContext("webgl2", {antialias: false, preserveDrawingBuffer: true});
    if (!gl) throw new Error("no WebGL2");
    this.gl = gl;
    this.multiview = gl.getExtension("OVR_multiview2");
    this.initGeometry();
    this.prog = compile(gl, SCENE_VS, SCENE_FS);
    this.mvProg = this.multiview ? compile(gl, SCENE_VS, SCENE_FS, "#define MULTIVIEW 1") : null;
    this.splat = compile(gl, SPLAT_VS, SPLAT_FS);
    this.blockProg = compile(gl, QUAD_VS, BLOCK_FS);
    this.gatherProg = compile(gl, QUAD_VS, GATHER_FS);
    this.blocks = {fb: gl.createFramebuffer(), tex: gl.createTexture()};
    gl.bindTexture(gl.TEXTURE_2D, this.blocks.tex);
    gl.texStorage2D(gl.TEXTURE_2D, 1, gl.RGBA8, Math.ceil(w / BLOCK), h);
    gl.bindFramebuffer(gl.FRAMEBUFFER, this.blocks.fb);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, this.blocks.tex, 0);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    this.cellProg = compile(gl, QUAD_VS, CELL_FS);
    this.meshProg = compile(gl, MESH_VS, MESH_FS);
    this.markGatherProg = compile(gl, MESH_VS, GATHER_FS);
    this.markPatchProg = compile(gl, MESH_VS, PATCH_FS);
    this.cells = {fb: gl.createFramebuffer(), tex: gl.createTexture(),
                  n: [Math.max(1, Math.ceil((w - 1) / CELL)), Math.max(1, Math.ceil((h - 1) / CELL))]};
    gl.bindTexture(gl.TEXTURE_2D, this.cells.tex);
    gl.texStorage2D(gl.TEXTURE_2D, 1, gl.RGBA8, ...this.cells.n);
    gl.bindFramebuffer(gl.FRAMEBUFFER, this.cells.fb);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, this.cells.tex, 0);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    this.patchProg = compile(gl, QUAD_VS, PATCH_FS);
    this.fillProg = compile(gl, QUAD_VS, FILL_FS);
    this.copyProg = compile(gl, QUAD_VS, COPY_FS);
    this.empty = gl.createVertexArray();
    this.targets = {left: this.target(), right: this.target(), splat: this.target(), patched: this.target()};
    if (this.multiview) this.initMultiview();
  }

  initGeometry() {
    const gl = this.gl, s = this.scene, T = this.total, p = s.positions;
    const normals = new Float32Array(9 * T), colours = new Float32Array(9 * T), albedo = triangleColours(s);
    for (let t = 0; t < T; ++t) {
      const o = 9 * t;
      const n = cross3(sub3(p.subarray(o + 3, o + 6), p.subarray(o, o + 3)), sub3(p.subarray(o + 6, o + 9), p.subarray(o, o + 3)));
      const c = [albedo[t] & 255, (albedo[t] >> 8) & 255, (albedo[t] >> 16) & 255].map((v) => v / 255);
      for (let k = 0; k < 3; ++k) { normals.set(n, o + 3 * k); colours.set(c, o + 3 * k); }
    }
    this.far = 4 * diagonal(p) + 10;
    this.vao = gl.createVertexArray();
    gl.bindVertexArray(this.vao);
    [p, normals, colours].forEach((data, i) => {
      const b = gl.createBuffer();
      gl.bindBuffer(gl.ARRAY_BUFFER, b);
      gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW);
      gl.enableVertexAttribArray(i);
      gl.vertexAttribPointer(i, 3, gl.FLOAT, false, 0, 0);
    });
    this.index = gl.createBuffer();
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, this.index);
    gl.bindVertexArray(null);
    this.count = 0;
  }

  setTriangles(ids) {
    const gl = this.gl, idx = new Uint32Array(3 * ids.length);
    for (let i = 0; i < ids.length; ++i) idx.set([3 * ids[i], 3 * ids[i] + 1, 3 * ids[i] + 2], 3 * i);
    gl.bindVertexArray(this.vao);
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, idx, gl.STATIC_DRAW);
    gl.bindVertexArray(null);
    this.count = idx.length;
  }

  // A W x H target: RGBA8 colour and a sampled depth-stencil texture.
  target() {
    const gl = this.gl, t = {fb: gl.createFramebuffer(), colour: gl.createTexture(), depth: gl.createTexture()};
    gl.bindTexture(gl.TEXTURE_2D, t.colour);
    gl.texStorage2D(gl.TEXTURE_2D, 1, gl.RGBA8, this.W, this.H);
    gl.bindTexture(gl.TEXTURE_2D, t.depth);
    gl.texStorage2D(gl.TEXTURE_2D, 1, gl.DEPTH32F_STENCIL8, this.W, this.H);
    for (const tex of [t.colour, t.depth]) {
      gl.bindTexture(gl.TEXTURE_2D, tex);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
    }
    gl.bindFramebuffer(gl.FRAMEBUFFER, t.fb);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, t.colour, 0);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.DEPTH_STENCIL_ATTACHMENT, gl.TEXTURE_2D, t.depth, 0);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    return t;
  }

  initMultiview() {
    const gl = this.gl, mv = this.multiview;
    this.mv = {fb: gl.createFramebuffer(), colour: gl.createTexture(), depth: gl.createTexture()};
    gl.bindTexture(gl.TEXTURE_2D_ARRAY, this.mv.colour);
    gl.texStorage3D(gl.TEXTURE_2D_ARRAY, 1, gl.RGBA8, this.W, this.H, 2);
    gl.bindTexture(gl.TEXTURE_2D_ARRAY, this.mv.depth);
    gl.texStorage3D(gl.TEXTURE_2D_ARRAY, 1, gl.DEPTH_COMPONENT32F, this.W, this.H, 2);
    gl.bindFramebuffer(gl.DRAW_FRAMEBUFFER, this.mv.fb);
    mv.framebufferTextureMultiviewOVR(gl.DRAW_FRAMEBUFFER, gl.COLOR_ATTACHMENT0, this.mv.colour, 0, 0, 2);
    mv.framebufferTextureMultiviewOVR(gl.DRAW_FRAMEBUFFER, gl.DEPTH_ATTACHMENT, this.mv.depth, 0, 0, 2);
    gl.bindFramebuffer(gl.DRAW_FRAMEBUFFER, null);
  }

  clear(t, colour = BACKGROUND.map((c) => c / 255).concat([1])) {
    const gl = this.gl;
    gl.bindFramebuffer(gl.FRAMEBUFFER, t.fb);
    gl.viewport(0, 0, this.W, this.H);
    gl.clearColor(...colour);
    gl.clearDepth(1);
    gl.clearStencil(0);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT | gl.STENCIL_BUFFER_BIT);
  }

  // Draws the set from camera c into target t (cleared first unless `holesOnly`: then only where
  // the stencil is not 1, the splat's holes).
  renderEye(t, c, holesOnly = false) {
    const gl = this.gl, P = this.prog;
    if (!holesOnly) this.clear(t);
    else gl.bindFramebuffer(gl.FRAMEBUFFER, t.fb);
    gl.enable(gl.DEPTH_TEST);
    gl.depthFunc(gl.LEQUAL);
    if (holesOnly) {
      gl.enable(gl.STENCIL_TEST);
      gl.stencilFunc(gl.NOTEQUAL, 1, 0xff);
      gl.stencilOp(gl.KEEP, gl.KEEP, gl.KEEP);
    }
    gl.useProgram(P.p);
    gl.uniformMatrix4fv(P.u.viewProj, false, c.viewProj);
    gl.uniform3fv(P.u.eye, c.eye);
    gl.bindVertexArray(this.vao);
    gl.drawElements(gl.TRIANGLES, this.count, gl.UNSIGNED_INT, 0);
    gl.bindVertexArray(null);
    gl.disable(gl.STENCIL_TEST);
  }

  renderMultiview(cams) {
    const gl = this.gl, P = this.mvProg;
    gl.bindFramebuffer(gl.DRAW_FRAMEBUFFER, this.mv.fb);
    gl.viewport(0, 0, this.W, this.H);
    gl.clearColor(...BACKGROUND.map((c) => c / 255), 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.enable(gl.DEPTH_TEST);
    gl.depthFunc(gl.LEQUAL);
    gl.useProgram(P.p);
    gl.uniformMatrix4fv(P.u.viewProjs, false, new Float32Array([...cams[0].viewProj, ...cams[1].viewProj]));
    gl.uniform3fv(P.u.eyes, new Float32Array([...cams[0].eye, ...cams[1].eye]));
    gl.bindVertexArray(this.vao);
    gl.drawElements(gl.TRIANGLES, this.count, gl.UNSIGNED_INT, 0);
    gl.bindVertexArray(null);
    gl.bindFramebuffer(gl.DRAW_FRAMEBUFFER, null);
  }

  // Single-render stereo: the dominant eye rendered, reprojected to the other, patched.
  single(src, dst, cs, cd) {
    this.renderEye(src, cs);
    this.reprojectEye(src, cs, cd);
    return this.patchSplat(dst, cd);
  }

  // The source eye (rendered into src from cs) reprojected to cd: into this.targets.splat.
  reprojectEye(src, cs, cd) {
    const gl = this.gl;
    // The splat: colour, alpha 1 where written, the splat's depth, stencil 1 where written.
    this.clear(this.targets.splat, [0, 0, 0, 0]);
    gl.enable(gl.DEPTH_TEST);
    gl.depthFunc(gl.LEQUAL);
    gl.enable(gl.STENCIL_TEST);
    gl.stencilFunc(gl.ALWAYS, 1, 0xff);
    gl.stencilOp(gl.KEEP, gl.KEEP, gl.REPLACE);
    gl.activeTexture(gl.TEXTURE0);
    gl.bindTexture(gl.TEXTURE_2D, src.colour);
    gl.activeTexture(gl.TEXTURE1);
    gl.bindTexture(gl.TEXTURE_2D, src.depth);
    gl.bindVertexArray(this.empty);
    if (this.reproject === "points") {
      const S = this.splat;
      gl.useProgram(S.p);
      gl.uniform1i(S.u.srcColour, 0);
      gl.uniform1i(S.u.srcDepth, 1);
      gl.uniformMatrix4fv(S.u.srcInverse, false, invert(cs.viewProj));
      gl.uniformMatrix4fv(S.u.dstViewProj, false, cd.viewProj);
      gl.uniform3fv(S.u.srcEye, cs.eye);
      gl.uniform1i(S.u.width, this.W);
      gl.drawArrays(gl.POINTS, 0, this.W * this.H);
    } else {
      const D = (this.H / 2) / Math.tan((this.fov * Math.PI) / 360) * this.ipd;
      const set = (P) => {
        gl.useProgram(P.p);
        gl.uniform1i(P.u.srcDepth, 1);
        gl.uniform1f(P.u.near, NEAR);
        gl.uniform1f(P.u.far, this.far);
        gl.uniform1f(P.u.D, D);
      };
      const side = dot3(sub3(cd.eye, cs.eye), cs.r) > 0 ? 1 : -1;
      this.side = side;
      this.D = D;
      const mesh = this.reproject === "mesh";
      gl.disable(gl.STENCIL_TEST);
      gl.disable(gl.DEPTH_TEST);
      gl.bindFramebuffer(gl.FRAMEBUFFER, this.blocks.fb);
      gl.viewport(0, 0, Math.ceil(this.W / BLOCK), this.H);
      set(this.blockProg);
      gl.drawArrays(gl.TRIANGLES, 0, 3);
      if (mesh) {
        gl.bindFramebuffer(gl.FRAMEBUFFER, this.cells.fb);
        gl.viewport(0, 0, ...this.cells.n);
        set(this.cellProg);
        gl.drawArrays(gl.TRIANGLES, 0, 3);
      }
      gl.bindFramebuffer(gl.FRAMEBUFFER, this.targets.splat.fb);
      gl.viewport(0, 0, this.W, this.H);
      gl.enable(gl.STENCIL_TEST);
      if (mesh) {
        const M = this.meshProg, n = 6 * this.cells.n[0] * this.cells.n[1];
        set(M);
        gl.activeTexture(gl.TEXTURE3);
        gl.bindTexture(gl.TEXTURE_2D, this.cells.tex);
        gl.uniform1i(M.u.srcColour, 0);
        gl.uniform1i(M.u.cells, 3);
        gl.uniform1f(M.u.side, side);
        // The marks (stencil 2, nothing else written), then the warped cells outside them.
        gl.colorMask(false, false, false, false);
        gl.stencilFunc(gl.ALWAYS, 2, 0xff);
        gl.uniform1i(M.u.marks, 1);
        gl.drawArrays(gl.TRIANGLES, 0, n);
        gl.colorMask(true, true, true, true);
        gl.enable(gl.DEPTH_TEST);
        gl.depthFunc(gl.LEQUAL);
        gl.stencilFunc(gl.EQUAL, 1, 0x02);  // passes where unmarked, writes 1
        gl.uniform1i(M.u.marks, 0);
        gl.drawArrays(gl.TRIANGLES, 0, n);
        gl.stencilFunc(gl.NOTEQUAL, 1, 0x02);  // the gather where marked, writes 1
      }
      // The gather: full-screen, or over the marks only (a fragment shader writing its depth is
      // not stencil-tested before it runs).
      const G = mesh ? this.markGatherProg : this.gatherProg;
      gl.enable(gl.DEPTH_TEST);
      gl.depthFunc(gl.ALWAYS);
      set(G);
      gl.activeTexture(gl.TEXTURE2);
      gl.bindTexture(gl.TEXTURE_2D, this.blocks.tex);
      gl.uniform1i(G.u.srcColour, 0);
      gl.uniform1i(G.u.blocks, 2);
      gl.uniform1f(G.u.side, side);
      if (mesh) {
        gl.uniform1i(G.u.cells, 3);
        gl.uniform1i(G.u.marks, 1);
        gl.drawArrays(gl.TRIANGLES, 0, 6 * this.cells.n[0] * this.cells.n[1]);
      } else {
        gl.drawArrays(gl.TRIANGLES, 0, 3);
      }
      gl.depthFunc(gl.LEQUAL);
    }
    gl.disable(gl.STENCIL_TEST);
  }

  // The splat's holes patched (this.patch): returns the target holding the produced eye.
  patchSplat(dst, cd) {
    const gl = this.gl;
    if (this.patch === "render") {
      // The holes: the background colour, then the set drawn from the target eye, where the
      // stencil is not 1 only.
      gl.bindFramebuffer(gl.FRAMEBUFFER, this.targets.splat.fb);
      gl.viewport(0, 0, this.W, this.H);
      gl.enable(gl.STENCIL_TEST);
      gl.stencilFunc(gl.NOTEQUAL, 1, 0xff);
      gl.stencilOp(gl.KEEP, gl.KEEP, gl.KEEP);
      gl.disable(gl.DEPTH_TEST);
      gl.useProgram(this.fillProg.p);
      gl.uniform3fv(this.fillProg.u.colour, BACKGROUND.map((c) => c / 255));
      gl.drawArrays(gl.TRIANGLES, 0, 3);
      this.renderEye(this.targets.splat, cd, true);
      return this.targets.splat;
    }
    // With the mesh, holes lie only in the marks (the warped cells and the marks tile the target
    // between the row's outermost landings) and in the strip of the image's side the content
    // moves away from: the splat is copied and the patcher runs there only.
    const marks = this.reproject === "mesh" && this.patch === "yoro";
    gl.bindFramebuffer(gl.FRAMEBUFFER, dst.fb);
    gl.viewport(0, 0, this.W, this.H);
    gl.disable(gl.DEPTH_TEST);
    gl.disable(gl.STENCIL_TEST);
    if (marks) this.copyPass(this.targets.splat, dst);
    const Q = marks ? this.markPatchProg : this.patchProg;
    gl.useProgram(Q.p);
    gl.activeTexture(gl.TEXTURE0);
    gl.bindTexture(gl.TEXTURE_2D, this.targets.splat.colour);
    gl.activeTexture(gl.TEXTURE1);
    gl.bindTexture(gl.TEXTURE_2D, this.targets.splat.depth);
    gl.uniform1i(Q.u.img, 0);
    gl.uniform1i(Q.u.depth, 1);
    gl.uniform1f(Q.u.near, NEAR);
    gl.uniform1f(Q.u.far, this.far);
    gl.uniform1i(Q.u.patchMode, this.patch === "none" ? 0 : 1);
    gl.bindVertexArray(this.empty);
    if (!marks) {
      gl.drawArrays(gl.TRIANGLES, 0, 3);
      return dst;
    }
    gl.activeTexture(gl.TEXTURE3);
    gl.bindTexture(gl.TEXTURE_2D, this.cells.tex);
    gl.uniform1i(Q.u.srcDepth, 1);
    gl.uniform1i(Q.u.cells, 3);
    gl.uniform1f(Q.u.side, this.side);
    gl.uniform1i(Q.u.marks, 1);
    gl.uniform1f(Q.u.D, this.D);
    gl.drawArrays(gl.TRIANGLES, 0, 6 * this.cells.n[0] * this.cells.n[1]);
    const strip = Math.min(this.W, MAX_DISPARITY + 2);
    gl.useProgram(this.patchProg.p);
    for (const [k, v] of [["img", 0], ["depth", 1], ["patchMode", 1]]) gl.uniform1i(this.patchProg.u[k], v);
    gl.uniform1f(this.patchProg.u.near, NEAR);
    gl.uniform1f(this.patchProg.u.far, this.far);
    gl.enable(gl.SCISSOR_TEST);
    gl.scissor(this.side > 0 ? this.W - strip : 0, 0, strip, this.H);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
    gl.disable(gl.SCISSOR_TEST);
    return dst;
  }

  copyPass(src, dst) {
    const gl = this.gl, P = this.copyProg;
    gl.bindFramebuffer(gl.FRAMEBUFFER, dst.fb);
    gl.viewport(0, 0, this.W, this.H);
    gl.disable(gl.DEPTH_TEST);
    gl.disable(gl.STENCIL_TEST);
    gl.useProgram(P.p);
    gl.activeTexture(gl.TEXTURE0);
    gl.bindTexture(gl.TEXTURE_2D, src.colour);
    gl.uniform1i(P.u.img, 0);
    gl.bindVertexArray(this.empty);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
  }

  // Waits for the GPU (a one-pixel read) and returns the ms since t0.
  sync(t0) {
    const gl = this.gl;
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));
    return performance.now() - t0;
  }

  read(t) {
    const gl = this.gl, px = new Uint8Array(4 * this.W * this.H);
    gl.bindFramebuffer(gl.FRAMEBUFFER, t.fb);
    gl.readPixels(0, 0, this.W, this.H, gl.RGBA, gl.UNSIGNED_BYTE, px);
    const out = new Uint8ClampedArray(px.length), row = 4 * this.W;
    for (let y = 0; y < this.H; ++y) out.set(px.subarray((this.H - 1 - y) * row, (this.H - y) * row), y * row);
    return out;
  }

  async step(i) {
    const f = this.path[i];
    const mid = f.eye, look = f.look || [mid[0] + 1, mid[1], mid[2]];
    const fwd = norm3(sub3(look, mid));
    const r = norm3(cross3(fwd, [0, 1, 0]));
    const eyes = [mid.map((v, k) => v - r[k] * this.ipd / 2), mid.map((v, k) => v + r[k] * this.ipd / 2)];
    const aspect = this.W / this.H;
    const cams = eyes.map((e) => camera(e, fwd, this.fov, aspect, this.far));
    // The cells holding the eyes, their union drawn.
    const cells = [], union = new Set();
    for (const e of eyes) {
      const q = await this.client.lookup(e, -1);
      if (q.cell < 0) throw new Error(`eye ${e} is in no cell`);
      if (!cells.includes(q.cell)) cells.push(q.cell);
      for (const t of q.ids) union.add(t);
    }
    this.setTriangles(Uint32Array.from(union).sort());
    const d = this.dominant === "left" ? 0 : 1, o = 1 - d;
    const T = this.targets, src = d === 0 ? T.left : T.right;
    const timed = (fn) => {
      fn();
      this.sync(performance.now());  // warm-up
      const ms = [];
      for (let k = 0; k < Math.max(1, this.reps); ++k) {
        const t0 = performance.now();
        fn();
        ms.push(this.sync(t0));
      }
      ms.sort((a, b) => a - b);
      return ms[Math.floor(ms.length / 2)];
    };
    const msTwo = timed(() => { this.renderEye(T.left, cams[0]); this.renderEye(T.right, cams[1]); });
    const truth = [this.read(T.left), this.read(T.right)];
    const msMultiview = this.multiview ? timed(() => this.renderMultiview(cams)) : null;
    // The parts: one render, and render + reprojection without patching.
    const msOne = timed(() => this.renderEye(src, cams[d]));
    const patchMode = this.patch;
    this.patch = "none";
    const msNoPatch = timed(() => this.single(src, T.patched, cams[d], cams[o]));
    this.patch = patchMode;
    // The passes alone, on the source eye just rendered: reprojection, patching, and a full-screen
    // copy of the source (the least any pass writing every target pixel costs).
    this.renderEye(src, cams[d]);
    const msReproject = timed(() => this.reprojectEye(src, cams[d], cams[o]));
    const msPatch = timed(() => this.patchSplat(T.patched, cams[o]));
    const msCopy = timed(() => this.copyPass(src, T.patched));
    let produced;
    const msSingle = timed(() => { produced = this.single(src, T.patched, cams[d], cams[o]); });
    const other = this.read(produced);
    const patch = this.patch;
    this.patch = "none";  // the holes before patching (the render patcher fills the splat)
    this.single(src, T.patched, cams[d], cams[o]);
    const splat = this.read(T.splat);
    this.patch = patch;
    this.single(src, T.patched, cams[d], cams[o]);
    let holes = 0;
    for (let k = 3; k < splat.length; k += 4) holes += splat[k] === 0 ? 1 : 0;
    this.pair = d === 0 ? [this.read(src), other] : [other, this.read(src)];
    this.truth = truth;
    const q = compareImages(other, truth[o]);
    const rec = {mode: "stereo", frame: i, ms: msSingle, eyes, cells, triangles_drawn: union.size, triangles_total: this.total,
                 size: [this.W, this.H], ipd: this.ipd, dominant: this.dominant, patch: this.patch,
                 hole_pixels: holes, hole_share: holes / (this.W * this.H),
                 psnr: q.psnr, off_by_8_share: q.offShare,
                 ms_single: msSingle, ms_one_render: msOne, ms_unpatched: msNoPatch,
                 ms_reproject: msReproject, ms_patch: msPatch, ms_copy_pass: msCopy, ms_two_renders: msTwo, ms_multiview: msMultiview,
                 ratio_single_to_two: msSingle / msTwo,
                 ratio_single_to_multiview: msMultiview ? msSingle / msMultiview : null,
                 reps: Math.max(1, this.reps), multiview: !!this.multiview};
    this.show();
    this.overlayEl.innerHTML =
      `single-render stereo ${this.W} x ${this.H} an eye, ${this.dominant} eye rendered, patch ${this.patch}\n` +
      `cells ${cells.join(", ")}: ${union.size} / ${this.total} triangles\n` +
      `holes ${(100 * rec.hole_share).toFixed(2)}%, PSNR ${q.psnr.toFixed(2)} dB against the true eye\n` +
      `ms: single ${msSingle.toFixed(1)}, two renders ${msTwo.toFixed(1)}` +
      (msMultiview ? `, multiview ${msMultiview.toFixed(1)}` : "");
    return rec;
  }

  // The produced pair, left | right, on the canvas.
  show() {
    const gl = this.gl;
    gl.bindFramebuffer(gl.DRAW_FRAMEBUFFER, null);
    const d = this.dominant === "left" ? 0 : 1;
    const srcs = d === 0 ? [this.targets.left, this.patch === "render" ? this.targets.splat : this.targets.patched]
                         : [this.patch === "render" ? this.targets.splat : this.targets.patched, this.targets.right];
    srcs.forEach((t, k) => {
      gl.bindFramebuffer(gl.READ_FRAMEBUFFER, t.fb);
      gl.blitFramebuffer(0, 0, this.W, this.H, k * this.W, 0, (k + 1) * this.W, this.H, gl.COLOR_BUFFER_BIT, gl.NEAREST);
    });
    gl.bindFramebuffer(gl.READ_FRAMEBUFFER, null);
  }

  // PNG of the frame: top row the produced pair (left | right), bottom row the two true renders.
  async framePng() {
    const W = this.W, H = this.H, c = document.createElement("canvas");
    c.width = 2 * W;
    c.height = 2 * H;
    const ctx = c.getContext("2d");
    [this.pair[0], this.pair[1], this.truth[0], this.truth[1]].forEach((px, k) =>
      ctx.putImageData(new ImageData(px, W, H), (k % 2) * W, Math.floor(k / 2) * H));
    return c.toDataURL("image/png");
  }

  startWalking() {
    const at = this.params.get("at") ? vec3(this.params.get("at")) : [0, 1.6, 0];
    const look = this.params.get("look") ? vec3(this.params.get("look")) : [at[0] + 1, at[1], at[2]];
    this.path = [{eye: at, look}];
    this.step(0);
  }
}

// PSNR over RGB and the share of pixels off by more than 8 steps in a channel.
export function compareImages(a, b) {
  let se = 0, off = 0;
  const n = a.length / 4;
  for (let p = 0; p < a.length; p += 4) {
    let m = 0;
    for (let k = 0; k < 3; ++k) {
      const d = a[p + k] - b[p + k];
      se += d * d;
      m = Math.max(m, Math.abs(d));
    }
    if (m > 8) ++off;
  }
  const mse = se / (3 * n);
  return {psnr: mse > 0 ? 10 * Math.log10((255 * 255) / mse) : Infinity, offShare: off / n};
}
