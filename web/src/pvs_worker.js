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
// (pvs_rt_neighbours, then pvs_rt_delta_chain: the neighbour's block and the blocks of its Delta
// chain, read through readRange and kept), so that crossing into one costs no request.
//   {op: "geometry", positions, triangleObject, objectCount, dynamic, nearFar: {r1, r2, centre,
//    clovr}}                     -> {} (the scene's triangles, for the near-far partition and the
//                                    CloVR scheduler of the C API, runtime/near_far_c.h)
// With near-far on, a lookup that enters a cell also returns the cell's partition
// (pvs_rt_partition_near_far: `geometry` drawn per frame, `farDynamic` displaced by Eq. 2 under
// the range test, `environment` rendered into the cube map from O); with CloVR on, every lookup
// advances the scheduler one frame (pvs_rt_clovr_next_frame) and returns `clovr` (the frame) and,
// when the near set changed, its `near` and `environment` ids.
//   {op: "disc", centre, radius}  -> {cell, cells, inRegion, ids: Uint32Array} (the cells an ODS
//                                    panorama's viewing disc needs, as `pvs view --ods` takes
//                                    them: the cell containing the centre if the disc lies in
//                                    its box, else also every neighbour whose box the disc
//                                    touches; ids: the union of their sets, sorted)
// Each range fetched is kept (a cell's block is fetched once); `bytes` counts every byte the
// server sent for this file, so the page can show what streaming cost.
/* global createPvsRuntime, importScripts */
importScripts("../build/pvs_runtime.js");

let rt = null;  // the WebAssembly module
let handle = 0;
let url = null;
let bytesFetched = 0;
let requests = 0;
let chainBlocks = 0;  // blocks of neighbours' Delta chains prefetched beyond their own blocks
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
  const cap = 4096, chainCap = 256;
  const out = rt._malloc(4 * cap + 4 * chainCap + 16);
  const chain = out + 4 * cap, countP = chain + 4 * chainCap;
  if (rt._pvs_rt_neighbours(handle, cell, margin, out, cap, countP) === 0) {
    const n = new Uint32Array(rt.HEAPU8.buffer, countP, 1)[0];
    const cells = new Uint32Array(rt.HEAPU8.buffer, out, n).slice();
    // Each chain's blocks are read by the runtime through readRange, which keeps them.
    for (const c of cells) {
      if (idCache.has(c) || rt._pvs_rt_delta_chain(handle, c, chain, chainCap, countP) !== 0)
        continue;
      chainBlocks += new Uint32Array(rt.HEAPU8.buffer, countP, 1)[0] - 1;
    }
  }
  rt._free(out);
}

// ---- Near-far and CloVR through the C API (runtime/near_far_c.h) -----------------------------

let geometry = 0;  // pvs_rt_geometry* (its arrays live as long as the worker)
// {r1, r2, centre (pinned, or null), centres (per cell, pvs export --centres; or null), clovr}
let nearFar = null;
let triangleCount = 0;
let clovr = 0;  // pvs_rt_clovr*
let clovrFrame = 0;  // pvs_rt_clovr_frame*
let clovrStarted = false;  // a growth was started (a cell entered)

function copyIn(array) {
  const p = rt._malloc(Math.max(4, array.byteLength));
  rt.HEAPU8.set(new Uint8Array(array.buffer, array.byteOffset, array.byteLength), p);
  return p;
}

function check(status, what) {
  if (status !== 0) throw new Error(`${what}: ${lastError()}`);
}

function setGeometry(m) {
  triangleCount = m.triangleObject.length;
  const indices = new Uint32Array(3 * triangleCount);
  for (let i = 0; i < indices.length; ++i) indices[i] = i;  // the page's de-indexed triangles
  // pvs_rt_geometry in wasm32: 7 words (pointers and size_t are 32-bit).
  const words = [copyIn(m.positions), 3 * triangleCount, copyIn(indices), triangleCount,
                 copyIn(m.triangleObject), m.objectCount, copyIn(m.dynamic)];
  geometry = rt._malloc(28);  // (a view is made after the last allocation: memory may grow)
  new Uint32Array(rt.HEAPU8.buffer, geometry, 7).set(words);
  nearFar = m.nearFar;
  if (nearFar && nearFar.clovr) {
    const params = rt._malloc(40);  // pvs_rt_clovr_params: 3 doubles, uint32 (+4), double
    rt._pvs_rt_clovr_default_params(nearFar.r2, params);
    const out = rt._malloc(4);
    check(rt._pvs_rt_clovr_create(geometry, params, out), "pvs_rt_clovr_create");
    clovr = new Uint32Array(rt.HEAPU8.buffer, out, 1)[0];
    rt._free(out);
    rt._free(params);
    clovrFrame = rt._malloc(56);
  }
}

// O of a cell and where it came from: pinned (centre=), pvs view's choice (centres=), or the
// centre of the cell's lookup box (neither given, or every sample of the cell enclosed).
function cellCentre(cell) {
  if (nearFar.centre) return {centre: nearFar.centre, source: "pinned"};
  if (nearFar.centres && nearFar.centres[cell])
    return {centre: nearFar.centres[cell], source: "pvs view"};
  const p = rt._malloc(48);
  rt._pvs_rt_cell_box(handle, cell, p, p + 24);
  const b = new Float64Array(rt.HEAPU8.buffer, p, 6).slice();
  rt._free(p);
  return {centre: [(b[0] + b[3]) / 2, (b[1] + b[4]) / 2, (b[2] + b[5]) / 2], source: "lookup box"};
}

function idList(p, n) {
  return new Uint32Array(rt.HEAPU32.buffer, p, n).slice();
}

// pvs_rt_partition_near_far of a cell's set about its centre.
function partition(ids, centre) {
  const n = ids.length, lists = 6;
  const idsP = copyIn(ids);
  const buf = rt._malloc(4 * Math.max(1, n) * lists);
  const out = rt._malloc(52);  // pvs_rt_near_far: 6 pointers, capacity, 6 counts
  const o = new Uint32Array(rt.HEAPU8.buffer, out, 13);
  for (let k = 0; k < lists; ++k) o[k] = buf + 4 * Math.max(1, n) * k;
  o[6] = n;
  const c = rt._malloc(24);
  new Float64Array(rt.HEAPU8.buffer, c, 3).set(centre);
  check(rt._pvs_rt_partition_near_far(geometry, idsP, n, c, nearFar.r1, nearFar.r2, out),
        "pvs_rt_partition_near_far");
  const w = new Uint32Array(rt.HEAPU8.buffer, out, 13).slice();
  // w[0..5]: near, intermediate, far static, far dynamic, environment map, geometry; counts w[7..12]
  const farDynamic = idList(w[3], w[10]);
  const dyn = new Set(farDynamic);
  const geometryIds = idList(w[5], w[12]).filter((t) => !dyn.has(t));
  const result = {centre, geometry: geometryIds, farDynamic, environment: idList(w[4], w[11]),
                  near: w[7], intermediate: w[8], farStatic: w[9]};
  for (const p of [idsP, buf, out, c]) rt._free(p);
  return result;
}

function clovrIds(fn, capacity) {
  const out = rt._malloc(4 * Math.max(1, capacity) + 4);
  const countP = out + 4 * Math.max(1, capacity);
  check(fn(clovr, out, capacity, countP), "pvs_rt_clovr ids");
  const ids = idList(out, new Uint32Array(rt.HEAPU8.buffer, countP, 1)[0]);
  rt._free(out);
  return ids;
}

// One frame of the CloVR scheduler: the frame's description, and the sets when they changed.
function clovrNext(total) {
  check(rt._pvs_rt_clovr_next_frame(clovr, clovrFrame), "pvs_rt_clovr_next_frame");
  const u = new Uint32Array(rt.HEAPU8.buffer, clovrFrame, 14);
  const d = new Float64Array(rt.HEAPU8.buffer, clovrFrame, 5);
  const f = {frame: u[0], ring: u[1], ring_count: u[2], ring_radius: d[2], radius: d[3],
             near_radius: d[4], near_changed: u[10], done: u[11], near_count: u[12],
             environment_count: u[13]};
  if (f.near_changed || f.frame === 0) {
    f.near = clovrIds(rt._pvs_rt_clovr_near_ids, total);
    f.environment = clovrIds(rt._pvs_rt_clovr_environment_ids, total);
  }
  return f;
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

// The cells of the viewing disc (radius r about c, horizontal): runtime/ods.h's
// disc_inside_box / disc_touches_box on the cells' boxes (for a grid the view region is the
// box with y replaced by the eye band, the same in x-z; the centre's cell contains c in y).
function cellBox(cell) {
  const p = rt._malloc(48);
  check(rt._pvs_rt_cell_box(handle, cell, p, p + 24), "pvs_rt_cell_box");
  const b = new Float64Array(rt.HEAPU8.buffer, p, 6).slice();
  rt._free(p);
  return b;
}
function discCells(c, r) {
  const cell = lookup(c);
  if (cell < 0) return {cell, cells: [], inRegion: false, ids: new Uint32Array(0)};
  const b = cellBox(cell);
  const inRegion = c[0] - r >= b[0] && c[0] + r <= b[3] && c[2] - r >= b[2] && c[2] + r <= b[5];
  const cells = [cell];
  if (!inRegion) {
    const cap = 4096, out = rt._malloc(4 * cap + 16), countP = out + 4 * cap;
    check(rt._pvs_rt_neighbours(handle, cell, r, out, cap, countP), "pvs_rt_neighbours");
    const n = new Uint32Array(rt.HEAPU8.buffer, countP, 1)[0];
    const near = new Uint32Array(rt.HEAPU8.buffer, out, n).slice();
    rt._free(out);
    for (const u of near) {
      const q = cellBox(u);
      if (c[1] < q[1] || c[1] > q[4]) continue;
      const dx = Math.max(q[0] - c[0], 0, c[0] - q[3]), dz = Math.max(q[2] - c[2], 0, c[2] - q[5]);
      if (dx * dx + dz * dz <= r * r) cells.push(u);
    }
  }
  const union = new Set();
  for (const u of cells) for (const t of visibleIds(u)) union.add(t);
  return {cell, cells, inRegion, ids: Uint32Array.from(union).sort()};
}

self.onmessage = async (ev) => {
  const m = ev.data;
  try {
    if (m.op === "open") {
      const r = await open(m.url);
      self.postMessage({id: m.id, ok: true, ...r});
    } else if (m.op === "geometry") {
      setGeometry(m);
      self.postMessage({id: m.id, ok: true});
    } else if (m.op === "disc") {
      const r = discCells(m.centre, m.radius);
      self.postMessage({id: m.id, ok: true, ...r, bytes: bytesFetched, requests});
    } else if (m.op === "lookup") {
      const before = requests;
      const cell = lookup(m.position);
      const reply = {id: m.id, ok: true, cell};
      if (cell >= 0 && m.have !== cell) {
        reply.ids = visibleIds(cell);
        if (nearFar) {
          const o = cellCentre(cell);
          reply.partition = partition(reply.ids, o.centre);
          reply.partition.centreSource = o.source;
          if (clovr) {
            const c = rt._malloc(24);
            new Float64Array(rt.HEAPU8.buffer, c, 3).set(reply.partition.centre);
            const idsP = copyIn(reply.ids);
            check(rt._pvs_rt_clovr_start(clovr, idsP, reply.ids.length, c), "pvs_rt_clovr_start");
            clovrStarted = true;
            rt._free(idsP);
            rt._free(c);
          }
        }
      }
      if (clovrStarted) reply.clovr = clovrNext(triangleCount);
      reply.bytes = bytesFetched;
      reply.requests = requests;
      reply.lookupRequests = requests - before;  // what this frame waited for
      reply.chainBlocks = chainBlocks;
      self.postMessage(reply);
      if (cell >= 0 && m.have !== cell && m.prefetch >= 0) prefetchNeighbours(cell, m.prefetch);
    }
  } catch (e) {
    self.postMessage({id: m.id, ok: false, error: String(e && e.message ? e.message : e)});
  }
};
