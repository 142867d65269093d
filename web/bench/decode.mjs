// Decode time of a stream in Node through the WebAssembly package, best of N, as one JSON line:
// the figure BENCHMARKS.md sets beside the native decoder on one thread
// (RAYON_NUM_THREADS=1 target/release/examples/time_codec STREAM.mc N).
//   bash web/build.sh && node web/bench/decode.mjs STREAM.mc [N]
import { readFileSync } from "node:fs";
import { fileURLToPath } from "node:url";
import init, { decode } from "../pkg/meshcodec.js";

const [stream, repeats = "10"] = process.argv.slice(2);
if (!stream) {
  console.error("usage: node web/bench/decode.mjs STREAM.mc [N]");
  process.exit(2);
}
await init({ module_or_path: readFileSync(fileURLToPath(new URL("../pkg/meshcodec_bg.wasm", import.meta.url))) });
const bytes = new Uint8Array(readFileSync(stream));
let best = Infinity;
let mesh;
for (let i = 0; i < Number(repeats); i++) {
  const started = performance.now();
  mesh = decode(bytes);
  best = Math.min(best, (performance.now() - started) / 1000);
}
console.log(JSON.stringify({ decode_seconds: best, vertices: mesh.vertices, triangles: mesh.triangles, bytes: bytes.length }));
