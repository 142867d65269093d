// What the web tests compare with: the native `meshcodec` binary's decode of a stream.
import assert from "node:assert/strict";
import { execFileSync } from "node:child_process";
import { readFileSync } from "node:fs";
import { join } from "node:path";
import { fileURLToPath } from "node:url";

export const root = fileURLToPath(new URL("../../", import.meta.url));
export const native = process.env.MESHCODEC_BIN ?? join(root, "target/release/meshcodec");

/** The native decoder's mesh of `stream` after `level` levels, from the binary PLY it writes. */
export function nativeLevel(stream, level, scratch) {
  const out = join(scratch, `level-${level}.ply`);
  execFileSync(native, ["decode", stream, out, "--level", String(level), "--drop-attributes"]);
  return readPly(out);
}

/** A binary PLY as the native binary writes it (double x, y, z; faces of three int corners):
 * {positions: Float64Array, indices: Uint32Array}. */
export function readPly(path) {
  const bytes = readFileSync(path);
  const headerEnd = bytes.indexOf("end_header\n") + "end_header\n".length;
  const header = bytes.subarray(0, headerEnd).toString("latin1");
  const vertices = Number(/element vertex (\d+)/.exec(header)[1]);
  const faces = Number(/element face (\d+)/.exec(header)[1]);
  const view = new DataView(bytes.buffer, bytes.byteOffset + headerEnd);
  const positions = new Float64Array(vertices * 3);
  for (let i = 0; i < positions.length; i++) positions[i] = view.getFloat64(i * 8, true);
  const indices = new Uint32Array(faces * 3);
  let at = vertices * 24;
  for (let f = 0; f < faces; f++) {
    assert.equal(view.getUint8(at), 3);
    for (let c = 0; c < 3; c++) indices[f * 3 + c] = view.getInt32(at + 1 + 4 * c, true);
    at += 13;
  }
  return { positions, indices };
}

/** A mesh's triangles, each rotated to start at its least corner, sorted: the same triangles
 * in any order (an adapted mesh's face order follows the order its splits were made in). */
export function triangleSet(indices) {
  const out = [];
  for (let f = 0; f < indices.length; f += 3) {
    const t = Array.from(indices.subarray(f, f + 3));
    const least = t.indexOf(Math.min(...t));
    out.push([...t.slice(least), ...t.slice(0, least)].join(" "));
  }
  return out.sort();
}

/** Positions compared bit for bit (NaN-safe, -0 apart from +0). */
export function assertSameBits(actual, expected, what) {
  assert.equal(actual.length, expected.length, `${what}: lengths`);
  const a = new BigUint64Array(actual.buffer, actual.byteOffset, actual.length);
  const e = new BigUint64Array(expected.buffer, expected.byteOffset, expected.length);
  for (let i = 0; i < a.length; i++) {
    if (a[i] !== e[i]) assert.fail(`${what}: coordinate ${i} is ${actual[i]}, natively ${expected[i]}`);
  }
}


/** The native decoder's full level of `stream` with its appearance, from the OBJ it writes:
 * each wedge's uv and normal (as written: Rust's shortest round-trip digits, so they parse back
 * to the same doubles), each corner's wedge, each face's material name, each vertex's colour. */
export function nativeAppearance(stream, scratch) {
  const out = join(scratch, "full.obj");
  execFileSync(native, ["decode", stream, out]);
  const uvs = [];
  const normals = [];
  const colours = [];
  const corners = [];
  const faceMaterial = [];
  let material = "";
  for (const line of readFileSync(out, "latin1").split("\n")) {
    const [tag, ...rest] = line.trim().split(/\s+/);
    if (tag === "v" && rest.length === 6) colours.push(rest.slice(3).map(Number));
    else if (tag === "vt") uvs.push(...rest.map(Number));
    else if (tag === "vn") normals.push(...rest.map(Number));
    else if (tag === "usemtl") material = rest.join(" ");
    else if (tag === "f") {
      for (const corner of rest) {
        const wedge = corner.split("/")[1] || corner.split("/")[2];
        corners.push(Number(wedge) - 1);
      }
      faceMaterial.push(material);
    }
  }
  return { uvs, normals, colours, corners, faceMaterial };
}
