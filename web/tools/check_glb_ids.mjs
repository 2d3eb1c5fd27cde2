// check_glb_ids.mjs: the web client reads triangles in vislib's id order. Compares what
// web/src/glb.js makes of `pvs export SCENE -o scene.glb` with `pvs export SCENE -o flat.obj`
// (face i = triangle id i, %.17g coordinates, an `o` line where the object changes): the same
// number of triangles, and triangle i's corners equal within float rounding and in the same order,
// with the object of each triangle named as the OBJ names it.
// Usage: node check_glb_ids.mjs scene.glb flat.obj   (exit 0 equal, 1 not)
import fs from "node:fs";
import {parseGlb} from "../src/glb.js";

const [glbPath, objPath] = process.argv.slice(2);
const b = fs.readFileSync(glbPath);
const scene = parseGlb(b.buffer.slice(b.byteOffset, b.byteOffset + b.length));
const verts = [], faces = [], faceObject = [];
let object = null;
for (const line of fs.readFileSync(objPath, "utf8").split("\n")) {
  if (line.startsWith("v ")) verts.push(line.slice(2).split(" ").map(Number));
  else if (line.startsWith("o ")) object = line.slice(2);
  else if (line.startsWith("f ")) {
    faces.push(line.slice(2).split(" ").map((s) => Number(s) - 1));
    faceObject.push(object);
  }
}
const T = scene.triangleObject.length;
let bad = 0;
if (T !== faces.length) {
  console.error(`check_glb_ids: ${T} triangles in ${glbPath}, ${faces.length} in ${objPath}`);
  process.exit(1);
}
for (let t = 0; t < T && bad < 10; ++t) {
  for (let k = 0; k < 3; ++k)
    for (let a = 0; a < 3; ++a) {
      const want = Math.fround(verts[faces[t][k]][a]), got = scene.positions[9 * t + 3 * k + a];
      if (got !== want) {
        if (bad++ < 10) console.error(`triangle ${t} corner ${k}: ${got} != ${want}`);
      }
    }
  const name = scene.objectNames[scene.triangleObject[t]];
  if (name !== faceObject[t] && bad++ < 10)
    console.error(`triangle ${t}: object "${name}" != "${faceObject[t]}"`);
}
console.log(`check_glb_ids: ${T} triangles, ${scene.objectCount} objects: ${bad ? "MISMATCH" : "same ids, corners and objects"}`);
process.exit(bad ? 1 : 0);
