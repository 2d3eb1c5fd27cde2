// pvs_client.js: the page's side of the runtime worker (pvs_worker.js): one promise per request.
export class PvsClient {
  constructor() {
    this.worker = new Worker(new URL("./pvs_worker.js", import.meta.url));
    this.pending = new Map();
    this.next = 1;
    this.worker.onmessage = (ev) => {
      const p = this.pending.get(ev.data.id);
      this.pending.delete(ev.data.id);
      if (ev.data.ok) p.resolve(ev.data);
      else p.reject(new Error(ev.data.error));
    };
  }
  call(message) {
    const id = this.next++;
    return new Promise((resolve, reject) => {
      this.pending.set(id, {resolve, reject});
      this.worker.postMessage({...message, id});
    });
  }
  // Opens the PVS at `url` (header, layout and index by range request).
  open(url) { return this.call({op: "open", url}); }
  // The scene's triangles for the near-far partition and CloVR (pvs_worker.js, op geometry).
  setGeometry(scene, nearFar) {
    return this.call({op: "geometry", positions: scene.positions, triangleObject: scene.triangleObject,
                      objectCount: scene.objectCount, dynamic: scene.dynamic, nearFar});
  }
  // The cell containing `position` (-1: none) and, when it is not `have`, its visible ids; on a
  // cell change with `prefetch` >= 0, the worker then fetches the neighbours' blocks.
  // The cells an ODS panorama centred at `centre` needs (its viewing disc of `radius`) and the
  // union of their sets (pvs_worker.js, op disc).
  disc(centre, radius) { return this.call({op: "disc", centre, radius}); }
  lookup(position, have, prefetch = -1) {
    return this.call({op: "lookup", position, have, prefetch});
  }
}
