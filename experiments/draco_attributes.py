"""Draco as the single-rate anchor for appearance: whole textured / coloured / normal-carrying
meshes, measured on this machine, written as result files beside ours.

For each mesh: `meshcodec convert` writes it as glTF, whose vertices are split at every seam
(one vertex per wedge, as Draco needs). DracoPy (compression_level 10) encodes
  * the geometry alone, welded (one vertex per position), at quantization_bits Qp, and
  * the split mesh with its attributes: uvs at tex_coord_quantization_bits Qt (DracoPy stores them
    as raw floats unless that is given), normals at normal_quantization_bits Qn, colours as 8-bit
    channels,
decodes both (best of five each), writes the decoded whole mesh as PLY and measures it against
the original with `meshcodec distance` (geometry and appearance error, docs/CONTRACT.md §5 and
§5.1). Bits per vertex are over the canonical mesh's vertex count at Qp (from `meshcodec info`),
as for every other codec. Materials are not carried (DracoPy has no per-face attribute).

Run (after the release build, with the venv of experiments/requirements.txt):
    .venv/bin/python experiments/draco_attributes.py bunny-10k-textured spot airplane-colored dragon-res3
"""

import argparse
import json
import struct
import tempfile
from pathlib import Path

import DracoPy
import numpy as np

from anchor_common import ROOT, best_of, canonical_counts, distance_report, meshcodec, resolve, single_rate_result


COMPONENT = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16, 5125: np.uint32, 5126: np.float32}
WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}


def read_glb(path):
    """Split-vertex arrays of every triangle primitive of a .glb, concatenated."""
    data = path.read_bytes()
    magic, _, length = struct.unpack_from("<4sII", data, 0)
    if magic != b"glTF":
        raise SystemExit(f"{path}: not a glb")
    offset, doc, blob = 12, None, b""
    while offset < length:
        chunk_length, kind = struct.unpack_from("<II", data, offset)
        chunk = data[offset + 8: offset + 8 + chunk_length]
        if kind == 0x4E4F534A:
            doc = json.loads(chunk)
        elif kind == 0x004E4942:
            blob = chunk
        offset += 8 + chunk_length

    def accessor(i):
        a = doc["accessors"][i]
        view = doc["bufferViews"][a["bufferView"]]
        dtype = np.dtype(COMPONENT[a["componentType"]])
        width = WIDTH[a["type"]]
        start = view.get("byteOffset", 0) + a.get("byteOffset", 0)
        stride = view.get("byteStride", dtype.itemsize * width)
        raw = np.frombuffer(blob, dtype=np.uint8, count=stride * (a["count"] - 1) + dtype.itemsize * width,
                            offset=start)
        rows = np.lib.stride_tricks.as_strided(raw, shape=(a["count"], dtype.itemsize * width), strides=(stride, 1))
        return np.ascontiguousarray(rows).view(dtype).reshape(a["count"], width)

    parts = {"POSITION": [], "NORMAL": [], "TEXCOORD_0": [], "COLOR_0": []}
    faces, base = [], 0
    for mesh in doc["meshes"]:
        for prim in mesh["primitives"]:
            attrs = prim["attributes"]
            count = doc["accessors"][attrs["POSITION"]]["count"]
            for key in parts:
                if key in attrs:
                    parts[key].append(accessor(attrs[key]))
            faces.append(accessor(prim["indices"]).reshape(-1, 3).astype(np.int64) + base)
            base += count
    arrays = {k: np.concatenate(v) if v else None for k, v in parts.items()}
    return arrays, np.concatenate(faces)


def weld(points, faces):
    unique, inverse = np.unique(points, axis=0, return_inverse=True)
    return unique, inverse.reshape(-1)[faces]


def write_ply(path, points, faces, normals, uvs, colours):
    props = ["property float x", "property float y", "property float z"]
    columns = [points.astype("<f4")]
    if normals is not None:
        props += ["property float nx", "property float ny", "property float nz"]
        columns.append(normals.astype("<f4"))
    if uvs is not None:
        props += ["property float s", "property float t"]
        columns.append(uvs.astype("<f4"))
    header = "ply\nformat binary_little_endian 1.0\n" f"element vertex {len(points)}\n" + "\n".join(props) + "\n"
    if colours is not None:
        header += "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n"
    header += f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n"
    rows = np.concatenate(columns, axis=1).view(np.uint8).reshape(len(points), -1)
    if colours is not None:
        rows = np.concatenate([rows, colours.astype(np.uint8)], axis=1)
    tri = np.empty((len(faces), 13), dtype=np.uint8)
    tri[:, 0] = 3
    tri[:, 1:] = np.asarray(faces, dtype="<i4").view(np.uint8).reshape(len(faces), 12)
    path.write_bytes(header.encode() + rows.tobytes() + tri.tobytes())


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("meshes", nargs="+")
    parser.add_argument("--quant", type=int, default=12, help="Qp, position bits")
    parser.add_argument("--uv-bits", type=int, default=12, help="Qt, uv bits")
    parser.add_argument("--normal-bits", type=int, default=10, help="Qn, bits per octahedral coordinate")
    parser.add_argument("--samples", type=int, default=10)
    parser.add_argument("--out", default=str(ROOT / "results"))
    args = parser.parse_args()
    out = Path(args.out) / "draco"
    out.mkdir(parents=True, exist_ok=True)
    for name in args.meshes:
        path = resolve(name)
        with tempfile.TemporaryDirectory() as tmp:
            tmp = Path(tmp)
            vertices, triangles = canonical_counts(path, args.quant, tmp)
            meshcodec("convert", path, tmp / "split.glb")
            arrays, faces = read_glb(tmp / "split.glb")
            points = arrays["POSITION"].astype(np.float32)
            normals, uvs, colours = arrays["NORMAL"], arrays["TEXCOORD_0"], arrays["COLOR_0"]
            if colours is not None and colours.dtype != np.uint8:
                colours = np.clip(np.round(colours.astype(np.float64) * 255.0), 0, 255).astype(np.uint8)
            if colours is not None and colours.shape[1] == 3:
                colours = np.concatenate([colours, np.full((len(colours), 1), 255, np.uint8)], axis=1)
            welded, welded_faces = weld(points, faces)
            common = dict(quantization_bits=args.quant, compression_level=10)
            geometry = DracoPy.encode(welded, welded_faces.astype(np.uint32), **common)
            whole_options = dict(common)
            fields = []
            if uvs is not None:
                whole_options.update(tex_coord=uvs.astype(np.float64), tex_coord_quantization_bits=args.uv_bits)
                fields.append("uvs")
            if normals is not None:
                whole_options.update(normals=normals.astype(np.float64), normal_quantization_bits=args.normal_bits)
                fields.append("normals")
            if colours is not None:
                whole_options.update(colors=colours)
                fields.append("colours")
            enc_s, whole = best_of(lambda: DracoPy.encode(points, faces.astype(np.uint32), **whole_options))
            dec_s, decoded = best_of(lambda: DracoPy.decode(whole))
            geometry_dec_s, _ = best_of(lambda: DracoPy.decode(geometry))
            decoded_points = np.asarray(decoded.points, dtype=np.float64).reshape(-1, 3)
            decoded_faces = np.asarray(decoded.faces, dtype=np.int64).reshape(-1, 3)
            get = lambda a, k: None if a is None else np.asarray(a, dtype=np.float64).reshape(len(decoded_points), k)
            decoded_colours = None
            if colours is not None:
                decoded_colours = np.asarray(decoded.colors, dtype=np.uint8).reshape(len(decoded_points), -1)
            write_ply(tmp / "decoded.ply", decoded_points, decoded_faces,
                      get(decoded.normals if normals is not None else None, 3),
                      get(decoded.tex_coord if uvs is not None else None, 2), decoded_colours)
            report = distance_report(path, tmp / "decoded.ply", args.samples)
        bits = len(whole) * 8
        result = single_rate_result(
            name, path, (vertices, triangles), args.quant, whole, (enc_s, dec_s),
            (len(decoded_points), len(decoded_faces)), report,
            "Draco is single-rate and quantizes on its own grids; not checked against docs/CONTRACT.md §3",
            {
                "compression_level": 10, "quantization_bits": args.quant, "tex_coord_quantization_bits": args.uv_bits,
                "normal_quantization_bits": args.normal_bits, "version": getattr(DracoPy, "__version__", ""),
                "split_vertices": len(points), "geometry_bytes": len(geometry),
                "geometry_decode_seconds": geometry_dec_s, "fields": fields,
            })
        target = out / f"{name}-appearance.json"
        target.write_text(json.dumps(result, indent=2) + "\n")
        print(f"draco {name}: {len(whole)} bytes = {bits / vertices:.2f} bits/vertex "
              f"(geometry alone {len(geometry) * 8 / vertices:.2f}, {len(points)} split vertices, {', '.join(fields)}), "
              f"appearance error {report.get('appearance')}")


if __name__ == "__main__":
    main()
