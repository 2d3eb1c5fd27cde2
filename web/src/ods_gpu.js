// ods_gpu.js: omnidirectional stereo (ODS) panoramas on WebGPU, the paper's pipeline
// (../shared/papers/omnidirectional-stereo.txt, Marrinan & Papka) with the corrections of
// runtime/ods.h, as `pvs view --ods --ods-method raster-exact` does it on the CPU:
//
//  1. levels (compute, one thread per triangle): Alg. 1 from the mono projection (from the centre
//     C) of the triangle's vertices and opposite-edge midpoints (edge_outer_level: lonDist and
//     half the latitude span, d = max(|edge| / 8, 1), the pole multiplier max(2.8284/90 max|lat|,
//     1), at most 64), Eq. 4's inner level max(m - 2, min(m, 3)), each rounded up; or a static
//     level K for every edge (K = 1: none). The triangle gets n = max(levels) segments a side (n^2
//     small triangles) and, if the vertical axis through C crosses it (axis_crossing), the pole
//     flag.
//  2. scan (compute, one workgroup): the output slots of each triangle (2 per small triangle, 12
//     when the pole flag is set), exclusive prefix sums, and the indirect draw's vertex count.
//  3. emit (compute, one workgroup per triangle, per eye): each small triangle of the grid with
//     its boundary points snapped to the edge's own outer level (tessellate_triangle: crack-free
//     from both sides of a shared edge), every vertex projected exactly from the eye's point on
//     the viewing circle (ods_project_exact: lon = lon_c - s asin(h / r_h), lat = atan2(dy,
//     sqrt(r_h^2 - h^2)), h = IPD/2 times Eq. 6's pole-merge factor at the solved latitude, by
//     fixed-point iteration), then split at the seam (split_seam_pole: unwrapped from the first
//     vertex's centre longitude, a copy shifted by 2 pi when it spills past +-pi; the clipper
//     removes the rest) and, for a small triangle the axis crosses, the paper's case 3 strip to
//     the pole row.
//  4. draw (render, per eye into its half of a W x W texture, left eye on top): x = lon / pi,
//     y = lat / (pi / 2), depth = range (linear in the image, the paper's orthographic z =
//     -|v|). The fragment shades as the CPU reference does (shade_triangle): albedo times
//     0.35 + 0.65 max(|n . d|, 0.6 |n_y|), d the direction of the pixel centre's ray
//     (pixel_to_lonlat).
//
// Deviation from runtime/ods.h: a vertex inside the viewing circle (r_h <= h at its latitude; no
// ODS ray reaches it) is placed on the pole row at lon_c - s pi / 2, the limit of the projection
// as r_h falls to h, instead of the CPU raster's bisection to the visibility boundary; such
// vertices are counted (`inside_circle`). Arithmetic is f32 on positions relative to C.

import {diagonal} from "./scene_load.js";

// Alg. 1's constants as the paper gives them (degrees): a segment per 8 degrees of projected edge,
// the pole multiplier max(2.8284 / 90 * |lat|, 1), at most 64 segments an edge.
export const ALG1_PAPER = {segment: 8, poleSlope: 2.8284 / 90, maxLevel: 64};

const WGSL_COMMON = /* wgsl */ `
const PI = 3.14159265358979;
struct Params {
  centre: vec3f, halfIpd: f32,
  top: vec4f,      // pole merging, top: start_deg, end_deg, exponent, 1 if merging
  bottom: vec4f,   // the same for the bottom pole
  count: u32, staticLevel: u32, eye: f32, capacity: u32,
  width: f32, height: f32, rowOffset: f32, maxRange: f32,
  tess: vec4f,     // Alg. 1's constants: target segment (degrees), pole multiplier's slope, max level
};
@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var<storage, read> pos: array<f32>;

fn corner(t: u32, i: u32) -> vec3f {
  let o = 9u * t + 3u * i;
  return vec3f(pos[o], pos[o + 1u], pos[o + 2u]) - P.centre;
}
// wrap_longitude: into (-pi, pi].
fn wrapLon(x: f32) -> f32 {
  var w = x - 2.0 * PI * round(x / (2.0 * PI));
  if (w <= -PI) { w += 2.0 * PI; }
  if (w > PI) { w -= 2.0 * PI; }
  return w;
}
fn lonOf(d: vec3f) -> f32 {
  if (d.x == 0.0 && d.z == 0.0) { return 0.0; }
  return wrapLon(-atan2(d.x, d.z));
}
fn latOf(d: vec3f) -> f32 { return atan2(d.y, length(d.xz)); }
// Eq. 6 (pole_merge_factor): side parameters m = (start_deg, end_deg, exponent, merging).
fn mergeFactor(lat: f32) -> f32 {
  var m = P.bottom;
  if (lat >= 0.0) { m = P.top; }
  if (m.w == 0.0) { return 1.0; }
  let incl = abs(lat) * 180.0 / PI;
  let x = clamp((incl - (90.0 - m.x)) / ((90.0 - m.y) - (90.0 - m.x)), 0.0, 1.0);
  return pow(1.0 - x, m.z);
}
// axis_crossing: does the vertical axis through C (the origin here) cross triangle abc in x-z?
// Returns (w0, w1, w2, crosses).
fn axisCrossing(a: vec3f, b: vec3f, c: vec3f) -> vec4f {
  let total = (b.x - a.x) * (c.z - a.z) - (b.z - a.z) * (c.x - a.x);
  if (total == 0.0) { return vec4f(0.0); }
  let w0 = (b.x * c.z - b.z * c.x) / total;
  let w1 = (c.x * a.z - c.z * a.x) / total;
  let w2 = (a.x * b.z - a.z * b.x) / total;
  if (w0 < 0.0 || w1 < 0.0 || w2 < 0.0) { return vec4f(0.0); }
  return vec4f(w0, w1, w2, 1.0);
}
`;

const WGSL_LEVELS = WGSL_COMMON + /* wgsl */ `
@group(0) @binding(2) var<storage, read> ids: array<u32>;
@group(0) @binding(3) var<storage, read_write> levels: array<vec4u>;
@group(0) @binding(4) var<storage, read_write> slots: array<u32>;

// edge_outer_level (Alg. 1 lines 6-14), in degrees as the paper's constants.
fn edgeLevel(a: vec2f, b: vec2f, mid: vec2f) -> f32 {
  let k = 180.0 / PI;
  let d = abs(a.x - b.x) * k;
  let dlon = min(d, 360.0 - d);
  let dlat = max(abs(a.y - b.y), max(abs(a.y - mid.y), abs(b.y - mid.y))) * k;
  let maxLat = max(abs(a.y), max(abs(b.y), abs(mid.y))) * k;
  let edge = sqrt(dlon * dlon + 0.25 * dlat * dlat);
  let dd = max(edge / P.tess.x, 1.0);
  let pole = max(P.tess.y * maxLat, 1.0);
  return min(pole * dd, P.tess.z);
}
fn ll(d: vec3f) -> vec2f { return vec2f(lonOf(d), latOf(d)); }

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) g: vec3u) {
  let k = g.x;
  if (k >= P.count) { return; }
  let t = ids[k];
  let p0 = corner(t, 0u); let p1 = corner(t, 1u); let p2 = corner(t, 2u);
  var o = vec3u(P.staticLevel);
  var inner = P.staticLevel;
  if (P.staticLevel == 0u) {
    let l0 = ll(p0); let l1 = ll(p1); let l2 = ll(p2);
    let e0 = edgeLevel(l1, l2, ll(0.5 * (p1 + p2)));
    let e1 = edgeLevel(l2, l0, ll(0.5 * (p2 + p0)));
    let e2 = edgeLevel(l0, l1, ll(0.5 * (p0 + p1)));
    let m = max(e0, max(e1, e2));
    o = vec3u(u32(ceil(e0)), u32(ceil(e1)), u32(ceil(e2)));
    inner = u32(ceil(max(m - 2.0, min(m, 3.0))));
  }
  let n = max(max(o.x, o.y), max(o.z, inner));
  let pole = axisCrossing(p0, p1, p2).w > 0.0;
  levels[k] = vec4u(o, n | select(0u, 0x10000u, pole));
  slots[k] = n * n * select(2u, 12u, pole);
}
`;

const SCAN_THREADS = 256;
const WGSL_SCAN = WGSL_COMMON + /* wgsl */ `
@group(0) @binding(4) var<storage, read_write> slots: array<u32>;
@group(0) @binding(5) var<storage, read_write> draw: array<u32>;
var<workgroup> partial: array<u32, ${SCAN_THREADS}>;

@compute @workgroup_size(${SCAN_THREADS})
fn main(@builtin(local_invocation_index) i: u32) {
  let chunk = (P.count + ${SCAN_THREADS - 1}u) / ${SCAN_THREADS}u;
  let k0 = min(P.count, i * chunk);
  let k1 = min(P.count, k0 + chunk);
  var s = 0u;
  for (var k = k0; k < k1; k++) { s += slots[k]; }
  partial[i] = s;
  workgroupBarrier();
  if (i == 0u) {
    var run = 0u;
    for (var j = 0u; j < ${SCAN_THREADS}u; j++) { let c = partial[j]; partial[j] = run; run += c; }
    slots[P.count] = run;
    draw[0] = 3u * min(run, P.capacity);
    draw[1] = 1u; draw[2] = 0u; draw[3] = 0u;
    draw[4] = run;
    draw[5] = 0u;
  }
  workgroupBarrier();
  var run = partial[i];
  for (var k = k0; k < k1; k++) { let c = slots[k]; slots[k] = run; run += c; }
}
`;

const WGSL_EMIT = WGSL_COMMON + /* wgsl */ `
@group(0) @binding(2) var<storage, read> ids: array<u32>;
@group(0) @binding(3) var<storage, read> levels: array<vec4u>;
@group(0) @binding(4) var<storage, read> slots: array<u32>;
@group(0) @binding(5) var<storage, read_write> counters: array<atomic<u32>>;
@group(0) @binding(6) var<storage, read_write> outv: array<vec4f>;

// ods_project_exact for this eye: v = (lon, lat, range, lon_c); inside: within the viewing circle.
struct Proj { v: vec4f, inside: bool };
fn project(d: vec3f) -> Proj {
  let rh = length(d.xz);
  let dy = d.y;
  let lonc = lonOf(d);
  var h = P.halfIpd;
  var lat = 0.0;
  var merging = P.bottom.w;
  if (dy >= 0.0) { merging = P.top.w; }
  if (dy == 0.0) {
    h = P.halfIpd * mergeFactor(0.0);
  } else if (merging == 0.0 || P.halfIpd == 0.0) {
    lat = atan2(dy, sqrt(max(rh * rh - h * h, 0.0)));
  } else {
    lat = atan2(dy, rh);
    for (var k = 0; k < 12; k++) {
      let hh = P.halfIpd * mergeFactor(lat);
      lat = atan2(dy, sqrt(max(rh * rh - hh * hh, 0.0)));
    }
    h = P.halfIpd * mergeFactor(lat);
  }
  if (!(h < rh)) {
    var poleLat = 0.0;
    if (dy != 0.0) { poleLat = sign(dy) * 0.5 * PI; }
    return Proj(vec4f(wrapLon(lonc - P.eye * 0.5 * PI), poleLat, length(d), lonc), true);
  }
  return Proj(vec4f(wrapLon(lonc - P.eye * asin(h / rh)), lat, sqrt(rh * rh - h * h + dy * dy), lonc),
              false);
}
// unwrap_from: b placed relative to a (a's centre longitude, the short way to b's, b's offset).
fn unwrapFrom(a: vec4f, b: vec4f) -> vec4f {
  let ac = a.x - wrapLon(a.x - a.w);
  return vec4f(ac + wrapLon(b.w - a.w) + wrapLon(b.x - b.w), b.yzw);
}
fn put(slot: u32, a: vec4f, b: vec4f, c: vec4f, tri: f32) {
  if (slot >= P.capacity) { return; }
  outv[3u * slot] = vec4f(a.xyz, tri);
  outv[3u * slot + 1u] = vec4f(b.xyz, tri);
  outv[3u * slot + 2u] = vec4f(c.xyz, tri);
}
fn clearSlot(slot: u32) { put(slot, vec4f(0.0), vec4f(0.0), vec4f(0.0), 0.0); }
// split_seam_pole's emit: the triangle, and in slot + 1 its copy shifted by 2 pi if it spills.
fn emit(slot: u32, a: vec4f, b: vec4f, c: vec4f, tri: f32) {
  put(slot, a, b, c, tri);
  let lo = min(a.x, min(b.x, c.x));
  let hi = max(a.x, max(b.x, c.x));
  if (lo < -PI || hi > PI) {
    var s = -2.0 * PI;
    if (lo < -PI) { s = 2.0 * PI; }
    let sh = vec4f(s, 0.0, 0.0, 0.0);
    put(slot + 1u, a + sh, b + sh, c + sh, tri);
  } else {
    clearSlot(slot + 1u);
  }
}
// Grid point (i, j) of an n-segment triangle with edges snapped to their outer levels o
// (tessellate_triangle): barycentric weights of vertices 0, 1, 2.
fn gridPoint(i: u32, j: u32, n: u32, o: vec3u) -> vec3f {
  let nf = f32(n);
  if (i == 0u && j == 0u) { return vec3f(1.0, 0.0, 0.0); }
  if (i == n) { return vec3f(0.0, 1.0, 0.0); }
  if (j == n) { return vec3f(0.0, 0.0, 1.0); }
  if (i + j == n) {  // edge opposite vertex 0: v1 -> v2, parameter w2
    let k = floor(f32(j) * f32(o.x) / nf + 0.5);
    return vec3f(0.0, (f32(o.x) - k) / f32(o.x), k / f32(o.x));
  }
  if (i == 0u) {  // edge opposite vertex 1: v0 -> v2
    let k = floor(f32(j) * f32(o.y) / nf + 0.5);
    return vec3f((f32(o.y) - k) / f32(o.y), 0.0, k / f32(o.y));
  }
  if (j == 0u) {  // edge opposite vertex 2: v0 -> v1
    let k = floor(f32(i) * f32(o.z) / nf + 0.5);
    return vec3f((f32(o.z) - k) / f32(o.z), k / f32(o.z), 0.0);
  }
  return vec3f(f32(n - i - j) / nf, f32(i) / nf, f32(j) / nf);
}

@compute @workgroup_size(64)
fn main(@builtin(workgroup_id) wg: vec3u, @builtin(local_invocation_index) lid: u32) {
  let k = wg.x + 65535u * wg.y;
  if (k >= P.count) { return; }
  let lv = levels[k];
  let n = lv.w & 0xffffu;
  let pole = (lv.w >> 16u) != 0u;
  let per = select(2u, 12u, pole);
  let base = slots[k];
  let t = ids[k];
  let tri = bitcast<f32>(t);
  let p0 = corner(t, 0u); let p1 = corner(t, 1u); let p2 = corner(t, 2u);
  for (var q = lid; q < n * n; q += 64u) {
    // Row j of the grid holds 2 (n - j) - 1 triangles; j (2n - j) come before it.
    var j = u32(max(0.0, floor(f32(n) - sqrt(f32(n * n - q)))));
    while (j > 0u && j * (2u * n - j) > q) { j--; }
    while ((j + 1u) * (2u * n - j - 1u) <= q) { j++; }
    let r = q - j * (2u * n - j);
    var ia: vec2u; var ib: vec2u; var ic: vec2u;
    if (r < n - j) {
      ia = vec2u(r, j); ib = vec2u(r + 1u, j); ic = vec2u(r, j + 1u);
    } else {
      let i = r - (n - j);
      ia = vec2u(i + 1u, j); ib = vec2u(i + 1u, j + 1u); ic = vec2u(i, j + 1u);
    }
    let wa = gridPoint(ia.x, ia.y, n, lv.xyz);
    let wb = gridPoint(ib.x, ib.y, n, lv.xyz);
    let wc = gridPoint(ic.x, ic.y, n, lv.xyz);
    let slot = base + q * per;
    if (all(wa == wb) || all(wb == wc) || all(wa == wc)) {  // collapsed by the snapping
      for (var s = 0u; s < per; s++) { clearSlot(slot + s); }
      continue;
    }
    // Summed in this order so a point on a shared edge is the same from both triangles.
    let a = (wa.x * p0 + wa.y * p1) + wa.z * p2;
    let b = (wb.x * p0 + wb.y * p1) + wb.z * p2;
    let c = (wc.x * p0 + wc.y * p1) + wc.z * p2;
    let pa = project(a); let pb = project(b); let pc = project(c);
    if (pa.inside || pb.inside || pc.inside) { atomicAdd(&counters[5], 1u); }
    var v = array<vec4f, 3>(pa.v, pb.v, pc.v);
    var ax = vec4f(0.0);
    if (pole) { ax = axisCrossing(a, b, c); }
    if (ax.w == 0.0) {
      emit(slot, v[0], unwrapFrom(v[0], v[1]), unwrapFrom(v[0], v[2]), tri);
      for (var s = 2u; s < per; s++) { clearSlot(slot + s); }
      continue;
    }
    // The paper's case 3: for each edge (a, b) the quad a, b, (b.lon, pole), (a.lon, pole).
    let yc = ax.x * a.y + ax.y * b.y + ax.z * c.y;
    let poleLat = select(-0.5 * PI, 0.5 * PI, yc >= 0.0);
    let poleRange = abs(yc);
    for (var e = 0u; e < 3u; e++) {
      let va = v[e];
      let vb = unwrapFrom(va, v[(e + 1u) % 3u]);
      let qa = vec4f(va.x, poleLat, poleRange, va.w);
      let qb = vec4f(vb.x, poleLat, poleRange, vb.w);
      emit(slot + 4u * e, va, vb, qb, tri);
      emit(slot + 4u * e + 2u, va, qb, qa, tri);
    }
  }
}
`;

const WGSL_DRAW = WGSL_COMMON + /* wgsl */ `
@group(0) @binding(2) var<storage, read> colours: array<u32>;
@group(0) @binding(6) var<storage, read> outv: array<vec4f>;
struct VOut { @builtin(position) p: vec4f, @location(0) @interpolate(flat) tri: u32 };

@vertex fn vs(@builtin(vertex_index) i: u32) -> VOut {
  let v = outv[i];
  return VOut(vec4f(v.x / PI, v.y / (0.5 * PI), v.z / P.maxRange, 1.0), bitcast<u32>(v.w));
}
// shade_triangle (vislib/eval/render.cpp): albedo * (0.35 + 0.65 min(max(|n . d|, 0.6 |n_y|), 1)),
// d the pixel centre's direction (kRenderAmbient, kRenderSky).
@fragment fn fs(in: VOut) -> @location(0) vec4f {
  let u = in.p.x;
  let v = in.p.y - P.rowOffset;
  let lon = -PI + 2.0 * PI * u / P.width;
  let lat = 0.5 * PI - PI * v / P.height;
  let d = vec3f(-sin(lon) * cos(lat), sin(lat), cos(lon) * cos(lat));
  let a = corner(in.tri, 0u);
  let n = cross(corner(in.tri, 1u) - a, corner(in.tri, 2u) - a);
  let nl = length(n);
  var lambert = 0.0;
  var sky = 0.0;
  if (nl > 0.0) { lambert = abs(dot(n, d)) / nl; sky = 0.6 * abs(n.y) / nl; }
  let shade = 0.35 + 0.65 * min(max(lambert, sky), 1.0);
  let c = colours[in.tri];
  let albedo = vec3f(f32(c & 255u), f32((c >> 8u) & 255u), f32((c >> 16u) & 255u)) / 255.0;
  return vec4f(albedo * shade, 1.0);
}
`;

export const BACKGROUND = [150, 170, 195];  // kRenderBackground

// WebGPU's device, or null with the reason (the caller reports it).
export async function odsDevice() {
  if (!navigator.gpu) return {device: null, why: "this browser offers no WebGPU (navigator.gpu)"};
  const adapter = await navigator.gpu.requestAdapter();
  if (!adapter) return {device: null, why: "WebGPU offers no adapter"};
  const device = await adapter.requestDevice({
    requiredLimits: {maxStorageBufferBindingSize: adapter.limits.maxStorageBufferBindingSize,
                     maxBufferSize: adapter.limits.maxBufferSize}});
  const info = adapter.info || {};
  // The adapter is returned too: the caller keeps it (Chromium's WebGPU fails map requests with
  // "A valid external Instance reference no longer exists" once the adapter is collected).
  return {device, gpuAdapter: adapter, adapter: `${info.vendor || "?"} ${info.architecture || ""}`.trim()};
}

// Eq. 6 settings per pole: {start, end, exponent} in degrees from the pole (start = end: none).
function sideParams(s) {
  return s && s.start !== s.end ? [s.start, s.end, s.exponent, 1] : [0, 0, 1, 0];
}

export class OdsGpu {
  // scene: parseGlb's (positions: 9 floats a triangle, triangleObject); colours: Uint32Array of
  // each triangle's albedo (r | g << 8 | b << 16); width: the panorama's width (height width/2).
  constructor(device, scene, colours, width) {
    if (width % 2 !== 0) throw new Error(`ODS width ${width}: must be even`);
    this.device = device;
    this.width = width;
    this.height = width / 2;
    const d = device;
    const storage = (data, usage = 0) => {
      const b = d.createBuffer({size: Math.max(16, data.byteLength), usage: GPUBufferUsage.STORAGE | GPUBufferUsage.COPY_DST | usage});
      d.queue.writeBuffer(b, 0, data);
      return b;
    };
    this.pos = storage(scene.positions);
    this.colours = storage(colours);
    this.maxRange = 4 * diagonal(scene.positions) + 1;  // > any range from a centre near the scene
    this.params = [0, 1].map(() => d.createBuffer({size: 96, usage: GPUBufferUsage.UNIFORM | GPUBufferUsage.COPY_DST}));
    this.draw = d.createBuffer({size: 32, usage: GPUBufferUsage.STORAGE | GPUBufferUsage.INDIRECT | GPUBufferUsage.COPY_SRC | GPUBufferUsage.COPY_DST});
    this.drawRead = d.createBuffer({size: 32, usage: GPUBufferUsage.MAP_READ | GPUBufferUsage.COPY_DST});
    const module = (code) => {
      const m = d.createShaderModule({code});
      return m;
    };
    this.levelsPipe = d.createComputePipeline({layout: "auto", compute: {module: module(WGSL_LEVELS), entryPoint: "main"}});
    this.scanPipe = d.createComputePipeline({layout: "auto", compute: {module: module(WGSL_SCAN), entryPoint: "main"}});
    this.emitPipe = d.createComputePipeline({layout: "auto", compute: {module: module(WGSL_EMIT), entryPoint: "main"}});
    const drawModule = module(WGSL_DRAW);
    this.drawPipe = d.createRenderPipeline({
      layout: "auto",
      vertex: {module: drawModule, entryPoint: "vs"},
      fragment: {module: drawModule, entryPoint: "fs", targets: [{format: "rgba8unorm"}]},
      primitive: {topology: "triangle-list", cullMode: "none"},
      depthStencil: {format: "depth32float", depthWriteEnabled: true, depthCompare: "less"},
    });
    this.target = d.createTexture({size: [width, width], format: "rgba8unorm",
      usage: GPUTextureUsage.RENDER_ATTACHMENT | GPUTextureUsage.COPY_SRC | GPUTextureUsage.TEXTURE_BINDING});
    this.depth = d.createTexture({size: [width, width], format: "depth32float", usage: GPUTextureUsage.RENDER_ATTACHMENT});
    this.capacity = 1 << 16;  // output slots (3 vertices each); grows when a frame needs more
    this.count = 0;
  }

  // The triangles to draw (ids into the scene).
  setTriangles(ids) {
    const d = this.device;
    this.count = ids.length;
    this.ids = d.createBuffer({size: Math.max(16, 4 * ids.length), usage: GPUBufferUsage.STORAGE | GPUBufferUsage.COPY_DST});
    d.queue.writeBuffer(this.ids, 0, ids);
    this.levels = d.createBuffer({size: Math.max(16, 16 * ids.length), usage: GPUBufferUsage.STORAGE});
    this.slots = d.createBuffer({size: 4 * (ids.length + 1), usage: GPUBufferUsage.STORAGE});
    this.bind = null;
  }

  ensureOutput() {
    if (this.out && this.out.size >= 48 * this.capacity) return;
    this.out = this.device.createBuffer({size: 48 * this.capacity, usage: GPUBufferUsage.STORAGE});
    this.bind = null;
  }

  bindGroups() {
    if (this.bind) return this.bind;
    const d = this.device;
    const group = (pipe, eye, entries) => d.createBindGroup({
      layout: pipe.getBindGroupLayout(0),
      entries: Object.entries(entries).map(([b, buffer]) => ({binding: Number(b), resource: {buffer}}))
        .concat([{binding: 0, resource: {buffer: this.params[eye]}}]),
    });
    this.bind = {
      levels: group(this.levelsPipe, 0, {1: this.pos, 2: this.ids, 3: this.levels, 4: this.slots}),
      scan: group(this.scanPipe, 0, {4: this.slots, 5: this.draw}),
      emit: [0, 1].map((e) => group(this.emitPipe, e, {1: this.pos, 2: this.ids, 3: this.levels, 4: this.slots, 5: this.draw, 6: this.out})),
      draw: [0, 1].map((e) => group(this.drawPipe, e, {1: this.pos, 2: this.colours, 6: this.out})),
    };
    return this.bind;
  }

  // Renders the pair centred at `centre` (both eyes into this.target, left on top) and waits for
  // the GPU. settings: {ipd (scene units), merge: {top, bottom} or null, tessellation: 0 = dynamic,
  // K = static level K}. Returns {ms (submit to completion), slots, inside_circle}.
  async render(centre, settings) {
    const d = this.device;
    const level = settings.tessellation | 0;
    if (!(level >= 0 && level <= 64)) throw new Error(`tessellation ${settings.tessellation}: 0 (dynamic) or 1..64`);
    const merge = settings.merge || {};
    for (let eye = 0; eye < 2; ++eye) {
      const buf = new ArrayBuffer(96), f = new Float32Array(buf), u = new Uint32Array(buf);
      f.set([centre[0], centre[1], centre[2], settings.ipd / 2], 0);
      f.set(sideParams(merge.top), 4);
      f.set(sideParams(merge.bottom), 8);
      u[12] = this.count; u[13] = level; f[14] = eye === 0 ? -1 : 1; u[15] = this.capacity;
      f.set([this.width, this.height, eye === 0 ? 0 : this.height, this.maxRange], 16);
      const a = settings.alg1 || ALG1_PAPER;
      f.set([a.segment, a.poleSlope, a.maxLevel, 0], 20);
      d.queue.writeBuffer(this.params[eye], 0, buf);
    }
    if (this.count === 0) {
      const t0 = performance.now();
      this.encode();
      await d.queue.onSubmittedWorkDone();
      return {ms: performance.now() - t0, slots: 0, inside_circle: 0};
    }
    for (;;) {
      this.ensureOutput();
      const t0 = performance.now();
      this.encode();
      await d.queue.onSubmittedWorkDone();
      const ms = performance.now() - t0;
      const enc = d.createCommandEncoder();
      enc.copyBufferToBuffer(this.draw, 0, this.drawRead, 0, 32);
      d.queue.submit([enc.finish()]);
      await this.drawRead.mapAsync(GPUMapMode.READ);
      const counts = new Uint32Array(this.drawRead.getMappedRange().slice(0));
      this.drawRead.unmap();
      const slots = counts[4];
      if (slots <= this.capacity) return {ms, slots, inside_circle: counts[5]};
      this.capacity = Math.ceil(slots * 1.25);
      for (let eye = 0; eye < 2; ++eye) d.queue.writeBuffer(this.params[eye], 60, new Uint32Array([this.capacity]));
    }
  }

  // The frame's passes, submitted.
  encode() {
    const d = this.device;
    const b = this.bindGroups();
    const enc = d.createCommandEncoder();
    if (this.count > 0) {
      let pass = enc.beginComputePass();
      pass.setPipeline(this.levelsPipe);
      pass.setBindGroup(0, b.levels);
      pass.dispatchWorkgroups(Math.ceil(this.count / 64));
      pass.setPipeline(this.scanPipe);
      pass.setBindGroup(0, b.scan);
      pass.dispatchWorkgroups(1);
      pass.end();
    }
    const bg = BACKGROUND.map((c) => c / 255);
    for (let eye = 0; eye < 2; ++eye) {
      if (this.count > 0) {
        const pass = enc.beginComputePass();
        pass.setPipeline(this.emitPipe);
        pass.setBindGroup(0, b.emit[eye]);
        pass.dispatchWorkgroups(Math.min(this.count, 65535), Math.ceil(this.count / 65535));
        pass.end();
      }
      const r = enc.beginRenderPass({
        colorAttachments: [{view: this.target.createView(), loadOp: eye === 0 ? "clear" : "load", storeOp: "store",
                            clearValue: {r: bg[0], g: bg[1], b: bg[2], a: 1}}],
        depthStencilAttachment: {view: this.depth.createView(), depthLoadOp: eye === 0 ? "clear" : "load",
                                 depthClearValue: 1, depthStoreOp: "store"},
      });
      r.setViewport(0, eye * this.height, this.width, this.height, 0, 1);
      r.setScissorRect(0, eye * this.height, this.width, this.height);
      if (this.count > 0) {
        r.setPipeline(this.drawPipe);
        r.setBindGroup(0, b.draw[eye]);
        r.drawIndirect(this.draw, 0);
      }
      r.end();
    }
    d.queue.submit([enc.finish()]);
  }

  // The pair's pixels, RGBA, W x W rows top-down (left eye in rows 0..H-1).
  async readPixels() {
    const d = this.device, W = this.width;
    const row = Math.ceil((4 * W) / 256) * 256;
    const buf = d.createBuffer({size: row * W, usage: GPUBufferUsage.MAP_READ | GPUBufferUsage.COPY_DST});
    const enc = d.createCommandEncoder();
    enc.copyTextureToBuffer({texture: this.target}, {buffer: buf, bytesPerRow: row}, [W, W]);
    d.queue.submit([enc.finish()]);
    await buf.mapAsync(GPUMapMode.READ);
    const src = new Uint8Array(buf.getMappedRange());
    const out = new Uint8ClampedArray(4 * W * W);
    for (let y = 0; y < W; ++y) out.set(src.subarray(y * row, y * row + 4 * W), 4 * W * y);
    buf.unmap();
    buf.destroy();
    return out;
  }
}
