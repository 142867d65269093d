// Draco's encoder and decoder (npm draco3d in Node; three.js's copy of Draco's wasm decoder in
// a browser) driven as three.js's DRACOLoader drives them; plain functions of the module, so
// that Node and a page import the same code (web/bench/draco.mjs, web/bench/draco-browser.mjs).

/** Draco's encoding of `{positions, indices}` at 12 bits a coordinate, compression level 10
 * (speed 0), edgebreaker. */
export function dracoEncode(encoderModule, { positions, indices }) {
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
export function dracoDecode(decoderModule, encoded) {
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
