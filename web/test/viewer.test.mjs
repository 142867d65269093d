// The viewer in a real browser (Debian's Chromium, headless, driven by playwright-core): served
// by web/serve.mjs, it opens bunny's `emc` stream, shows its levels one after another as the
// bytes arrive, ends holding exactly the native decoder's mesh, and draws it; a cut stream ends
// in the viewer's error line, not in a hung page. Run by tests/run.sh (tests/chromium.sh
// installs the browser):   node --test web/test/
import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import { execFileSync } from "node:child_process";
import { mkdirSync, readFileSync, writeFileSync } from "node:fs";
import { join } from "node:path";

import { launchChromium } from "../chromium.mjs";
import { serve } from "../serve.mjs";
import { assertSameBits, native, nativeLevel, readPly, root, triangleSet } from "./native.mjs";

const scratch = join(root, "target/web-test");

let browser;
let server;

before(async () => {
  mkdirSync(scratch, { recursive: true });
  execFileSync(native, ["encode", "--codec", "emc", "bunny", join(scratch, "bunny-emc.mc")]);
  const bytes = readFileSync(join(scratch, "bunny-emc.mc"));
  writeFileSync(join(scratch, "bunny-emc-cut.mc"), bytes.subarray(0, Math.floor(bytes.length * 0.6)));
  execFileSync(native, ["encode", "--codec", "came", "bunny", join(scratch, "bunny-came-viewer.mc")]);
  // 200 KB a second: bunny's 68 KB arrive over a third of a second, its levels one by one.
  server = await serve({ root, rate: 200_000 });
  browser = await launchChromium();
});

after(async () => {
  await browser?.close();
  server?.server.close();
});

async function openViewer(stream, until = () => ["done", "error"].includes(window.viewer?.state.status)) {
  const page = await browser.newPage({ viewport: { width: 800, height: 600 } });
  const problems = [];
  page.on("pageerror", (e) => problems.push(`page error: ${e.message}`));
  page.on("console", (m) => m.type() === "error" && problems.push(`console: ${m.text()}`));
  await page.goto(`http://127.0.0.1:${server.port}/web/viewer/index.html?src=/target/web-test/${stream}`);
  await page.waitForFunction(until, null, { timeout: 60_000 });
  return { page, problems };
}

test("the viewer streams bunny's emc levels one by one and ends on the native decode", async () => {
  const stream = join(scratch, "bunny-emc.mc");
  const { page, problems } = await openViewer("bunny-emc.mc");
  const state = await page.evaluate(() => window.viewer.state);
  assert.equal(state.status, "done", state.error ?? "");
  assert.equal(state.codec, "emc");
  assert.equal(state.level, state.levels);
  assert.equal(state.levels, 12);
  // Levels arrived one after another, not all at the end.
  assert.ok(state.levelsSeen.length >= 2, `levels seen: ${state.levelsSeen}`);
  assert.deepEqual(state.levelsSeen, [...state.levelsSeen].sort((a, b) => a - b));
  const positions = new Float64Array(
    await page.evaluate(() => Array.from(window.viewer.mesh.geometry.userData.meshcodec.positions)),
  );
  const indices = new Uint32Array(await page.evaluate(() => Array.from(window.viewer.mesh.geometry.index.array)));
  const theirs = nativeLevel(stream, state.levels, scratch);
  assertSameBits(positions, theirs.positions, "the viewer's last level");
  assert.deepEqual(indices, theirs.indices);
  // The server sent the stream once, whole.
  assert.equal(server.sent.get("/target/web-test/bunny-emc.mc"), readFileSync(stream).length);
  // The mesh is drawn: a good share of the frame is not background.
  await page.waitForFunction((frames) => window.viewer.state.frames > frames + 2, state.frames);
  const shot = await page.screenshot({ path: join(scratch, "viewer-bunny.png") });
  const covered = await page.evaluate(() => {
    const canvas = document.getElementById("view");
    const gl = canvas.getContext("webgl2");
    const pixels = new Uint8Array(gl.drawingBufferWidth * gl.drawingBufferHeight * 4);
    gl.readPixels(0, 0, gl.drawingBufferWidth, gl.drawingBufferHeight, gl.RGBA, gl.UNSIGNED_BYTE, pixels);
    let mesh = 0;
    for (let i = 0; i < pixels.length; i += 4) {
      if (Math.abs(pixels[i] - 0x1d) + Math.abs(pixels[i + 1] - 0x21) + Math.abs(pixels[i + 2] - 0x27) > 24) mesh++;
    }
    return mesh / (pixels.length / 4);
  });
  assert.ok(shot.length > 1000);
  assert.ok(covered > 0.05 && covered < 0.9, `the mesh covers ${covered} of the frame`);
  assert.deepEqual(problems, []);
  await page.close();
});

test("the viewer draws the outline the project's rasterizer draws from the same camera", async (t) => {
  const stream = join(scratch, "bunny-emc.mc");
  const { positions } = nativeLevel(stream, 12, scratch);
  const low = [Infinity, Infinity, Infinity];
  const high = [-Infinity, -Infinity, -Infinity];
  positions.forEach((x, i) => {
    low[i % 3] = Math.min(low[i % 3], x);
    high[i % 3] = Math.max(high[i % 3], x);
  });
  const target = low.map((l, k) => (l + high[k]) / 2);
  const diagonal = Math.hypot(...high.map((h, k) => h - low[k]));
  const eye = [target[0] + 0.4 * diagonal, target[1] + 0.3 * diagonal, target[2] + 1.4 * diagonal];
  const camera = ["--eye", eye.join(","), "--target", target.join(","), "--fov", "40", "--size", "800x600"];
  execFileSync(native, ["render", stream, join(scratch, "reference.png"), ...camera]);
  const { page, problems } = await openViewer(`bunny-emc.mc&eye=${eye.join(",")}&target=${target.join(",")}&fov=40`);
  const frames = await page.evaluate(() => window.viewer.state.frames);
  await page.waitForFunction((n) => window.viewer.state.frames > n + 2, frames);
  const masks = await page.evaluate(async () => {
    const image = new Image();
    image.src = "/target/web-test/reference.png";
    await image.decode();
    const canvas = document.createElement("canvas");
    canvas.width = image.width;
    canvas.height = image.height;
    const context = canvas.getContext("2d");
    context.drawImage(image, 0, 0);
    const reference = context.getImageData(0, 0, image.width, image.height).data;
    const gl = document.getElementById("view").getContext("webgl2");
    const [w, h] = [gl.drawingBufferWidth, gl.drawingBufferHeight];
    const drawn = new Uint8Array(w * h * 4);
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, drawn);
    let both = 0;
    let either = 0;
    let ours = 0;
    let theirs = 0;
    for (let y = 0; y < h; y++) {
      for (let x = 0; x < w; x++) {
        const r = (y * w + x) * 4;
        // The rasterizer's background is white; the viewer's #1d2127, its rows bottom-up.
        const inReference = reference[r] + reference[r + 1] + reference[r + 2] < 3 * 250;
        const d = ((h - 1 - y) * w + x) * 4;
        const inViewer = Math.abs(drawn[d] - 0x1d) + Math.abs(drawn[d + 1] - 0x21) + Math.abs(drawn[d + 2] - 0x27) > 24;
        both += inReference && inViewer;
        either += inReference || inViewer;
        ours += inViewer;
        theirs += inReference;
      }
    }
    return { size: [w, h, image.width, image.height], both, either, ours, theirs };
  });
  assert.deepEqual(masks.size, [800, 600, 800, 600]);
  const overlap = masks.both / masks.either;
  assert.ok(masks.theirs > 0.05 * 800 * 600, `the reference covers ${masks.theirs} pixels`);
  t.diagnostic(`outlines overlap ${overlap.toFixed(4)} (viewer ${masks.ours}, rasterizer ${masks.theirs} pixels)`);
  await page.screenshot({ path: join(scratch, "viewer-camera.png") });
  assert.ok(overlap > 0.97, `outlines overlap ${overlap.toFixed(4)} (viewer ${masks.ours}, rasterizer ${masks.theirs} pixels)`);
  assert.deepEqual(problems, []);
  await page.close();
});

test("a stream with appearance is drawn with its uvs through the checker, a vertex a wedge", async () => {
  const { page, problems } = await openViewer("../../tests/golden/v8/emc-spot-appearance.mc");
  const state = await page.evaluate(() => window.viewer.state);
  assert.equal(state.status, "done", state.error ?? "");
  assert.ok(state.appearance.includes("uvs"), `appearance: ${state.appearance}`);
  // emc carries the appearance with its levels: every level drawn had its uvs.
  assert.ok(state.levelsSeen.length >= 1);
  assert.deepEqual(state.levelsWithUvs, state.levelsSeen);
  const drawn = await page.evaluate(() => {
    const { geometry, material } = window.viewer.mesh;
    const data = geometry.userData.meshcodec;
    return {
      vertices: geometry.getAttribute("position").count,
      uvs: geometry.getAttribute("uv")?.count ?? 0,
      wedges: data.appearance.wedgeVertex.length,
      textured: [material].flat().every((m) => m.map !== null),
    };
  });
  assert.equal(drawn.vertices, drawn.wedges);
  assert.equal(drawn.uvs, drawn.wedges);
  assert.ok(drawn.textured);
  await page.screenshot({ path: join(scratch, "viewer-spot.png") });
  assert.deepEqual(problems, []);
  await page.close();
});

test("a cut stream ends in the viewer's error line", async () => {
  const { page, problems } = await openViewer("bunny-emc-cut.mc");
  const state = await page.evaluate(() => window.viewer.state);
  assert.equal(state.status, "error");
  assert.match(state.error, /ended after \d+ bytes/);
  assert.ok(state.level >= 1, "the levels its bytes hold were shown");
  assert.equal(await page.textContent("#error"), state.error);
  assert.deepEqual(problems, []);
  await page.close();
});

test("a came stream is refined to the viewer's camera from the meta-nodes it fetches by range", async (t) => {
  const stream = join(scratch, "bunny-came-viewer.mc");
  const path = "/target/web-test/bunny-came-viewer.mc";
  const size = readFileSync(stream).length;
  // A close look at the bunny's flank, as experiment came-vd's near view.
  const eye = [-0.0775, 0.1389, 0.0767];
  const target = [-0.0775, 0.1317, 0.0527];
  const { page, problems } = await openViewer(
    `bunny-came-viewer.mc&eye=${eye.join(",")}&target=${target.join(",")}&fov=50`,
    () => window.viewer?.state.status === "error" || window.viewer?.state.came?.settled,
  );
  const state = await page.evaluate(() => window.viewer.state);
  assert.equal(state.error, null);
  assert.equal(state.codec, "came");
  const came = state.came;
  t.diagnostic(
    `first frame after ${came.firstFrameBytes} bytes; settled with ${state.faces} faces after ${came.bytesRead} of ${size} bytes, ${came.unitsLoaded} of ${came.units} meta-nodes, ${came.views} adaptations`,
  );
  // The server sent what the viewer read, and no more: a part of the stream, by Range
  // requests; before the first frame, one request for the head.
  assert.equal(server.sent.get(path), came.bytesRead);
  const asked = server.requests.filter((r) => r.path === path);
  assert.ok(asked.every((r) => r.status === 206));
  assert.equal(asked[0].start, 0);
  assert.equal(asked[0].end + 1, came.firstFrameBytes, "the first frame after the first request");
  t.diagnostic(`${asked.length} requests`);
  assert.ok(came.bytesRead < 0.9 * size, `read ${came.bytesRead} of ${size} bytes`);
  assert.ok(came.firstFrameBytes < size / 4, `first frame after ${came.firstFrameBytes} bytes`);
  // The mesh it holds is the one meshcodec view makes for the same camera and viewport.
  const out = join(scratch, "viewer-came-native.ply");
  execFileSync(native, ["view", stream, out, "--eye", eye.join(","), "--target", target.join(","), "--fov", "50", "--size", "800x600"]);
  const theirs = readPly(out);
  const ours = await page.evaluate(() => {
    const data = window.viewer.mesh.geometry.userData.meshcodec;
    return { positions: Array.from(data.positions), indices: Array.from(data.indices) };
  });
  assertSameBits(new Float64Array(ours.positions), theirs.positions, "the viewer's adapted mesh");
  assert.deepEqual(triangleSet(new Uint32Array(ours.indices)), triangleSet(theirs.indices));
  // Drawn: the flank fills much of the frame.
  await page.waitForFunction((frames) => window.viewer.state.frames > frames + 2, state.frames);
  await page.screenshot({ path: join(scratch, "viewer-came.png") });
  assert.deepEqual(problems, []);
  await page.close();
});
