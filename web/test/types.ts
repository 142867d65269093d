// The hand-written declarations, checked by `tsc -p web` (web/test/package.test.mjs): the API as
// a TypeScript user calls it compiles, and misuse does not (each @ts-expect-error must fail).
import { CameView, MeshcodecError, ProgressiveDecoder, decode, info, init } from "../index.js";
import { MeshcodecLoader } from "../loader.js";
import { CameStream } from "../came.js";
import { MeshcodecGLTFPlugin } from "../gltf-plugin.js";
import { GLTFLoader } from "three/addons/loaders/GLTFLoader.js";

export async function typed(bytes: Uint8Array): Promise<number> {
  await init();
  const level = decode(bytes, { level: 3 });
  const single: Float32Array = decode(bytes, { float32: true }).positions;
  const double: Float64Array = level.positions;
  const uvs: Float64Array | undefined = level.appearance?.uvs;
  // @ts-expect-error: options are an object
  decode(bytes, 3);
  // @ts-expect-error: no such option
  decode(bytes, { lvl: 3 });
  // @ts-expect-error: a Float64Array unless float32
  const wrong: Float32Array = level.positions;
  const described = info(bytes);
  const ends: number[] = described.levelEnds;
  const decoder = new ProgressiveDecoder();
  const pushed = decoder.push(bytes);
  const view = new CameView(bytes);
  const adapted = view.adapt({ eye: [0, 0, 3], target: { x: 0, y: 0, z: 0 }, fov: 45, width: 800, height: 600 });
  // @ts-expect-error: adapt takes one camera object
  view.adapt([0, 0, 3], [0, 0, 0], [0, 1, 0], 45, 800, 600, 1, false);
  try {
    decode(bytes);
  } catch (e) {
    if (e instanceof MeshcodecError && e.code === "truncated") return 0;
  }
  const loader = new MeshcodecLoader().setDecoderPath("/meshcodec/").setWorkerLimit(2);
  const controller = new AbortController();
  const geometry = await loader.loadAsync("bunny.mc", undefined, { signal: controller.signal, onLevel: (g, f) => f.codec });
  const stream = await CameStream.open("came.mc");
  const refined = await stream.refine({ eye: [0, 0, 3], target: [0, 0, 0], fov: 45, width: 800, height: 600 });
  const gltf = new GLTFLoader().register((parser) => new MeshcodecGLTFPlugin(parser, { loader, signal: controller.signal }));
  return (
    single.length + double.length + (uvs?.length ?? 0) + wrong.length + ends.length + (pushed?.level ?? 0) +
    adapted.faces + geometry.index!.count + refined.faces + (gltf ? 1 : 0)
  );
}
