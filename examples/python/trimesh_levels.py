"""trimesh in, trimesh out: a mesh loaded by trimesh is encoded with meshcodec, and every level
of the stream comes back as a trimesh.Trimesh (watertightness, area and volume per level).

    python examples/python/trimesh_levels.py [MESH] [--codec emc] [--out DIR]

MESH defaults to the shared bunny-3k-closed.obj; DIR (default: the current folder) receives the
stream and the finest and a coarse level as PLY.
"""

import argparse
import os
from pathlib import Path

import numpy as np
import trimesh

import meshcodec

ROOT = Path(__file__).resolve().parents[2]
MESHES = Path(os.environ.get("MESHCODEC_DATA", ROOT.parent / "shared" / "meshes"))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("mesh", nargs="?", default=str(MESHES / "bunny-3k-closed.obj"))
    parser.add_argument("--codec", default="emc")
    parser.add_argument("--out", default=".")
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    # process=False: trimesh keeps the file's vertices and faces as they are.
    source = trimesh.load(args.mesh, process=False, force="mesh")
    stream = meshcodec.encode(source.vertices, source.faces, codec=args.codec, quant_bits=12)
    (out / "stream.mc").write_bytes(stream)
    ends = meshcodec.level_ends(stream)
    print(f"{Path(args.mesh).name}: {len(source.vertices)} vertices, {len(source.faces)} faces "
          f"-> {len(stream)} bytes with {args.codec}, {len(ends)} levels")
    print(f"{'level':>5} {'bytes':>8} {'vertices':>9} {'faces':>7} {'watertight':>10} {'area':>10} {'volume':>10}")
    levels = []
    for level in meshcodec.levels(stream):
        mesh = trimesh.Trimesh(level.vertices, level.faces, process=False)
        levels.append(mesh)
        volume = f"{mesh.volume:.3e}" if mesh.is_watertight else "—"
        print(f"{level.level:>5} {ends[level.level - 1]:>8} {len(mesh.vertices):>9} {len(mesh.faces):>7} "
              f"{str(mesh.is_watertight):>10} {mesh.area:>10.3e} {volume:>10}")
    levels[-1].export(out / "finest.ply")
    levels[len(levels) // 2].export(out / "coarse.ply")
    # The finest level is the source quantized at 12 bits: its area is the source's, nearly.
    print(f"area of the source {source.area:.6e}, of the finest level {levels[-1].area:.6e}")
    assert np.isclose(levels[-1].area, source.area, rtol=1e-3)


if __name__ == "__main__":
    main()
