// The WebAssembly package against the native decoder: every golden stream decodes in Node exactly
// as `meshcodec decode` decodes it (positions to the last bit, faces, level counts), level by
// level and fed in chunks; cut and corrupted streams end in an Error with the library's message,
// never in a trap. Run by tests/run.sh after `bash web/build.sh` and the release build:
//   node --test web/test/
import { test } from "node:test";
import assert from "node:assert/strict";
import { mkdtempSync, readdirSync, readFileSync, rmSync, statSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { fileURLToPath } from "node:url";

import init, { decode, info, levelEnds, ProgressiveDecoder } from "../pkg/meshcodec.js";
import { assertSameBits, nativeAppearance, nativeLevel } from "./native.mjs";

const root = fileURLToPath(new URL("../../", import.meta.url));
await init({ module_or_path: readFileSync(join(root, "web/pkg/meshcodec_bg.wasm")) });

/** Every golden stream of tests/golden/ (all format versions). */
function goldenStreams() {
  const dir = join(root, "tests/golden");
  return readdirSync(dir)
    .filter((d) => statSync(join(dir, d)).isDirectory())
    .flatMap((d) => readdirSync(join(dir, d)).filter((f) => f.endsWith(".mc")).map((f) => join(dir, d, f)))
    .sort();
}

const streams = goldenStreams();

test("there are golden streams of every codec", () => {
  const codecs = new Set(streams.map((s) => info(readFileSync(s)).codec));
  for (const codec of ["raw", "emc-paper", "emc", "pm", "pm-reordered", "came-paper", "came"]) {
    assert.ok(codecs.has(codec), `no golden stream of ${codec}`);
  }
});

for (const stream of streams) {
  const name = stream.slice(join(root, "tests/golden/").length);
  test(`${name} decodes as natively, every level`, () => {
    const bytes = new Uint8Array(readFileSync(stream));
    const described = info(bytes);
    assert.deepEqual(Array.from(levelEnds(bytes)), Array.from(described.levelEnds));
    const scratch = mkdtempSync(join(tmpdir(), "meshcodec-web-"));
    try {
      for (let level = 1; level <= described.levels; level++) {
        const ours = decode(bytes, level);
        assert.equal(ours.level, level);
        assert.equal(ours.levels, described.levels);
        assert.equal(ours.codec, described.codec);
        const theirs = nativeLevel(stream, level, scratch);
        assertSameBits(ours.positions, theirs.positions, `${name} level ${level}`);
        assert.deepEqual(ours.indices, theirs.indices, `${name} level ${level}: faces`);
      }
      const full = decode(bytes);
      assert.equal(full.level, described.levels);
      assert.equal(full.appearance !== null, described.appearance !== null, `${name}: appearance`);
      if (full.appearance) {
        const a = full.appearance;
        const theirs = nativeAppearance(stream, scratch);
        assert.deepEqual(Array.from(a.corners), theirs.corners, `${name}: corner wedges`);
        if (a.uvs) assertSameBits(a.uvs, Float64Array.from(theirs.uvs), `${name}: uvs`);
        else assert.equal(theirs.uvs.length, 0);
        if (a.normals) assertSameBits(a.normals, Float64Array.from(theirs.normals), `${name}: normals`);
        else assert.equal(theirs.normals.length, 0);
        if (a.materials) {
          const names = Array.from(a.materials.face, (m) => a.materials.names[m]);
          assert.deepEqual(names, theirs.faceMaterial, `${name}: materials`);
        }
        if (a.colours) {
          for (let w = 0; w < a.wedgeVertex.length; w++) {
            const rgb = Array.from(a.colours.subarray(w * 4, w * 4 + 3));
            assert.deepEqual(rgb, theirs.colours[a.wedgeVertex[w]], `${name}: colour of wedge ${w}`);
          }
        }
        // Each corner's wedge belongs to the corner's vertex.
        for (let c = 0; c < a.corners.length; c++) assert.equal(a.wedgeVertex[a.corners[c]], full.indices[c]);
      }
    } finally {
      rmSync(scratch, { recursive: true, force: true });
    }
  });

  test(`${name} fed in chunks hands over each level as its bytes arrive`, () => {
    const bytes = new Uint8Array(readFileSync(stream));
    const ends = Array.from(levelEnds(bytes));
    const decoder = new ProgressiveDecoder();
    const chunk = Math.max(1, Math.ceil(bytes.length / 37));
    let last = 0;
    for (let at = 0; at < bytes.length; at += chunk) {
      const end = Math.min(bytes.length, at + chunk);
      const level = decoder.push(bytes.subarray(at, end));
      const complete = ends.filter((e) => e <= end).length;
      if (level === undefined) {
        assert.equal(complete, last, `${name}: a level completed at byte ${end} was not handed over`);
        continue;
      }
      assert.equal(level.level, complete);
      const whole = decode(bytes, complete);
      assertSameBits(level.positions, whole.positions, `${name} level ${complete} from chunks`);
      last = complete;
    }
    assert.equal(last, ends.length);
    decoder.free();
  });
}

test("cut and corrupted streams end in an Error with the library's message", () => {
  let refused = 0;
  for (const stream of streams) {
    const bytes = new Uint8Array(readFileSync(stream));
    const cuts = [0, 1, 5, 17, 40, bytes.length >> 3, bytes.length >> 1, bytes.length - 1];
    const variants = cuts.filter((n) => n < bytes.length).map((n) => bytes.slice(0, n));
    for (let k = 0; k < 24; k++) {
      const broken = bytes.slice();
      const at = (k * 7919 + 13) % broken.length;
      broken[at] ^= 1 << (k % 8);
      variants.push(broken);
    }
    for (const variant of variants) {
      try {
        decode(variant);
      } catch (e) {
        assert.ok(e instanceof Error, `${stream}: threw ${e}`);
        assert.ok(!(e instanceof WebAssembly.RuntimeError), `${stream}: the module trapped: ${e}`);
        assert.ok(e.message.length > 0 && !e.message.includes("\n"), e.message);
        refused++;
      }
    }
  }
  assert.ok(refused > streams.length * 4, `only ${refused} refused`);
});
