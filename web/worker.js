// The decoding side of MeshcodecLoader, off the main thread: fetches a stream (or takes bytes
// already read), feeds its chunks to the WebAssembly ProgressiveDecoder as they arrive and
// posts each level as soon as its bytes are in. Messages out: {type: "progress", received,
// total}, {type: "level", level, levels, codec, positions, indices, received, ...} (the typed
// arrays transferred), {type: "done", received} and {type: "error", message}: a corrupt or cut
// stream ends in "error", and the worker stays alive for the next load.
//
// A `came` stream asked for with {viewDependent: true} is refined to a camera instead: the
// worker reads its first bytes (one Range request), posts {type: "came", codec, box, ...}, and
// for each {type: "camera", camera, tolerance} adapts, posts {type: "view", positions,
// indices, faces, bytesRead, adaptMs, settled, ...} and fetches the meta-nodes the view asked
// for by Range requests, adapting again as they arrive, to the newest camera.
import init, { ProgressiveDecoder, info } from "./pkg/meshcodec.js";
import { CameStream, concat, rangeReader } from "./came.js";

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

/** The chunks of `request` (a URL to fetch, a byte range [start, end) of one, or bytes
 * already read) and the bytes expected. */
async function open(request) {
  if (request.bytes) return [chunksOfBytes(request.bytes), request.bytes.byteLength];
  if (request.range) {
    const [start, end] = request.range;
    const response = await fetch(request.url, { headers: { Range: `bytes=${start}-${end - 1}` } });
    if (!response.ok) throw new Error(`${request.url}: HTTP ${response.status} ${response.statusText}`);
    if (response.status === 206) return [chunksOfResponse(response), end - start];
    // A server without Range: the whole file, the range cut out of it as it arrives.
    return [sliceOf(chunksOfResponse(response), start, end), end - start];
  }
  const response = await fetch(request.url);
  if (!response.ok) throw new Error(`${request.url}: HTTP ${response.status} ${response.statusText}`);
  return [chunksOfResponse(response), Number(response.headers.get("content-length")) || 0];
}

/** The bytes [start, end) of a stream of chunks. */
async function* sliceOf(chunks, start, end) {
  let at = 0;
  for await (const chunk of chunks) {
    const from = Math.max(start - at, 0);
    const to = Math.min(end - at, chunk.length);
    if (to > from) yield chunk.subarray(from, to);
    at += chunk.length;
    if (at >= end) return;
  }
}

/** The first bytes of `url` by one Range request (more while its header and index run on):
 * {head, total}, or null where the server sends the whole stream instead (no Range). */
async function headOf(url) {
  const response = await fetch(url, { headers: { Range: "bytes=0-16383" } });
  if (response.status !== 206) {
    response.body?.cancel();
    return null;
  }
  let head = new Uint8Array(await response.arrayBuffer());
  const total = Number(/\/(\d+)$/.exec(response.headers.get("content-range") ?? "")?.[1]) || 0;
  const read = rangeReader(url);
  for (;;) {
    try {
      return { head, total, codec: info(head) };
    } catch (e) {
      if (!/truncated/.test(e.message) || (total && head.length >= total)) throw e;
      const more = await read(head.length, head.length * 4);
      if (more.length === 0) throw e;
      head = concat(head, more);
    }
  }
}

/** The view-dependent side: one came stream, refined to the newest camera the page sent. */
const views = new Map();

async function openView(request, opened) {
  const read = rangeReader(request.url);
  const stream = await CameStream.open(async (start, end) => {
    // The head is in: CameStream asks for it first.
    if (end <= opened.head.length) return opened.head.subarray(start, end);
    return read(start, end);
  }, { firstRequest: opened.head.length });
  const { origin, cell, quantBits } = opened.codec;
  const extent = (1 << quantBits) - 1;
  const box = [Array.from(origin), Array.from(origin, (o, k) => o + cell[k] * extent)];
  const entry = { stream, camera: null, running: false, frames: 0, firstFrameBytes: 0 };
  views.set(request.id, entry);
  postMessage({ type: "came", id: request.id, codec: opened.codec.codec, box, ...stream.fetched() });
}

/** Adapts to the newest camera until the front settles for it, posting each adapted mesh. */
async function refineView(id) {
  const entry = views.get(id);
  if (!entry || entry.running) return;
  entry.running = true;
  try {
    while (entry.camera) {
      const { camera, tolerance, twoSided } = entry.camera;
      const { adapted, fetched } = entry.stream.round(camera, { tolerance, twoSided });
      const mesh = entry.stream.view.mesh();
      entry.frames++;
      const figures = entry.stream.fetched();
      if (entry.frames === 1) entry.firstFrameBytes = figures.bytesRead;
      const message = {
        type: "view",
        id,
        ...mesh,
        ...figures,
        faces: adapted.faces,
        settled: adapted.settled,
        waiting: adapted.waiting,
        adaptMs: adapted.ms,
        frames: entry.frames,
        firstFrameBytes: entry.firstFrameBytes,
      };
      postMessage(message, [mesh.positions.buffer, mesh.indices.buffer]);
      const units = await fetched;
      entry.stream.supply(units);
      // Settled for this camera (or stuck: nothing changed, nothing to fetch): wait for the
      // next camera.
      const stuck = units.length === 0 && adapted.splits + adapted.collapses === 0;
      if ((adapted.settled || stuck) && entry.camera.camera === camera) entry.camera = null;
    }
  } catch (e) {
    postMessage({ type: "error", id, message: e instanceof Error ? e.message : String(e) });
  } finally {
    entry.running = false;
  }
}

async function load(request) {
  await ready;
  if (request.url && request.viewDependent) {
    const opened = await headOf(request.url);
    if (opened && ["came", "came-paper"].includes(opened.codec.codec)) return openView(request, opened);
    if (opened) return progressive(request, opened);
  }
  return progressive(request, null);
}

/** Levels as the bytes arrive; `opened` the head already read (the rest is asked for by
 * range). */
async function progressive(request, opened) {
  const [chunks, total] = opened ? await rest(request.url, opened) : await open(request);
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

/** The head, then the bytes after it as they arrive. */
async function rest(url, opened) {
  const { head, total } = opened;
  async function* chunks() {
    yield head;
    if (total && head.length >= total) return;
    const response = await fetch(url, { headers: { Range: `bytes=${head.length}-` } });
    if (!response.ok) throw new Error(`${url}: HTTP ${response.status} ${response.statusText}`);
    yield* chunksOfResponse(response);
  }
  return [chunks(), total];
}

self.onmessage = ({ data }) => {
  if (data.type === "camera") {
    const entry = views.get(data.id);
    if (entry) {
      entry.camera = data;
      refineView(data.id);
    }
    return;
  }
  if (data.type === "close") {
    views.get(data.id)?.stream.free();
    views.delete(data.id);
    return;
  }
  load(data).catch((e) => {
    postMessage({ type: "error", id: data.id, message: e instanceof Error ? e.message : String(e) });
  });
};
