"""What the portable wheel (x86-64-v2, python/pyproject.toml) costs against one built for this
machine's processor: `meshcodec.decode` of each mesh's `emc` stream through both builds,
alternated round by round in one run (best of each), so that the shared machine's drift falls
on both. Each build is installed into a folder of its own:

    (cd python && maturin build --release -o ../target/wheels-portable)
    (cd python && RUSTFLAGS="-C target-cpu=native" maturin build --release -o ../target/wheels-native)
    pip install --no-deps --target DIR-PORTABLE target/wheels-portable/*.whl   # likewise native
    python python/benchmarks/portable.py DIR-PORTABLE DIR-NATIVE MESH... [--rounds 5] [--repeats 5]
"""

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

# Run inside each build's interpreter: decodes the stream `repeats` times, prints the best.
PROBE = r"""
import json, sys, time
import meshcodec
path, codec, repeats = sys.argv[1], sys.argv[2], int(sys.argv[3])
mesh = meshcodec.load(path, drop_attributes=True)
stream = meshcodec.encode(mesh.vertices, mesh.faces, codec=codec, quant_bits=12)
best = float("inf")
for _ in range(repeats):
    started = time.perf_counter()
    meshcodec.decode(stream)
    best = min(best, time.perf_counter() - started)
print(json.dumps({"decode_seconds": best, "bytes": len(stream), "module": meshcodec._core.__file__}))
"""


def probe(folder, mesh, codec, repeats):
    env = dict(os.environ, PYTHONPATH=str(folder))
    out = subprocess.run([sys.executable, "-c", PROBE, str(mesh), codec, str(repeats)],
                         check=True, capture_output=True, text=True, env=env).stdout
    report = json.loads(out)
    assert Path(report["module"]).resolve().is_relative_to(Path(folder).resolve()), report
    return report


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("portable", type=Path)
    parser.add_argument("native", type=Path)
    parser.add_argument("meshes", nargs="+", type=Path)
    parser.add_argument("--codec", default="emc")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    rows = []
    for mesh in args.meshes:
        best = {"portable": float("inf"), "native": float("inf")}
        sizes = set()
        for _ in range(args.rounds):
            for name in ("portable", "native"):
                report = probe(getattr(args, name), mesh, args.codec, args.repeats)
                best[name] = min(best[name], report["decode_seconds"])
                sizes.add(report["bytes"])
        assert len(sizes) == 1, f"the two builds wrote different streams: {sizes}"
        row = {"mesh": mesh.name, "codec": args.codec, "bytes": sizes.pop(),
               "portable_decode_seconds": best["portable"], "native_decode_seconds": best["native"],
               "portable_over_native": best["portable"] / best["native"]}
        rows.append(row)
        print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()
