// MeshcodecLoader: meshcodec streams into three.js, as DRACOLoader brings Draco's. `load` hands
// over a BufferGeometry at once and refines it in place level by level as the stream arrives,
// decoded in a Web Worker (worker.js) so that the page never waits on the decoder:
//
//   const loader = new MeshcodecLoader();
//   loader.load("bunny.mc", (geometry) => {...}, onProgress, onError, (geometry, level) => {...});
//
// `onLoad` runs once the last level is in; `onLevel` after each level (geometry.userData.meshcodec
// holds its figures and its positions in double precision). Errors arrive at `onError` as
// `Error`s with the library's one-line message.
//
// View-dependent `came` streams: with `loader.viewDependent = true`, a `came` stream is not
// downloaded: its first bytes are read, `onLevel` runs with userData.meshcodec.came set (and
// the box the stream's grid spans), and `loader.refine(geometry, camera, width, height)` adapts
// the geometry to a three.js camera, the worker fetching the meta-nodes it needs by Range
// requests; `onLevel` runs after each adaptation with faces, bytes read and adaptation time.
import { BufferAttribute, BufferGeometry, Loader } from "three";

let nextId = 1;

export class MeshcodecLoader extends Loader {
  constructor(manager) {
    super(manager);
    this.worker = null;
    this.pending = new Map();
    /** Refine came streams to a camera rather than download them. */
    this.viewDependent = false;
  }

  /** The worker, started on first use. */
  start() {
    if (!this.worker) {
      this.worker = new Worker(new URL("./worker.js", import.meta.url), { type: "module" });
      this.worker.onmessage = ({ data }) => this.pending.get(data.id)?.(data);
      this.worker.onerror = (event) => {
        for (const handle of this.pending.values()) handle({ type: "error", message: event.message });
      };
    }
    return this.worker;
  }

  /** Streams `url` into a BufferGeometry, returned at once and refined as levels arrive. */
  load(url, onLoad, onProgress, onError, onLevel) {
    const resolved = this.manager.resolveURL(this.path + url);
    const request = { url: new URL(resolved, globalThis.location?.href).href, viewDependent: this.viewDependent };
    return this.decode(request, onLoad, onProgress, onError, onLevel);
  }

  /** The same for bytes already read (an ArrayBuffer, handed over to the worker). */
  parse(buffer, onLoad, onError, onLevel) {
    return this.decode({ bytes: buffer }, onLoad, undefined, onError, onLevel, [buffer]);
  }

  /** A Promise of the geometry once its last level is in. */
  loadAsync(url, onProgress) {
    return new Promise((resolve, reject) => this.load(url, resolve, onProgress, reject));
  }

  /** Decodes `request` into `geometry` (a new one unless given: a primitive's own, which
   * every mesh sharing it then shows refined). */
  decode(request, onLoad, onProgress, onError, onLevel, transfer = [], geometry = new BufferGeometry()) {
    const id = nextId++;
    this.manager.itemStart(id);
    const end = () => {
      this.pending.delete(id);
      this.manager.itemEnd(id);
    };
    this.pending.set(id, (message) => {
      switch (message.type) {
        case "progress":
          onProgress?.({ loaded: message.received, total: message.total, lengthComputable: message.total > 0 });
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
          end();
          const error = new Error(message.message);
          this.manager.itemError(id);
          if (onError) onError(error);
          else console.error(error);
          break;
        }
      }
    });
    this.start().postMessage({ ...request, id }, transfer);
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
    this.start().postMessage({ type: "camera", id: data.id, camera: view, tolerance, twoSided });
  }

  dispose() {
    this.worker?.terminate();
    this.worker = null;
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
MeshcodecLoader.prototype.loadRange = function (url, start, end, onLoad, onProgress, onError, onLevel, geometry) {
  const resolved = new URL(this.manager.resolveURL(this.path + url), globalThis.location?.href).href;
  return this.decode({ url: resolved, range: [start, end] }, onLoad, onProgress, onError, onLevel, [], geometry);
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
