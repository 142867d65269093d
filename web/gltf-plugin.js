// MeshcodecGLTFPlugin: three.js's GLTFLoader reads glTF scenes whose primitives are meshcodec's
// progressive streams (the MESHCODEC_progressive extension, docs/GLTF.md; `meshcodec pack`
// writes them), as its meshopt plugin reads EXT_meshopt_compression:
//
//   import { GLTFLoader } from "three/addons/loaders/GLTFLoader.js";
//   import { MeshcodecGLTFPlugin } from "./gltf-plugin.js";
//   const loader = new GLTFLoader();
//   loader.register((parser) => new MeshcodecGLTFPlugin(parser, { onLevel }));
//   const gltf = await loader.loadAsync("scene.glb");   // the scene with its coarse fallbacks
//
// The scene comes back as soon as GLTFLoader has it, each packed primitive showing the coarse
// level its own accessors hold; then each primitive's stream is decoded level by level in a
// Web Worker (MeshcodecLoader's) and the primitive's geometry replaced as each level is in,
// its material, textures and transform kept. A stream in the GLB is read from the GLB's bytes;
// one in a file of its own (`pack --external`) is fetched by a Range request for its bytes
// alone, each level decoded as soon as its bytes have arrived. `onLevel({ mesh, meshIndex,
// primitive, level, levels, done })` runs after each level; `onError(error, where)` when a
// stream cannot be decoded (the primitive keeps the last level it had). `plugin.done` is a
// Promise of every stream's last level. `signal` (an AbortSignal) stops the refinement. Types:
// gltf-plugin.d.ts.
import { MeshcodecLoader } from "./loader.js";

export const EXTENSION = "MESHCODEC_progressive";

/** The loader (and its worker) every plugin shares unless given its own. */
let shared = null;

export class MeshcodecGLTFPlugin {
  constructor(parser, { loader, onLevel, onError, signal } = {}) {
    this.name = EXTENSION;
    /** Aborting it stops every stream's refinement (each primitive keeps the level it has). */
    this.signal = signal;
    this.parser = parser;
    this.loader = loader ?? (shared ??= new MeshcodecLoader());
    this.onLevel = onLevel;
    this.onError = onError;
    this.pending = [];
    this.done = Promise.resolve();
  }

  /** GLTFLoader's hook: the mesh as the parser makes it (the fallback), refined afterwards. */
  loadMesh(meshIndex) {
    const definition = this.parser.json.meshes?.[meshIndex];
    const packed = definition?.primitives?.map((p) => p.extensions?.[EXTENSION]) ?? [];
    if (!packed.some(Boolean)) return null;
    return this.parser.loadMesh(meshIndex).then((object) => {
      const meshes = object.isGroup ? object.children : [object];
      packed.forEach((extension, primitive) => {
        const mesh = meshes[primitive];
        if (extension && mesh) this.refine(mesh, meshIndex, primitive, extension);
      });
      this.done = Promise.allSettled(this.pending).then(() => undefined);
      return object;
    });
  }

  /** Decodes one primitive's stream and puts each level into its mesh. */
  refine(mesh, meshIndex, primitive, extension) {
    const json = this.parser.json;
    const view = json.bufferViews?.[extension.bufferView];
    const buffer = view && json.buffers?.[view.buffer];
    if (!buffer) {
      this.fail(new Error(`${EXTENSION}: buffer view ${extension.bufferView} is missing`), meshIndex, primitive);
      return;
    }
    const levels = extension.levels.length;
    // Refined in place: every node that draws this mesh (GLTFLoader clones share the
    // geometry) shows each level.
    const geometry = mesh.geometry;
    const finished = new Promise((resolve) => {
      const onLevel = (refined, figures) => {
        this.onLevel?.({ mesh, meshIndex, primitive, level: figures.level, levels, done: figures.level === levels });
      };
      const onLoad = () => resolve();
      const onError = (error) => {
        this.fail(error, meshIndex, primitive);
        resolve();
      };
      if (buffer.uri === undefined) {
        // In the GLB: the view's bytes, copied (the worker takes them).
        this.parser.getDependency("bufferView", extension.bufferView).then((bytes) => {
          const copy = bytes.slice(0);
          this.loader.decode({ bytes: copy }, onLoad, undefined, onError, { onLevel, signal: this.signal, transfer: [copy], geometry });
        }, onError);
      } else {
        const url = new URL(buffer.uri, new URL(this.parser.options.path || "./", globalThis.location?.href)).href;
        const start = view.byteOffset ?? 0;
        this.loader.loadRange(url, start, start + view.byteLength, onLoad, undefined, onError, { onLevel, signal: this.signal, geometry });
      }
    });
    this.pending.push(finished);
  }

  fail(error, meshIndex, primitive) {
    if (this.onError) this.onError(error, { meshIndex, primitive });
    else console.error(`mesh ${meshIndex} primitive ${primitive}:`, error);
  }
}
