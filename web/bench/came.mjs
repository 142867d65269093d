// A came stream refined to one camera through the WebAssembly package (web/came.js), its units
// read by range from the file as a browser would fetch them: bytes before the first frame (the
// header, the index and the first unit), bytes and meta-nodes read once the front settles,
// adaptation rounds and their time, as one JSON line; `meshcodec view` reads the same units.
//   bash web/build.sh && node web/bench/came.mjs STREAM.mc EYE TARGET [WIDTHxHEIGHT] [GAP]
// (GAP: units at most this many bytes apart are read with one request; 1024 by default.)
// (EYE and TARGET as x,y,z; 50° vertical field of view, 1 px, one-sided.)
import { fstatSync, openSync, readFileSync, readSync } from "node:fs";
import { fileURLToPath } from "node:url";
import { init } from "../index.js";
import { CameStream } from "../came.js";

const [stream, eye, target, size = "1280x720", gap = "1024"] = process.argv.slice(2);
if (!target) {
  console.error("usage: node web/bench/came.mjs STREAM.mc EYE TARGET [WIDTHxHEIGHT] [GAP]");
  process.exit(2);
}
await init();
const file = openSync(stream, "r");
const length = fstatSync(file).size;
const read = async (start, end) => {
  const bytes = new Uint8Array(Math.max(0, Math.min(end, length) - start));
  readSync(file, bytes, 0, bytes.length, start);
  return bytes;
};
const [width, height] = size.split("x").map(Number);
const camera = { eye: eye.split(",").map(Number), target: target.split(",").map(Number), up: [0, 1, 0], fov: 50, width, height };
const started = performance.now();
const came = await CameStream.open(read, { gap: Number(gap) });
const opened = came.fetched();
const openMs = performance.now() - started;
const rounds = [];
const result = await came.refine(camera, { onRound: (adapted) => rounds.push(adapted) });
console.log(
  JSON.stringify({
    stream,
    stream_bytes: length,
    gap: Number(gap),
    first_frame_bytes: opened.bytesRead,
    open_ms: openMs,
    first_frame_faces: rounds[0].faces,
    settled: result.settled,
    faces: result.faces,
    bytes_read: result.bytesRead,
    share_read: result.bytesRead / length,
    units_loaded: result.unitsLoaded,
    units: result.units,
    requests: result.requests,
    rounds: result.rounds,
    adapt_ms: result.adaptMs,
  }),
);
