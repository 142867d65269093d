// CameStream (came.js): a came stream refined to a camera, its meta-nodes fetched by byte range.
import type { Adapted, CameView, Fetched, ViewMeshData } from "./index.js";

/** Reads bytes [start, end) of a stream (fewer where it ends). */
export type RangeRead = (start: number, end: number) => Promise<Uint8Array>;

/** HTTP Range requests on `url`. */
export function rangeReader(url: string | URL, fetchOptions?: RequestInit): RangeRead;
/** Ranges of bytes already in memory. */
export function bytesReader(bytes: Uint8Array | ArrayBuffer): RangeRead;
export function concat(a: Uint8Array, b: Uint8Array): Uint8Array;

export interface StreamCamera {
  eye: [number, number, number];
  target: [number, number, number];
  up?: [number, number, number];
  /** Vertical, degrees. */
  fov: number;
  width: number;
  height: number;
}

export interface StreamFetched extends Fetched {
  requests: number;
}

export class CameStream {
  /** Opens a came stream from a URL or a reader, reading its header, index and first unit. */
  static open(source: string | URL | RangeRead, options?: { firstRequest?: number; gap?: number }): Promise<CameStream>;
  readonly view: CameView;
  round(
    camera: StreamCamera,
    options?: { tolerance?: number; twoSided?: boolean },
  ): { adapted: Adapted & { ms: number }; fetched: Promise<[number, Uint8Array | null][]> };
  supply(units: [number, Uint8Array | null][]): void;
  refine(
    camera: StreamCamera,
    options?: { tolerance?: number; twoSided?: boolean; rounds?: number; onRound?: (adapted: Adapted) => void },
  ): Promise<{ mesh: ViewMeshData; faces: number; rounds: number; settled: boolean; adaptMs: number } & StreamFetched>;
  fetched(): StreamFetched;
  free(): void;
}
