"""meshoptimizer's simplifier beside CAME's view-dependent fronts (paper-tables/came-vd.md).

For every mesh of results/came/vd.json (and the fly-through's, results/came/flythrough.json),
a ladder of meshoptimizer simplifications of the mesh's full decode, the target error lowered
a quarter octave at a time, each measured by `meshcodec distance` (Hausdorff, both ways). A view
whose tolerance is t (a pixel's size at the nearest point in view) gets the fewest triangles of
a rung whose measured Hausdorff distance is within t: the count a mesh that knows nothing of
the view needs to show within one pixel everywhere in it.

Each view's chosen mesh, and each fly-through frame's, is also measured on the screen as the
view's front is (`meshcodec screen-distance`: the same camera, both ways, in pixels).

Writes results/came/vd-meshoptimizer.json, and renders of the meshes chosen for the far and
near views under results/came/vd/ (the project's rasterizer, `meshcodec render`).

Run by experiments/came-vd.sh, after `experiment came-vd` and `experiment came-fly`.
"""

import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import meshoptimizer
import numpy as np

from anchor_common import BIN, ROOT, meshcodec

RESULTS = ROOT / "results" / "came"
# A quarter octave between rungs.
STEP = 2.0 ** -0.25
# Samples per triangle for the Hausdorff distance (at most a million each way).
SAMPLES = 10
FACE = np.dtype([("n", "u1"), ("i", "<i4", (3,))])


def read_ply(path):
    """Positions (float64) and triangles of a binary PLY as `meshcodec` writes it."""
    with open(path, "rb") as f:
        header = []
        while True:
            line = f.readline().decode().strip()
            header.append(line)
            if line == "end_header":
                break
        counts = {l.split()[1]: int(l.split()[2]) for l in header if l.startswith("element")}
        properties = [l for l in header if l.startswith("property")]
        if properties[:3] != ["property double x", "property double y", "property double z"] or len(
            properties
        ) != 4:
            raise SystemExit(f"{path}: not a binary PLY of double positions and triangles")
        vertices = np.frombuffer(f.read(counts["vertex"] * 24), dtype="<f8").reshape(-1, 3)
        faces = np.frombuffer(f.read(counts["face"] * FACE.itemsize), dtype=FACE)
    if np.any(faces["n"] != 3):
        raise SystemExit(f"{path}: a face is not a triangle")
    return vertices, faces["i"].astype(np.uint32)


def write_ply(path, vertices, triangles):
    """The used vertices and `triangles` as a binary PLY."""
    used, remapped = np.unique(triangles.reshape(-1), return_inverse=True)
    tri = remapped.reshape(-1, 3)
    with open(path, "wb") as f:
        f.write(
            (
                "ply\nformat binary_little_endian 1.0\n"
                f"element vertex {len(used)}\nproperty double x\nproperty double y\nproperty double z\n"
                f"element face {len(tri)}\nproperty list uchar int vertex_indices\nend_header\n"
            ).encode()
        )
        f.write(np.ascontiguousarray(vertices[used], dtype="<f8").tobytes())
        records = np.zeros(len(tri), dtype=FACE)
        records["n"] = 3
        records["i"] = tri
        f.write(records.tobytes())


def simplify(vertices, triangles, target_error):
    """meshoptimizer's simplification as far as `target_error` (absolute) allows."""
    indices = triangles.reshape(-1)
    out = np.zeros_like(indices)
    error = np.zeros(1, dtype=np.float32)
    count = meshoptimizer.simplify(
        out,
        indices,
        np.ascontiguousarray(vertices, dtype=np.float32),
        target_index_count=0,
        target_error=float(target_error),
        options=meshoptimizer.SIMPLIFY_ERROR_ABSOLUTE,
        result_error=error,
    )
    return out[:count].reshape(-1, 3)


def ladder(full_path, tolerances, tmp, log):
    """Rungs from the largest tolerance down until one is within the smallest, or the count
    stops growing, then the full mesh: target error, triangles, measured Hausdorff distance,
    seconds."""
    vertices, triangles = read_ply(full_path)
    rungs = []
    target = max(tolerances)
    smallest = min(tolerances)
    while True:
        started = time.perf_counter()
        simplified = simplify(vertices, triangles, target)
        seconds = time.perf_counter() - started
        if len(simplified) == 0:
            hausdorff = float("inf")
        else:
            path = Path(tmp) / "simplified.ply"
            write_ply(path, vertices, simplified)
            report = json.loads(
                meshcodec("distance", full_path, path, "--samples", SAMPLES, "--json")
            )
            hausdorff = report["hausdorff"]
        rungs.append(
            {
                "target_error": target,
                "triangles": int(len(simplified)),
                "hausdorff": hausdorff,
                "simplify_seconds": seconds,
            }
        )
        log(f"  target {target:.3e}: {len(simplified)} triangles, Hausdorff {hausdorff:.3e}")
        # meshoptimizer keeps a few collapses at any error (the bunny: 66,057 of 69,451
        # triangles, 8e-5 away, down to a target of 1e-10): when the count has stopped growing,
        # or the target is far below every tolerance, the full mesh is the only mesh left
        # within less.
        stalled = len(rungs) > 4 and len({r["triangles"] for r in rungs[-5:]}) == 1
        far_below = target < smallest / 16
        if hausdorff <= smallest or len(simplified) == len(triangles) or stalled or far_below:
            rungs.append(
                {"target_error": 0.0, "triangles": int(len(triangles)), "hausdorff": 0.0,
                 "simplify_seconds": 0.0, "full_mesh": True}
            )
            return rungs, vertices, triangles
        target *= STEP


def within(rungs, tolerance):
    """The rung with the fewest triangles whose measured Hausdorff distance is within
    `tolerance`."""
    fits = [r for r in rungs if r["hausdorff"] <= tolerance]
    return min(fits, key=lambda r: r["triangles"]) if fits else None


def render(mesh_path, out, eye, target, size, fov):
    meshcodec(
        "render", mesh_path, out,
        "--eye", ",".join(map(repr, eye)), "--target", ",".join(map(repr, target)),
        "--size", size, "--fov", fov,
    )


def fly_frames(fly, rungs, vertices, triangles, mesh, tmp, log):
    """For each fly-through frame, the rung within its tolerance and that mesh's error on the
    frame's screen, measured as the frame's two-sided front is (none where no rung fits; 0 where
    only the full mesh does)."""
    size = f"{fly['width']}x{fly['height']}"
    written = {}
    out = []
    for frame in fly["frames"]:
        rung = within(rungs, frame["pixel_at_nearest"])
        entry = {"frame": frame["frame"], "tolerance": frame["pixel_at_nearest"],
                 "triangles": (rung or {}).get("triangles")}
        if rung and rung.get("full_mesh"):
            entry.update(full_mesh=True, screen_max_px=0.0, screen_mean_px=0.0)
        elif rung:
            target = rung["target_error"]
            if target not in written:
                written[target] = Path(tmp) / f"frame-rung-{len(written)}.ply"
                write_ply(written[target], vertices, simplify(vertices, triangles, target))
            error = json.loads(meshcodec(
                "screen-distance", ROOT / mesh["full_mesh"], written[target], "--json",
                "--eye", ",".join(map(repr, frame["eye"])),
                "--target", ",".join(map(repr, frame["target"])),
                "--size", size, "--fov", fly["fov_degrees"],
            ))
            entry.update(screen_max_px=error["max_px"], screen_mean_px=error["mean_px"])
        out.append(entry)
    measured = [f["screen_mean_px"] for f in out if "screen_mean_px" in f and not f.get("full_mesh")]
    if measured:
        log(f"  fly-through: meshoptimizer's mean on the screen {min(measured):.4f}-{max(measured):.4f} px "
            f"in the {len(measured)} frames where it simplifies")
    return out


def main():
    log = lambda line: print(line, flush=True)
    if not BIN.is_file():
        raise SystemExit(f"{BIN} is missing: cargo build --release --bins")
    vd = json.loads((RESULTS / "vd.json").read_text())
    fly = json.loads((RESULTS / "flythrough.json").read_text())
    out = {
        "command": "bash experiments/came-vd.sh",
        "meshoptimizer": "PyPI meshoptimizer " + meshoptimizer.__dict__.get("__version__", "0.2.30a0"),
        "simplify": "meshopt_simplify(target_index_count=0, target_error, SIMPLIFY_ERROR_ABSOLUTE) on the full decode",
        "distance": f"meshcodec distance --samples {SAMPLES} (Hausdorff, both ways)",
        "step": STEP,
        "meshes": [],
    }
    with tempfile.TemporaryDirectory() as tmp:
        for mesh in vd["meshes"]:
            name = mesh["mesh"] if mesh["subdivisions"] == 0 else f"{mesh['mesh']}-x{4 ** mesh['subdivisions']}"
            tolerances = [v["pixel_at_nearest"] for v in mesh["views"]]
            frames = []
            if fly["mesh"] == mesh["mesh"] and fly["subdivisions"] == mesh["subdivisions"]:
                frames = [f["pixel_at_nearest"] for f in fly["frames"]]
                if not all(t > 0 for t in frames):
                    raise SystemExit("flythrough.json has no pixel_at_nearest: run experiment came-fly")
                tolerances += frames
            log(f"{name}: {mesh['triangles']} triangles, tolerances {min(tolerances):.3e} to {max(tolerances):.3e}")
            rungs, vertices, triangles = ladder(ROOT / mesh["full_mesh"], tolerances, tmp, log)
            views = []
            size = f"{vd['width']}x{vd['height']}"
            for view in mesh["views"]:
                rung = within(rungs, view["pixel_at_nearest"])
                entry = {"view": view["view"], "tolerance": view["pixel_at_nearest"], **(rung or {})}
                if rung:
                    path = Path(tmp) / "chosen.ply"
                    chosen = triangles if rung.get("full_mesh") else simplify(vertices, triangles, rung["target_error"])
                    write_ply(path, vertices, chosen)
                    if rung.get("full_mesh"):
                        entry.update(screen_max_px=0.0, screen_mean_px=0.0)
                    else:
                        # Measured as the view's front is: the same camera, both ways, in pixels.
                        error = json.loads(meshcodec(
                            "screen-distance", ROOT / mesh["full_mesh"], path, "--json",
                            "--eye", ",".join(map(repr, view["eye"])),
                            "--target", ",".join(map(repr, view["target"])),
                            "--size", size, "--fov", vd["fov_degrees"],
                        ))
                        entry.update(screen_max_px=error["max_px"], screen_mean_px=error["mean_px"])
                        log(f"  {view['view']}: {entry['triangles']} triangles, "
                            f"{error['max_px']:.3f} px max, {error['mean_px']:.4f} px mean on the screen")
                    if view["view"] in ("far", "near"):
                        picture = RESULTS / "vd" / f"{name}-{view['view']}-meshoptimizer.png"
                        render(path, picture, view["render_eye"], view["render_target"], size, vd["fov_degrees"])
                views.append(entry)
            entry = {"mesh": mesh["mesh"], "subdivisions": mesh["subdivisions"], "triangles": mesh["triangles"],
                     "rungs": rungs, "views": views}
            if frames:
                entry["flythrough_frames"] = fly_frames(fly, rungs, vertices, triangles, mesh, tmp, log)
            out["meshes"].append(entry)
    path = RESULTS / "vd-meshoptimizer.json"
    path.write_text(json.dumps(out, indent=2) + "\n")
    log(f"wrote {path}")


if __name__ == "__main__":
    sys.exit(main())
