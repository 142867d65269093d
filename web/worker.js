// The decoding side of MeshcodecLoader, off the main thread: fetches a stream (or takes bytes
// already read), feeds its chunks to the WebAssembly ProgressiveDecoder as they arrive and
// posts each level as soon as its bytes are in. Messages in: {type: "init", wasm} (where the
// .wasm is: the loader's decoder path; first, before any load), a load ({id, url | bytes,
// range, viewDependent}), {type: "abort", id}, {type: "camera", id, ...} and {type: "close",
// id}. Messages out: {type: "progress", received, total}, {type: "level", level, levels, codec,
// positions, indices, received, ...} (the typed arrays transferred), {type: "done", received}
// and {type: "error", message, code}: a corrupt or cut stream ends in "error", and the worker
// stays alive for the next load.
//
// A `came` stream asked for with {viewDependent: true} is refined to a camera instead: the
// worker reads its first bytes (one Range request), posts {type: "came", codec, box, ...}, and
// for each {type: "camera", camera, tolerance} adapts, posts {type: "view", positions,
// indices, faces, bytesRead, adaptMs, settled, ...} and fetches the meta-nodes the view asked
// for by Range requests, adapting again as they arrive, to the newest camera.
import { MeshcodecError, ProgressiveDecoder, asMeshcodecError, info, init } from "./index.js";
import { CameStream, concat, rangeReader } from "./came.js";

/** The module, loaded from the loader's decoder path (or the package's own) at the first
 * message. */
let ready = null;

/** The loads under way, by id: each one's AbortController. */
const running = new Map();

/** `fetch`, its failures as MeshcodecErrors with code "network". */
async function fetchOrFail(url, options) {
  const response = await fetch(url, options);
  if (!response.ok) throw new MeshcodecError(`${url}: HTTP ${response.status} ${response.statusText}`, "network");
  return response;
}

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
    const response = await fetchOrFail(request.url, { headers: { Range: `bytes=${start}-${end - 1}` }, signal: request.signal });
    if (response.status === 206) return [chunksOfResponse(response), end - start];
    // A server without Range: the whole file, the range cut out of it as it arrives.
    return [sliceOf(chunksOfResponse(response), start, end), end - start];
  }
  const response = await fetchOrFail(request.url, { signal: request.signal });
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
async function headOf(url, signal) {
  const response = await fetch(url, { headers: { Range: "bytes=0-16383" }, signal });
  if (response.status !== 206) {
    response.body?.cancel();
    return null;
  }
  let head = new Uint8Array(await response.arrayBuffer());
  const total = Number(/\/(\d+)$/.exec(response.headers.get("content-range") ?? "")?.[1]) || 0;
  const read = rangeReader(url, { signal });
  for (;;) {
    try {
      return { head, total, codec: info(head) };
    } catch (e) {
      if (e.code !== "truncated" || (total && head.length >= total)) throw e;
      const more = await read(head.length, head.length * 4);
      if (more.length === 0) throw e;
      head = concat(head, more);
    }
  }
}

/** The view-dependent side: one came stream, refined to the newest camera the page sent. */
const views = new Map();

async function openView(request, opened) {
  const read = rangeReader(request.url, { signal: request.signal });
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
    fail(id, e);
  } finally {
    entry.running = false;
  }
}

async function load(request) {
  await (ready ??= init());
  if (request.url && request.viewDependent) {
    const opened = await headOf(request.url, request.signal);
    if (opened && ["came", "came-paper"].includes(opened.codec.codec)) return openView(request, opened);
    if (opened) return progressive(request, opened);
  }
  return progressive(request, null);
}

/** Levels as the bytes arrive; `opened` the head already read (the rest is asked for by
 * range). */
async function progressive(request, opened) {
  const [chunks, total] = opened ? await rest(request.url, opened, request.signal) : await open(request);
  const decoder = new ProgressiveDecoder();
  try {
    for await (const chunk of chunks) {
      if (request.signal.aborted) return;
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
      throw new MeshcodecError(
        `truncated: the stream ended after ${decoder.received} bytes, at level ${decoder.level} of ${decoder.levels}`,
        "truncated",
      );
    }
    postMessage({ type: "done", id: request.id, received: decoder.received });
  } finally {
    decoder.free();
  }
}

/** The head, then the bytes after it as they arrive. */
async function rest(url, opened, signal) {
  const { head, total } = opened;
  async function* chunks() {
    yield head;
    if (total && head.length >= total) return;
    const response = await fetchOrFail(url, { headers: { Range: `bytes=${head.length}-` }, signal });
    yield* chunksOfResponse(response);
  }
  return [chunks(), total];
}

/** Posts a load's error (none for a load aborted: the page has said so already). */
function fail(id, e) {
  if (running.get(id)?.signal.aborted) return;
  const error = asMeshcodecError(e);
  postMessage({ type: "error", id, message: error.message, code: error.code });
}

self.onmessage = ({ data }) => {
  switch (data.type) {
    case "init":
      ready ??= init(data.wasm);
      return;
    case "camera": {
      const entry = views.get(data.id);
      if (entry) {
        entry.camera = data;
        refineView(data.id);
      }
      return;
    }
    case "abort":
      running.get(data.id)?.abort();
      closeView(data.id);
      return;
    case "close":
      closeView(data.id);
      return;
  }
  const controller = new AbortController();
  running.set(data.id, controller);
  load({ ...data, signal: controller.signal })
    .catch((e) => fail(data.id, e))
    .finally(() => {
      // A view stays open for its cameras; a download is over.
      if (!views.has(data.id)) running.delete(data.id);
    });
};

function closeView(id) {
  views.get(id)?.stream.free();
  views.delete(id);
  running.delete(id);
}
