// web_check.mjs: drives the web client in Debian's chromium, headless (WebGL2 through
// SwiftShader), with puppeteer-core: replays a path frame by frame and writes what each frame
// did (scripts/web-check.sh starts the server and calls this). WebGPU (the ods and stereo modes)
// comes from SwiftShader too, with --enable-unsafe-webgpu on a page served from 127.0.0.1. A page
// whose viewer offers framePng() (the ods and stereo modes) gives its own frame's pixels for the
// PNGs; otherwise they are screenshots. With the overlays shown, it also records where they lie
// after the last frame (`layout`, see overlayLayout) and that key H hides and shows them again.
//
// node web_check.mjs --url PAGE_URL --json OUT [--png-dir DIR --png-frames 0,5,9] [--size WxH]
//                    [--server-log FILE --pvs-name NAME] [--chromium PATH]
// Exit: 0 done, 1 the page failed, 2 bad arguments, 77 chromium cannot start or the page's mode
// needs WebGPU and chromium offers none (a skip for ctest).
import fs from "node:fs";
import path from "node:path";
import os from "node:os";
import puppeteer from "puppeteer-core";

// How long to wait for the server's log to record the page's last requests (milliseconds).
const kServerLogWaitMs = 10000;

function args() {
  const a = {pngFrames: []};
  const argv = process.argv.slice(2);
  for (let i = 0; i < argv.length; i += 2) {
    const k = argv[i], v = argv[i + 1];
    if (v === undefined) throw new Error(`${k}: missing value`);
    if (k === "--url") a.url = v;
    else if (k === "--json") a.json = v;
    else if (k === "--png-dir") a.pngDir = v;
    else if (k === "--png-frames") a.pngFrames = v.split(",").filter((s) => s).map(Number);
    else if (k === "--server-log") a.serverLog = v;
    else if (k === "--pvs-name") a.pvsName = v;
    else if (k === "--chromium") a.chromium = v;
    else if (k === "--size") a.size = v.split("x").map(Number);
    else throw new Error(`unknown option ${k}`);
  }
  if (!a.url || !a.json) throw new Error("--url and --json are required");
  return a;
}

function findChromium() {
  for (const p of ["/usr/lib/chromium/chromium", "/usr/bin/chromium", "/usr/bin/chromium-browser"])
    if (fs.existsSync(p)) return p;
  return null;
}

// The overlays' boxes (getBoundingClientRect, CSS pixels) in the page's viewport, and what is
// wrong with them: each must lie inside the viewport in its own corner (overlay: top left, map:
// top right, help: bottom left), none may overlap another, the map's side may not exceed 30% of
// the viewport's shorter side (+1 px of rounding), and no text may be clipped (an element's
// scrolling size beyond its client size). Runs in the page.
function overlayLayout() {
  const W = innerWidth, H = innerHeight, boxes = {}, problems = [];
  for (const id of ["overlay", "map", "help"]) {
    const e = document.getElementById(id);
    if (getComputedStyle(e).display === "none") continue;
    const r = e.getBoundingClientRect();
    boxes[id] = {left: r.left, top: r.top, right: r.right, bottom: r.bottom,
                 clipped: e.scrollWidth > e.clientWidth || e.scrollHeight > e.clientHeight};
  }
  const corner = {overlay: (b) => b.left < W / 2 && b.top < H / 2,
                  map: (b) => b.right > W / 2 && b.top < H / 2,
                  help: (b) => b.left < W / 2 && b.bottom > H / 2};
  const ids = Object.keys(boxes);
  for (const id of ids) {
    const b = boxes[id];
    if (b.left < 0 || b.top < 0 || b.right > W || b.bottom > H) problems.push(`${id} leaves the viewport`);
    if (!corner[id](b)) problems.push(`${id} is not in its corner`);
    if (b.clipped) problems.push(`${id}'s text is clipped`);
  }
  for (let i = 0; i < ids.length; ++i)
    for (let j = i + 1; j < ids.length; ++j) {
      const a = boxes[ids[i]], b = boxes[ids[j]];
      if (a.left < b.right && b.left < a.right && a.top < b.bottom && b.top < a.bottom)
        problems.push(`${ids[i]} and ${ids[j]} overlap`);
    }
  if (boxes.map && boxes.map.right - boxes.map.left > 0.3 * Math.min(W, H) + 1)
    problems.push(`the map is ${boxes.map.right - boxes.map.left} px wide, over 30% of ${Math.min(W, H)} px`);
  return {viewport: [W, H], boxes, problems};
}

async function main() {
  let a;
  try {
    a = args();
  } catch (e) {
    console.error(`web_check: ${e.message}`);
    return 2;
  }
  const exe = a.chromium || findChromium();
  if (!exe) {
    console.error("web_check: SKIPPED: no chromium (bash scripts/install-web-deps.sh installs it)");
    return 77;
  }
  const profile = fs.mkdtempSync(path.join(os.tmpdir(), "vislib-chromium-"));
  let browser;
  try {
    browser = await puppeteer.launch({
      executablePath: exe,
      headless: true,
      userDataDir: profile,
      args: ["--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--enable-unsafe-webgpu", "--no-sandbox",
             "--disable-background-networking", "--disable-component-update", "--disable-sync",
             "--no-first-run", "--disable-dev-shm-usage"],
      timeout: 60000,
    });
  } catch (e) {
    console.error(`web_check: SKIPPED: chromium (${exe}) cannot start: ${e.message.split("\n")[0]}`);
    fs.rmSync(profile, {recursive: true, force: true});
    return 77;
  }
  let code = 0;
  try {
    const page = await browser.newPage();
    if (a.size) await page.setViewport({width: a.size[0], height: a.size[1]});
    const errors = [];
    page.on("console", (m) => {
      if (m.type() === "error" || m.type() === "warning") errors.push(m.text());
    });
    page.on("pageerror", (e) => errors.push(String(e)));
    await page.goto(a.url, {waitUntil: "load", timeout: 120000});
    let info;
    try {
      info = await page.evaluate(() => window.viewerReady);
    } catch (e) {
      if (/needs WebGPU/.test(e.message)) {
        console.error(`web_check: SKIPPED: ${e.message.split("\n")[0]}`);
        code = 77;
        return code;
      }
      throw new Error(`the page failed to open: ${e.message}\n${errors.join("\n")}`);
    }
    const gpu = await page.evaluate(() => {
      const gl = document.createElement("canvas").getContext("webgl2");
      const d = gl && gl.getExtension("WEBGL_debug_renderer_info");
      return gl ? (d ? gl.getParameter(d.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER)) : null;
    });
    const n = await page.evaluate(() => window.viewer.path ? window.viewer.path.length : 0);
    const frames = [];
    if (a.pngDir) fs.mkdirSync(a.pngDir, {recursive: true});
    for (let i = 0; i < n; ++i) {
      const rec = await page.evaluate((k) => window.viewer.step(k), i);
      if (a.pngFrames.includes(i)) {
        rec.png = path.join(a.pngDir || ".", `frame_${String(i).padStart(4, "0")}.png`);
        const own = await page.evaluate(() => typeof window.viewer.framePng === "function");
        if (own) {
          const url = await page.evaluate(() => window.viewer.framePng());
          fs.writeFileSync(rec.png, Buffer.from(url.slice(url.indexOf(",") + 1), "base64"));
        } else {
          await page.screenshot({path: rec.png});
        }
      }
      frames.push(rec);
    }
    let layout = null;
    // A page without the overlays (range.html) has nothing to lay out.
    const shown = () => page.evaluate(() => ["overlay", "map", "help"].map((id) => {
      const el = document.getElementById(id);
      return el !== null && getComputedStyle(el).display !== "none";
    }));
    if ((await shown()).every((v) => v)) {
      layout = await page.evaluate(overlayLayout);
      await page.keyboard.press("h");
      layout.hidden_by_h = (await shown()).every((v) => !v);
      await page.keyboard.press("h");
      layout.shown_again_by_h = (await shown()).every((v) => v);
    }
    const ms = frames.map((f) => f.ms).sort((x, y) => x - y);
    const out = {
      url: a.url, renderer: gpu, chromium: await browser.version(), ...info,
      frames,
      layout,
      summary: {
        frames: n,
        ms_median: ms.length ? ms[Math.floor(ms.length / 2)] : null,
        ms_max: ms.length ? ms[ms.length - 1] : null,
        bytes_fetched: frames.length ? frames[frames.length - 1].bytes_fetched : 0,
        range_requests: frames.length ? frames[frames.length - 1].range_requests : 0,
      },
      page_errors: errors,
    };
    if (a.serverLog && fs.existsSync(a.serverLog)) {
      // The server records a request after its body is sent, so the page can hold the last
      // block before the record is written: wait until the log holds every range request the
      // page made, or kServerLogWaitMs. A line without its newline is still being written.
      const servedNow = () => fs.readFileSync(a.serverLog, "utf8").split("\n").slice(0, -1)
        .filter((l) => l)
        .map((l) => JSON.parse(l)).filter((r) => !a.pvsName || r.path.endsWith("/" + a.pvsName));
      let served = servedNow();
      for (const end = Date.now() + kServerLogWaitMs;
        served.length < out.summary.range_requests && Date.now() < end;
        served = servedNow()) {
        await new Promise((done) => setTimeout(done, 50));
      }
      out.server = {requests: served.length, bytes: served.reduce((s, r) => s + r.bytes, 0),
                    ranges: served.map((r) => r.range)};
    }
    fs.writeFileSync(a.json + ".tmp", JSON.stringify(out, null, 1) + "\n");
    fs.renameSync(a.json + ".tmp", a.json);
    if (errors.length) {
      console.error(`web_check: the page reported errors:\n${errors.join("\n")}`);
      code = 1;
    }
    console.log(`web_check: ${n} frames, median ${out.summary.ms_median?.toFixed(1)} ms/frame, ` +
                `${out.summary.bytes_fetched} PVS bytes fetched (${gpu}) -> ${a.json}`);
  } catch (e) {
    console.error(`web_check: ${e.message}`);
    code = 1;
  } finally {
    await browser.close();
    fs.rmSync(profile, {recursive: true, force: true});
  }
  return code;
}

process.exit(await main());
