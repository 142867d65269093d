// meshcodec's decoders in WebAssembly: the package's API (index.js).

/** What went wrong, for code to branch on. */
export type MeshcodecErrorCode =
  | "corrupt" // bytes that contradict the stream's own syntax
  | "truncated" // the bytes end before something that must be there
  | "unsupported" // a valid stream this build cannot decode (another format version, codec)
  | "limit" // a count beyond what the decoder accepts or the input can justify
  | "invalid-mesh"
  | "io"
  | "network" // a fetch failed (HTTP status, the .wasm not found)
  | "uninitialised" // a function called before `await init()`
  | "internal";

/** A stream the decoder refuses, or a fetch that failed: the library's one-line message. */
export class MeshcodecError extends Error {
  constructor(message: string, code: MeshcodecErrorCode, options?: ErrorOptions);
  readonly name: "MeshcodecError";
  readonly code: MeshcodecErrorCode;
}

/** Any value as a MeshcodecError (one already is; others get code "internal" unless they carry
 * a code). */
export function asMeshcodecError(error: unknown): MeshcodecError;

/** Bytes as the functions take them. */
export type Bytes = Uint8Array | ArrayBuffer | ArrayBufferView;

/** Loads the WebAssembly module, once. Absent `source`: the package's own meshcodec_bg.wasm. */
export function init(source?: string | URL | Response | BufferSource | WebAssembly.Module): Promise<void>;

/** A level's appearance as Hoppe's wedges: a wedge is a vertex with one value of each attribute
 * (a vertex on a seam has one wedge a side). */
export interface Appearance {
  /** The wedge of each face corner, face by face (3 a face). */
  corners: Uint32Array;
  /** Each wedge's vertex. */
  wedgeVertex: Uint32Array;
  /** x, y, z a wedge. */
  normals?: Float64Array;
  /** u, v a wedge. */
  uvs?: Float64Array;
  /** r, g, b, a in [0, 1] a wedge. */
  colours?: Float64Array;
  materials?: { face: Uint32Array; names: string[] };
}

/** A decoded level. */
export interface DecodedLevel<P extends Float32Array | Float64Array = Float64Array> {
  /** x, y, z a vertex. */
  positions: P;
  /** Three vertex indices a triangle. */
  indices: Uint32Array;
  /** Levels decoded (1 is the coarsest). */
  level: number;
  /** Levels the stream holds. */
  levels: number;
  codec: string;
  vertices: number;
  triangles: number;
  /** Vertices of the full mesh. */
  meshVertices: number;
  appearance: Appearance | null;
}

export interface DecodeOptions {
  /** Decode the first `level` levels (1 to the stream's levels); all when absent. */
  level?: number;
  /** Use only the first `bytes` bytes: the newest level they complete. */
  bytes?: number;
  /** Positions as a Float32Array (for GPU upload) rather than the library's Float64Array. */
  float32?: boolean;
}

/** Decodes a stream or the levels a prefix of it holds. Throws a TypeError or RangeError for a
 * bad argument, a MeshcodecError for a stream the decoder refuses. */
export function decode(bytes: Bytes, options: DecodeOptions & { float32: true }): DecodedLevel<Float32Array>;
export function decode(bytes: Bytes, options?: DecodeOptions & { float32?: false }): DecodedLevel<Float64Array>;
export function decode(bytes: Bytes, options?: DecodeOptions): DecodedLevel<Float32Array | Float64Array>;

/** One unit of a stream (a level, a level's appearance part, a meta-node) by byte range. */
export interface StreamUnit {
  unit: number;
  /** The unit it needs first, if any. */
  parent: number | null;
  firstByte: number;
  /** Exclusive. */
  endByte: number;
  bytes: number;
  /** Whether its bytes are all in the bytes given. */
  present: boolean;
}

/** How a stream carries appearance. */
export interface StreamAppearance {
  normalBits: number | null;
  normals: string | null;
  uvBits: number | null;
  uvOrigin: [number, number] | null;
  uvCell: number | null;
  colours: boolean;
  materials: number | null;
  materialLibrary: string | null;
  /** Whether it is coded with the levels (a part a level) rather than in one unit. */
  inLevels: boolean;
  unit: StreamUnit | null;
  levelParts: StreamUnit[] | null;
}

/** What a stream's header and index say (`meshcodec info --json`'s keys in camelCase). */
export interface StreamInfo {
  codec: string;
  formatVersion: number;
  syntax: number;
  /** Bytes given. */
  bytes: number;
  /** Bytes the whole stream holds. */
  streamBytes: number;
  truncated: boolean;
  quantBits: number;
  origin: [number, number, number];
  cell: [number, number, number];
  vertices: number;
  triangles: number;
  levels: number;
  levelEnds: number[];
  payloadStart: number;
  layered: boolean;
  units: StreamUnit[];
  appearance: StreamAppearance | null;
  levelSizes: number[] | null;
  [key: string]: unknown;
}

export function info(bytes: Bytes): StreamInfo;

/** The byte each level ends at, from a prefix holding the header and index. */
export function levelEnds(bytes: Bytes): number[];

/** A decoder fed a stream's bytes as they arrive. */
export class ProgressiveDecoder<P extends Float32Array | Float64Array = Float64Array> {
  constructor(options?: { float32?: boolean });
  /** The newest level the chunk completed, or undefined. */
  push(chunk: Bytes): DecodedLevel<P> | undefined;
  readonly received: number;
  /** Levels the stream holds (0 until its header and index are in). */
  readonly levels: number;
  /** Levels handed over so far. */
  readonly level: number;
  /** Whether each level is decoded once, going on from the last. */
  readonly incremental: boolean;
  free(): void;
  [Symbol.dispose](): void;
}

/** A point or direction. */
export type Vector = [number, number, number] | ArrayLike<number> | { x: number; y: number; z: number };

/** A camera and viewport for CameView.adapt. */
export interface ViewCamera {
  eye: Vector;
  target: Vector;
  /** Default [0, 1, 0]. */
  up?: Vector;
  /** Vertical field of view, degrees (0 < fov ≤ 179). */
  fov: number;
  /** Viewport, pixels. */
  width: number;
  height: number;
  /** Screen-space error allowed, pixels (default 1). */
  tolerance?: number;
  /** Refine faces turned away too. */
  twoSided?: boolean;
}

export interface Adapted {
  splits: number;
  collapses: number;
  /** Splits waiting for units `wanted` lists. */
  waiting: number;
  /** Whether the front is final for this camera. */
  settled: boolean;
  faces: number;
  vertices: number;
}

export interface ViewMeshData<P extends Float32Array | Float64Array = Float64Array> {
  positions: P;
  indices: Uint32Array;
  vertices: number;
  triangles: number;
}

export interface Fetched {
  bytesRead: number;
  streamBytes: number;
  unitsLoaded: number;
  unitsRefused: number;
  units: number;
}

/** How many of a came stream's first bytes `new CameView` needs; undefined while the prefix is
 * too short to say. */
export function cameHeadLength(prefix: Bytes): number | undefined;

/** A came stream refined to a camera, its meta-nodes supplied by the caller. */
export class CameView {
  constructor(head: Bytes);
  adapt(camera: ViewCamera): Adapted;
  /** Units asked for since the last call, in order; `end` exclusive. */
  wanted(): { unit: number; start: number; end: number }[];
  supply(unit: number, bytes: Bytes): void;
  mesh(options: { float32: true }): ViewMeshData<Float32Array>;
  mesh(options?: { float32?: false }): ViewMeshData<Float64Array>;
  fetched(): Fetched;
  free(): void;
  [Symbol.dispose](): void;
}
