// main.js: the web client. Opens a scene (GLB from `pvs export SCENE -o scene.glb`: triangles in
// vislib's id order) and a PVS (read by range requests through the runtime in WebAssembly), and
// per frame asks the runtime for the eye's cell and draws only that cell's visible triangles.
//
// URL parameters: scene=URL (GLB), pvs=URL, at=x,y,z and look=x,y,z (start), fov=degrees
// (vertical, default 60), prefetch=MARGIN (on entering a cell, fetch the blocks of its neighbours
// within MARGIN scene units; off by default, so that only visited cells are fetched), overlay=0
// (the frame alone, to compare with the CPU renderer's), path="x,y,z[@lx,ly,lz];..." (replay: window.viewer.step(i) renders
// frame i; without @ a frame looks towards the next point), size=WxH (fixed canvas size),
// nearfar=r1,r2 with centre=x,y,z or centres=URL (JSON), envsize=N, lookup=eye|cylinder and
// clovr=1, shading=materials|reference (docs/web.md); mode=ods|stereo (ods.js, stereo.js). Key H
// hides and shows the overlays.
//
// Outside every cell the last cell's set stays drawn (before any cell was entered: the whole
// scene), and the overlay says so in red.
//
// Shading (shading=...): `reference` is the CPU reference renderer's (vislib/eval/render.h),
// which the frame comparisons use: albedo = the object's colour from a hash of its id
// (vislib::object_colour, glb.js), shade = 0.35 + 0.65 max(|n.v|, 0.6 |n.y|) with n the geometric
// normal of the triangle and v the direction from the eye to the point (two-sided headlight,
// light from above), background RGB (150, 170, 195); no colour management, no tone mapping.
// `materials` (the default) draws the scene's own glTF materials, base colour factor times base
// colour texture (sRGB-decoded), times the same shade in linear light, encoded to sRGB; a
// triangle without a material gets its object's colour. The CPU renderer samples pixel centres
// by ray casting and rounds albedo and result to 8 bits; WebGL rasterises the same triangles
// with the same camera, so frames agree up to rasterisation on triangle edges and one 8-bit step.
import * as THREE from "three";
import {parseGlb, objectColour} from "./glb.js";
import {drawTriangles, loadTextures} from "./materials.js";
import {parsePath, vec3} from "./path.js";
import {PvsClient} from "./pvs_client.js";
import {OdsViewer} from "./ods.js";
import {StereoViewer} from "./stereo.js";

const params = new URLSearchParams(location.search);
const overlay = document.getElementById("overlay");
const mapCanvas = document.getElementById("map");
const canvas = document.getElementById("view");
const SHADINGS = ["materials", "reference"];

// Vertex displacement by `mode` (the GPU counterparts of runtime/near_far.h, which the worker's
// partition and scheduler use through the C API):
//   0: none.
//   1: near-far Eq. 1 (near-far paper §4.1, morph_vertex, a = r2 - r): a vertex at axis distance
//      r from the centre O is kept (r <= r1), sent to U + |OP| d_O (r >= r2: where O's
//      environment map shows it) or, in between, to U + t d with d = normalize(w d_U + (1 - w)
//      d_O), t = w |UP| + (1 - w) |OP|, w = (r2 - r) / (r2 - r1).
//   2: Eq. 2 for dynamic far vertices (displace_far): Q = U + P - O.
//   3: CloVR's injection (Alg. 1, inject_vertex) with R = r2 and R_n = r1: a vertex at r >= R_n
//      moves to where the ray from U along normalize(w d_U + (1 - w) d_O), w = clamp((R - r) /
//      (R - R_n), 0, 1), leaves the cylinder of radius r.
const VERTEX = `
in vec3 position; in vec3 normal; in vec3 colour; in vec2 uv;
uniform mat4 projectionMatrix, viewMatrix;
uniform vec3 eye, centre;
uniform float r1, r2;
uniform int mode;
out vec3 vWorld; out vec3 vNormal; out vec3 vColour; out vec2 vUv;
vec3 morph(vec3 p) {
  float r = length(p.xz - centre.xz);
  if (r <= r1) return p;
  vec3 up = p - eye, op = p - centre;
  if (r >= r2) return eye + length(op) * normalize(op);
  float w = (r2 - r) / (r2 - r1);
  vec3 d = normalize(w * normalize(up) + (1.0 - w) * normalize(op));
  return eye + (w * length(up) + (1.0 - w) * length(op)) * d;
}
vec3 inject(vec3 p) {
  float r = length(p.xz - centre.xz);
  if (r < r1) return p;
  float w = clamp((r2 - r) / (r2 - r1), 0.0, 1.0);
  vec3 d = normalize(w * normalize(p - eye) + (1.0 - w) * normalize(p - centre));
  vec2 u = eye.xz - centre.xz;
  float a = dot(d.xz, d.xz), b = 2.0 * dot(u, d.xz), c = dot(u, u) - r * r;
  if (!(a > 0.0)) return p;
  return eye + d * ((-b + sqrt(max(0.0, b * b - 4.0 * a * c))) / (2.0 * a));
}
void main() {
  vWorld = mode == 1 ? morph(position) : mode == 2 ? eye + position - centre
         : mode == 3 ? inject(position) : position;
  vNormal = normal; vColour = colour; vUv = uv;
  gl_Position = projectionMatrix * viewMatrix * vec4(vWorld, 1.0);
}`;
// Shading; with rangeTest (dynamic far fragments, near-far Eq. 3, passes_range_test) a fragment
// at displaced position q survives iff |q - U| <= r_O (1 + kRangeRelativeTolerance), r_O the
// range the cube map from O stores for direction q - U (0: no surface there, infinitely far).
// shade = 0.35 + 0.65 max(|n.v|, 0.6 |n.y|) (kRenderAmbient, kRenderSky); shading 0 (reference):
// colour = vColour (the object's colour) * shade, as the CPU; shading 1 (materials): vColour is
// the linear base colour factor, times the texture where `textured`, times shade, to sRGB.
const FRAGMENT = `precision highp float;
precision highp int;
uniform vec3 eye;
uniform bool rangeTest;
uniform samplerCube rangeMap;
uniform int mode, shading;
uniform bool textured;
uniform sampler2D map;
in vec3 vWorld; in vec3 vNormal; in vec3 vColour; in vec2 vUv;
out vec4 outColour;
vec3 toLinear(vec3 c) { return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), step(0.04045, c)); }
vec3 toSrgb(vec3 c) {
  return mix(c * 12.92, 1.055 * pow(max(c, 0.0), vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
}
void main() {
  vec3 v = vWorld - eye;
  // A morphed triangle is shaded as the CPU shades it: by its displaced corners' plane.
  vec3 n = mode == 1 || mode == 3 ? cross(dFdx(vWorld), dFdy(vWorld)) : vNormal;
  float nl = length(n), vl = length(v);
  if (rangeTest) {
    float rO = texture(rangeMap, v).r;
    if (rO > 0.0 && vl > rO * (1.0 + 1.0e-6)) discard;
  }
  float lambert = nl > 0.0 && vl > 0.0 ? abs(dot(n, v)) / (nl * vl) : 0.0;
  float sky = nl > 0.0 ? 0.6 * abs(n.y) / nl : 0.0;
  float shade = 0.35 + 0.65 * min(max(lambert, sky), 1.0);
  if (shading == 0) {
    outColour = vec4(vColour * shade, 1.0);
    return;
  }
  vec3 albedo = textured ? vColour * toLinear(texture(map, vUv).rgb) : vColour;
  outColour = vec4(toSrgb(min(albedo * shade, 1.0)), 1.0);
}`;
// The environment map's range channel: the distance from O (the cube camera) to the surface.
const RANGE_FRAGMENT = `precision highp float;
uniform vec3 eye;
in vec3 vWorld; in vec3 vNormal; in vec3 vColour;
out vec4 outColour;
void main() { outColour = vec4(length(vWorld - eye), 0.0, 0.0, 1.0); }`;
// The far region: a full-screen pass behind everything that samples the cube map (filtered
// linearly; shading=reference: the nearest texel, as the CPU's cube_pixel) along the eye ray (lookup=eye, the paper) or where the eye ray
// leaves the cylinder of radius r2 about O's axis (lookup=cylinder), as pvs view --lookup.
const BACKGROUND_VERTEX = `
in vec3 position;
out vec2 vNdc;
void main() { vNdc = position.xy; gl_Position = vec4(position.xy, 1.0, 1.0); }`;
const BACKGROUND_FRAGMENT = `precision highp float;
uniform mat4 inverseProjectionView;
uniform vec3 eye, centre;
uniform float r2;
uniform bool cylinder;
uniform samplerCube envMap;
in vec2 vNdc;
out vec4 outColour;
void main() {
  vec4 far = inverseProjectionView * vec4(vNdc, 1.0, 1.0);
  vec3 d = normalize(far.xyz / far.w - eye), look = d;
  if (cylinder) {
    vec2 u = eye.xz - centre.xz;
    float a = dot(d.xz, d.xz), b = 2.0 * dot(u, d.xz), c = dot(u, u) - r2 * r2;
    if (a > 0.0) look = eye + d * ((-b + sqrt(max(0.0, b * b - 4.0 * a * c))) / (2.0 * a)) - centre;
  }
  outColour = vec4(texture(envMap, look).rgb, 1.0);
}`;

// The popping meter's id pass (WebGL2 has no primitive id): the full scene, de-indexed, so the
// vertex id / 3 is the triangle id, written as 24-bit RGB; the background stays 0xFFFFFF.
const ID_VERTEX = `
in vec3 position;
uniform mat4 projectionMatrix, viewMatrix;
flat out int vId;
void main() {
  vId = gl_VertexID / 3;
  gl_Position = projectionMatrix * viewMatrix * vec4(position, 1.0);
}`;
const ID_FRAGMENT = `
precision highp float;
precision highp int;
flat in int vId;
out vec4 outColour;
void main() {
  outColour = vec4(float(vId & 255), float((vId >> 8) & 255), float((vId >> 16) & 255), 255.0) / 255.0;
}`;
const NO_ID = 0xFFFFFF;

async function fetchBytes(url) {
  const r = await fetch(url);
  if (!r.ok) throw new Error(`${url}: HTTP ${r.status}`);
  return r.arrayBuffer();
}

// The sRGB value c in [0, 1] in linear light.
function toLinear(c) {
  return c <= 0.04045 ? c / 12.92 : Math.pow((c + 0.055) / 1.055, 2.4);
}

// The de-indexed scene's attributes: position, normal (the triangle's geometric normal), uv and
// colour: with shading=reference the object's colour as the CPU renders it; with materials the
// triangle's material's base colour factor (linear), or for a triangle without one its object's
// colour in linear light.
function buildGeometry(scene, shading) {
  const T = scene.triangleObject.length;
  const normals = new Float32Array(9 * T);
  const colours = new Float32Array(9 * T);
  const palette = new Map();
  const materials = shading === "materials";
  const objectColourOf = (ob) => objectColour(ob).map((c) => materials ? toLinear(c / 255) : c / 255);
  const p = scene.positions;
  for (let t = 0; t < T; ++t) {
    const o = 9 * t;
    const ax = p[o + 3] - p[o], ay = p[o + 4] - p[o + 1], az = p[o + 5] - p[o + 2];
    const bx = p[o + 6] - p[o], by = p[o + 7] - p[o + 1], bz = p[o + 8] - p[o + 2];
    const n = [ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx];
    const ob = scene.triangleObject[t], m = materials ? scene.triangleMaterial[t] : -1;
    if (m < 0 && !palette.has(ob)) palette.set(ob, objectColourOf(ob));
    const c = m >= 0 ? scene.materials[m].baseColour.slice(0, 3) : palette.get(ob);
    for (let k = 0; k < 3; ++k) {
      normals.set(n, o + 3 * k);
      colours.set(c, o + 3 * k);
    }
  }
  const g = new THREE.BufferGeometry();
  g.setAttribute("position", new THREE.BufferAttribute(scene.positions, 3));
  g.setAttribute("normal", new THREE.BufferAttribute(normals, 3));
  g.setAttribute("colour", new THREE.BufferAttribute(colours, 3));
  g.setAttribute("uv", new THREE.BufferAttribute(scene.uvs, 2));
  g.computeBoundingSphere();
  return g;
}

class Viewer {
  async init() {
    THREE.ColorManagement.enabled = false;
    const sceneUrl = params.get("scene"), pvsUrl = params.get("pvs");
    if (!sceneUrl || !pvsUrl) throw new Error("give ?scene=URL.glb&pvs=URL.pvs");
    this.fov = Number(params.get("fov") || 60);
    this.shading = params.get("shading") || "materials";
    if (!SHADINGS.includes(this.shading)) throw new Error(`shading=${this.shading}: ${SHADINGS.join(" or ")}`);
    // The overlays: off with overlay=0; key H hides and shows them.
    const overlays = ["overlay", "map", "help"].map((id) => document.getElementById(id));
    if (params.get("overlay") === "0") for (const e of overlays) e.style.display = "none";
    addEventListener("keydown", (e) => {
      if (e.key !== "h" && e.key !== "H") return;
      const hidden = overlays[0].style.display === "none";
      for (const o of overlays) o.style.display = hidden ? "" : "none";
    });
    // nearfar=r1,r2: the near-far mode (off by default); envsize=N: the cube map's face size;
    // centre=x,y,z: O for every cell; centres=URL: each cell's O as pvs view chooses it (the JSON
    // of `pvs export --centres`); neither: the centre of the cell's lookup box.
    this.nearFar = params.get("nearfar") ? params.get("nearfar").split(",").map(Number) : null;
    this.envSize = Number(params.get("envsize") || 512);
    // popping=K: the popping meter every K frames (0: off; key P measures once).
    this.poppingEvery = Number(params.get("popping") || 0);
    this.frameCount = 0;
    this.popping = null;
    this.prefetch = params.has("prefetch") ? Number(params.get("prefetch") || 0) : -1;
    const size = params.get("size");
    if (size) {
      const [w, h] = size.split("x").map(Number);
      canvas.style.width = `${w}px`;
      canvas.style.height = `${h}px`;
      canvas.width = w;
      canvas.height = h;
    }
    this.client = new PvsClient();
    const [glb, opened] = await Promise.all([fetchBytes(sceneUrl), this.client.open(pvsUrl)]);
    this.sceneBytes = glb.byteLength;
    this.scene = parseGlb(glb);
    this.pvs = opened;
    this.total = this.scene.triangleObject.length;
    if (opened.info.granularity !== 0)
      throw new Error("this PVS holds object ids; the viewer draws triangle ids");
    if (opened.info.universe !== this.total)
      throw new Error(`the PVS has ${opened.info.universe} triangle ids, the scene ${this.total} triangles: not this scene's PVS`);
    this.bytes = opened.bytes;
    this.requests = opened.requests;

    this.renderer = new THREE.WebGLRenderer({canvas, antialias: false, preserveDrawingBuffer: true});
    this.renderer.outputColorSpace = THREE.LinearSRGBColorSpace;
    this.renderer.setPixelRatio(1);
    this.renderer.setSize(canvas.clientWidth || canvas.width, canvas.clientHeight || canvas.height, false);
    this.renderer.setClearColor(new THREE.Color(150 / 255, 170 / 255, 195 / 255), 1);
    this.textures = this.shading === "materials" ? await loadTextures(this.scene, sceneUrl)
                                                 : {groups: null, errors: []};
    this.geometry = buildGeometry(this.scene, this.shading);
    this.material = new THREE.RawShaderMaterial({
      vertexShader: VERTEX, fragmentShader: FRAGMENT, side: THREE.DoubleSide,
      glslVersion: THREE.GLSL3,
      uniforms: {eye: {value: new THREE.Vector3()}, centre: {value: new THREE.Vector3()},
                 r1: {value: 0}, r2: {value: 1}, mode: {value: 0},
                 rangeTest: {value: false}, rangeMap: {value: null},
                 shading: {value: this.shading === "reference" ? 0 : 1}, textured: {value: false},
                 map: {value: null}},
    });
    this.mesh = new THREE.Mesh(this.geometry, this.withTextures(this.material));
    this.mesh.frustumCulled = false;
    this.world = new THREE.Scene();
    this.world.add(this.mesh);
    const r = this.geometry.boundingSphere.radius;
    const aspect = this.renderer.domElement.width / this.renderer.domElement.height;
    this.camera = new THREE.PerspectiveCamera(this.fov, aspect, 0.05, 4 * r + 10);
    this.cell = -1;  // the cell whose set is drawn (-1: none yet, the whole scene)
    this.found = -1;  // the cell found this frame
    this.path = params.get("path") ? parsePath(params.get("path")) : null;
    const at = params.get("at") ? vec3(params.get("at")) : this.path ? this.path[0].eye : [0, 1.6, 0];
    this.camera.position.set(...at);
    if (params.get("look")) this.camera.lookAt(...vec3(params.get("look")));
    else this.camera.lookAt(at[0] + 1, at[1], at[2]);
    if (this.nearFar) await this.initNearFar();
    this.initPopping();
    this.setDrawList(null);
    this.drawMapBase();
    return this;
  }

  // `base` alone, or with textures one material per draw group (materials.js).
  withTextures(base) {
    return this.textures.groups ? this.textures.groups.materialsFor(base) : base;
  }

  // Draws the triangles `ids` (null: all) of the de-indexed geometry (by texture, materials.js).
  drawIds(geometry, ids) {
    drawTriangles(geometry, ids, this.textures.groups);
  }

  // The draw list of a cell (null: the whole scene). With near-far on, `partition` is the
  // worker's (pvs_rt_partition_near_far): its geometry ids are drawn, its environment ids go to
  // the cube map; with CloVR on, the scheduler's frames replace it (setClovr).
  setDrawList(ids, partition) {
    this.far = 0;
    this.farDynamic = 0;
    this.mask = null;
    if (ids) {
      this.mask = new Uint8Array(this.total);
      for (const t of ids) this.mask[t] = 1;
    }
    if (ids && this.nearFar) ids = this.applyPartition(partition);
    if (ids) {
      this.drawIds(this.geometry, ids);
      this.drawn = ids.length;
    } else {
      this.drawIds(this.geometry, null);
      this.drawn = this.total;
    }
  }

  // Near-far: the environment cube map is rendered from the centre O on entering the cell, colour
  // and range (distance from O, float), from the static triangles with a vertex beyond r2; the
  // main pass draws the near and intermediate triangles (morphed, Eq. 1) over the far region, and
  // the dynamic far ones displaced by Eq. 2 under the range test (Eq. 3). `centre=x,y,z` pins O;
  // otherwise `centres=URL` gives each cell's (pvs view's choice, computed by `pvs export
  // --centres`); else, or for a cell listed as null there, it is the centre of the cell's lookup
  // box. `lookup=eye|cylinder` as pvs view's.
  // `clovr=1`: the near region grows by CloVR's scheduler (pvs_rt_clovr_*) on entering a cell.
  async initNearFar() {
    const [r1, r2] = this.nearFar;
    if (!(r1 >= 0 && r2 > r1)) throw new Error(`nearfar=${this.nearFar}: need 0 <= r1 < r2`);
    this.lookupMode = params.get("lookup") || "eye";
    if (!["eye", "cylinder"].includes(this.lookupMode))
      throw new Error(`lookup=${this.lookupMode}: eye or cylinder`);
    this.clovr = params.get("clovr") === "1";
    // The colour map is filtered linearly (no stair steps on far edges), except with
    // shading=reference, whose frames are compared with pvs view's (nearest texel, cube_pixel);
    // the range map is always read at the nearest texel (ranges do not blend across edges).
    const nearest = {minFilter: THREE.NearestFilter, magFilter: THREE.NearestFilter,
                     generateMipmaps: false};
    const filter = this.shading === "reference" ? THREE.NearestFilter : THREE.LinearFilter;
    this.envTarget = new THREE.WebGLCubeRenderTarget(
      this.envSize, {...nearest, minFilter: filter, magFilter: filter});
    this.rangeTarget = new THREE.WebGLCubeRenderTarget(
      this.envSize, {...nearest, type: THREE.FloatType, format: THREE.RGBAFormat});
    this.cubeCamera = new THREE.CubeCamera(0.05, this.camera.far, this.envTarget);
    this.rangeCamera = new THREE.CubeCamera(0.05, this.camera.far, this.rangeTarget);
    this.envGeometry = new THREE.BufferGeometry();
    this.dynGeometry = new THREE.BufferGeometry();
    for (const name of ["position", "normal", "colour", "uv"]) {
      this.envGeometry.setAttribute(name, this.geometry.getAttribute(name));
      this.dynGeometry.setAttribute(name, this.geometry.getAttribute(name));
    }
    this.envMaterial = this.material.clone();
    this.envMaterial.uniforms.mode.value = 0;
    this.rangeMaterial = new THREE.RawShaderMaterial({
      vertexShader: VERTEX, fragmentShader: RANGE_FRAGMENT, side: THREE.DoubleSide,
      glslVersion: THREE.GLSL3, uniforms: this.envMaterial.uniforms,
    });
    this.envMaterials = this.withTextures(this.envMaterial);
    this.envMesh = new THREE.Mesh(this.envGeometry, this.envMaterials);
    this.envMesh.frustumCulled = false;
    this.envWorld = new THREE.Scene();
    this.envWorld.add(this.envMesh);
    this.material.uniforms.r1.value = r1;
    this.material.uniforms.r2.value = r2;
    this.dynMaterial = this.material.clone();
    this.dynMaterial.uniforms.mode.value = 2;
    this.dynMaterial.uniforms.rangeTest.value = true;
    this.dynMaterial.uniforms.rangeMap.value = this.rangeTarget.texture;
    this.dynMaterial.uniforms.eye = this.material.uniforms.eye;  // shared
    this.dynMesh = new THREE.Mesh(this.dynGeometry, this.withTextures(this.dynMaterial));
    this.dynMesh.frustumCulled = false;
    this.dynMesh.visible = false;
    this.world.add(this.dynMesh);
    this.background = new THREE.RawShaderMaterial({
      vertexShader: BACKGROUND_VERTEX, fragmentShader: BACKGROUND_FRAGMENT, depthWrite: false,
      glslVersion: THREE.GLSL3,
      uniforms: {inverseProjectionView: {value: new THREE.Matrix4()}, eye: this.material.uniforms.eye,
                 centre: {value: new THREE.Vector3()}, r2: {value: r2},
                 cylinder: {value: this.lookupMode === "cylinder"}, envMap: {value: this.envTarget.texture}},
    });
    const quad = new THREE.BufferGeometry();
    quad.setAttribute("position", new THREE.BufferAttribute(
      new Float32Array([-1, -1, 0, 3, -1, 0, -1, 3, 0]), 3));
    this.backgroundMesh = new THREE.Mesh(quad, this.background);
    this.backgroundMesh.frustumCulled = false;
    this.backgroundMesh.renderOrder = -1;
    this.backgroundMesh.visible = false;
    this.world.add(this.backgroundMesh);
    const centre = params.get("centre") ? vec3(params.get("centre")) : null;
    let centres = null;
    if (!centre && params.get("centres")) {
      const url = params.get("centres");
      const response = await fetch(url);
      if (!response.ok) throw new Error(`${url}: HTTP ${response.status}`);
      const j = await response.json();
      if (j.format !== "vislib-view-centres 1" || !Array.isArray(j.centres))
        throw new Error(`${url}: not the output of pvs export --centres`);
      if (j.centres.length !== this.pvs.info.cell_count)
        throw new Error(`${url}: ${j.centres.length} cells, the PVS ${this.pvs.info.cell_count}: not this PVS's centres`);
      centres = j.centres;
    }
    await this.client.setGeometry(this.scene, {r1, r2, centre, centres, clovr: this.clovr});
  }

  // Renders the cube maps (colour and range) from O of the triangles `ids`.
  renderEnvironment(ids, o) {
    this.drawIds(this.envGeometry, ids);
    this.envMaterial.uniforms.eye.value.set(...o);
    this.cubeCamera.position.set(...o);
    this.rangeCamera.position.set(...o);
    const clear = new THREE.Color();
    this.renderer.getClearColor(clear);
    this.renderer.setClearColor(new THREE.Color(150 / 255, 170 / 255, 195 / 255), 1);
    this.envMesh.material = this.envMaterials;
    this.cubeCamera.update(this.renderer, this.envWorld);
    this.renderer.setClearColor(new THREE.Color(0, 0, 0), 0);  // range 0: nothing there
    this.envMesh.material = this.rangeMaterial;
    this.rangeCamera.update(this.renderer, this.envWorld);
    this.envMesh.material = this.envMaterials;
    this.renderer.setClearColor(clear, 1);
    this.backgroundMesh.visible = true;
  }

  applyPartition(part) {
    const o = part.centre;
    this.centre = o;
    this.centreSource = part.centreSource;
    this.material.uniforms.centre.value.set(...o);
    this.dynMaterial.uniforms.centre.value.set(...o);
    this.background.uniforms.centre.value.set(...o);
    this.material.uniforms.mode.value = 1;
    this.partition = part;
    this.clovrExact = false;
    if (this.clovr) return [];  // the scheduler's first frame (setClovr) sets the sets
    return this.applyExact(part);
  }

  // The cell's exact near-far partition by triangle: the environment map from its environment
  // ids, the dynamic far triangles under the range test, and (returned) the ids drawn morphed.
  applyExact(part) {
    const o = part.centre;
    this.material.uniforms.mode.value = 1;
    this.material.uniforms.r1.value = this.nearFar[0];
    this.material.uniforms.r2.value = this.nearFar[1];
    this.renderEnvironment(part.environment, o);
    this.drawIds(this.dynGeometry, part.farDynamic);
    this.dynMesh.visible = part.farDynamic.length > 0;
    this.far = part.farStatic;
    this.farDynamic = part.farDynamic.length;
    this.envCount = part.environment.length;
    return part.geometry;
  }

  // A CloVR frame (pvs_worker.js clovrNext): R and R_n drive the injection (mode 3); when the near
  // set changed, the draw list and the environment map (from the same O) are rebuilt. Once the
  // growth is complete (done), the scheduler's object-level sets give way to the cell's exact
  // partition by triangle (applyExact), as drawn with CloVR off.
  setClovr(f) {
    this.clovrFrame = f;
    if (this.clovrExact) return;
    if (f.done && this.partition) {
      this.clovrExact = true;
      const ids = this.applyExact(this.partition);
      this.drawIds(this.geometry, ids);
      this.drawn = ids.length;
      return;
    }
    const u = this.material.uniforms;
    u.mode.value = 3;
    u.r1.value = f.near_radius;
    u.r2.value = f.radius;
    this.dynMesh.visible = false;
    if (f.near) {
      this.drawIds(this.geometry, f.near);
      this.drawn = f.near.length;
      this.renderEnvironment(f.environment, this.centre);
      this.far = f.environment.length;
      this.envCount = f.environment.length;
    }
    // Alg. 1 needs the eye strictly inside R_n; until R_n reaches it the near set is drawn as is.
    const p = this.camera.position;
    const inside = Math.hypot(p.x - this.centre[0], p.z - this.centre[2]) < f.near_radius;
    u.mode.value = inside ? 3 : 0;
  }

  initPopping() {
    const w = this.renderer.domElement.width, h = this.renderer.domElement.height;
    this.idTarget = new THREE.WebGLRenderTarget(w, h, {depthBuffer: true});
    this.idMaterial = new THREE.RawShaderMaterial({
      vertexShader: ID_VERTEX, fragmentShader: ID_FRAGMENT, side: THREE.DoubleSide,
      glslVersion: THREE.GLSL3,
    });
    const g = new THREE.BufferGeometry();
    g.setAttribute("position", this.geometry.getAttribute("position"));
    const mesh = new THREE.Mesh(g, this.idMaterial);
    mesh.frustumCulled = false;
    this.idWorld = new THREE.Scene();
    this.idWorld.add(mesh);
    this.idPixels = new Uint8Array(4 * w * h);
    this.heat = document.createElement("canvas");
    this.heat.width = w;
    this.heat.height = h;
    this.heat.style.cssText = "position:absolute;left:0;top:0;pointer-events:none;" +
      `width:${canvas.style.width || "100%"};height:${canvas.style.height || "100%"}`;
    if (params.get("overlay") === "0") this.heat.style.display = "none";
    document.body.insertBefore(this.heat, overlay);  // under the text overlays
    addEventListener("keydown", (e) => { if (e.key === "p") this.measureNext = true; });
  }

  // The popping meter: the full scene's first triangle per pixel (id pass); a pixel pops when
  // that triangle is not in the drawn cell's set (what the CPU renderer counts as a missed
  // pixel). Shown as a red heat overlay; returns the count.
  measurePopping() {
    const w = this.idTarget.width, h = this.idTarget.height;
    const clear = new THREE.Color();
    this.renderer.getClearColor(clear);
    this.renderer.setRenderTarget(this.idTarget);
    this.renderer.setClearColor(new THREE.Color(1, 1, 1), 1);
    this.renderer.clear();
    this.renderer.render(this.idWorld, this.camera);
    this.renderer.readRenderTargetPixels(this.idTarget, 0, 0, w, h, this.idPixels);
    this.renderer.setRenderTarget(null);
    this.renderer.setClearColor(clear, 1);
    const ctx = this.heat.getContext("2d");
    const img = ctx.createImageData(w, h);
    let count = 0;
    for (let y = 0; y < h; ++y)
      for (let x = 0; x < w; ++x) {
        const i = 4 * (y * w + x);
        const id = this.idPixels[i] | (this.idPixels[i + 1] << 8) | (this.idPixels[i + 2] << 16);
        if (id === NO_ID || !this.mask || this.mask[id]) continue;
        ++count;
        const o = 4 * ((h - 1 - y) * w + x);  // the read-back rows run bottom-up
        img.data[o] = 255;
        img.data[o + 3] = 200;
      }
    ctx.putImageData(img, 0, 0);
    return count;
  }

  // One frame from the camera's current pose: the runtime's cell, the draw list, the render.
  async frame() {
    const t0 = performance.now();
    const p = this.camera.position;
    const r = await this.client.lookup([p.x, p.y, p.z], this.cell, this.prefetch);
    this.found = r.cell;
    if (r.cell >= 0 && r.cell !== this.cell) {
      this.cell = r.cell;
      this.setDrawList(r.ids, r.partition);
    }
    if (r.clovr) this.setClovr(r.clovr);
    this.bytes = r.bytes;
    this.requests = r.requests;
    this.lookupRequests = r.lookupRequests;
    this.chainBlocks = r.chainBlocks;
    this.material.uniforms.eye.value.copy(p);
    if (this.background) {
      this.camera.updateMatrixWorld();
      this.background.uniforms.inverseProjectionView.value
        .multiplyMatrices(this.camera.projectionMatrix, this.camera.matrixWorldInverse).invert();
    }
    this.renderer.render(this.world, this.camera);
    const measure = this.measureNext ||
      (this.poppingEvery > 0 && this.frameCount % this.poppingEvery === 0);
    this.measureNext = false;
    this.frameCount += 1;
    if (measure) this.popping = this.measurePopping();
    const gl = this.renderer.getContext();
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));  // waits for the GPU
    const ms = performance.now() - t0;
    this.showOverlay(ms);
    this.drawMap();
    return {cell: this.found, drawn_cell: this.cell, triangles_drawn: this.drawn,
            triangles_far: this.far, triangles_far_dynamic: this.farDynamic ?? 0,
            clovr: this.clovrFrame ? {frame: this.clovrFrame.frame, ring: this.clovrFrame.ring,
                                      ring_count: this.clovrFrame.ring_count, radius: this.clovrFrame.radius,
                                      near_radius: this.clovrFrame.near_radius, done: this.clovrFrame.done,
                                      near_count: this.clovrFrame.near_count,
                                      environment_count: this.clovrFrame.environment_count,
                                      exact: this.clovrExact} : null,
            popping_pixels: measure ? this.popping : null,
            triangles_total: this.total, ms, bytes_fetched: this.bytes,
            range_requests: this.requests, frame_range_requests: this.lookupRequests,
            prefetched_chain_blocks: this.chainBlocks, eye: [p.x, p.y, p.z],
            centre: this.centre ?? null, centre_source: this.centreSource ?? null,
            shading: this.shading, textures: this.textures.groups ? this.textures.groups.count : 0,
            texture_errors: this.textures.errors};
  }

  // Replay: frame i of the path.
  async step(i) {
    const f = this.path[i];
    this.camera.position.set(...f.eye);
    let look = f.look;
    if (!look) {
      const next = this.path[i + 1] || null, prev = this.path[i - 1] || null;
      if (next) look = next.eye;
      else if (prev) look = f.eye.map((v, k) => 2 * v - prev.eye[k]);
      else look = [f.eye[0] + 1, f.eye[1], f.eye[2]];
      look = [look[0], f.eye[1], look[2]];
      if (look[0] === f.eye[0] && look[2] === f.eye[2]) look[0] += 1;
    }
    this.camera.up.set(0, 1, 0);
    this.camera.lookAt(...look);
    const rec = await this.frame();
    rec.frame = i;
    return rec;
  }

  showOverlay(ms) {
    const outside = this.found < 0;
    const cellText = outside
      ? `<span class="outside">outside every cell: ${this.cell >= 0 ? `keeping cell ${this.cell}'s set` : "drawing the whole scene"}</span>`
      : `cell ${this.found} of ${this.pvs.info.cell_count}`;
    overlay.innerHTML =
      `${cellText}\ntriangles drawn ${this.drawn}${this.nearFar ? ` near + ${this.far} far (environment map)${this.farDynamic ? ` + ${this.farDynamic} dynamic far` : ""}` : ""} / ${this.total}` +
      ` (${(100 * (this.drawn + this.far) / this.total).toFixed(1)}%)\n${ms.toFixed(1)} ms/frame\n` +
      `PVS bytes fetched ${this.bytes} of ${this.pvs.info.file_size} (${this.requests} range requests)` +
      `\nscene ${this.sceneBytes} bytes` +
      (this.clovrFrame ? `\nCloVR ring ${this.clovrFrame.ring} of ${this.clovrFrame.ring_count}, R ${this.clovrFrame.radius.toFixed(1)}${this.clovrFrame.done ? " (complete: the exact set by triangle)" : ""}` : "") +
      (this.popping === null ? "" : `\npopping pixels ${this.popping} (last measured; P measures)`) +
      (this.textures.errors.length ? `\n<span class="outside">textures not shown: ${this.textures.errors.join("; ")}</span>` : "");
  }

  // Top view of the cells, coloured by PVS size (dark blue: smallest, yellow: largest).
  drawMapBase() {
    const b = this.pvs.boxes, n = this.pvs.info.cell_count;
    let x0 = Infinity, z0 = Infinity, x1 = -Infinity, z1 = -Infinity, cmax = 1, cmin = Infinity;
    for (let c = 0; c < n; ++c) {
      x0 = Math.min(x0, b[6 * c]); z0 = Math.min(z0, b[6 * c + 2]);
      x1 = Math.max(x1, b[6 * c + 3]); z1 = Math.max(z1, b[6 * c + 5]);
      cmax = Math.max(cmax, this.pvs.counts[c]); cmin = Math.min(cmin, this.pvs.counts[c]);
    }
    const W = mapCanvas.width, s = (W - 10) / Math.max(x1 - x0, z1 - z0, 1e-9);
    this.map = {x0, z0, s, cmin, cmax};
    const ctx = mapCanvas.getContext("2d");
    const base = document.createElement("canvas");
    base.width = base.height = W;
    const bc = base.getContext("2d");
    for (let c = 0; c < n; ++c) {
      const f = (this.pvs.counts[c] - cmin) / Math.max(1, cmax - cmin);
      bc.fillStyle = `rgb(${Math.round(40 + 215 * f)},${Math.round(40 + 180 * f)},${Math.round(140 - 110 * f)})`;
      const [x, y, w, h] = this.mapRect(c);
      bc.fillRect(x, y, w, h);
    }
    this.mapBase = base;
    ctx.drawImage(base, 0, 0);
  }

  mapRect(c) {
    const b = this.pvs.boxes, m = this.map;
    return [5 + (b[6 * c] - m.x0) * m.s, 5 + (b[6 * c + 2] - m.z0) * m.s,
            Math.max(1, (b[6 * c + 3] - b[6 * c]) * m.s), Math.max(1, (b[6 * c + 5] - b[6 * c + 2]) * m.s)];
  }

  drawMap() {
    const ctx = mapCanvas.getContext("2d"), m = this.map;
    ctx.clearRect(0, 0, mapCanvas.width, mapCanvas.height);
    ctx.drawImage(this.mapBase, 0, 0);
    if (this.cell >= 0) {
      ctx.strokeStyle = "#fff";
      ctx.lineWidth = 2;
      ctx.strokeRect(...this.mapRect(this.cell));
    }
    const p = this.camera.position;
    ctx.fillStyle = this.found >= 0 ? "#fff" : "#f44";
    ctx.beginPath();
    ctx.arc(5 + (p.x - m.x0) * m.s, 5 + (p.z - m.z0) * m.s, 3, 0, 2 * Math.PI);
    ctx.fill();
  }

  // WASD + mouse drag; Q/E down/up; shift for speed.
  startWalking() {
    const keys = new Set();
    addEventListener("keydown", (e) => keys.add(e.key.toLowerCase()));
    addEventListener("keyup", (e) => keys.delete(e.key.toLowerCase()));
    let dragging = false, yaw = 0, pitch = 0;
    const d = new THREE.Vector3();
    this.camera.getWorldDirection(d);
    yaw = Math.atan2(d.x, -d.z);
    pitch = Math.asin(Math.max(-1, Math.min(1, d.y)));
    canvas.addEventListener("mousedown", () => (dragging = true));
    addEventListener("mouseup", () => (dragging = false));
    addEventListener("mousemove", (e) => {
      if (!dragging) return;
      yaw += e.movementX * 0.004;
      pitch = Math.max(-1.5, Math.min(1.5, pitch - e.movementY * 0.004));
    });
    addEventListener("resize", () => {
      this.renderer.setSize(canvas.clientWidth, canvas.clientHeight, false);
      this.camera.aspect = canvas.clientWidth / canvas.clientHeight;
      this.camera.updateProjectionMatrix();
    });
    let last = performance.now();
    const loop = async () => {
      const now = performance.now(), dt = Math.min(0.1, (now - last) / 1000);
      last = now;
      const speed = (keys.has("shift") ? 20 : 6) * dt;
      const fwd = new THREE.Vector3(Math.sin(yaw), 0, -Math.cos(yaw));
      const right = new THREE.Vector3(Math.cos(yaw), 0, Math.sin(yaw));
      const p = this.camera.position;
      if (keys.has("w")) p.addScaledVector(fwd, speed);
      if (keys.has("s")) p.addScaledVector(fwd, -speed);
      if (keys.has("d")) p.addScaledVector(right, speed);
      if (keys.has("a")) p.addScaledVector(right, -speed);
      if (keys.has("e")) p.y += speed;
      if (keys.has("q")) p.y -= speed;
      const look = new THREE.Vector3(Math.sin(yaw) * Math.cos(pitch), Math.sin(pitch),
                                     -Math.cos(yaw) * Math.cos(pitch));
      this.camera.lookAt(p.clone().add(look));
      await this.frame();
      requestAnimationFrame(loop);
    };
    requestAnimationFrame(loop);
  }
}

// mode=ods (ods.js) and mode=stereo (stereo.js) are viewers of their own with the same interface
// (init, path, step, startWalking); docs/web.md.
const mode = params.get("mode") || "walk";
if (!["walk", "ods", "stereo"].includes(mode)) throw new Error(`mode=${mode}: walk, ods or stereo`);
const viewer = mode === "ods" ? new OdsViewer(params, overlay, canvas)
  : mode === "stereo" ? new StereoViewer(params, overlay, canvas) : new Viewer();
window.viewer = viewer;
window.viewerReady = viewer.init().then(
  async () => {
    if (viewer.path) {
      await viewer.step(0);
      if (params.get("autoplay") !== null) {
        for (let i = 0; i < viewer.path.length; ++i) await viewer.step(i);
      }
    } else {
      viewer.startWalking();
    }
    return {triangles: viewer.total, cells: viewer.pvs.info.cell_count,
            file_size: viewer.pvs.info.file_size, scene_bytes: viewer.sceneBytes};
  },
  (e) => {
    overlay.innerHTML = `<span class="outside">error: ${e.message}</span>`;
    throw e;
  });
