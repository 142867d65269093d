"""Open3D in, Open3D out: an open3d.geometry.TriangleMesh is encoded with meshcodec, a prefix of
the stream is decoded as a client that has received part of it would, and the levels come back
as Open3D meshes, measured against the original with Open3D's own exact point-to-surface
distances.

    python examples/python/open3d_levels.py [MESH] [--codec emc] [--out DIR]
"""

import argparse
import os
from pathlib import Path

import numpy as np
import open3d as o3d

import meshcodec

ROOT = Path(__file__).resolve().parents[2]
MESHES = Path(os.environ.get("MESHCODEC_DATA", ROOT.parent / "shared" / "meshes"))


def to_open3d(mesh):
    out = o3d.geometry.TriangleMesh(
        o3d.utility.Vector3dVector(mesh.vertices),
        o3d.utility.Vector3iVector(mesh.faces.astype(np.int32)),
    )
    out.compute_vertex_normals()
    return out


def largest_distance(mesh, scene):
    """Largest distance of a level's vertices to the original surface (Open3D, exact)."""
    points = o3d.core.Tensor(np.asarray(mesh.vertices, dtype=np.float32))
    return float(scene.compute_distance(points).numpy().max())


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("mesh", nargs="?", default=str(MESHES / "bunny-closed-35k.off"))
    parser.add_argument("--codec", default="emc")
    parser.add_argument("--out", default=".")
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    source = o3d.io.read_triangle_mesh(args.mesh)
    vertices, faces = np.asarray(source.vertices), np.asarray(source.triangles)
    stream = meshcodec.encode(vertices, faces, codec=args.codec)
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.t.geometry.TriangleMesh.from_legacy(source))
    diagonal = np.linalg.norm(source.get_max_bound() - source.get_min_bound())

    print(f"{Path(args.mesh).name}: {len(stream)} bytes with {args.codec}")
    for fraction in (0.05, 0.2, 0.5, 1.0):
        received = int(len(stream) * fraction)
        level = meshcodec.decode(stream, nbytes=received)
        mesh = to_open3d(level)
        error = largest_distance(mesh, scene) / diagonal
        print(f"first {fraction:>4.0%} of the stream ({received} bytes): level {level.level} of "
              f"{level.levels}, {len(mesh.triangles)} triangles, vertices within {error:.2e} of the diagonal")
        o3d.io.write_triangle_mesh(str(out / f"received-{int(fraction * 100)}.ply"), mesh)
    assert level.level == level.levels and error < 1e-3


if __name__ == "__main__":
    main()
