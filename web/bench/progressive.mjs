// A stream decoded whole against the same stream fed to ProgressiveDecoder in chunks (as
// `fetch()` hands them over), each level handed over as its bytes complete it, best of N, as
// one JSON line: what handing over the levels costs on top of one decode.
//   bash web/build.sh && node web/bench/progressive.mjs STREAM.mc [CHUNK] [N]
import { readFileSync } from "node:fs";
import { fileURLToPath } from "node:url";
import init, { decode, ProgressiveDecoder } from "../pkg/meshcodec.js";

const [stream, chunk = "16384", repeats = "3"] = process.argv.slice(2);
if (!stream) {
  console.error("usage: node web/bench/progressive.mjs STREAM.mc [CHUNK] [N]");
  process.exit(2);
}
await init({ module_or_path: readFileSync(fileURLToPath(new URL("../pkg/meshcodec_bg.wasm", import.meta.url))) });
const bytes = new Uint8Array(readFileSync(stream));
const step = Number(chunk);
let whole = Infinity;
let fed = Infinity;
let handed = 0;
let incremental = false;
for (let r = 0; r < Number(repeats); r++) {
  let started = performance.now();
  decode(bytes);
  whole = Math.min(whole, performance.now() - started);
  started = performance.now();
  const decoder = new ProgressiveDecoder();
  handed = 0;
  for (let at = 0; at < bytes.length; at += step) {
    if (decoder.push(bytes.subarray(at, at + step)) !== undefined) handed++;
  }
  fed = Math.min(fed, performance.now() - started);
  incremental = decoder.incremental;
  decoder.free();
}
console.log(JSON.stringify({ stream, chunk: step, whole_ms: whole, fed_ms: fed, levels_handed: handed, incremental, fed_over_whole: fed / whole }));
