// materials.js: the scene's own glTF materials in the web client (shading=materials, the
// default): the base colour textures decoded, the triangles grouped by texture, and the draw
// lists ordered by group, one three.js geometry group (and material) per texture.
import * as THREE from "three";

// The index buffer drawing triangles `ids` of the de-indexed geometry (triangle t = vertices
// 3t, 3t+1, 3t+2).
export function indexOf(ids) {
  const idx = new Uint32Array(3 * ids.length);
  for (let i = 0; i < ids.length; ++i) {
    idx[3 * i] = 3 * ids[i];
    idx[3 * i + 1] = 3 * ids[i] + 1;
    idx[3 * i + 2] = 3 * ids[i] + 2;
  }
  return new THREE.BufferAttribute(idx, 1);
}

// The triangles of a scene (glb.js's parseGlb) by texture: group[t] = 1 + i when triangle t's
// material has image i as its base colour texture and that image was decoded, else 0.
class TextureGroups {
  constructor(scene, textures) {
    this.textures = textures;
    this.count = textures.filter((t) => t).length;
    this.groupCount = 1 + textures.length;
    const T = scene.triangleObject.length;
    this.group = new Uint16Array(T);
    for (let t = 0; t < T; ++t) {
      const m = scene.triangleMaterial[t], image = m >= 0 ? scene.materials[m].image : -1;
      if (image >= 0 && textures[image]) this.group[t] = 1 + image;
    }
  }

  // One material per group: `base` for group 0 (untextured), for group 1 + i a material with
  // image i's texture whose other uniforms are base's own objects, so that setting base's
  // uniforms sets them all. `base` is a RawShaderMaterial with `textured` and `map` uniforms.
  materialsFor(base) {
    return [base, ...this.textures.map((tex) => new THREE.RawShaderMaterial({
      vertexShader: base.vertexShader, fragmentShader: base.fragmentShader, side: base.side,
      glslVersion: THREE.GLSL3,
      uniforms: {...base.uniforms, textured: {value: tex !== null}, map: {value: tex}},
    }))];
  }
}

// Decodes the images that the materials of `scene` (parseGlb's) use as base colour textures:
// embedded bytes, or a URI relative to `sceneUrl`. Returns {groups: a TextureGroups, or null when
// no material has a texture, errors: one line per image that could not be read or decoded (its
// triangles are drawn untextured)}.
export async function loadTextures(scene, sceneUrl) {
  const used = new Map();  // image -> the first material using it (its sampler's wrap modes)
  for (const m of scene.materials) if (m.image >= 0 && !used.has(m.image)) used.set(m.image, m);
  const errors = [];
  if (used.size === 0) return {groups: null, errors};
  const wrap = {33071: THREE.ClampToEdgeWrapping, 33648: THREE.MirroredRepeatWrapping};
  const textures = await Promise.all(scene.images.map(async (im, i) => {
    if (!used.has(i)) return null;
    try {
      let blob;
      if (im.bytes) blob = new Blob([im.bytes], {type: im.mimeType});
      else {
        const r = await fetch(new URL(im.uri, new URL(sceneUrl, location.href)));
        if (!r.ok) throw new Error(`${im.uri}: HTTP ${r.status}`);
        blob = await r.blob();
      }
      // glTF's UV origin is the image's top left corner: rows are uploaded unflipped.
      const tex = new THREE.Texture(await createImageBitmap(blob, {imageOrientation: "none"}));
      tex.flipY = false;
      tex.wrapS = wrap[used.get(i).wrapS] ?? THREE.RepeatWrapping;
      tex.wrapT = wrap[used.get(i).wrapT] ?? THREE.RepeatWrapping;
      tex.minFilter = THREE.LinearMipmapLinearFilter;
      tex.needsUpdate = true;
      return tex;
    } catch (e) {
      errors.push(`image ${i}: ${e.message}`);
      return null;
    }
  }));
  return {groups: new TextureGroups(scene, textures), errors};
}

// Sets `geometry`'s index to the triangles `ids` (null: all). With `groups` (a TextureGroups),
// the triangles are ordered by group (a stable counting sort) and each non-empty group becomes a
// geometry group whose material index is the group's.
export function drawTriangles(geometry, ids, groups) {
  if (!groups) {
    geometry.setIndex(ids ? indexOf(ids) : null);
    return;
  }
  if (!ids) ids = Array.from({length: groups.group.length}, (_, t) => t);
  const G = groups.groupCount, start = new Uint32Array(G + 1);
  for (const t of ids) ++start[groups.group[t] + 1];
  for (let g = 0; g < G; ++g) start[g + 1] += start[g];
  const fill = start.slice(0, G), sorted = new Uint32Array(ids.length);
  for (const t of ids) sorted[fill[groups.group[t]]++] = t;
  geometry.setIndex(indexOf(sorted));
  geometry.clearGroups();
  for (let g = 0; g < G; ++g)
    if (start[g + 1] > start[g]) geometry.addGroup(3 * start[g], 3 * (start[g + 1] - start[g]), g);
}
