// meshcodec's WebAssembly decoder against Draco's own (npm draco3d) on the same mesh in Node,
// rounds alternated, best of each, as one JSON line. The mesh is the stream's full decode (its
// 12-bit grid's positions and its faces), which Draco encodes at 12 bits a coordinate,
// compression level 10 (speed 0), edgebreaker; each decoder's time covers what a user takes out:
// positions and triangle indices as typed arrays.
//   bash web/build.sh && node web/bench/draco.mjs STREAM.mc [ROUNDS] [REPEATS]
import { readFileSync } from "node:fs";
import { fileURLToPath } from "node:url";
import draco3d from "draco3d";
import init, { decode } from "../pkg/meshcodec.js";
import { dracoDecode as decodeWith, dracoEncode as encodeWith } from "./draco-lib.mjs";

const [stream, rounds = "5", repeats = "5"] = process.argv.slice(2);
if (!stream) {
  console.error("usage: node web/bench/draco.mjs STREAM.mc [ROUNDS] [REPEATS]");
  process.exit(2);
}
await init({ module_or_path: readFileSync(fileURLToPath(new URL("../pkg/meshcodec_bg.wasm", import.meta.url))) });
const bytes = new Uint8Array(readFileSync(stream));
const mesh = decode(bytes);
const [encoderModule, decoderModule] = await Promise.all([draco3d.createEncoderModule({}), draco3d.createDecoderModule({})]);

const dracoEncode = (m) => encodeWith(encoderModule, m);
const dracoDecode = (e) => decodeWith(decoderModule, e);
const encoded = dracoEncode(mesh);
const check = dracoDecode(encoded);
if (check.indices.length !== mesh.indices.length) throw new Error("Draco's mesh has another face count");

const time = (work) => {
  let best = Infinity;
  for (let i = 0; i < Number(repeats); i++) {
    const started = performance.now();
    work();
    best = Math.min(best, (performance.now() - started) / 1000);
  }
  return best;
};
let ours = Infinity;
let theirs = Infinity;
for (let round = 0; round < Number(rounds); round++) {
  ours = Math.min(ours, time(() => decode(bytes)));
  theirs = Math.min(theirs, time(() => dracoDecode(encoded)));
}
console.log(
  JSON.stringify({
    stream,
    vertices: mesh.vertices,
    triangles: mesh.triangles,
    meshcodec_bytes: bytes.length,
    meshcodec_decode_seconds: ours,
    draco_bytes: encoded.length,
    draco_decode_seconds: theirs,
    meshcodec_over_draco: ours / theirs,
  }),
);
