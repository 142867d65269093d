"""What the Draco anchor scripts share: where the meshes and our binary are, timing, and the
canonical mesh's counts that every codec's bits per vertex are taken over."""

import json
import subprocess
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
BIN = ROOT / "target" / "release" / "meshcodec"
MESHES = ROOT.parent / "shared" / "meshes"


def resolve(name):
    for ext in ("ply", "obj", "off", "m", "stl", "glb", "gltf"):
        path = MESHES / f"{name}.{ext}"
        if path.is_file():
            return path
    raise SystemExit(f"unknown mesh {name}")


def meshcodec(*args):
    """Runs our CLI; returns what it printed."""
    return subprocess.run([str(BIN), *map(str, args)], check=True, capture_output=True, text=True).stdout


def canonical_counts(path, quant, tmp):
    """Vertices and triangles of the canonical mesh of `path` at `quant` bits."""
    stream = Path(tmp) / "raw.mc"
    meshcodec("encode", "--codec", "raw", "--quant", quant, "--drop-attributes", path, stream)
    info = json.loads(meshcodec("info", stream, "--json"))
    return info["vertices"], info["triangles"]


def best_of(fn, runs=5):
    """The shortest of `runs` wall-clock timings of `fn`, and its last result."""
    best, out = float("inf"), None
    for _ in range(runs):
        start = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - start)
    return best, out


def distance_report(original, decoded, samples):
    """`meshcodec distance` of a decoded file against the original, as JSON."""
    return json.loads(meshcodec("distance", original, decoded, "--samples", samples, "--json"))


def single_rate_result(name, path, counts, quant, data, seconds, decoded_counts, report, why, draco):
    """A result file (docs/CONTRACT.md §6) of one single-rate level: `counts` are the canonical
    mesh's (vertices, triangles), `seconds` (encode, decode), `decoded_counts` the decoded
    file's, `report` its `distance_report` (with appearance error when both have appearance),
    `why` the reason it is not called lossless, `draco` the coder's own settings and figures."""
    vertices, triangles = counts
    bits = len(data) * 8
    return {
        "codec": "draco", "mesh": name, "source": str(path),
        "vertices": vertices, "triangles": triangles, "quant_bits": quant, "bytes": len(data),
        "encode_seconds": seconds[0], "decode_seconds": seconds[1], "lossless": False,
        "lossless_error": why,
        "draco": draco,
        "levels": [{
            "level": 1, "bits": bits, "connectivity_bits": 0, "geometry_bits": 0,
            "vertices": decoded_counts[0], "triangles": decoded_counts[1],
            "bits_per_vertex": bits / vertices, "bits_per_triangle": bits / triangles,
            "hausdorff": report["hausdorff_relative"], "rms": report["rms_relative"],
            "hausdorff_paper": report["hausdorff_paper"] / report["diagonal"],
            **(report.get("appearance") or {}),
        }],
    }
