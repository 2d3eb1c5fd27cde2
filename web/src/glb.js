// glb.js: reads the GLB that `pvs export SCENE -o scene.glb` writes into triangles in vislib's id
// order: node i of the scene is object i, its mesh's primitives hold that object's triangles in
// id order (vislib/scene/write_gltf.h), and the export refuses scenes whose objects are not in id
// order. So concatenating the nodes' primitives gives triangle id t at position t.
// Plain ES module, no dependency: the browser page and node (the id-order test) both use it.

const FLOAT = 5126, UINT32 = 5125, UINT16 = 5123, UINT8 = 5121;

function accessorArray(gltf, bin, index, want) {
  const a = gltf.accessors[index];
  const view = gltf.bufferViews[a.bufferView];
  const comps = {SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4}[a.type];
  if (comps !== want) throw new Error(`accessor ${index}: ${a.type}, expected ${want} components`);
  const size = {[FLOAT]: 4, [UINT32]: 4, [UINT16]: 2, [UINT8]: 1}[a.componentType];
  if (!size) throw new Error(`accessor ${index}: component type ${a.componentType}`);
  if (view.byteStride && view.byteStride !== size * comps)
    throw new Error(`accessor ${index}: interleaved data is not supported`);
  const offset = bin.byteOffset + (view.byteOffset || 0) + (a.byteOffset || 0);
  const n = a.count * comps;
  const copy = bin.buffer.slice(offset, offset + n * size);  // aligned copy
  if (a.componentType === FLOAT) return new Float32Array(copy);
  if (a.componentType === UINT32) return new Uint32Array(copy);
  if (a.componentType === UINT16) return new Uint32Array(new Uint16Array(copy));
  return new Uint32Array(new Uint8Array(copy));
}

// Returns {positions: Float32Array(9 * T) (triangle t's corners at 9t..9t+8, de-indexed),
// triangleObject: Uint32Array(T), dynamic: Uint8Array(T) (1: a vertex of the triangle moves in
// some state, as vislib::moving_triangles; positions are the rest state 0), objectCount,
// objectNames, and what the page needs to draw the scene's own materials:
// triangleMaterial: Int32Array(T) (index into materials, -1: the primitive has none),
// uvs: Float32Array(6 * T) (TEXCOORD_0 of triangle t's corners at 6t..6t+5; 0 where a primitive
// has no float TEXCOORD_0), materials: [{name, baseColour: linear RGBA, image: index into images
// or -1, wrapS, wrapT (WebGL wrap modes)}], images: [{bytes: Uint8Array or null, mimeType, uri}]
// (embedded bytes, else the URI as the file writes it)}. Throws on anything else than the
// export's layout (node transforms, non-triangle primitives, several scenes).
export function parseGlb(arrayBuffer) {
  const dv = new DataView(arrayBuffer);
  if (dv.getUint32(0, true) !== 0x46546c67) throw new Error("not a GLB file (bad magic)");
  let off = 12, gltf = null, bin = null;
  while (off + 8 <= arrayBuffer.byteLength) {
    const len = dv.getUint32(off, true), type = dv.getUint32(off + 4, true);
    const chunk = new Uint8Array(arrayBuffer, off + 8, len);
    if (type === 0x4e4f534a) gltf = JSON.parse(new TextDecoder().decode(chunk));
    else if (type === 0x004e4942) bin = chunk;
    off += 8 + len;
  }
  if (!gltf) throw new Error("GLB without a JSON chunk");
  const scene = gltf.scenes[gltf.scene || 0];
  const nodes = scene.nodes || [];
  const parts = [], objects = [], names = [];
  let total = 0;
  nodes.forEach((nodeIndex, object) => {
    const node = gltf.nodes[nodeIndex];
    names.push(node.name || `object ${object}`);
    if (node.matrix || node.translation || node.rotation || node.scale || node.children)
      throw new Error(`node ${nodeIndex}: transforms or children (export the scene with pvs export -o FILE.glb)`);
    if (node.mesh === undefined) return;
    for (const prim of gltf.meshes[node.mesh].primitives) {
      if ((prim.mode ?? 4) !== 4) throw new Error(`mesh ${node.mesh}: not TRIANGLES`);
      const pos = accessorArray(gltf, bin, prim.attributes.POSITION, 3);
      const idx = accessorArray(gltf, bin, prim.indices, 1);
      // A vertex moves when a morph target (the export's states 1..K-1) displaces it.
      const moves = new Uint8Array(pos.length / 3);
      for (const target of prim.targets || []) {
        const d = accessorArray(gltf, bin, target.POSITION, 3);
        for (let v = 0; v < moves.length; ++v)
          if (d[3 * v] !== 0 || d[3 * v + 1] !== 0 || d[3 * v + 2] !== 0) moves[v] = 1;
      }
      // Texture coordinates only as float (the export writes them so); else untextured.
      const uvAccessor = prim.attributes.TEXCOORD_0;
      const uv = uvAccessor !== undefined && gltf.accessors[uvAccessor].componentType === FLOAT
        ? accessorArray(gltf, bin, uvAccessor, 2) : null;
      parts.push({pos, idx, moves, uv, material: prim.material ?? -1});
      objects.push([object, idx.length / 3]);
      total += idx.length / 3;
    }
  });
  const positions = new Float32Array(9 * total);
  const triangleObject = new Uint32Array(total);
  const dynamic = new Uint8Array(total);
  const triangleMaterial = new Int32Array(total);
  const uvs = new Float32Array(6 * total);
  let t = 0;
  parts.forEach(({pos, idx, moves, uv, material}, k) => {
    const [object, n] = objects[k];
    for (let i = 0; i < 3 * n; ++i) {
      const v = idx[i];
      positions[3 * (3 * t) + 3 * (i % 3)] = pos[3 * v];
      positions[3 * (3 * t) + 3 * (i % 3) + 1] = pos[3 * v + 1];
      positions[3 * (3 * t) + 3 * (i % 3) + 2] = pos[3 * v + 2];
      if (moves[v]) dynamic[t] = 1;
      if (uv) {
        uvs[6 * t + 2 * (i % 3)] = uv[2 * v];
        uvs[6 * t + 2 * (i % 3) + 1] = uv[2 * v + 1];
      }
      if (i % 3 === 2) {
        triangleMaterial[t] = material;
        triangleObject[t++] = object;
      }
    }
  });
  return {positions, triangleObject, dynamic, objectCount: nodes.length, objectNames: names,
          triangleMaterial, uvs, ...readMaterials(gltf, bin)};
}

// The materials' base colour (factor and texture) and the images they use (see parseGlb).
function readMaterials(gltf, bin) {
  const REPEAT = 10497;
  const materials = (gltf.materials || []).map((m, k) => {
    const pbr = m.pbrMetallicRoughness || {};
    const texture = pbr.baseColorTexture && (pbr.baseColorTexture.texCoord ?? 0) === 0
      ? gltf.textures[pbr.baseColorTexture.index] : null;
    const sampler = texture && texture.sampler !== undefined ? gltf.samplers[texture.sampler] : {};
    return {name: m.name || `material ${k}`, baseColour: pbr.baseColorFactor || [1, 1, 1, 1],
            image: texture && texture.source !== undefined ? texture.source : -1,
            wrapS: sampler.wrapS ?? REPEAT, wrapT: sampler.wrapT ?? REPEAT};
  });
  const images = (gltf.images || []).map((im) => {
    if (im.bufferView === undefined) return {bytes: null, mimeType: im.mimeType || "", uri: im.uri || ""};
    const view = gltf.bufferViews[im.bufferView];
    const start = bin.byteOffset + (view.byteOffset || 0);
    return {bytes: new Uint8Array(bin.buffer.slice(start, start + view.byteLength)),
            mimeType: im.mimeType || "", uri: ""};
  });
  return {materials, images};
}

// splitmix64 as vislib/eval/render.cpp has it (BigInt: 64-bit wrapping arithmetic).
function splitmix(x) {
  const M = (1n << 64n) - 1n;
  let z = (x + 0x9E3779B97F4A7C15n) & M;
  z = ((z ^ (z >> 30n)) * 0xBF58476D1CE4E5B9n) & M;
  z = ((z ^ (z >> 27n)) * 0x94D049BB133111EBn) & M;
  return z ^ (z >> 31n);
}

function toByte(v) {
  const s = Math.round(v * 255);
  return s < 0 ? 0 : s > 255 ? 255 : s;
}

// The colour of object `object` in the CPU reference renderer (vislib::object_colour): a hue,
// saturation and value drawn from splitmix64 of the id, as 8-bit RGB.
export function objectColour(object) {
  const h = splitmix(BigInt(object));
  const hue = Number(h & 0xFFFFn) / 65536 * 6;
  const sat = 0.45 + 0.35 * Number((h >> 16n) & 0xFFn) / 255;
  const val = 0.65 + 0.35 * Number((h >> 24n) & 0xFFn) / 255;
  const sector = Math.floor(hue), frac = hue - sector;
  const p = val * (1 - sat), q = val * (1 - sat * frac), t = val * (1 - sat * (1 - frac));
  const rgb = [[val, t, p], [q, val, p], [p, val, t], [p, q, val], [t, p, val]][sector] ||
              [val, p, q];
  return rgb.map(toByte);
}
