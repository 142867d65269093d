// Packed glTF scenes (`meshcodec pack`, docs/GLTF.md) as users load them: every packed file has
// no glTF-Validator error; in headless Chromium, three.js's stock GLTFLoader draws each scene's
// fallbacks, and with the meshcodec plugin every primitive ends on the native decode of its
// stream, bit for bit, each level textured as it arrives; a cut streams' file leaves a valid
// coarser scene and an error line. Run by tests/run.sh:   node --test web/test/
import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import { execFileSync } from "node:child_process";
import { mkdirSync, readFileSync, writeFileSync } from "node:fs";
import { join } from "node:path";
import validator from "gltf-validator";

import { launchChromium } from "../chromium.mjs";
import { serve } from "../serve.mjs";
import { assertSameBits, native, nativeLevel, root } from "./native.mjs";

const scratch = join(root, "target/web-test/gltf");

/** A GLB's JSON and binary chunk. */
function readGlb(bytes) {
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  assert.equal(view.getUint32(0, true), 0x46546c67);
  const jsonLength = view.getUint32(12, true);
  const json = JSON.parse(Buffer.from(bytes.subarray(20, 20 + jsonLength)).toString("utf8"));
  const binAt = 20 + jsonLength;
  const bin = binAt < bytes.length ? bytes.subarray(binAt + 8, binAt + 8 + view.getUint32(binAt, true)) : null;
  return { json, bin };
}

/** A GLB of `json` and `bin`. */
function writeGlb(json, bin) {
  let text = Buffer.from(JSON.stringify(json));
  text = Buffer.concat([text, Buffer.alloc((4 - (text.length % 4)) % 4, 0x20)]);
  const padded = Buffer.concat([bin, Buffer.alloc((4 - (bin.length % 4)) % 4)]);
  const header = Buffer.alloc(12);
  header.writeUInt32LE(0x46546c67, 0);
  header.writeUInt32LE(2, 4);
  header.writeUInt32LE(12 + 8 + text.length + 8 + padded.length, 8);
  const chunk = (length, type) => {
    const b = Buffer.alloc(8);
    b.writeUInt32LE(length, 0);
    b.writeUInt32LE(type, 4);
    return b;
  };
  return Buffer.concat([header, chunk(text.length, 0x4e4f534a), text, chunk(padded.length, 0x004e4942), padded]);
}

const scenes = {};
let browser;
let server;

before(async () => {
  mkdirSync(scratch, { recursive: true });
  const pack = (input, output, ...args) => {
    execFileSync(native, ["pack", input, join(scratch, output), ...args], { stdio: "pipe" });
    return join(scratch, output);
  };
  scenes.spot = pack("spot", "spot.glb");
  scenes.bunny = pack("bunny-10k-textured", "bunny-10k-textured.glb");
  scenes.airplane = pack("airplane-colored", "airplane-colored.glb");
  // A scene of mixed primitives: spot's triangles, and the same positions as points in a mesh
  // of their own, which pack keeps as they are.
  execFileSync(native, ["convert", "spot", join(scratch, "spot-plain.glb")], { stdio: "pipe" });
  const { json, bin } = readGlb(readFileSync(join(scratch, "spot-plain.glb")));
  const position = json.meshes[0].primitives[0].attributes.POSITION;
  json.meshes.push({ name: "points", primitives: [{ attributes: { POSITION: position }, mode: 0 }] });
  json.nodes.push({ mesh: json.meshes.length - 1, translation: [2, 0, 0], name: "points" });
  json.scenes[0].nodes.push(json.nodes.length - 1);
  writeFileSync(join(scratch, "mixed-plain.glb"), writeGlb(json, bin));
  scenes.mixed = pack(join(scratch, "mixed-plain.glb"), "mixed.glb");
  // Streams in a file of their own, and that file cut short.
  scenes.external = pack("spot", "spot-external.glb", "--external");
  const streams = readFileSync(join(scratch, "spot-external.streams.bin"));
  pack("spot", "spot-cut.glb", "--external");
  writeFileSync(join(scratch, "spot-cut.streams.bin"), streams.subarray(0, Math.floor(streams.length * 0.5)));
  server = await serve({ root, rate: 2_000_000 });
  browser = await launchChromium();
});

after(async () => {
  await browser?.close();
  server?.server.close();
});

test("every packed file passes glTF-Validator without an error", async () => {
  for (const [name, path] of Object.entries(scenes)) {
    const report = await validator.validateBytes(new Uint8Array(readFileSync(path)), {
      uri: path,
      externalResourceFunction: (uri) => Promise.resolve(new Uint8Array(readFileSync(join(scratch, decodeURIComponent(uri))))),
    });
    const errors = report.issues.messages.filter((m) => m.severity === 0).map((m) => `${m.code} ${m.pointer}`);
    assert.deepEqual(errors, [], `${name}: ${errors.join("; ")}`);
  }
});

/** The viewer on a scene of the scratch folder, once it has loaded it (and refined it). */
async function openScene(file, plugin = true) {
  const page = await browser.newPage({ viewport: { width: 640, height: 480 } });
  const problems = [];
  page.on("pageerror", (e) => problems.push(`page error: ${e.message}`));
  page.on("console", (m) => m.type() === "error" && problems.push(`console: ${m.text()}`));
  const query = `src=/target/web-test/gltf/${file}${plugin ? "" : "&plugin=off"}`;
  await page.goto(`http://127.0.0.1:${server.port}/web/viewer/index.html?${query}`);
  await page.waitForFunction(() => ["done", "error"].includes(window.viewer?.state.status), null, { timeout: 60_000 });
  return { page, problems };
}

/** Each packed primitive's extension, by "mesh/primitive". */
function packedPrimitives(path) {
  const { json } = readGlb(readFileSync(path));
  const out = {};
  json.meshes.forEach((m, i) =>
    m.primitives.forEach((p, j) => {
      if (p.extensions?.MESHCODEC_progressive) out[`${i}/${j}`] = p.extensions.MESHCODEC_progressive;
    }),
  );
  return out;
}

test("the stock GLTFLoader draws every packed scene's fallbacks", async () => {
  for (const [name, path] of Object.entries(scenes)) {
    if (name === "external") continue;
    const { page, problems } = await openScene(path.split("/").pop(), false);
    const state = await page.evaluate(() => window.viewer.state);
    assert.equal(state.status, "done", `${name}: ${state.error}`);
    const fallbackFaces = Object.values(packedPrimitives(path)).reduce(
      (sum, e) => sum + e.levels[e.fallbackLevel - 1].faces,
      0,
    );
    assert.equal(state.faces, fallbackFaces, name);
    assert.ok((await page.evaluate(() => window.viewer.state.frames)) > 0, name);
    assert.deepEqual(problems, [], name);
    await page.close();
  }
});

test("with the plugin every primitive ends on the native decode of its stream, each level textured", async () => {
  for (const name of ["spot", "bunny", "airplane", "mixed", "external"]) {
    const path = scenes[name];
    const { page, problems } = await openScene(path.split("/").pop());
    const state = await page.evaluate(() => window.viewer.state);
    assert.equal(state.status, "done", `${name}: ${state.error}`);
    const packed = packedPrimitives(path);
    assert.equal(state.gltf.refined, Object.keys(packed).length, name);
    const { json, bin } = readGlb(readFileSync(path));
    const external = name === "external" ? readFileSync(join(scratch, "spot-external.streams.bin")) : null;
    for (const [key, extension] of Object.entries(packed)) {
      const [meshIndex, primitive] = key.split("/").map(Number);
      assert.equal(state.gltf.levels[key], extension.levels.length, `${name} ${key}`);
      const view = json.bufferViews[extension.bufferView];
      const buffer = json.buffers[view.buffer].uri ? external : bin;
      const stream = buffer.subarray(view.byteOffset ?? 0, (view.byteOffset ?? 0) + view.byteLength);
      const file = join(scratch, `${name}-${meshIndex}-${primitive}.mc`);
      writeFileSync(file, stream);
      const theirs = nativeLevel(file, extension.levels.length, scratch);
      // GLTFLoader's associations name each object's mesh and primitive.
      const ours = await page.evaluate(
        ([m, p]) => {
          const { scene, parser } = window.viewer.gltf;
          let found = null;
          scene.traverse((o) => {
            const at = o.isMesh && parser.associations.get(o);
            if (at && at.meshes === m && (at.primitives ?? 0) === p) found = o;
          });
          return Array.from(found.geometry.userData.meshcodec.positions);
        },
        [meshIndex, primitive],
      );
      assertSameBits(new Float64Array(ours), theirs.positions, `${name} ${key}`);
    }
    if (name !== "airplane") {
      assert.equal(state.levelsWithUvs.length, state.levelsSeen.length, `${name}: every level has uvs`);
    }
    assert.deepEqual(problems, [], name);
    await page.close();
  }
});

test("a cut streams' file leaves a valid coarser scene and an error line", async () => {
  const { page, problems } = await openScene("spot-cut.glb");
  const state = await page.evaluate(() => window.viewer.state);
  assert.equal(state.status, "error");
  assert.match(state.error, /ended after \d+ bytes/);
  const [extension] = Object.values(packedPrimitives(join(scratch, "spot-cut.glb")));
  const level = state.gltf.levels["0/0"];
  assert.ok(level >= extension.fallbackLevel && level < extension.levels.length, `level ${level}`);
  assert.equal(state.faces, extension.levels[level - 1].faces);
  assert.deepEqual(
    problems.filter((p) => !p.includes("ended after")),
    [],
  );
  await page.close();
});
