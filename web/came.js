// CameStream: a `came` stream refined to a camera, its meta-nodes fetched by byte range as the
// views need them (HTTP `Range` requests, or bytes already read), as `meshcodec view` refines
// it natively. Works in browsers, Web Workers and Node 20:
//
//   await init({ module_or_path });                    // the package, once
//   const stream = await CameStream.open("dragon.mc"); // header, index and first unit only
//   const { mesh, faces, bytesRead } = await stream.refine(camera, { tolerance: 1 });
//
// `camera` is {eye, target, up: [x, y, z], fov (vertical, degrees), width, height (pixels)}.
// Each round adapts to the camera with the units at hand, then fetches the units it asked for
// (neighbours in the stream in one request) and hands them over, until the front settles.
import { CameView, cameHeadLength } from "./pkg/meshcodec.js";

/** Reads byte ranges of `url` with HTTP Range requests: `read(start, end)` → Uint8Array of
 * bytes start … end − 1 (fewer where the stream ends). */
export function rangeReader(url, fetchOptions = {}) {
  return async (start, end) => {
    const response = await fetch(url, { ...fetchOptions, headers: { ...fetchOptions.headers, Range: `bytes=${start}-${end - 1}` } });
    if (response.status === 416) return new Uint8Array(0);
    if (!response.ok) throw new Error(`${url}: HTTP ${response.status} ${response.statusText}`);
    const bytes = new Uint8Array(await response.arrayBuffer());
    // A server that ignores Range sends the whole stream: take the part asked for.
    return response.status === 206 ? bytes : bytes.subarray(start, end);
  };
}

/** `read(start, end)` over bytes already in memory. */
export function bytesReader(bytes) {
  const all = bytes instanceof Uint8Array ? bytes : new Uint8Array(bytes);
  return async (start, end) => all.subarray(start, Math.min(end, all.length));
}

function concat(a, b) {
  const out = new Uint8Array(a.length + b.length);
  out.set(a);
  out.set(b, a.length);
  return out;
}

/** Runs of units contiguous in the stream, each fetched with one request: [{start, end,
 * units: [[unit, start, end], …]}]. */
function runs(wanted) {
  const units = [];
  for (let i = 0; i < wanted.length; i += 3) units.push([wanted[i], wanted[i + 1], wanted[i + 2]]);
  units.sort((a, b) => a[1] - b[1]);
  const out = [];
  for (const unit of units) {
    const last = out[out.length - 1];
    if (last && last.end === unit[1]) {
      last.end = unit[2];
      last.units.push(unit);
    } else {
      out.push({ start: unit[1], end: unit[2], units: [unit] });
    }
  }
  return out;
}

export class CameStream {
  /** A stream whose first bytes are in: use `CameStream.open`. */
  constructor(view, read, head) {
    this.view = view;
    this.read = read;
    /** The stream's first bytes, as fetched to open it (the first units may lie in them). */
    this.head = head;
    /** Bytes fetched so far (header, index, units), and requests made. */
    this.bytesFetched = head.length;
    this.requests = 1;
  }

  /** Bytes start … end − 1 of the stream: what the head holds of them, the rest fetched. */
  async bytes(start, end) {
    const held = this.head.length;
    if (end <= held) return this.head.subarray(start, end);
    const from = Math.max(start, held);
    const rest = await this.read(from, end);
    this.requests++;
    this.bytesFetched += rest.length;
    return start < held ? concat(this.head.subarray(start), rest) : rest;
  }

  /** Opens a `came` stream from `source` (a URL, fetched by Range requests; or a
   * `read(start, end)` function) having read its header, its index and its first unit. */
  static async open(source, { firstRequest = 16384 } = {}) {
    const read = typeof source === "function" ? source : rangeReader(source);
    let head = await read(0, firstRequest);
    let requests = 1;
    let need = cameHeadLength(head);
    // The index's length is known once it is in: fetch on from where the last read stopped.
    while (need === undefined) {
      const more = await read(head.length, head.length * 4);
      requests++;
      if (more.length === 0) throw new Error(`the stream ends after ${head.length} bytes, inside its header or index`);
      head = concat(head, more);
      need = cameHeadLength(head);
    }
    if (head.length < need) {
      head = concat(head, await read(head.length, need));
      requests++;
    }
    const stream = new CameStream(new CameView(head), read, head);
    stream.requests = requests;
    return stream;
  }

  /** One round: adapts to `camera` with the units at hand and fetches the units it asked for
   * (without handing them over). Returns {adapted, fetched: Promise of [[unit, bytes], …]}. */
  round(camera, { tolerance = 1, twoSided = false } = {}) {
    const started = performance.now();
    const adapted = this.view.adapt(camera.eye, camera.target, camera.up ?? [0, 1, 0], camera.fov, camera.width, camera.height, tolerance, twoSided);
    adapted.ms = performance.now() - started;
    const fetches = runs(this.view.wanted()).map(async (run) => {
      const bytes = await this.bytes(run.start, run.end);
      return run.units.map(([unit, start, end]) => [unit, bytes.subarray(start - run.start, end - run.start)]);
    });
    return { adapted, fetched: Promise.all(fetches).then((parts) => parts.flat()) };
  }

  /** Hands over fetched units (as `round` returns them), decoded at once. */
  supply(units) {
    for (const [unit, bytes] of units) this.view.supply(unit, bytes);
  }

  /** Refines to `camera` until the front settles (at most `rounds` adaptations, as `meshcodec
   * view`), fetching what it asks for; `onRound(adapted)` after each adaptation. Returns {mesh: {positions,
   * indices, vertices, triangles}, faces, rounds, settled, adaptMs, ...fetched()}. */
  async refine(camera, { tolerance = 1, twoSided = false, rounds = 64, onRound } = {}) {
    let adaptMs = 0;
    let done = 0;
    let adapted;
    while (done < rounds) {
      const round = this.round(camera, { tolerance, twoSided });
      adapted = round.adapted;
      adaptMs += adapted.ms;
      done++;
      onRound?.(adapted);
      const units = await round.fetched;
      if (adapted.settled) break;
      this.supply(units);
    }
    return { mesh: this.view.mesh(), faces: adapted.faces, rounds: done, settled: adapted.settled, adaptMs, ...this.fetched() };
  }

  /** {bytesRead (bytes fetched: the first bytes and the units' beyond them), requests,
   * streamBytes, unitsLoaded, unitsRefused, units}. */
  fetched() {
    return { ...this.view.fetched(), bytesRead: this.bytesFetched, requests: this.requests };
  }

  free() {
    this.view.free();
  }
}
