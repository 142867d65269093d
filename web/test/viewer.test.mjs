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
import { chromium } from "playwright-core";

import { serve } from "../serve.mjs";
import { assertSameBits, native, nativeLevel, root } from "./native.mjs";

const scratch = join(root, "target/web-test");
const CHROMIUM_FLAGS = [
  "--headless",
  "--no-sandbox",
  "--disable-gpu",
  "--enable-unsafe-swiftshader",
  "--disable-quic",
  "--no-first-run",
  "--disable-background-networking",
  "--disable-component-update",
  "--disable-sync",
];

let browser;
let server;

before(async () => {
  mkdirSync(scratch, { recursive: true });
  execFileSync(native, ["encode", "--codec", "emc", "bunny", join(scratch, "bunny-emc.mc")]);
  const bytes = readFileSync(join(scratch, "bunny-emc.mc"));
  writeFileSync(join(scratch, "bunny-emc-cut.mc"), bytes.subarray(0, Math.floor(bytes.length * 0.6)));
  // 200 KB a second: bunny's 68 KB arrive over a third of a second, its levels one by one.
  server = await serve({ root, rate: 200_000 });
  browser = await chromium.launch({
    executablePath: process.env.CHROMIUM ?? "/usr/bin/chromium",
    args: CHROMIUM_FLAGS,
  });
});

after(async () => {
  await browser?.close();
  server?.server.close();
});

async function openViewer(stream) {
  const page = await browser.newPage({ viewport: { width: 800, height: 600 } });
  const problems = [];
  page.on("pageerror", (e) => problems.push(`page error: ${e.message}`));
  page.on("console", (m) => m.type() === "error" && problems.push(`console: ${m.text()}`));
  await page.goto(`http://127.0.0.1:${server.port}/web/viewer/index.html?src=/target/web-test/${stream}`);
  await page.waitForFunction(() => ["done", "error"].includes(window.viewer?.state.status), null, { timeout: 60_000 });
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

test("a stream with appearance is drawn with its uvs through the checker, a vertex a wedge", async () => {
  const { page, problems } = await openViewer("../../tests/golden/v4/emc-spot-appearance.mc");
  const state = await page.evaluate(() => window.viewer.state);
  assert.equal(state.status, "done", state.error ?? "");
  assert.ok(state.appearance.includes("uvs"), `appearance: ${state.appearance}`);
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
