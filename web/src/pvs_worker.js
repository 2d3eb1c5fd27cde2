// pvs_worker.js: the PVS runtime (WebAssembly, web/build/pvs_runtime.{js,wasm}) in a Worker.
//
// The C++ reader asks for byte ranges synchronously (pvs_rt_open_ranges); a Worker may make
// synchronous XMLHttpRequests, so each range is one blocking HTTP range request here and the
// WebAssembly needs no ASYNCIFY. The page talks to this worker by messages (pvs_client.js):
//   {op: "open", url}            -> {info, boxes: Float64Array(6 * cells), counts: Uint32Array}
//   {op: "lookup", position, have, prefetch}
//                                -> {cell (-1: outside every cell), ids?: Uint32Array (when the
//                                    cell is not `have`), bytes, requests}
// With `prefetch` = a margin (scene units) on a cell change, after the reply the worker fetches
// the blocks of the cells the runtime names as neighbours within that margin
// (pvs_rt_neighbours, pvs_rt_block_range), so that crossing into one costs no request; their
// Delta chains are fetched when a cell is entered (they are known only from the block).
// Each range fetched is kept (a cell's block is fetched once); `bytes` counts every byte the
// server sent for this file, so the page can show what streaming cost.
/* global createPvsRuntime, importScripts */
importScripts("../build/pvs_runtime.js");

let rt = null;  // the WebAssembly module
let handle = 0;
let url = null;
let bytesFetched = 0;
let requests = 0;
const ranges = new Map();  // "offset:size" -> Uint8Array
const idCache = new Map();  // cell -> Uint32Array

// One synchronous range request; returns [bytes, total file size].
function fetchRange(offset, size) {
  const xhr = new XMLHttpRequest();
  xhr.open("GET", url, false);
  xhr.responseType = "arraybuffer";  // allowed for synchronous requests in workers
  xhr.setRequestHeader("Range", `bytes=${offset}-${offset + size - 1}`);
  xhr.send();
  if (xhr.status !== 206) throw new Error(`${url}: range request answered ${xhr.status} (the server must answer byte ranges: scripts/serve-web.sh)`);
  const bytes = new Uint8Array(xhr.response);
  requests += 1;
  bytesFetched += bytes.length;
  const m = /\/(\d+)$/.exec(xhr.getResponseHeader("Content-Range") || "");
  return [bytes, m ? Number(m[1]) : NaN];
}

function readRange(offset, size) {
  const key = `${offset}:${size}`;
  let bytes = ranges.get(key);
  if (!bytes) {
    try {
      bytes = fetchRange(offset, size)[0];
    } catch (e) {
      console.error(String(e));
      return null;
    }
    ranges.set(key, bytes);
  }
  return bytes;
}

function lastError() {
  return rt.UTF8ToString(rt._pvs_rt_last_error());
}

async function open(u) {
  url = u;
  rt = await createPvsRuntime({
    readRange,
    locateFile: (file) => new URL(`../build/${file}`, self.location.href).href,
  });
  // The header's range answer carries the file size (Content-Range), which the runtime needs.
  const [head, size] = fetchRange(0, 64);
  if (!(size >= 64)) throw new Error(`${url}: no file size in the range answer`);
  ranges.set("0:64", head);
  handle = rt._pvs_web_open(size);
  if (!handle) throw new Error(`${url}: ${lastError()}`);
  const p = rt._malloc(64);
  // pvs_rt_info: 6 x uint32, then 2 x uint64 (offset 24 and 32).
  if (rt._pvs_rt_get_info(handle, p) !== 0) throw new Error(lastError());
  const u32 = new Uint32Array(rt.HEAPU8.buffer, p, 6).slice();
  const info = {format_version: u32[0], cell_count: u32[1], universe: u32[2],
                granularity: u32[3], layout: u32[4], partial: u32[5], file_size: size};
  const boxes = new Float64Array(6 * info.cell_count);
  const counts = new Uint32Array(info.cell_count);
  for (let c = 0; c < info.cell_count; ++c) {
    rt._pvs_rt_cell_box(handle, c, p, p + 24);
    boxes.set(new Float64Array(rt.HEAPU8.buffer, p, 6), 6 * c);
    rt._pvs_rt_visible_count(handle, c, p + 48);
    counts[c] = new Uint32Array(rt.HEAPU8.buffer, p + 48, 1)[0];
  }
  rt._free(p);
  return {info, boxes, counts, bytes: bytesFetched, requests};
}

function visibleIds(cell) {
  let ids = idCache.get(cell);
  if (ids) return ids;
  const countP = rt._malloc(16);
  rt._pvs_rt_visible_count(handle, cell, countP);
  const n = new Uint32Array(rt.HEAPU8.buffer, countP, 1)[0];
  const out = rt._malloc(Math.max(4, 4 * n));
  const status = rt._pvs_rt_visible_ids(handle, cell, out, n, countP + 8);
  if (status !== 0) {
    const msg = lastError();
    rt._free(out);
    rt._free(countP);
    throw new Error(`cell ${cell}: ${msg}`);
  }
  const got = new Uint32Array(rt.HEAPU8.buffer, countP + 8, 1)[0];  // size_t is 32-bit in wasm32
  ids = new Uint32Array(rt.HEAPU8.buffer, out, got).slice();
  rt._free(out);
  rt._free(countP);
  idCache.set(cell, ids);
  return ids;
}

function prefetchNeighbours(cell, margin) {
  const cap = 4096;
  const out = rt._malloc(4 * cap + 32);
  const countP = out + 4 * cap, offP = countP + 8, sizeP = countP + 16;
  if (rt._pvs_rt_neighbours(handle, cell, margin, out, cap, countP) === 0) {
    const n = new Uint32Array(rt.HEAPU8.buffer, countP, 1)[0];
    const cells = new Uint32Array(rt.HEAPU8.buffer, out, n).slice();
    for (const c of cells) {
      if (idCache.has(c) || rt._pvs_rt_block_range(handle, c, offP, sizeP) !== 0) continue;
      const off = Number(new BigUint64Array(rt.HEAPU8.buffer, offP, 1)[0]);
      const size = new Uint32Array(rt.HEAPU8.buffer, sizeP, 1)[0];
      readRange(off, size);
    }
  }
  rt._free(out);
}

function lookup(position) {
  const p = rt._malloc(32);
  new Float64Array(rt.HEAPU8.buffer, p, 3).set(position);
  const status = rt._pvs_rt_find_cell(handle, p, p + 24);
  const cell = status === 0 ? new Uint32Array(rt.HEAPU8.buffer, p + 24, 1)[0] : -1;
  rt._free(p);
  if (status !== 0 && status !== 5) throw new Error(lastError());  // 5: PVS_RT_NOT_FOUND
  return cell;
}

self.onmessage = async (ev) => {
  const m = ev.data;
  try {
    if (m.op === "open") {
      const r = await open(m.url);
      self.postMessage({id: m.id, ok: true, ...r});
    } else if (m.op === "lookup") {
      const cell = lookup(m.position);
      const reply = {id: m.id, ok: true, cell};
      if (cell >= 0 && m.have !== cell) reply.ids = visibleIds(cell);
      reply.bytes = bytesFetched;
      reply.requests = requests;
      self.postMessage(reply);
      if (cell >= 0 && m.have !== cell && m.prefetch >= 0) prefetchNeighbours(cell, m.prefetch);
    }
  } catch (e) {
    self.postMessage({id: m.id, ok: false, error: String(e && e.message ? e.message : e)});
  }
};
