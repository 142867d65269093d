"""Open3D's time for the workload of lab/benches/distance.rs: 1M samples against a 1M-triangle torus.

Run: .venv/bin/python lab/benches/open3d_distance.py   (after tests/run.sh made the venv)
"""

import time

import numpy as np
import open3d as o3d


def torus(major, minor, u, v):
    a = np.repeat(np.arange(u) / u * 2 * np.pi, v)
    b = np.tile(np.arange(v) / v * 2 * np.pi, u)
    r = major + minor * np.cos(b)
    points = np.stack([r * np.cos(a), r * np.sin(a), minor * np.sin(b)], axis=1)
    i, j = np.meshgrid(np.arange(u), np.arange(v), indexing="ij")
    i, j = i.ravel(), j.ravel()
    idx = lambda i, j: (i % u) * v + (j % v)
    a_, b_, c_, d_ = idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)
    faces = np.concatenate([np.stack([a_, b_, c_], 1), np.stack([a_, c_, d_], 1)])
    return o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(points), o3d.utility.Vector3iVector(faces))


surface = torus(1.0, 0.35, 1000, 500)
samples = np.asarray(torus(1.0, 0.36, 300, 120).sample_points_uniformly(1_000_000).points, dtype=np.float32)
start = time.perf_counter()
scene = o3d.t.geometry.RaycastingScene()
scene.add_triangles(o3d.t.geometry.TriangleMesh.from_legacy(surface))
query = o3d.core.Tensor(samples)
scene.compute_distance(query[:1000]).numpy()  # builds the BVH
built = time.perf_counter()
best = min(
    (lambda t0: (scene.compute_distance(query).numpy(), time.perf_counter() - t0)[1])(time.perf_counter())
    for _ in range(5)
)
print(f"Open3D {o3d.__version__}: {len(surface.triangles)} triangles, BVH build {built - start:.3f} s, "
      f"1M distance queries best of 5: {best:.3f} s")
