"""What the Python package costs over the Rust library: encode and decode of a mesh through
`meshcodec.encode` / `meshcodec.decode` (numpy arrays in and out) against the library's
`canonical_for` + `Codec::encode` / `codecs::decode` (examples/time_codec.rs), measured in
alternation in one run, best of each, so that the shared machine's drift falls on both.

    cargo build --release --example time_codec
    python python/benchmarks/overhead.py [MESH] [--codecs emc,pm,came] [--rounds 5] [--repeats 10]
"""

import argparse
import json
import os
import subprocess
import time
from pathlib import Path

import meshcodec

ROOT = Path(__file__).resolve().parents[2]
MESHES = Path(os.environ.get("MESHCODEC_DATA", ROOT.parent / "shared" / "meshes"))
ANCHOR = ROOT / "target" / "release" / "examples" / "time_codec"


def best_python(mesh, codec, repeats):
    encode = decode = float("inf")
    for _ in range(repeats):
        started = time.perf_counter()
        stream = meshcodec.encode(mesh.vertices, mesh.faces, codec=codec, quant_bits=12)
        encode = min(encode, time.perf_counter() - started)
        started = time.perf_counter()
        meshcodec.decode(stream)
        decode = min(decode, time.perf_counter() - started)
    return encode, decode, len(stream)


def best_rust(path, codec, repeats):
    out = subprocess.run([str(ANCHOR), str(path), codec, str(repeats)], check=True,
                         capture_output=True, text=True).stdout
    report = json.loads(out)
    return report["encode_seconds"], report["decode_seconds"], report["bytes"]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("mesh", nargs="?", default=str(MESHES / "bunny.ply"))
    parser.add_argument("--codecs", default="emc,pm,came")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--repeats", type=int, default=10)
    args = parser.parse_args()
    mesh = meshcodec.load(args.mesh, drop_attributes=True)
    print(f"{Path(args.mesh).name}: {mesh.vertex_count} vertices, {mesh.face_count} faces; "
          f"best of {args.rounds} x {args.repeats}, package and library alternating")
    print(f"{'codec':<6} {'encode lib':>11} {'package':>9} {'ratio':>6}   {'decode lib':>11} {'package':>9} {'ratio':>6}")
    for codec in args.codecs.split(","):
        lib, pkg = [float("inf")] * 2, [float("inf")] * 2
        for _ in range(args.rounds):
            e, d, lib_bytes = best_rust(args.mesh, codec, args.repeats)
            lib = [min(lib[0], e), min(lib[1], d)]
            e, d, pkg_bytes = best_python(mesh, codec, args.repeats)
            pkg = [min(pkg[0], e), min(pkg[1], d)]
        assert lib_bytes == pkg_bytes, "the package and the library wrote different streams"
        print(f"{codec:<6} {lib[0] * 1e3:>9.2f}ms {pkg[0] * 1e3:>7.2f}ms {pkg[0] / lib[0]:>6.3f}   "
              f"{lib[1] * 1e3:>9.2f}ms {pkg[1] * 1e3:>7.2f}ms {pkg[1] / lib[1]:>6.3f}")


if __name__ == "__main__":
    main()
