"""`emc` against Draco decoding the same meshes, in one process: Draco on its one thread, `emc`
on all of this machine's cores (the ×16 mesh's stream has slabs, decoded at once; the smaller
meshes' streams have none and decode on one thread).

For bunny.ply and bunny-closed-35k as shared and subdivided twice at the edge midpoints (×16,
as `experiment emc-scale` makes it), at 12 bits: encodes with the meshcodec package (`emc`) and
with DracoPy (compression level 10, quantization_bits 12), then times the two decoders in
alternating rounds (best of seven each, arrays out in both cases), and writes
results/emc/draco-decode.json. Rates are over the canonical mesh's vertices (what `emc`
decodes), for both decoders.

Run (after tests/run.sh has made the venv and installed the package):
    .venv/bin/pip install -r experiments/requirements.txt
    .venv/bin/python experiments/draco_decode_scale.py
"""

import argparse
import json
import os
import time
from importlib.metadata import version
from pathlib import Path

import DracoPy
import numpy as np

import meshcodec
from anchor_common import ROOT, resolve

COMMAND = ".venv/bin/python experiments/draco_decode_scale.py"
QUANT = 12


def subdivide(vertices, faces):
    """Every triangle into four at its edge midpoints (each edge's midpoint once)."""
    m = len(faces)
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    unique, index = np.unique(np.sort(edges, axis=1), axis=0, return_inverse=True)
    midpoints = (vertices[unique[:, 0]] + vertices[unique[:, 1]]) / 2
    a, b, c = (index.reshape(3, m) + len(vertices))
    f0, f1, f2 = faces.T
    split = np.concatenate([
        np.stack([f0, a, c], 1), np.stack([a, f1, b], 1),
        np.stack([c, b, f2], 1), np.stack([a, b, c], 1),
    ])
    return np.concatenate([vertices, midpoints]), split


def timed(fn):
    start = time.perf_counter()
    out = fn()
    return time.perf_counter() - start, out


def measure(name, subdivisions, rounds):
    mesh = meshcodec.load(resolve(name), drop_attributes=True)
    vertices, faces = mesh.vertices, mesh.faces.astype(np.int64)
    for _ in range(subdivisions):
        vertices, faces = subdivide(vertices, faces)
    stream = meshcodec.encode(vertices, faces, codec="emc", quant_bits=QUANT)
    draco = DracoPy.encode(vertices, faces.astype(np.uint32), quantization_bits=QUANT,
                           compression_level=10)
    best = {"emc": float("inf"), "draco": float("inf")}
    decoded = None
    for _ in range(rounds):
        seconds, decoded = timed(lambda: meshcodec.decode(stream))
        best["emc"] = min(best["emc"], seconds)
        seconds, out = timed(lambda: DracoPy.decode(draco))
        best["draco"] = min(best["draco"], seconds)
        if len(out.faces) != len(faces):
            raise SystemExit(f"{name}: Draco decoded {len(out.faces)} faces of {len(faces)}")
    n = decoded.vertex_count
    row = {
        "mesh": name,
        "subdivisions": subdivisions,
        "vertices": n,
        "triangles": decoded.face_count,
        "emc_bytes": len(stream),
        "draco_bytes": len(draco),
        "emc_decode_seconds": best["emc"],
        "draco_decode_seconds": best["draco"],
        "emc_vertices_per_second": n / best["emc"],
        "draco_vertices_per_second": n / best["draco"],
        "emc_over_draco": best["draco"] / best["emc"],
    }
    print(f"{name} x{4 ** subdivisions}: {n} vertices; emc {best['emc'] * 1e3:.1f} ms "
          f"({n / best['emc'] / 1e6:.2f} M v/s, {len(stream)} B), Draco {best['draco'] * 1e3:.1f} ms "
          f"({n / best['draco'] / 1e6:.2f} M v/s, {len(draco)} B): emc at {row['emc_over_draco']:.2f}x Draco's rate")
    return row


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--out", default=str(ROOT / "results"))
    args = parser.parse_args()
    rows = [measure(name, s, args.rounds)
            for name, s in (("bunny", 0), ("bunny-closed-35k", 0), ("bunny-closed-35k", 2))]
    out = Path(args.out) / "emc" / "draco-decode.json"
    out.parent.mkdir(parents=True, exist_ok=True)
    report = {"command": COMMAND, "quant_bits": QUANT, "threads": 1, "emc_threads": os.cpu_count(),
              "draco": f"DracoPy {version('DracoPy')}, compression level 10", "rows": rows}
    out.write_text(json.dumps(report, indent=2) + "\n")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
