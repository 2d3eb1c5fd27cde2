// range_check.js: the runtime worker alone, without a scene (web/range.html?pvs=URL&path=...):
// opens the PVS and looks up each point of the path, reading the visible ids of its cell. It
// answers web_check.mjs like the viewer does (window.viewerReady, window.viewer.step), so the
// streaming test measures what the client fetches from a file of any size.
import {PvsClient} from "./pvs_client.js";
import {parsePath} from "./path.js";

const params = new URLSearchParams(location.search);
const out = document.getElementById("out");

const viewer = {
  path: parsePath(params.get("path") || ""),
  cell: -1,
  async step(i) {
    const t0 = performance.now();
    const r = await this.client.lookup(this.path[i].eye, this.cell);
    if (r.cell >= 0 && r.cell !== this.cell) {
      this.cell = r.cell;
      this.drawn = r.ids.length;
    }
    const rec = {frame: i, cell: r.cell, triangles_drawn: this.drawn ?? 0,
                 ms: performance.now() - t0, bytes_fetched: r.bytes, range_requests: r.requests};
    out.textContent = JSON.stringify(rec);
    return rec;
  },
};
window.viewer = viewer;
window.viewerReady = (async () => {
  viewer.client = new PvsClient();
  const o = await viewer.client.open(params.get("pvs"));
  out.textContent = `opened: ${o.info.cell_count} cells, ${o.info.file_size} bytes`;
  return {cells: o.info.cell_count, file_size: o.info.file_size, open_bytes: o.bytes};
})();
