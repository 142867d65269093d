// The decoding side of MeshcodecLoader, off the main thread: fetches a stream (or takes bytes
// already read), feeds its chunks to the WebAssembly ProgressiveDecoder as they arrive and
// posts each level as soon as its bytes are in. Messages out: {type: "progress", received,
// total}, {type: "level", level, levels, codec, positions, indices, received, ...} (the typed
// arrays transferred), {type: "done", received} and {type: "error", message}: a corrupt or cut
// stream ends in "error", and the worker stays alive for the next load.
import init, { ProgressiveDecoder } from "./pkg/meshcodec.js";

const ready = init({ module_or_path: new URL("./pkg/meshcodec_bg.wasm", import.meta.url) });

/** Bytes already read, in chunks. */
async function* chunksOfBytes(buffer) {
  const bytes = new Uint8Array(buffer);
  const step = 1 << 16;
  for (let at = 0; at < bytes.length; at += step) yield bytes.subarray(at, at + step);
}

/** A response's body, chunk by chunk as it arrives. */
async function* chunksOfResponse(response) {
  const reader = response.body.getReader();
  for (;;) {
    const { done, value } = await reader.read();
    if (done) return;
    yield value;
  }
}

/** The chunks of `request` (a URL to fetch, or bytes already read) and the bytes expected. */
async function open(request) {
  if (request.bytes) return [chunksOfBytes(request.bytes), request.bytes.byteLength];
  const response = await fetch(request.url);
  if (!response.ok) throw new Error(`${request.url}: HTTP ${response.status} ${response.statusText}`);
  return [chunksOfResponse(response), Number(response.headers.get("content-length")) || 0];
}

async function load(request) {
  await ready;
  const [chunks, total] = await open(request);
  const decoder = new ProgressiveDecoder();
  try {
    for await (const chunk of chunks) {
      const level = decoder.push(chunk);
      postMessage({ type: "progress", id: request.id, received: decoder.received, total });
      if (level !== undefined) {
        level.type = "level";
        level.id = request.id;
        level.received = decoder.received;
        postMessage(level, [level.positions.buffer, level.indices.buffer]);
      }
    }
    if (decoder.levels === 0 || decoder.level < decoder.levels) {
      throw new Error(
        `the stream ended after ${decoder.received} bytes, at level ${decoder.level} of ${decoder.levels}`,
      );
    }
    postMessage({ type: "done", id: request.id, received: decoder.received });
  } finally {
    decoder.free();
  }
}

self.onmessage = ({ data }) => {
  load(data).catch((e) => {
    postMessage({ type: "error", id: data.id, message: e instanceof Error ? e.message : String(e) });
  });
};
