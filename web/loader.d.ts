// MeshcodecLoader (loader.js): meshcodec streams into three.js, refined level by level.
import { BufferGeometry, Camera, Loader, LoadingManager, PerspectiveCamera } from "three";
import type { Appearance, MeshcodecError } from "./index.js";

/** What `geometry.userData.meshcodec` holds after each level. */
export interface LevelFigures {
  codec: string;
  level: number;
  levels: number;
  vertices: number;
  triangles: number;
  meshVertices: number;
  /** Bytes received when the level was complete. */
  received: number;
  /** The level's own positions, double precision. */
  positions: Float64Array;
  indices: Uint32Array;
  appearance: Appearance | null;
  materials: string[];
}

/** What it holds for a view-dependent came stream. */
export interface ViewFigures {
  came: true;
  id: number;
  codec: string;
  /** The box the stream's grid spans: [min, max]. */
  box: [[number, number, number], [number, number, number]];
  figures: Record<string, unknown>;
  faces?: number;
  vertices?: number;
  positions?: Float64Array;
  indices?: Uint32Array;
}

export type OnLevel = (geometry: BufferGeometry, figures: LevelFigures | ViewFigures) => void;

export interface LoadOptions {
  onLevel?: OnLevel;
  /** Aborting stops the download and decoding; `onError` gets the signal's reason. */
  signal?: AbortSignal;
}

export class MeshcodecLoader extends Loader<BufferGeometry> {
  constructor(manager?: LoadingManager);
  /** Refine came streams to a camera rather than download them. */
  viewDependent: boolean;
  decoderPath: string;
  workerLimit: number;
  /** The folder holding meshcodec_bg.wasm (default: the package's own). */
  setDecoderPath(path: string): this;
  /** Workers decoding at once (1 to 64, default 4). */
  setWorkerLimit(limit: number): this;
  load(
    url: string | URL,
    onLoad?: (geometry: BufferGeometry) => void,
    onProgress?: (event: ProgressEvent) => void,
    onError?: (error: MeshcodecError | unknown) => void,
    options?: OnLevel | LoadOptions,
  ): BufferGeometry;
  parse(
    buffer: ArrayBuffer,
    onLoad?: (geometry: BufferGeometry) => void,
    onError?: (error: MeshcodecError | unknown) => void,
    options?: OnLevel | LoadOptions,
  ): BufferGeometry;
  loadAsync(url: string | URL, onProgress?: (event: ProgressEvent) => void, options?: LoadOptions): Promise<BufferGeometry>;
  /** Streams bytes [start, end) of `url` (a stream inside a larger file). */
  loadRange(
    url: string | URL,
    start: number,
    end: number,
    onLoad?: (geometry: BufferGeometry) => void,
    onProgress?: (event: ProgressEvent) => void,
    onError?: (error: MeshcodecError | unknown) => void,
    options?: LoadOptions & { geometry?: BufferGeometry },
  ): BufferGeometry;
  /** Adapts a view-dependent came geometry to a camera, on a viewport of width × height pixels. */
  refine(
    geometry: BufferGeometry,
    camera: PerspectiveCamera | { eye: number[]; target: number[]; up?: number[]; fov: number },
    width: number,
    height: number,
    options?: { tolerance?: number; twoSided?: boolean; target?: Camera["position"] },
  ): void;
  dispose(): this;
}

/** Puts a decoded level into a geometry (what the loader does after each level). */
export function setLevel(geometry: BufferGeometry, level: Record<string, unknown>): void;
