"""Cross-check of meshcodec's distances against Open3D (open3d-cpu).

1. Exactness: every sample point `meshcodec distance --write-samples` writes is measured again
   with Open3D's RaycastingScene.compute_distance (exact point-to-triangle distance); both must
   agree to 1e-6 of the reference mesh's bounding-box diagonal, on several real mesh pairs.
2. Sampling: a Metro-style measurement made only with Open3D (its own uniform area sampler plus
   all vertices, both directions) must give the same Hausdorff distance and RMS, within
   sampling noise, as the Python package's `meshcodec.distance`.

The decoded meshes are made with the package too. Run by tests/run.sh; needs the release binary
(MESHCODEC_BIN to use another) and the package (`pip install ./python`).
"""

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import open3d as o3d
import pytest

import meshcodec

ROOT = Path(__file__).resolve().parent.parent
MESHES = Path(os.environ.get("MESHCODEC_DATA", ROOT.parent / "shared" / "meshes"))
BIN = Path(os.environ.get("MESHCODEC_BIN", ROOT / "target" / "release" / "meshcodec"))

# Reference mesh, compared mesh: a shared mesh, or "raw@Q" for the reference decoded from our
# uncompressed codec at Q bits (a codec's output against its original, as experiments measure).
PAIRS = [
    ("bunny.ply", "bunny-res3.ply"),
    ("bunny-res2.ply", "bunny-res4.ply"),
    ("bunny-closed-35k.off", "bunny-3k-libigl.off"),
    ("camelhead.off", "raw@7"),
    ("max-planck-5k.obj", "raw@8"),
]


def materialize(a, b, tmp_path):
    """Path of the compared mesh, decoding it from a fresh stream when it is "raw@Q"."""
    if not b.startswith("raw@"):
        return MESHES / b
    decoded = tmp_path / "decoded.ply"
    original = meshcodec.load(MESHES / a, drop_attributes=True)
    stream = meshcodec.encode(original.vertices, original.faces, codec="raw", quant_bits=int(b.split("@")[1]))
    meshcodec.save(meshcodec.decode(stream), decoded)
    return decoded


def load(path):
    mesh = o3d.io.read_triangle_mesh(str(path))
    assert len(mesh.triangles) > 0, path
    return mesh


def scene_of(mesh):
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.t.geometry.TriangleMesh.from_legacy(mesh))
    return scene


def exact_distances(scene, points):
    query = o3d.core.Tensor(points.astype(np.float32), dtype=o3d.core.Dtype.Float32)
    return scene.compute_distance(query).numpy().astype(np.float64)


def ours(a, b, tmp_path, samples):
    dump = tmp_path / "samples.csv"
    out = subprocess.run(
        [str(BIN), "distance", str(MESHES / a), str(b), "--samples", str(samples),
         "--json", "--write-samples", str(dump)],
        check=True, capture_output=True, text=True,
    )
    report = json.loads(out.stdout)
    direction = np.loadtxt(dump, delimiter=",", skiprows=1, usecols=0, dtype=str)
    values = np.loadtxt(dump, delimiter=",", skiprows=1, usecols=(1, 2, 3, 4))
    return report, direction, values


@pytest.mark.parametrize("a,b", PAIRS)
def test_every_sample_distance_matches_open3d(a, b, tmp_path):
    b = materialize(a, b, tmp_path)
    report, direction, values = ours(a, b, tmp_path, samples=3)
    mesh_a, mesh_b = load(MESHES / a), load(b)
    tolerance = 1e-6 * report["diagonal"]
    for tag, target in (("a_to_b", mesh_b), ("b_to_a", mesh_a)):
        rows = values[direction == tag]
        assert len(rows) > 1000
        theirs = exact_distances(scene_of(target), rows[:, :3])
        worst = np.abs(theirs - rows[:, 3]).max()
        assert worst <= tolerance, f"{tag}: differs by {worst:.3e} > {tolerance:.3e}"


def metro_style(mesh_a, mesh_b, per_triangle, seed):
    """Hausdorff and RMS from Open3D alone: vertices plus uniform area samples, both ways."""
    o3d.utility.random.seed(seed)
    distances = []
    for source, target in ((mesh_a, mesh_b), (mesh_b, mesh_a)):
        n = per_triangle * len(mesh_a.triangles)
        cloud = source.sample_points_uniformly(number_of_points=n)
        points = np.vstack([np.asarray(source.vertices), np.asarray(cloud.points)])
        distances.append(exact_distances(scene_of(target), points))
    both = np.concatenate(distances)
    return max(d.max() for d in distances), float(np.sqrt(np.mean(both**2)))


@pytest.mark.parametrize("a,b", PAIRS)
def test_hausdorff_and_rms_agree_with_a_metro_style_sampler(a, b, tmp_path):
    b = materialize(a, b, tmp_path)
    report = meshcodec.distance(meshcodec.load(MESHES / a, drop_attributes=True),
                                meshcodec.load(b, drop_attributes=True), samples=10)
    ours_hausdorff, ours_rms = report["hausdorff_absolute"], report["rms_absolute"]
    hausdorff, rms = metro_style(load(MESHES / a), load(b), per_triangle=10, seed=11)
    assert abs(ours_hausdorff - hausdorff) <= 0.05 * hausdorff, (ours_hausdorff, hausdorff)
    assert abs(ours_rms - rms) <= 0.01 * rms, (ours_rms, rms)
