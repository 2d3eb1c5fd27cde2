// scene_load.js: what the ODS and stereo viewers share: the scene (GLB of `pvs export`) and the
// PVS opened by the runtime worker, checked to belong together, and the scene's extent.
import {parseGlb} from "./glb.js";
import {PvsClient} from "./pvs_client.js";

// Opens params' scene=URL and pvs=URL: {client, scene, sceneBytes, pvs (the worker's open
// reply), total (triangles)}; throws with a message the page shows.
export async function loadScene(params) {
  const sceneUrl = params.get("scene"), pvsUrl = params.get("pvs");
  if (!sceneUrl || !pvsUrl) throw new Error("give ?scene=URL.glb&pvs=URL.pvs");
  const client = new PvsClient();
  const [glb, pvs] = await Promise.all([
    fetch(sceneUrl).then((r) => {
      if (!r.ok) throw new Error(`${sceneUrl}: HTTP ${r.status}`);
      return r.arrayBuffer();
    }),
    client.open(pvsUrl)]);
  const scene = parseGlb(glb), total = scene.triangleObject.length;
  if (pvs.info.universe !== total || pvs.info.granularity !== 0)
    throw new Error(`the PVS has ${pvs.info.universe} ids, the scene ${total} triangles: not this scene's triangle PVS`);
  return {client, scene, sceneBytes: glb.byteLength, pvs, total};
}

// The diagonal of the bounding box of positions (x, y, z triples).
export function diagonal(positions) {
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < positions.length; i += 3)
    for (let k = 0; k < 3; ++k) {
      lo[k] = Math.min(lo[k], positions[i + k]);
      hi[k] = Math.max(hi[k], positions[i + k]);
    }
  return Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
}
