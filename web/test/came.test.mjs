// CAME's view-dependent refinement in WebAssembly: CameStream, fetching meta-nodes by byte range
// from the header, the index and the first unit, ends on the mesh `meshcodec view` writes for the
// same camera (positions to the last bit, faces, meta-nodes read), reads only the units the view
// needs, and turns bad input into Errors. Run by tests/run.sh:   node --test web/test/
import { test, before } from "node:test";
import assert from "node:assert/strict";
import { execFileSync } from "node:child_process";
import { mkdirSync, readFileSync } from "node:fs";
import { join } from "node:path";

import { init } from "../index.js";
import { CameStream, bytesReader } from "../came.js";
import { assertSameBits, native, readPly, root, triangleSet } from "./native.mjs";

await init();

const scratch = join(root, "target/web-test");
const bunny = join(scratch, "bunny-came.mc");

before(() => {
  mkdirSync(scratch, { recursive: true });
  execFileSync(native, ["encode", "--codec", "came", "bunny", bunny]);
});

/** The mesh `meshcodec view` writes (binary PLY) and the meta-nodes it says it read. */
function nativeView(stream, camera, extra = []) {
  const out = join(scratch, "came-view.ply");
  const said = execFileSync(native, [
    "view", stream, out,
    "--eye", camera.eye.join(","), "--target", camera.target.join(","), "--up", camera.up.join(","),
    "--fov", String(camera.fov), "--size", `${camera.width}x${camera.height}`, ...extra,
  ]).toString();
  const units = Number(/(\d+) of \d+ meta-nodes/.exec(said)[1]);
  return { ...readPly(out), units };
}

/** Bytes served by range, counting what was asked for. */
function countingReader(bytes) {
  const read = bytesReader(bytes);
  const served = { bytes: 0, requests: 0 };
  const counted = async (start, end) => {
    const part = await read(start, end);
    served.bytes += part.length;
    served.requests++;
    return part;
  };
  return [counted, served];
}

// The bunny's came stream (about 0.25 units across, centred near (−0.017, 0.11, 0)).
const cameras = {
  whole: { eye: [-0.0168, 0.218, 0.358], target: [-0.0168, 0.110, -0.0015], up: [0, 1, 0], fov: 50, width: 1280, height: 720 },
  close: { eye: [-0.0775, 0.1389, 0.0767], target: [-0.0775, 0.1317, 0.0527], up: [0, 1, 0], fov: 50, width: 1280, height: 720 },
  far: { eye: [-0.0168, 1.548, 4.79], target: [-0.0168, 0.110, -0.0015], up: [0, 1, 0], fov: 50, width: 1280, height: 720 },
};

for (const [name, camera] of Object.entries(cameras)) {
  test(`bunny's came stream seen ${name}: the mesh meshcodec view writes, from the units it reads`, async () => {
    const bytes = new Uint8Array(readFileSync(bunny));
    const [read, served] = countingReader(bytes);
    const stream = await CameStream.open(read);
    const first = stream.fetched();
    assert.equal(first.unitsLoaded, 1, "the first unit only");
    assert.ok(first.bytesRead < bytes.length / 4, `opening read ${first.bytesRead} of ${bytes.length} bytes`);
    const result = await stream.refine(camera);
    assert.ok(result.settled, `not settled after ${result.rounds} rounds`);
    const theirs = nativeView(bunny, camera);
    assertSameBits(result.mesh.positions, theirs.positions, `${name}: positions`);
    assert.deepEqual(triangleSet(result.mesh.indices), triangleSet(theirs.indices), `${name}: faces`);
    assert.equal(result.unitsLoaded, theirs.units, "meta-nodes read");
    // Every byte fetched was a byte asked for, once.
    assert.equal(served.bytes, result.bytesRead);
    assert.equal(served.requests, result.requests);
    assert.ok(result.bytesRead <= bytes.length);
    stream.free();
  });
}

test("a close view reads a part of the stream, not all of it", async () => {
  const bytes = new Uint8Array(readFileSync(bunny));
  const stream = await CameStream.open(bytesReader(bytes));
  const result = await stream.refine(cameras.close);
  assert.ok(result.unitsLoaded < result.units, `${result.unitsLoaded} of ${result.units} units`);
  assert.ok(result.bytesRead < 0.9 * bytes.length, `${result.bytesRead} of ${bytes.length} bytes`);
  stream.free();
});

test("the golden came and came-paper streams refine as natively", async () => {
  for (const file of ["v8/came-beethoven.mc", "v8/came-paper-beethoven.mc", "v8/came-eight.mc"]) {
    const path = join(root, "tests/golden", file);
    const bytes = new Uint8Array(readFileSync(path));
    const stream = await CameStream.open(bytesReader(bytes), { firstRequest: 64 });
    // Beethoven and the eight both lie within a few units of the origin.
    const camera = { eye: [0.3, 0.5, 4], target: [0, 0, 0], up: [0, 1, 0], fov: 50, width: 640, height: 480 };
    const result = await stream.refine(camera);
    const theirs = nativeView(path, camera);
    assertSameBits(result.mesh.positions, theirs.positions, file);
    assert.deepEqual(triangleSet(result.mesh.indices), triangleSet(theirs.indices), file);
    stream.free();
  }
});

test("bad input ends in Errors with the library's message, never a trap", async () => {
  const bytes = new Uint8Array(readFileSync(bunny));
  const emc = new Uint8Array(readFileSync(join(root, "tests/golden/v8/emc-eight.mc")));
  await assert.rejects(CameStream.open(bytesReader(emc)), /emc streams hold no vertex hierarchy/);
  await assert.rejects(CameStream.open(bytesReader(bytes.subarray(0, 20))), /ends after 20 bytes|truncated/);
  const corrupt = bytes.slice();
  corrupt[3] ^= 0xff;
  await assert.rejects(CameStream.open(bytesReader(corrupt)), Error);
  // Units cut or supplied twice: refused, or an Error; the front stays usable.
  const stream = await CameStream.open(bytesReader(bytes));
  const { adapted, fetched } = stream.round(cameras.whole);
  assert.ok(adapted.waiting > 0);
  const units = await fetched;
  const [unit, unitBytes] = units[0];
  stream.view.supply(unit, unitBytes.subarray(0, unitBytes.length - 1));
  assert.throws(() => stream.view.supply(unit, unitBytes), /not waited for/);
  assert.throws(() => stream.view.supply(1 << 30, unitBytes), /the stream has \d+ units/);
  stream.supply(units.slice(1));
  const result = await stream.refine(cameras.whole);
  assert.equal(result.unitsRefused, 1);
  assert.ok(result.faces > 0);
  stream.free();
});
