// The npm package as a user gets it: `npm pack` makes a tarball holding what package.json's
// `exports` name; a scratch project installs it and imports it by name, in JavaScript and in
// TypeScript (tsc against the hand-written declarations); and the API refuses bad arguments
// naming them. Run by tests/run.sh after `bash web/build.sh`:   node --test web/test/
import { test } from "node:test";
import assert from "node:assert/strict";
import { execFileSync } from "node:child_process";
import { mkdirSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";

import { CameView, MeshcodecError, ProgressiveDecoder, decode, info, init } from "../index.js";
import { native, root } from "./native.mjs";

const web = join(root, "web");
const golden = join(root, "tests/golden/v8/emc-eight.mc");
const bytes = new Uint8Array(readFileSync(golden));

test("before init, the API says so in a MeshcodecError", async () => {
  // This file's import ran no init: the first call is refused with its code.
  assert.throws(() => decode(bytes), (e) => e instanceof MeshcodecError && e.code === "uninitialised");
  await init();
});

test("decode(bytes, {level: 3}) gives level 3, and bad levels are refused naming the argument", async () => {
  await init();
  const levels = info(bytes).levels;
  assert.equal(decode(bytes, { level: 3 }).level, 3);
  assert.equal(decode(bytes).level, levels);
  for (const [bad, kind] of [
    [-1, RangeError],
    [0, RangeError],
    [2.5, RangeError],
    [1e12, RangeError],
    [levels + 1, RangeError],
    ["x", TypeError],
    [null, TypeError],
    [NaN, RangeError],
  ]) {
    assert.throws(() => decode(bytes, { level: bad }), (e) => e instanceof kind && /^level: /.test(e.message), `level ${bad}`);
  }
  // Not an options object, an unknown option, the bytes' own argument.
  for (const bad of [3, -1, "x", [3]]) {
    assert.throws(() => decode(bytes, bad), (e) => e instanceof TypeError && /^options: /.test(e.message));
  }
  assert.throws(() => decode(bytes, { lvl: 3 }), /options: unknown option "lvl"/);
  assert.throws(() => decode("bytes"), (e) => e instanceof TypeError && /^bytes: /.test(e.message));
  assert.throws(() => decode(bytes, { bytes: -5 }), (e) => e instanceof RangeError && /^bytes: /.test(e.message));
  assert.throws(() => decode(bytes, { float32: 1 }), (e) => e instanceof TypeError && /^float32: /.test(e.message));
});

test("float32 positions equal the double ones rounded once", async () => {
  await init();
  const double = decode(bytes, { level: 5 });
  const single = decode(bytes, { level: 5, float32: true });
  assert.ok(single.positions instanceof Float32Array);
  assert.deepEqual(single.positions, Float32Array.from(double.positions));
  const decoder = new ProgressiveDecoder({ float32: true });
  let last;
  for (let at = 0; at < bytes.length; at += 300) last = decoder.push(bytes.subarray(at, at + 300)) ?? last;
  assert.ok(last.positions instanceof Float32Array);
  assert.deepEqual(last.positions, Float32Array.from(decode(bytes).positions));
  decoder.free();
});

test("streams the decoder refuses end in MeshcodecErrors with their codes", async () => {
  await init();
  const cut = bytes.subarray(0, 60);
  assert.throws(() => decode(cut), (e) => e instanceof MeshcodecError && e.code === "truncated");
  const damaged = Uint8Array.from(bytes);
  for (let at = 300; at < 700; at += 7) damaged[at] ^= 0x5a;
  assert.throws(() => decode(damaged), (e) => e instanceof MeshcodecError && e.code === "corrupt" && !e.message.includes("\n"));
  assert.throws(() => new CameView(bytes), (e) => e instanceof MeshcodecError && e.code === "unsupported");
  assert.throws(() => new ProgressiveDecoder({ float32: "yes" }), TypeError);
});

test("CameView.adapt takes one camera object and checks every field", async () => {
  await init();
  const came = readFileSync(join(root, "tests/golden/v8/came-beethoven.mc"));
  const view = new CameView(came);
  const { origin, cell, quantBits } = info(came);
  const centre = origin.map((o, k) => o + (cell[k] * (1 << quantBits)) / 2);
  const camera = { eye: [centre[0], centre[1], centre[2] + 3 * cell[2] * (1 << quantBits)], target: { x: centre[0], y: centre[1], z: centre[2] }, fov: 45, width: 640, height: 480 };
  const adapted = view.adapt(camera);
  assert.ok(adapted.faces > 0 && typeof adapted.settled === "boolean");
  assert.ok(view.wanted().every((u) => Number.isInteger(u.unit) && u.end > u.start));
  for (const [field, bad, kind] of [
    ["eye", [0, 0], TypeError],
    ["eye", [0, NaN, 1], RangeError],
    ["fov", 0, RangeError],
    ["fov", "45", TypeError],
    ["width", 0, RangeError],
    ["height", 2.5, RangeError],
    ["tolerance", -1, RangeError],
    ["twoSided", "no", TypeError],
  ]) {
    assert.throws(() => view.adapt({ ...camera, [field]: bad }), (e) => e instanceof kind && e.message.startsWith(`${field}: `), field);
  }
  assert.throws(() => view.adapt({ ...camera, fov: undefined }), /^TypeError: fov: /);
  assert.throws(() => view.adapt({ ...camera, zoom: 2 }), /unknown option "zoom"/);
  view.free();
});

test("npm pack makes a package a scratch project installs and imports, in JavaScript (the README's quick start) and TypeScript", () => {
  const scratch = mkdtempSync(join(tmpdir(), "meshcodec-npm-"));
  try {
    const packed = JSON.parse(execFileSync("npm", ["pack", "--json", "--pack-destination", scratch], { cwd: web }).toString())[0];
    const files = packed.files.map((f) => f.path);
    const manifest = JSON.parse(readFileSync(join(web, "package.json")));
    assert.equal(manifest.private, undefined);
    // Everything the exports and types name is in the tarball.
    for (const target of Object.values(manifest.exports).flatMap((e) => (typeof e === "string" ? [e] : Object.values(e)))) {
      assert.ok(files.includes(target.replace(/^\.\//, "")), `${target} is not in the package`);
    }
    assert.ok(files.includes("worker.js") && !files.some((f) => f.startsWith("test/") || f.startsWith("node_modules/")));

    const project = join(scratch, "project");
    mkdirSync(project);
    writeFileSync(join(project, "package.json"), JSON.stringify({ name: "scratch", private: true, type: "module" }));
    execFileSync("npm", ["install", "--no-audit", "--no-fund", "--loglevel=error", join(scratch, packed.filename)], { cwd: project });
    writeFileSync(
      join(project, "main.mjs"),
      `import { readFileSync } from "node:fs";
import { init, decode, info } from "meshcodec";
await init();
const bytes = readFileSync(process.argv[2]);
const mesh = decode(bytes, { level: 3, float32: true });
console.log(JSON.stringify({ codec: info(bytes).codec, level: mesh.level, vertices: mesh.vertices, float32: mesh.positions instanceof Float32Array }));
`,
    );
    const said = JSON.parse(execFileSync("node", ["main.mjs", golden], { cwd: project }).toString());
    const ours = decode(bytes, { level: 3 });
    assert.deepEqual(said, { codec: "emc", level: 3, vertices: ours.vertices, float32: true });

    // The README's JavaScript quick start, as written, on the stream its command-line quick
    // start writes.
    const readme = readFileSync(join(root, "README.md"), "utf8");
    const quickStart = /\n### JavaScript\n[\s\S]*?```js\n([\s\S]*?)```/.exec(readme)[1];
    writeFileSync(join(project, "readme.mjs"), quickStart);
    execFileSync(native, ["encode", "bunny", join(project, "bunny.mc")]);
    const printed = execFileSync("node", ["readme.mjs"], { cwd: project }).toString().trim().split(" ").map(Number);
    const bunny = new Uint8Array(readFileSync(join(project, "bunny.mc")));
    assert.deepEqual(printed, [info(bunny).levels, decode(bunny, { level: 6 }).vertices, decode(bunny).triangles]);

    // TypeScript resolves the package's types through its exports.
    writeFileSync(
      join(project, "main.mts"),
      `import { decode, MeshcodecError, type DecodedLevel } from "meshcodec";
export function coarse(bytes: Uint8Array): DecodedLevel<Float32Array> | string {
  try {
    return decode(bytes, { level: 2, float32: true });
  } catch (e) {
    return e instanceof MeshcodecError ? e.code : "other";
  }
}
// @ts-expect-error: options are an object
decode(new Uint8Array(0), 2);
`,
    );
    writeFileSync(
      join(project, "tsconfig.json"),
      JSON.stringify({
        compilerOptions: { strict: true, noEmit: true, module: "nodenext", moduleResolution: "nodenext", target: "es2022", lib: ["es2022", "dom", "esnext.disposable"], types: [] },
        files: ["main.mts"],
      }),
    );
    execFileSync(join(web, "node_modules/.bin/tsc"), ["-p", project], { cwd: project, stdio: "pipe" });
  } finally {
    rmSync(scratch, { recursive: true, force: true });
  }
});

test("the declarations compile with three.js's types, and misuse does not (tsc -p web)", () => {
  try {
    execFileSync(join(web, "node_modules/.bin/tsc"), ["-p", web], { stdio: "pipe" });
  } catch (e) {
    assert.fail(e.stdout.toString() + e.stderr.toString());
  }
});
