"""Draco as a single-rate anchor, measured on this machine, written as result files.

For each mesh and quantization, encodes the mesh's referenced vertices and faces with DracoPy
(compression_level 10, quantization_bits Q — both set), decodes it, times both (best of five),
measures the decoded mesh against the original with `meshcodec distance`, and writes
results/draco/<mesh>-q<Q>.json in the schema of docs/CONTRACT.md §6 (one level), with bits per vertex
over the canonical mesh's vertex count at Q bits (from `meshcodec info`), as every other codec.

Run (after tests/run.sh has made the venv and the release build):
    .venv/bin/pip install -r experiments/requirements.txt
    .venv/bin/python experiments/draco_anchor.py bunny armadillo-43k --quant 8 9 10 11 12 13 14 15 16
"""

import argparse
import json
import tempfile
from pathlib import Path

import DracoPy
import numpy as np
import open3d as o3d

from anchor_common import ROOT, best_of, canonical_counts, distance_report, resolve, single_rate_result


def write_ply(path, points, faces):
    header = (f"ply\nformat binary_little_endian 1.0\nelement vertex {len(points)}\n"
              "property double x\nproperty double y\nproperty double z\n"
              f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n")
    body = bytearray()
    body += np.asarray(points, dtype="<f8").tobytes()
    tri = np.empty((len(faces), 13), dtype=np.uint8)
    tri[:, 0] = 3
    tri[:, 1:] = np.asarray(faces, dtype="<i4").view(np.uint8).reshape(len(faces), 12)
    body += tri.tobytes()
    path.write_bytes(header.encode() + bytes(body))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("meshes", nargs="+")
    parser.add_argument("--quant", nargs="+", type=int, default=[12])
    parser.add_argument("--samples", type=int, default=10)
    parser.add_argument("--out", default=str(ROOT / "results"))
    args = parser.parse_args()
    out = Path(args.out) / "draco"
    out.mkdir(parents=True, exist_ok=True)
    for name in args.meshes:
        path = resolve(name)
        # Our own reader's counts matter; Open3D only supplies the arrays (it keeps all vertices).
        mesh = o3d.io.read_triangle_mesh(str(path))
        faces = np.asarray(mesh.triangles, dtype=np.int64)
        used = np.unique(faces)
        remap = np.full(len(mesh.vertices), -1)
        remap[used] = np.arange(len(used))
        points = np.asarray(mesh.vertices, dtype=np.float64)[used]
        faces = remap[faces]
        for q in args.quant:
            with tempfile.TemporaryDirectory() as tmp:
                tmp = Path(tmp)
                vertices, triangles = canonical_counts(path, q, tmp)
                enc_s, data = best_of(lambda: DracoPy.encode(points.astype(np.float32), faces.astype(np.uint32),
                                                             quantization_bits=q, compression_level=10))
                dec_s, decoded = best_of(lambda: DracoPy.decode(data))
                decoded_path = tmp / "decoded.ply"
                write_ply(decoded_path, np.asarray(decoded.points, dtype=np.float64),
                          np.asarray(decoded.faces, dtype=np.int64).reshape(-1, 3))
                report = distance_report(path, decoded_path, args.samples)
            bits = len(data) * 8
            result = single_rate_result(
                name, path, (vertices, triangles), q, data, (enc_s, dec_s),
                (len(np.asarray(decoded.points).reshape(-1, 3)), len(np.asarray(decoded.faces).reshape(-1, 3))),
                report,
                "Draco is single-rate and quantizes on its own grid; not checked against docs/CONTRACT.md §3",
                {"compression_level": 10, "quantization_bits": q, "version": getattr(DracoPy, "__version__", "")})
            target = out / f"{name}-q{q}.json"
            target.write_text(json.dumps(result, indent=2) + "\n")
            print(f"draco {name} q{q}: {len(data)} bytes = {bits / vertices:.2f} bits/vertex, "
                  f"decode {vertices / dec_s / 1e6:.2f} M v/s, Hausdorff {report['hausdorff_relative']:.3e}")


if __name__ == "__main__":
    main()
