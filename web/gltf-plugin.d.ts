// MeshcodecGLTFPlugin (gltf-plugin.js): GLTFLoader reads MESHCODEC_progressive scenes.
import type { Mesh } from "three";
import type { GLTFLoaderPlugin, GLTFParser } from "three/addons/loaders/GLTFLoader.js";
import type { MeshcodecLoader } from "./loader.js";

export const EXTENSION: "MESHCODEC_progressive";

export interface PrimitiveLevel {
  mesh: Mesh;
  meshIndex: number;
  primitive: number;
  level: number;
  levels: number;
  done: boolean;
}

export interface MeshcodecGLTFPluginOptions {
  /** The loader whose workers decode (default: one every plugin shares). */
  loader?: MeshcodecLoader;
  onLevel?: (event: PrimitiveLevel) => void;
  onError?: (error: unknown, where: { meshIndex: number; primitive: number }) => void;
  /** Aborting stops the refinement; each primitive keeps the level it has. */
  signal?: AbortSignal;
}

export class MeshcodecGLTFPlugin implements GLTFLoaderPlugin {
  constructor(parser: GLTFParser, options?: MeshcodecGLTFPluginOptions);
  readonly name: "MESHCODEC_progressive";
  /** Every stream's last level (or its error). */
  done: Promise<void>;
  loadMesh(meshIndex: number): Promise<Mesh> | null;
}
