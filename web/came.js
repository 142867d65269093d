// CameStream: a `came` stream refined to a camera, its meta-nodes fetched by byte range as the
// views need them (HTTP `Range` requests, or bytes already read), as `meshcodec view` refines
// it natively. Works in browsers, Web Workers and Node 20:
//
//   await init();                                      // the package, once (index.js)
//   const stream = await CameStream.open("dragon.mc"); // header, index and first unit only
//   const { mesh, faces, bytesRead } = await stream.refine(camera, { tolerance: 1 });
//
// `camera` is {eye, target, up: [x, y, z], fov (vertical, degrees), width, height (pixels)}.
// Each round adapts to the camera with the units at hand, then fetches the units it asked for
// (neighbours in the stream in one request) and hands them over, until the front settles.
import { CameView, MeshcodecError, cameHeadLength } from "./index.js";

/** Reads byte ranges of `url` with HTTP Range requests: `read(start, end)` → Uint8Array of
 * bytes start … end − 1 (fewer where the stream ends). */
export function rangeReader(url, fetchOptions = {}) {
  return async (start, end) => {
    const response = await fetch(url, { ...fetchOptions, headers: { ...fetchOptions.headers, Range: `bytes=${start}-${end - 1}` } });
    if (response.status === 416) return new Uint8Array(0);
    if (!response.ok) throw new MeshcodecError(`${url}: HTTP ${response.status} ${response.statusText}`, "network");
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

/** `a` then `b`, in one array. */
export function concat(a, b) {
  const out = new Uint8Array(a.length + b.length);
  out.set(a);
  out.set(b, a.length);
  return out;
}

/** The units wanted ([{unit, start, end}]) in runs, each fetched with one request: units
 * neighbouring in the stream, or apart by at most `gap` bytes (read and dropped: fewer
 * requests for a few more bytes). [{start, end, units: [{unit, start, end}, …]}] */
function runs(wanted, gap) {
  const units = [...wanted].sort((a, b) => a.start - b.start);
  const out = [];
  for (const unit of units) {
    const last = out[out.length - 1];
    if (last && unit.start - last.end <= gap) {
      last.end = unit.end;
      last.units.push(unit);
    } else {
      out.push({ start: unit.start, end: unit.end, units: [unit] });
    }
  }
  return out;
}

export class CameStream {
  /** A stream whose first bytes are in: use `CameStream.open`. */
  constructor(view, read, head, gap) {
    this.view = view;
    this.read = read;
    /** Bytes between two wanted units that one request reads through. */
    this.gap = gap;
    /** Every byte range fetched ({start, bytes}, sorted by start): the head, and each
     * request's bytes, gaps included, so that no byte is fetched twice. */
    this.held = [{ start: 0, bytes: head }];
    /** Bytes fetched so far (header, index, units), and requests made. */
    this.bytesFetched = head.length;
    this.requests = 1;
  }

  /** The index of the last held range starting at or before `at` (0 if none). */
  heldAt(at) {
    let low = 0;
    let high = this.held.length;
    while (high - low > 1) {
      const middle = (low + high) >> 1;
      if (this.held[middle].start <= at) low = middle;
      else high = middle;
    }
    return low;
  }

  /** Bytes start … end − 1 of the stream if they were fetched, else null. Held ranges never
   * overlap; a unit may span neighbouring ones. */
  heldBytes(start, end) {
    let k = this.heldAt(start);
    const pieces = [];
    let at = start;
    while (at < end && k < this.held.length) {
      const h = this.held[k];
      if (h.start > at || h.start + h.bytes.length <= at) return null;
      const to = Math.min(end, h.start + h.bytes.length);
      pieces.push(h.bytes.subarray(at - h.start, to - h.start));
      at = to;
      k++;
    }
    if (at < end) return null;
    return pieces.length === 1 ? pieces[0] : pieces.reduce(concat);
  }

  /** Fetches what is not held of bytes start … end − 1: one request a missing stretch. */
  async fetchMissing(start, end) {
    const stretches = [];
    let at = start;
    for (let k = this.heldAt(start); k < this.held.length && at < end; k++) {
      const h = this.held[k];
      if (h.start + h.bytes.length <= at) continue;
      if (h.start >= end) break;
      if (h.start > at) stretches.push([at, h.start]);
      at = Math.max(at, h.start + h.bytes.length);
    }
    if (at < end) stretches.push([at, end]);
    await Promise.all(
      stretches.map(async ([from, to]) => {
        const bytes = await this.read(from, to);
        this.requests++;
        this.bytesFetched += bytes.length;
        if (bytes.length === 0) return;
        const k = this.heldAt(from);
        const after = this.held[k].start <= from ? k + 1 : k;
        this.held.splice(after, 0, { start: from, bytes });
      }),
    );
  }

  /** Opens a `came` stream from `source` (a URL, fetched by Range requests; or a
   * `read(start, end)` function) having read its header, its index and its first unit.
   * `gap`: units at most this many bytes apart are fetched with one request. */
  static async open(source, { firstRequest = 16384, gap = 1024 } = {}) {
    const read = typeof source === "function" ? source : rangeReader(source);
    let head = await read(0, firstRequest);
    let requests = 1;
    let need = cameHeadLength(head);
    // The index's length is known once it is in: fetch on from where the last read stopped.
    while (need === undefined) {
      const more = await read(head.length, head.length * 4);
      requests++;
      if (more.length === 0) {
        throw new MeshcodecError(`truncated: the stream ends after ${head.length} bytes, inside its header or index`, "truncated");
      }
      head = concat(head, more);
      need = cameHeadLength(head);
    }
    if (head.length < need) {
      head = concat(head, await read(head.length, need));
      requests++;
    }
    const stream = new CameStream(new CameView(head), read, head, gap);
    stream.requests = requests;
    return stream;
  }

  /** One round: adapts to `camera` with the units at hand and fetches the units it asked for
   * (without handing them over). Returns {adapted, fetched: Promise of [[unit, bytes], …]}. */
  round(camera, { tolerance = 1, twoSided = false } = {}) {
    const started = performance.now();
    const { eye, target, up, fov, width, height } = camera;
    const adapted = this.view.adapt({ eye, target, up, fov, width, height, tolerance, twoSided });
    adapted.ms = performance.now() - started;
    // Units held already (read through a gap before) are not fetched again; the others are
    // fetched in runs, and all are handed back in the order the adaptation asked for them.
    const wanted = this.view.wanted();
    const missing = wanted.filter(({ start, end }) => !this.heldBytes(start, end));
    const fetches = Promise.all(runs(missing, this.gap).map((run) => this.fetchMissing(run.start, run.end)));
    const fetched = fetches.then(() => wanted.map(({ unit, start, end }) => [unit, this.heldBytes(start, end)]));
    return { adapted, fetched };
  }

  /** Hands over fetched units (as `round` returns them), decoded at once. */
  supply(units) {
    // Bytes the source did not have (a stream cut short) are no unit's: refused, not thrown.
    for (const [unit, bytes] of units) this.view.supply(unit, bytes ?? new Uint8Array(0));
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
