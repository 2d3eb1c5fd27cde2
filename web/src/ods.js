// ods.js: the page's ODS mode (`mode=ods`): a top-bottom stereo equirectangular pair (left eye
// above the right) centred at the eye, from the PVS of the cells covering the viewing disc (as
// `pvs view --ods` takes them), rendered by ods_gpu.js on WebGPU, shown whole (`odsview=pano`) or
// as a look-around view (`odsview=look`: the two eyes side by side, sampled from the pair along
// the view direction; drag to look, WASD moves the centre and re-renders the pair; `display=2d`:
// the whole pair through a read-back into a 2D canvas).
//
// URL parameters (docs/web.md): odssize=W (width; height W/2 an eye; default 2048), ipd=M
// (metres, default 0.064), upm=S (scene units per metre, default 1), polemerge=s,e,x[:s,e,x] (Eq.
// 6, degrees from the pole: as pvs view --pole-merge), tess=dynamic|K (K = 1: none), reps=N
// (each frame rendered N more times; the record's ms is their median), plus scene, pvs, at,
// path, overlay=0 as in the walking mode.
import {objectColour} from "./glb.js";
import {parsePath, vec3} from "./path.js";
import {loadScene} from "./scene_load.js";
import {ALG1_PAPER, OdsGpu, odsDevice} from "./ods_gpu.js";

// pvs view's --pole-merge syntax: "s,e,x" for both poles or "s,e,x:s,e,x" top:bottom.
export function parsePoleMerge(text) {
  if (!text) return null;
  const sides = text.split(":").map((t) => {
    const v = t.split(",").map(Number);
    if (v.length !== 3 || v.some((x) => !Number.isFinite(x)) || !(v[1] >= 0 && v[1] <= v[0] && v[0] <= 90 && v[2] > 0))
      throw new Error(`polemerge=${text}: s,e,x[:s,e,x] with 0 <= e <= s <= 90, x > 0`);
    return {start: v[0], end: v[1], exponent: v[2]};
  });
  if (sides.length > 2) throw new Error(`polemerge=${text}: at most two sides (top:bottom)`);
  return {top: sides[0], bottom: sides[sides.length - 1]};
}

// Each triangle's albedo packed r | g << 8 | b << 16 (vislib::object_colour of its object).
export function triangleColours(scene) {
  const T = scene.triangleObject.length, out = new Uint32Array(T), cache = new Map();
  for (let t = 0; t < T; ++t) {
    const o = scene.triangleObject[t];
    let c = cache.get(o);
    if (c === undefined) {
      const [r, g, b] = objectColour(o);
      c = r | (g << 8) | (b << 16);
      cache.set(o, c);
    }
    out[t] = c;
  }
  return out;
}

// Shows the pair on the page's canvas: whole, or the look-around view.
const BLIT = /* wgsl */ `
struct View { yaw: f32, pitch: f32, tanHalf: f32, look: f32, aspect: f32, pad0: f32, pad1: f32, pad2: f32 };
@group(0) @binding(0) var pano: texture_2d<f32>;
@group(0) @binding(1) var<uniform> V: View;
struct O { @builtin(position) p: vec4f, @location(0) uv: vec2f };
@vertex fn vs(@builtin(vertex_index) i: u32) -> O {
  let xy = vec2f(f32((i << 1u) & 2u), f32(i & 2u)) * 2.0 - 1.0;
  return O(vec4f(xy, 0.0, 1.0), vec2f(0.5 * xy.x + 0.5, 0.5 - 0.5 * xy.y));
}
@fragment fn fs(o: O) -> @location(0) vec4f {
  let size = vec2f(textureDimensions(pano));
  if (V.look == 0.0) {
    return textureLoad(pano, vec2i(min(o.uv * size, size - 1.0)), 0);
  }
  // Side by side: the left half shows the left eye (top of the pair), the right half the right.
  let eye = select(0.0, 1.0, o.uv.x >= 0.5);
  let sx = (fract(o.uv.x * 2.0) * 2.0 - 1.0) * V.tanHalf * V.aspect;
  let sy = (1.0 - 2.0 * o.uv.y) * V.tanHalf;
  let cy = cos(V.yaw); let syw = sin(V.yaw); let cp = cos(V.pitch); let sp = sin(V.pitch);
  let f = vec3f(syw * cp, sp, -cy * cp);
  let r = vec3f(cy, 0.0, syw);
  let u = cross(r, f);
  let d = normalize(f + sx * r + sy * u);
  let lon = -atan2(d.x, d.z);
  let lat = asin(clamp(d.y, -1.0, 1.0));
  let px = (lon + 3.14159265) / (2.0 * 3.14159265) * size.x;
  let py = (0.5 * 3.14159265 - lat) / 3.14159265 * 0.5 * size.y + eye * 0.5 * size.y;
  return textureLoad(pano, vec2i(clamp(vec2f(px, py), vec2f(0.0), size - 1.0)), 0);
}`;

export class OdsViewer {
  constructor(params, overlay, canvas) {
    this.params = params;
    this.overlayEl = overlay;
    this.canvas = canvas;
  }

  async init() {
    const params = this.params;
    if (params.get("overlay") === "0")
      for (const id of ["overlay", "map", "help"]) document.getElementById(id).style.display = "none";
    document.getElementById("map").style.display = "none";
    const gpu = await odsDevice();
    if (!gpu.device) throw new Error(`ODS needs WebGPU: ${gpu.why}`);
    this.device = gpu.device;
    this.adapter = gpu.adapter;
    this.gpuAdapter = gpu.gpuAdapter;
    this.device.lost.then((i) => console.error(`WebGPU device lost: ${i.message} (${i.reason})`));
    this.device.onuncapturederror = (e) => console.error(`WebGPU: ${e.error.message}`);
    this.width = Number(params.get("odssize") || 2048);
    const upm = Number(params.get("upm") || 1), ipdM = Number(params.get("ipd") || 0.064);
    if (!(ipdM >= 0 && upm > 0)) throw new Error("ipd=M >= 0 and upm=S > 0");
    const tess = params.get("tess") || "dynamic";
    this.settings = {ipd: ipdM * upm, merge: parsePoleMerge(params.get("polemerge")),
                     tessellation: tess === "dynamic" ? 0 : Number(tess),
                     alg1: {...ALG1_PAPER, segment: Number(params.get("tessdeg") || ALG1_PAPER.segment)}};
    if (!(this.settings.alg1.segment > 0)) throw new Error("tessdeg=DEG > 0");
    this.tessName = tess;
    this.reps = Number(params.get("reps") || 0);
    Object.assign(this, await loadScene(params));
    this.ods = new OdsGpu(this.device, this.scene, triangleColours(this.scene), this.width);
    this.path = params.get("path") ? parsePath(params.get("path")) : null;
    this.centre = params.get("at") ? vec3(params.get("at")) : this.path ? this.path[0].eye : [0, 1.6, 0];
    this.look = params.get("odsview") === "look";
    this.yaw = 0;
    this.pitch = 0;
    // display=2d: the pair shown through a read-back (presenting a WebGPU canvas loses the device
    // in headless chromium's SwiftShader; web-check.sh uses this).
    this.display2d = params.get("display") === "2d";
    this.initDisplay();
    return this;
  }

  initDisplay() {
    const d = this.device;
    // A canvas of its own, sized to the page's before its context is made.
    const c = document.createElement("canvas");
    c.id = "view";
    c.style.cssText = this.canvas.style.cssText;
    const size = this.params.get("size");
    if (size) {
      const [w, h] = size.split("x").map(Number);
      c.style.width = `${w}px`;
      c.style.height = `${h}px`;
    }
    this.canvas.replaceWith(c);
    this.canvas = c;
    c.width = c.clientWidth || 640;
    c.height = c.clientHeight || 400;
    if (this.display2d) return;
    this.context = c.getContext("webgpu");
    this.format = navigator.gpu.getPreferredCanvasFormat();
    this.context.configure({device: d, format: this.format, alphaMode: "opaque"});
    const m = d.createShaderModule({code: BLIT});
    this.blit = d.createRenderPipeline({layout: "auto", vertex: {module: m, entryPoint: "vs"},
      fragment: {module: m, entryPoint: "fs", targets: [{format: this.format}]}});
    this.viewBuf = d.createBuffer({size: 32, usage: GPUBufferUsage.UNIFORM | GPUBufferUsage.COPY_DST});
    this.blitBind = d.createBindGroup({layout: this.blit.getBindGroupLayout(0), entries: [
      {binding: 0, resource: this.ods.target.createView()}, {binding: 1, resource: {buffer: this.viewBuf}}]});
  }

  async show() {
    const d = this.device;
    if (this.display2d) {  // the whole pair, through a read-back into a 2D canvas
      const px = await this.ods.readPixels();
      const img = new OffscreenCanvas(this.width, this.width);
      img.getContext("2d").putImageData(new ImageData(px, this.width, this.width), 0, 0);
      const ctx = this.canvas.getContext("2d"), s = Math.min(this.canvas.width, this.canvas.height) / this.width;
      ctx.drawImage(img, 0, 0, this.width * s, this.width * s);
      return;
    }
    const fov = Number(this.params.get("fov") || 90) * Math.PI / 180;
    d.queue.writeBuffer(this.viewBuf, 0, new Float32Array(
      [this.yaw, this.pitch, Math.tan(fov / 2), this.look ? 1 : 0, 0.5 * this.canvas.width / this.canvas.height, 0, 0, 0]));
    const enc = d.createCommandEncoder();
    const pass = enc.beginRenderPass({colorAttachments: [{view: this.context.getCurrentTexture().createView(),
      loadOp: "clear", storeOp: "store", clearValue: {r: 0, g: 0, b: 0, a: 1}}]});
    pass.setPipeline(this.blit);
    pass.setBindGroup(0, this.blitBind);
    pass.draw(3);
    pass.end();
    d.queue.submit([enc.finish()]);
  }

  // The pair centred at `centre`: the disc's cells and their union (fetched once per centre
  // change), then the GPU pipeline; with reps > 0 rendered that many more times, ms the median.
  async renderAt(centre) {
    const key = centre.join(",");
    if (key !== this.discKey) {
      const r = await this.client.disc(centre, this.settings.ipd / 2);
      this.disc = r;
      this.discKey = key;
      this.ods.setTriangles(r.ids);
    }
    let r = await this.ods.render(centre, this.settings);
    const times = [];
    for (let k = 0; k < this.reps; ++k) {
      r = await this.ods.render(centre, this.settings);
      times.push(r.ms);
    }
    times.sort((a, b) => a - b);
    const ms = times.length ? times[Math.floor(times.length / 2)] : r.ms;
    await this.show();
    const rec = {mode: "ods", centre, cell: this.disc.cell, cells_used: this.disc.cells,
                 disc_in_cell_view_region: this.disc.inRegion, triangles_drawn: this.disc.ids.length,
                 triangles_total: this.total, small_triangle_slots: r.slots,
                 inside_circle: r.inside_circle, ms, ms_reps: times, tessellation: this.tessName,
                 tess_segment_deg: this.settings.alg1.segment,
                 ods_size: [this.width, this.width / 2], ipd: this.settings.ipd,
                 bytes_fetched: this.disc.bytes, range_requests: this.disc.requests, adapter: this.adapter};
    this.showOverlay(rec);
    return rec;
  }

  showOverlay(rec) {
    this.overlayEl.innerHTML =
      `ODS ${rec.ods_size[0]} x ${rec.ods_size[1]} an eye (left above right), IPD ${rec.ipd}, tessellation ${rec.tessellation}\n` +
      (rec.cell < 0 ? `<span class="outside">centre outside every cell: nothing drawn</span>\n`
                    : `cells ${rec.cells_used.join(", ")}${rec.disc_in_cell_view_region ? "" : " (the disc leaves the cell)"}\n`) +
      `triangles ${rec.triangles_drawn} / ${rec.triangles_total}, ${rec.small_triangle_slots} output slots\n` +
      `${rec.ms.toFixed(1)} ms a pair (GPU submit to completion; ${this.adapter})`;
  }

  async step(i) {
    const rec = await this.renderAt(this.path[i].eye);
    rec.frame = i;
    return rec;
  }

  // The last pair as a PNG data URL (W x W, top-bottom), for the headless check.
  async framePng() {
    const px = await this.ods.readPixels();
    const c = document.createElement("canvas");
    c.width = c.height = this.width;
    c.getContext("2d").putImageData(new ImageData(px, this.width, this.width), 0, 0);
    return c.toDataURL("image/png");
  }

  startWalking() {
    const keys = new Set();
    addEventListener("keydown", (e) => keys.add(e.key.toLowerCase()));
    addEventListener("keyup", (e) => keys.delete(e.key.toLowerCase()));
    let dragging = false;
    this.canvas.addEventListener("mousedown", () => (dragging = true));
    addEventListener("mouseup", () => (dragging = false));
    addEventListener("mousemove", (e) => {
      if (!dragging) return;
      this.yaw += e.movementX * 0.004;
      this.pitch = Math.max(-1.5, Math.min(1.5, this.pitch - e.movementY * 0.004));
    });
    let busy = false;
    const loop = async () => {
      const step = keys.has("shift") ? 0.5 : 0.1;
      const fwd = [Math.sin(this.yaw), 0, -Math.cos(this.yaw)], right = [Math.cos(this.yaw), 0, Math.sin(this.yaw)];
      const c = this.centre.slice();
      if (keys.has("w")) for (let k = 0; k < 3; ++k) c[k] += step * fwd[k];
      if (keys.has("s")) for (let k = 0; k < 3; ++k) c[k] -= step * fwd[k];
      if (keys.has("d")) for (let k = 0; k < 3; ++k) c[k] += step * right[k];
      if (keys.has("a")) for (let k = 0; k < 3; ++k) c[k] -= step * right[k];
      if (!busy && (c.join() !== this.centre.join() || !this.rendered)) {
        busy = true;
        this.centre = c;
        await this.renderAt(c);
        this.rendered = true;
        busy = false;
      } else if (!this.display2d) {
        this.show();
      }
      requestAnimationFrame(loop);
    };
    requestAnimationFrame(loop);
  }
}
