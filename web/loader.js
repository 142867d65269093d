// MeshcodecLoader: meshcodec streams into three.js, as DRACOLoader brings Draco's. `load` hands
// over a BufferGeometry at once and refines it in place level by level as the stream arrives,
// decoded in Web Workers (worker.js) so that the page never waits on the decoder:
//
//   const loader = new MeshcodecLoader().setDecoderPath("/meshcodec/").setWorkerLimit(2);
//   loader.load("bunny.mc", (geometry) => {...}, onProgress, onError, { onLevel, signal });
//   const geometry = await loader.loadAsync("bunny.mc", onProgress, { onLevel, signal });
//
// `onLoad` runs once the last level is in; `onLevel(geometry, figures)` after each level
// (geometry.userData.meshcodec holds its figures and its positions in double precision).
// Errors arrive at `onError` as MeshcodecErrors with the library's one-line message and a
// `code`; an aborted load (its `signal` aborted) ends in the signal's reason, as `fetch` does.
// Types: loader.d.ts.
//
// View-dependent `came` streams: with `loader.viewDependent = true`, a `came` stream is not
// downloaded: its first bytes are read, `onLevel` runs with userData.meshcodec.came set (and
// the box the stream's grid spans), and `loader.refine(geometry, camera, width, height)` adapts
// the geometry to a three.js camera, the worker fetching the meta-nodes it needs by Range
// requests; `onLevel` runs after each adaptation with faces, bytes read and adaptation time.
import { BufferAttribute, BufferGeometry, Loader } from "three";
import { MeshcodecError, integerArgument, optionsArgument } from "./index.js";

let nextId = 1;

/** The 5th argument of `load` and the like: an `onLevel` function, or {onLevel, signal}. */
function loadOptions(value) {
  if (typeof value === "function") return { onLevel: value };
  const o = optionsArgument(value, "options", ["onLevel", "signal"]);
  if (o.onLevel !== undefined && typeof o.onLevel !== "function") {
    throw new TypeError("onLevel: a function expected");
  }
  if (o.signal !== undefined && !(typeof AbortSignal !== "undefined" && o.signal instanceof AbortSignal)) {
    throw new TypeError("signal: an AbortSignal expected");
  }
  return o;
}

export class MeshcodecLoader extends Loader {
  constructor(manager) {
    super(manager);
    /** Where meshcodec_bg.wasm is served from ("" for the package's own, beside worker.js). */
    this.decoderPath = "";
    /** At most this many workers decode at once, one stream each. */
    this.workerLimit = 4;
    /** The workers started: {worker, tasks}. */
    this.workers = [];
    this.pending = new Map();
    /** Refine came streams to a camera rather than download them. */
    this.viewDependent = false;
  }

  /** The folder (a URL, absolute or relative to the page) holding meshcodec_bg.wasm, as
   * DRACOLoader's; set before the first load. */
  setDecoderPath(path) {
    if (typeof path !== "string") throw new TypeError("path: a string expected");
    this.decoderPath = path;
    return this;
  }

  /** How many workers may decode at once (default 4): a stream is decoded in one worker, and
   * streams loaded together share them. */
  setWorkerLimit(limit) {
    this.workerLimit = integerArgument(limit, "limit", 1, 64);
    return this;
  }

  /** A worker for a new task: an idle one, else a new one while under the limit, else the
   * least busy. */
  start() {
    let slot = this.workers.reduce((best, w) => (!best || w.tasks < best.tasks ? w : best), null);
    if (!slot || (slot.tasks > 0 && this.workers.length < this.workerLimit)) {
      const worker = new Worker(new URL("./worker.js", import.meta.url), { type: "module" });
      slot = { worker, tasks: 0 };
      worker.onmessage = ({ data }) => this.pending.get(data.id)?.handle(data);
      worker.onerror = (event) => {
        for (const task of this.pending.values()) {
          if (task.slot === slot) task.handle({ type: "error", message: event.message, code: "internal" });
        }
      };
      const wasm = this.decoderPath
        ? new URL("meshcodec_bg.wasm", new URL(this.decoderPath, globalThis.location?.href).href.replace(/\/?$/, "/")).href
        : undefined;
      worker.postMessage({ type: "init", wasm });
      this.workers.push(slot);
    }
    return slot;
  }

  /** Streams `url` into a BufferGeometry, returned at once and refined as levels arrive.
   * `options`: an `onLevel` function, or {onLevel, signal}. */
  load(url, onLoad, onProgress, onError, options) {
    if (typeof url !== "string" && !(url instanceof URL)) throw new TypeError("url: a string or URL expected");
    const { onLevel, signal } = loadOptions(options);
    const resolved = this.manager.resolveURL(this.path + url);
    const request = { url: new URL(resolved, globalThis.location?.href).href, viewDependent: this.viewDependent };
    return this.decode(request, onLoad, onProgress, onError, { onLevel, signal });
  }

  /** The same for bytes already read (an ArrayBuffer, handed over to the worker). */
  parse(buffer, onLoad, onError, options) {
    if (!(buffer instanceof ArrayBuffer)) throw new TypeError("buffer: an ArrayBuffer expected");
    const { onLevel, signal } = loadOptions(options);
    return this.decode({ bytes: buffer }, onLoad, undefined, onError, { onLevel, signal, transfer: [buffer] });
  }

  /** A Promise of the geometry once its last level is in; `options`: {onLevel, signal}. */
  loadAsync(url, onProgress, options) {
    return new Promise((resolve, reject) => this.load(url, resolve, onProgress, reject, options));
  }

  /** Decodes `request` into `geometry` (a new one unless given: a primitive's own, which
   * every mesh sharing it then shows refined). */
  decode(request, onLoad, onProgress, onError, { onLevel, signal, transfer = [], geometry = new BufferGeometry() } = {}) {
    const id = nextId++;
    const report = (error) => {
      if (onError) onError(error);
      else console.error(error);
    };
    if (signal?.aborted) {
      queueMicrotask(() => report(signal.reason));
      return geometry;
    }
    const slot = this.start();
    slot.tasks++;
    this.manager.itemStart(id);
    const end = () => {
      if (!this.pending.delete(id)) return false;
      slot.tasks--;
      signal?.removeEventListener("abort", abort);
      this.manager.itemEnd(id);
      return true;
    };
    const abort = () => {
      slot.worker.postMessage({ type: "abort", id });
      if (end()) {
        this.manager.itemError(id);
        report(signal.reason);
      }
    };
    signal?.addEventListener("abort", abort, { once: true });
    const handle = (message) => {
      switch (message.type) {
        case "progress":
          if (onProgress) {
            const figures = { loaded: message.received, total: message.total, lengthComputable: message.total > 0 };
            onProgress(typeof ProgressEvent === "function" ? new ProgressEvent("progress", figures) : figures);
          }
          break;
        case "level":
          setLevel(geometry, message);
          onLevel?.(geometry, geometry.userData.meshcodec);
          break;
        case "done":
          end();
          onLoad?.(geometry);
          break;
        case "came":
          geometry.userData.meshcodec = { came: true, id, codec: message.codec, box: message.box, figures: message };
          onLevel?.(geometry, geometry.userData.meshcodec);
          break;
        case "view":
          setView(geometry, message);
          onLevel?.(geometry, geometry.userData.meshcodec);
          break;
        case "error": {
          if (!end()) break;
          this.manager.itemError(id);
          report(new MeshcodecError(message.message, message.code ?? "internal"));
          break;
        }
      }
    };
    this.pending.set(id, { slot, handle });
    slot.worker.postMessage({ ...request, id }, transfer);
    return geometry;
  }

  /** Adapts a view-dependent geometry (see the top) to a camera — `{eye, target, up}` as
   * [x, y, z] and `fov` (vertical, degrees), or a three.js PerspectiveCamera looking at
   * `target` — on a viewport of `width` × `height` pixels, at `tolerance` pixels. */
  refine(geometry, camera, width, height, { tolerance = 1, twoSided = false, target } = {}) {
    const data = geometry.userData.meshcodec;
    if (!data?.came) throw new Error("not a view-dependent came geometry");
    const view = camera.isPerspectiveCamera
      ? {
          eye: camera.position.toArray(),
          target: (target ?? camera.getWorldDirection(camera.position.clone()).add(camera.position)).toArray(),
          up: camera.up.toArray(),
          fov: camera.fov,
        }
      : { eye: camera.eye, target: camera.target, up: camera.up ?? [0, 1, 0], fov: camera.fov };
    view.width = Math.max(1, Math.round(width));
    view.height = Math.max(1, Math.round(height));
    const task = this.pending.get(data.id);
    if (!task) throw new MeshcodecError("the view's stream is closed (it failed or was aborted)", "internal");
    task.slot.worker.postMessage({ type: "camera", id: data.id, camera: view, tolerance, twoSided });
  }

  dispose() {
    for (const { worker } of this.workers) worker.terminate();
    this.workers = [];
    this.pending.clear();
    return this;
  }
}

/** Puts an adapted mesh of a came stream into `geometry`, with its figures in userData. */
function setView(geometry, view) {
  geometry.setAttribute("position", new BufferAttribute(Float32Array.from(view.positions), 3));
  geometry.setIndex(new BufferAttribute(view.indices, 1));
  geometry.computeVertexNormals();
  geometry.computeBoundingSphere();
  const data = geometry.userData.meshcodec;
  Object.assign(data, {
    figures: view,
    faces: view.faces,
    vertices: view.vertices,
    positions: view.positions,
    indices: view.indices,
  });
}

/** Streams the byte range [start, end) of `url` (a stream inside a larger file) into a
 * geometry, as `load` does a whole file. */
MeshcodecLoader.prototype.loadRange = function (url, start, end, onLoad, onProgress, onError, { onLevel, signal, geometry } = {}) {
  integerArgument(start, "start", 0, Number.MAX_SAFE_INTEGER);
  integerArgument(end, "end", start, Number.MAX_SAFE_INTEGER);
  const resolved = new URL(this.manager.resolveURL(this.path + url), globalThis.location?.href).href;
  return this.decode({ url: resolved, range: [start, end] }, onLoad, onProgress, onError, { onLevel, signal, geometry });
};

/** Puts a decoded level into `geometry`: single-precision positions for drawing (a vertex a
 * wedge where the level carries appearance: normals, uvs and colours as attributes, a group a
 * material), the level's own double-precision positions and figures in `userData.meshcodec`. */
export function setLevel(geometry, level) {
  for (const name of ["normal", "uv", "color"]) geometry.deleteAttribute(name);
  geometry.clearGroups();
  if (level.appearance) {
    setAppearance(geometry, level);
  } else {
    geometry.setAttribute("position", new BufferAttribute(Float32Array.from(level.positions), 3));
    geometry.setIndex(new BufferAttribute(level.indices, 1));
  }
  if (!geometry.getAttribute("normal")) geometry.computeVertexNormals();
  geometry.computeBoundingBox();
  geometry.computeBoundingSphere();
  geometry.userData.meshcodec = {
    codec: level.codec,
    level: level.level,
    levels: level.levels,
    vertices: level.vertices,
    triangles: level.triangles,
    meshVertices: level.meshVertices,
    received: level.received,
    positions: level.positions,
    indices: level.indices,
    appearance: level.appearance,
    materials: level.appearance?.materials?.names ?? [],
  };
}

/** A vertex a wedge, as three.js draws seams: its vertex's position, its own normal, uv and
 * colour; faces ordered by material, a group each. */
function setAppearance(geometry, level) {
  const { corners, wedgeVertex, normals, uvs, colours, materials } = level.appearance;
  const wedges = wedgeVertex.length;
  const positions = new Float32Array(wedges * 3);
  for (let w = 0; w < wedges; w++) {
    const v = wedgeVertex[w] * 3;
    positions.set([level.positions[v], level.positions[v + 1], level.positions[v + 2]], w * 3);
  }
  geometry.setAttribute("position", new BufferAttribute(positions, 3));
  if (normals) {
    const unit = new Float32Array(normals.length);
    for (let i = 0; i < normals.length; i += 3) {
      const length = Math.hypot(normals[i], normals[i + 1], normals[i + 2]) || 1;
      unit.set([normals[i] / length, normals[i + 1] / length, normals[i + 2] / length], i);
    }
    geometry.setAttribute("normal", new BufferAttribute(unit, 3));
  }
  if (uvs) geometry.setAttribute("uv", new BufferAttribute(Float32Array.from(uvs), 2));
  if (colours) geometry.setAttribute("color", new BufferAttribute(Float32Array.from(colours), 4));
  const faces = corners.length / 3;
  if (!materials) {
    geometry.setIndex(new BufferAttribute(corners, 1));
    return;
  }
  const order = Array.from({ length: faces }, (_, f) => f).sort((a, b) => materials.face[a] - materials.face[b] || a - b);
  const index = new Uint32Array(corners.length);
  order.forEach((f, k) => index.set(corners.subarray(f * 3, f * 3 + 3), k * 3));
  geometry.setIndex(new BufferAttribute(index, 1));
  let start = 0;
  for (let k = 1; k <= faces; k++) {
    if (k === faces || materials.face[order[k]] !== materials.face[order[start]]) {
      geometry.addGroup(start * 3, (k - start) * 3, materials.face[order[start]]);
      start = k;
    }
  }
}
