// meshcodec's WebAssembly decoder against Draco's own (npm draco3d) on the same mesh in Node,
// rounds alternated, best of each, as one JSON line. The mesh is the stream's full decode (its
// 12-bit grid's positions and its faces), which Draco encodes at 12 bits a coordinate,
// compression level 10 (speed 0), edgebreaker; each decoder's time covers what a user takes out:
// positions and triangle indices as typed arrays.
//   bash web/build.sh && node web/bench/draco.mjs STREAM.mc [ROUNDS] [REPEATS]
import { readFileSync } from "node:fs";
import { fileURLToPath } from "node:url";
import draco3d from "draco3d";
import init, { decode } from "../pkg/meshcodec.js";

const [stream, rounds = "5", repeats = "5"] = process.argv.slice(2);
if (!stream) {
  console.error("usage: node web/bench/draco.mjs STREAM.mc [ROUNDS] [REPEATS]");
  process.exit(2);
}
await init({ module_or_path: readFileSync(fileURLToPath(new URL("../pkg/meshcodec_bg.wasm", import.meta.url))) });
const bytes = new Uint8Array(readFileSync(stream));
const mesh = decode(bytes);
const [encoderModule, decoderModule] = await Promise.all([draco3d.createEncoderModule({}), draco3d.createDecoderModule({})]);

function dracoEncode({ positions, indices }) {
  const encoder = new encoderModule.Encoder();
  const builder = new encoderModule.MeshBuilder();
  const dracoMesh = new encoderModule.Mesh();
  builder.AddFacesToMesh(dracoMesh, indices.length / 3, indices);
  builder.AddFloatAttributeToMesh(dracoMesh, encoderModule.POSITION, positions.length / 3, 3, Float32Array.from(positions));
  encoder.SetAttributeQuantization(encoderModule.POSITION, 12);
  encoder.SetSpeedOptions(0, 0);
  encoder.SetEncodingMethod(encoderModule.MESH_EDGEBREAKER_ENCODING);
  const out = new encoderModule.DracoInt8Array();
  const length = encoder.EncodeMeshToDracoBuffer(dracoMesh, out);
  if (length <= 0) throw new Error(`Draco could not encode: ${encoder.GetErrorMessage?.() ?? ""}`);
  const encoded = new Int8Array(length);
  for (let i = 0; i < length; i++) encoded[i] = out.GetValue(i);
  for (const object of [out, dracoMesh, builder, encoder]) encoderModule.destroy(object);
  return encoded;
}

/** Draco's decode as three.js's DRACOLoader does it: the mesh, then its arrays. */
function dracoDecode(encoded) {
  const decoder = new decoderModule.Decoder();
  const buffer = new decoderModule.DecoderBuffer();
  buffer.Init(encoded, encoded.length);
  const dracoMesh = new decoderModule.Mesh();
  const status = decoder.DecodeBufferToMesh(buffer, dracoMesh);
  if (!status.ok()) throw new Error(`Draco: ${status.error_msg()}`);
  const points = dracoMesh.num_points();
  const faces = dracoMesh.num_faces();
  const attribute = decoder.GetAttribute(dracoMesh, decoder.GetAttributeId(dracoMesh, decoderModule.POSITION));
  const floats = points * 3;
  let ptr = decoderModule._malloc(floats * 4);
  decoder.GetAttributeDataArrayForAllPoints(dracoMesh, attribute, decoderModule.DT_FLOAT32, floats * 4, ptr);
  const positions = new Float32Array(decoderModule.HEAPF32.buffer, ptr, floats).slice();
  decoderModule._free(ptr);
  ptr = decoderModule._malloc(faces * 12);
  decoder.GetTrianglesUInt32Array(dracoMesh, faces * 12, ptr);
  const indices = new Uint32Array(decoderModule.HEAPU32.buffer, ptr, faces * 3).slice();
  decoderModule._free(ptr);
  for (const object of [dracoMesh, buffer, decoder]) decoderModule.destroy(object);
  return { positions, indices };
}

const encoded = dracoEncode(mesh);
const check = dracoDecode(encoded);
if (check.indices.length !== mesh.indices.length) throw new Error("Draco's mesh has another face count");

const time = (work) => {
  let best = Infinity;
  for (let i = 0; i < Number(repeats); i++) {
    const started = performance.now();
    work();
    best = Math.min(best, (performance.now() - started) / 1000);
  }
  return best;
};
let ours = Infinity;
let theirs = Infinity;
for (let round = 0; round < Number(rounds); round++) {
  ours = Math.min(ours, time(() => decode(bytes)));
  theirs = Math.min(theirs, time(() => dracoDecode(encoded)));
}
console.log(
  JSON.stringify({
    stream,
    vertices: mesh.vertices,
    triangles: mesh.triangles,
    meshcodec_bytes: bytes.length,
    meshcodec_decode_seconds: ours,
    draco_bytes: encoded.length,
    draco_decode_seconds: theirs,
    meshcodec_over_draco: ours / theirs,
  }),
);
