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
