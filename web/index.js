// meshcodec for JavaScript: the codec core's decoders in WebAssembly (pkg/, built by
// web/build.sh), with an API in the language's habits. Every argument is checked: a wrong type is
// a TypeError, a number out of range a RangeError, each naming the argument; a stream the decoder
// refuses is a MeshcodecError with a `code`. Types: index.d.ts.
//
//   import { init, decode } from "meshcodec";
//   await init();                                   // the package's .wasm, once
//   const mesh = decode(bytes, { level: 3 });       // {positions, indices, level, levels, ...}
import initWasm, * as raw from "./pkg/meshcodec.js";

/** A fault in a stream or in its delivery. `code` says which kind: "corrupt", "truncated",
 * "unsupported", "limit", "invalid-mesh", "io", "network", "uninitialised", "internal". */
export class MeshcodecError extends Error {
  constructor(message, code, options) {
    super(message, options);
    this.name = "MeshcodecError";
    this.code = code;
  }
}

/** The library's error (an Error with `code`, from pkg/) or a trap as a MeshcodecError. */
export function asMeshcodecError(e) {
  if (e instanceof MeshcodecError) return e;
  // The bindings' errors carry a code; anything else (a trap, a freed object) is ours.
  const code = typeof e?.code === "string" ? e.code : "internal";
  return new MeshcodecError(e instanceof Error ? e.message : String(e), code, { cause: e });
}

/** `f()`, its errors as MeshcodecErrors. */
function call(f) {
  if (!initialised) {
    throw new MeshcodecError("the WebAssembly module is not loaded: await init() first", "uninitialised");
  }
  try {
    return f();
  } catch (e) {
    throw asMeshcodecError(e);
  }
}

let loading = null;
let initialised = false;

/** Loads the WebAssembly module, once (later calls return the first call's Promise).
 * `source`: where the module is — absent for the package's own `meshcodec_bg.wasm` beside this
 * file (fetched in browsers, read from disk in Node), or a URL, a string URL, a Response, its
 * bytes (ArrayBuffer, Uint8Array) or a compiled WebAssembly.Module. */
export function init(source) {
  if (
    source !== undefined &&
    !(typeof source === "string") &&
    !(source instanceof URL) &&
    !(source instanceof ArrayBuffer) &&
    !ArrayBuffer.isView(source) &&
    !(source instanceof WebAssembly.Module) &&
    !(typeof Response !== "undefined" && source instanceof Response)
  ) {
    throw new TypeError(`source: a URL, Response, bytes or WebAssembly.Module expected, got ${describe(source)}`);
  }
  loading ??= (async () => {
    let module = source ?? new URL("./pkg/meshcodec_bg.wasm", import.meta.url);
    const url = typeof module === "string" ? new URL(module, globalThis.location?.href ?? import.meta.url) : module;
    if (url instanceof URL && url.protocol === "file:") {
      // Node's fetch does not read files.
      const { readFile } = await import(/* webpackIgnore: true */ "node:fs/promises");
      module = await readFile(url);
    } else if (url instanceof URL) {
      module = url;
    }
    await initWasm({ module_or_path: module });
    initialised = true;
  })().catch((e) => {
    loading = null;
    throw new MeshcodecError(`cannot load the WebAssembly module: ${e?.message ?? e}`, "network", { cause: e });
  });
  return loading;
}

/** A value as an error message names it. */
function describe(value) {
  if (value === null) return "null";
  if (value === undefined) return "undefined";
  if (Array.isArray(value)) return "an Array";
  if (typeof value === "string") return JSON.stringify(value);
  if (typeof value === "object") return value.constructor?.name ? `a ${value.constructor.name}` : "an object";
  return String(value);
}

/** A stream's bytes: a Uint8Array as it is, an ArrayBuffer or another view as a Uint8Array. */
export function bytesArgument(value, name) {
  if (value instanceof Uint8Array) return value;
  if (value instanceof ArrayBuffer || (typeof SharedArrayBuffer !== "undefined" && value instanceof SharedArrayBuffer)) {
    return new Uint8Array(value);
  }
  if (ArrayBuffer.isView(value)) return new Uint8Array(value.buffer, value.byteOffset, value.byteLength);
  throw new TypeError(`${name}: a Uint8Array or ArrayBuffer expected, got ${describe(value)}`);
}

/** An options object with only `known` keys ({} when absent). */
export function optionsArgument(value, name, known) {
  if (value === undefined) return {};
  if (value === null || typeof value !== "object" || Array.isArray(value)) {
    throw new TypeError(`${name}: an options object ({${known.join(", ")}}) expected, got ${describe(value)}`);
  }
  for (const key of Object.keys(value)) {
    if (!known.includes(key)) throw new TypeError(`${name}: unknown option "${key}" (known: ${known.join(", ")})`);
  }
  return value;
}

/** An integer in [min, max], or `fallback` when absent. */
export function integerArgument(value, name, min, max, fallback) {
  if (value === undefined) return fallback;
  if (typeof value !== "number") throw new TypeError(`${name}: an integer expected, got ${describe(value)}`);
  if (!Number.isInteger(value)) throw new RangeError(`${name}: an integer expected, got ${value}`);
  if (value < min || value > max) throw new RangeError(`${name}: ${value} is outside ${min} to ${max}`);
  return value;
}

/** A finite number above `above` (or at least `min`), or `fallback` when absent. */
export function numberArgument(value, name, { above, min, max, fallback }) {
  if (value === undefined) return fallback;
  if (typeof value !== "number") throw new TypeError(`${name}: a number expected, got ${describe(value)}`);
  if (!Number.isFinite(value)) throw new RangeError(`${name}: a finite number expected, got ${value}`);
  if (above !== undefined && !(value > above)) throw new RangeError(`${name}: ${value} is not above ${above}`);
  if (min !== undefined && value < min) throw new RangeError(`${name}: ${value} is below ${min}`);
  if (max !== undefined && value > max) throw new RangeError(`${name}: ${value} is above ${max}`);
  return value;
}

/** true or false, or `fallback` when absent. */
export function booleanArgument(value, name, fallback) {
  if (value === undefined) return fallback;
  if (typeof value !== "boolean") throw new TypeError(`${name}: true or false expected, got ${describe(value)}`);
  return value;
}

/** A point or direction: [x, y, z] (an Array or typed array) or {x, y, z} (a three.js Vector3). */
export function vectorArgument(value, name, fallback) {
  if (value === undefined && fallback) return fallback;
  let xyz;
  if (Array.isArray(value) || (ArrayBuffer.isView(value) && !(value instanceof DataView))) {
    if (value.length !== 3) throw new TypeError(`${name}: three numbers expected, got ${value.length}`);
    xyz = Array.from(value);
  } else if (value !== null && typeof value === "object" && "x" in value && "y" in value && "z" in value) {
    xyz = [value.x, value.y, value.z];
  } else {
    throw new TypeError(`${name}: [x, y, z] or {x, y, z} expected, got ${describe(value)}`);
  }
  for (const c of xyz) {
    if (typeof c !== "number") throw new TypeError(`${name}: numbers expected, got ${describe(c)}`);
    if (!Number.isFinite(c)) throw new RangeError(`${name}: finite numbers expected, got ${c}`);
  }
  return xyz;
}

const U32_MAX = 0xffff_ffff;

/** Decodes a stream, or the levels a prefix of it holds. Options: `level` (decode the first
 * `level` levels; every level when absent), `bytes` (use only the first `bytes` bytes: the
 * newest level they complete), `float32` (positions as a Float32Array, for GPU upload; a
 * Float64Array of the library's own values otherwise). */
export function decode(bytes, options) {
  const stream = bytesArgument(bytes, "bytes");
  const o = optionsArgument(options, "options", ["level", "bytes", "float32"]);
  const level = integerArgument(o.level, "level", 1, U32_MAX, undefined);
  const prefix = integerArgument(o.bytes, "bytes", 0, U32_MAX, undefined);
  const float32 = booleanArgument(o.float32, "float32", false);
  if (level !== undefined) {
    const { levels } = call(() => raw.info(prefix === undefined ? stream : stream.subarray(0, prefix)));
    if (level > levels) throw new RangeError(`level: ${level} is past the stream's ${levels} levels`);
  }
  return call(() => raw.decode(stream, level, prefix, float32));
}

/** What a stream's header and index say, without decoding it (a prefix with the header and
 * index is enough): codec, format version, levels, each level's end, units, appearance, ... */
export function info(bytes) {
  const stream = bytesArgument(bytes, "bytes");
  return call(() => raw.info(stream));
}

/** The byte each level ends at, from a prefix holding the header and index. */
export function levelEnds(bytes) {
  const stream = bytesArgument(bytes, "bytes");
  return call(() => Array.from(raw.levelEnds(stream)));
}

/** A decoder fed a stream's bytes as they arrive: `push(chunk)` returns the newest level the
 * chunk completed, or undefined. Options: `float32` (positions as a Float32Array). */
export class ProgressiveDecoder {
  #raw;
  constructor(options) {
    const o = optionsArgument(options, "options", ["float32"]);
    const float32 = booleanArgument(o.float32, "float32", false);
    this.#raw = call(() => new raw.ProgressiveDecoder(float32));
  }

  /** Takes the next chunk; the newest level now complete, or undefined. */
  push(chunk) {
    const bytes = bytesArgument(chunk, "chunk");
    return call(() => this.#raw.push(bytes)) ?? undefined;
  }

  /** Bytes taken so far. */
  get received() {
    return this.#raw.received;
  }

  /** Levels the stream holds (0 until its header and index are in). */
  get levels() {
    return this.#raw.levels;
  }

  /** Levels handed over so far. */
  get level() {
    return this.#raw.level;
  }

  /** Whether each level is decoded once, going on from the last. */
  get incremental() {
    return this.#raw.incremental;
  }

  /** Frees the decoder's WebAssembly memory (it is unusable afterwards). */
  free() {
    this.#raw?.free();
    this.#raw = undefined;
  }

  [Symbol.dispose]() {
    this.free();
  }
}

/** How many of a `came` stream's first bytes `new CameView` needs, or undefined while
 * `prefix` is too short to say (read more). */
export function cameHeadLength(prefix) {
  const bytes = bytesArgument(prefix, "prefix");
  return call(() => raw.cameHeadLength(bytes)) ?? undefined;
}

/** A `came` stream refined to a camera, its meta-nodes supplied by the caller: `adapt` with
 * the units at hand, `wanted` lists the units to fetch, `supply` hands their bytes over. */
export class CameView {
  #raw;
  /** The front at the root, from the stream's first `cameHeadLength(…)` bytes (or more). */
  constructor(head) {
    const bytes = bytesArgument(head, "head");
    this.#raw = call(() => new raw.CameView(bytes));
  }

  /** Adapts to a camera: `eye`, `target`, `up` (default [0, 1, 0]) as [x, y, z] or {x, y, z};
   * `fov` the vertical field of view in degrees; `width` × `height` the viewport in pixels;
   * `tolerance` in pixels (default 1); `twoSided` refines faces turned away too. Returns
   * {splits, collapses, waiting, settled, faces, vertices}. */
  adapt(camera) {
    const o = optionsArgument(camera, "camera", ["eye", "target", "up", "fov", "width", "height", "tolerance", "twoSided"]);
    const eye = vectorArgument(o.eye, "eye");
    const target = vectorArgument(o.target, "target");
    const up = vectorArgument(o.up, "up", [0, 1, 0]);
    if (o.fov === undefined) throw new TypeError("fov: the vertical field of view in degrees is required");
    const fov = numberArgument(o.fov, "fov", { above: 0, max: 179 });
    if (o.width === undefined || o.height === undefined) throw new TypeError("width, height: the viewport in pixels is required");
    const width = integerArgument(o.width, "width", 1, 65535);
    const height = integerArgument(o.height, "height", 1, 65535);
    const tolerance = numberArgument(o.tolerance, "tolerance", { above: 0, fallback: 1 });
    const twoSided = booleanArgument(o.twoSided, "twoSided", false);
    return call(() => this.#raw.adapt(eye, target, up, fov, width, height, tolerance, twoSided));
  }

  /** The units the adaptations asked for since the last call, in the order asked:
   * [{unit, start, end}] (byte offsets in the stream, `end` exclusive). */
  wanted() {
    const flat = call(() => this.#raw.wanted());
    const units = [];
    for (let i = 0; i < flat.length; i += 3) units.push({ unit: flat[i], start: flat[i + 1], end: flat[i + 2] });
    return units;
  }

  /** Hands over unit `unit`'s bytes, as `wanted` asked (taken in at the next `adapt`). */
  supply(unit, bytes) {
    const u = integerArgument(unit, "unit", 0, U32_MAX);
    if (u === undefined) throw new TypeError("unit: an integer expected, got undefined");
    const b = bytesArgument(bytes, "bytes");
    call(() => this.#raw.supply(u, b));
  }

  /** The adapted mesh: {positions, indices, vertices, triangles}; options: `float32`. */
  mesh(options) {
    const o = optionsArgument(options, "options", ["float32"]);
    const float32 = booleanArgument(o.float32, "float32", false);
    return call(() => this.#raw.mesh(float32));
  }

  /** {bytesRead, streamBytes, unitsLoaded, unitsRefused, units}. */
  fetched() {
    return call(() => this.#raw.fetched());
  }

  free() {
    this.#raw?.free();
    this.#raw = undefined;
  }

  [Symbol.dispose]() {
    this.free();
  }
}
