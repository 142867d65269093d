"""How good could an octree prefix be? A feasibility estimate for `emc`'s intermediate levels.

Each level of `emc` at 12 bits is the vertex clustering of the mesh by its cells at one octree
depth, every cluster shown inside its cell. This probe keeps those cuts (no new order of splits)
and asks what moving bits the octree codes anyway would buy: each cluster shown at the centre
of the sub-cell, k more bits an axis, of one of its own vertices (the one nearest the cluster's
quadric-error optimum). Those are the bits that vertex's path costs when its cell splits later,
so a stream that sends them earlier need not grow at the end; here they are charged in full,
raw: 3k bits a cluster on top of the level's own bits.

What sending them early would add to the lossless stream: moved earlier along the
representative's path, the octree's own bits for that path (split or not; which half when not)
are only moved, but where the path's cell splits the decoder must also learn which child holds
the representative, a bit the octree never codes. The probe counts those steps ("rep bits at
splits") for every depth and k: an upper bound of the growth at one bit each, before any
prediction of the child; how often the representative lies in the half holding more of the
cell's vertices, and in the half holding its neighbouring clusters' mean (predictors of that
bit); and the RMS when the sub-cell is found by that rule
alone, which a decoder could follow without being told ("majority path").

For every depth l and k it prints the bits a vertex and the RMS error (both ways, relative to the
bounding box's diagonal, `meshcodec distance`) of that mesh; then, at each `emc` level's bits, the
lowest RMS among the probe's meshes that cost no more, beside `emc`'s own level, `pm`'s and (on
bunny) the valence coder's at the same bits (interpolated on log-log axes, as
paper-tables/emc-vs-anchors.md). The meshes are clusterings with the full mesh's faces mapped to
clusters: an estimate of what a coder could show, not a coder.

Needs: the release binaries (`cargo build --release --bins`), numpy, and results/emc/ and
results/pm/ at 12 bits for the mesh (`bash experiments/anchors.sh` makes them for bunny and
armadillo-43k). Writes results/emc/prefix-probe-MESH.json.
Run: .venv/bin/python experiments/emc_prefix_probe.py bunny armadillo-43k
"""
import csv
import json
import math
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
MESHCODEC = ROOT / "target/release/meshcodec"
LEVELS = range(4, 9)
EXTRA_BITS = [0, 1, 2, 3, 4, 6]


def run(*args):
    out = subprocess.run([str(MESHCODEC), *map(str, args)], capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(f"meshcodec {' '.join(map(str, args))}: {out.stderr.strip()}")
    return out.stdout


def read_obj(path):
    vertices, faces = [], []
    for line in open(path):
        if line.startswith("v "):
            vertices.append([float(x) for x in line.split()[1:4]])
        elif line.startswith("f "):
            faces.append([int(x.split("/")[0]) - 1 for x in line.split()[1:4]])
    return np.array(vertices), np.array(faces)


def write_obj(path, positions, faces):
    with open(path, "w") as f:
        for p in positions:
            f.write("v %.9g %.9g %.9g\n" % tuple(p))
        for t in faces:
            f.write("f %d %d %d\n" % tuple(t + 1))


def rms_relative(full, other):
    return json.loads(run("distance", "--json", full, other))["rms_relative"]


def loglog(points, bits):
    """RMS at `bits` on a curve of (bits, rms) points, interpolated on log-log axes."""
    points = sorted(points)
    for (b0, r0), (b1, r1) in zip(points, points[1:]):
        if b0 <= bits <= b1:
            t = (math.log(bits) - math.log(b0)) / (math.log(b1) - math.log(b0))
            return math.exp(math.log(r0) + t * (math.log(r1) - math.log(r0)))
    return None


def curve(codec, mesh):
    for stem in (f"{mesh}-q12", mesh):
        path = ROOT / "results" / codec / f"{stem}.csv"
        if path.is_file():
            rows = list(csv.DictReader(open(path)))
            return [(float(r["bits"]), float(r["rms"])) for r in rows]
    sys.exit(f"no 12-bit {codec} result for {mesh} in results/{codec}/ (bash experiments/anchors.sh)")


def valence_curve():
    path = ROOT.parent / "shared/anchors/valence-rd-bunny.json"
    if not path.is_file():
        return None
    return [(lv["bits"], lv["rms_relative"]) for lv in json.load(open(path))["levels"]]


def neighbour_means(cells, cluster, mapped, depth, q):
    """Per cluster, the mean of its neighbouring clusters' cell centres (grid units): what a
    decoder knows of where the surface runs past a cell before its vertices are placed."""
    clusters = cluster.max() + 1
    centre = np.zeros((clusters, 3))
    centre[cluster] = ((cells >> (q - depth)) + 0.5) * (1 << (q - depth))
    edges = np.concatenate([mapped[:, [0, 1]], mapped[:, [1, 2]], mapped[:, [2, 0]]])
    edges = np.unique(np.sort(edges, axis=1), axis=0)
    sums = np.zeros((clusters, 3))
    counts = np.zeros(clusters)
    for a, b in ((0, 1), (1, 0)):
        np.add.at(sums, edges[:, a], centre[edges[:, b]])
        np.add.at(counts, edges[:, a], 1)
    return np.where(counts[:, None] > 0, sums / np.maximum(counts, 1)[:, None], centre)


def rep_path_splits(cells, representative, depth, extra, q, axes, means=None):
    """Per step after `depth` (three a level, along `axes`): how many representatives' cells
    split there (hold vertices on both sides of the step's plane), at how many of those the
    representative lies in the half holding more of the cell's vertices, and at how many in the
    half its cluster's neighbours' mean lies in (`means`, per cluster in order)."""
    taken = [depth] * 3
    counts, agreeing, by_neighbours = [], [], []
    for _ in range(min(extra, q - depth)):
        for axis in axes:
            keys = np.stack([cells[:, a] >> (q - taken[a]) for a in range(3)], 1)
            _, cell_of = np.unique(keys, axis=0, return_inverse=True)
            cell_of = cell_of.ravel()
            side = (cells[:, axis] >> (q - taken[axis] - 1)) & 1
            lower = np.bincount(cell_of, weights=side == 0)
            upper = np.bincount(cell_of, weights=side == 1)
            split = (lower > 0) & (upper > 0)
            at = cell_of[representative]
            majority = (upper[at] > lower[at]).astype(np.int64)
            counts.append(int(split[at].sum()))
            agreeing.append(int((split[at] & (side[representative] == majority)).sum()))
            if means is not None:
                shift = q - taken[axis] - 1
                plane = ((cells[representative, axis] >> (shift + 1)) * 2 + 1) << shift
                predicted = (means[:, axis] >= plane).astype(np.int64)
                by_neighbours.append(
                    int((split[at] & (side[representative] == predicted)).sum()))
            taken[axis] += 1
    return np.array(counts), np.array(agreeing), np.array(by_neighbours)


def majority_cells(cells, cluster, depth, extra, q, axes):
    """Each cluster's sub-cell `extra` bits an axis below `depth` found without a
    representative: at every step, the half holding more of the cluster's vertices still on the
    path (ties: the lower). A stand-in for a rule a decoder could follow untold (it sees the
    halves' edges when a cell splits, not their vertices). Returns the sub-cells' coordinates
    at depth + extra."""
    alive = np.ones(len(cells), dtype=bool)
    clusters = cluster.max() + 1
    for level in range(extra):
        for axis in axes:
            side = (cells[:, axis] >> (q - depth - 1 - level)) & 1
            upper = np.bincount(cluster, weights=(alive & (side == 1)), minlength=clusters)
            lower = np.bincount(cluster, weights=(alive & (side == 0)), minlength=clusters)
            chosen = (upper > lower).astype(np.int64)
            alive &= side == chosen[cluster]
    first = np.full(clusters, -1)
    order = np.nonzero(alive)[0]
    first[cluster[order[::-1]]] = order[::-1]
    return cells[first] >> (q - depth - extra)


def probe(mesh, work):
    stream, full = work / "stream.mc", work / "full.obj"
    run("encode", "--codec", "emc", "--quant", 12, mesh, stream)
    run("decode", stream, full)
    info = json.loads(run("info", "--json", stream))
    origin, cell, q = np.array(info["origin"]), np.array(info["cell"]), info["quant_bits"]
    level_bits = [0.0] + [8.0 * end for end in info["level_ends"]]
    raw = open(stream, "rb").read()
    # The header's first parameter bytes: the axes of a level's three steps (docs/FORMAT.md §7).
    axes = list(raw[8:11])
    positions, faces = read_obj(full)
    cells = np.floor((positions - origin) / cell).astype(np.int64)
    n = len(positions)
    # Each vertex's plane quadric (area-weighted): the cluster's error at a point.
    a, b, c = (positions[faces[:, i]] for i in range(3))
    normal = np.cross(b - a, c - a)
    area = np.linalg.norm(normal, axis=1)
    unit = normal / np.maximum(area, 1e-300)[:, None]
    planes = np.concatenate([unit, -(unit * a).sum(1)[:, None]], 1)
    per_face = np.einsum("fi,fj->fij", planes, planes) * (area / 2)[:, None, None]
    quadrics = np.zeros((n, 4, 4))
    for k in range(3):
        np.add.at(quadrics, faces[:, k], per_face)
    homogeneous = np.concatenate([positions, np.ones((n, 1))], 1)
    points = []
    for depth in LEVELS:
        keys = cells >> (q - depth)
        _, cluster = np.unique(keys, axis=0, return_inverse=True)
        cluster = cluster.ravel()
        clusters = cluster.max() + 1
        # The representative: the vertex of each cluster nearest its quadric optimum, i.e. the
        # one of least error under the cluster's summed quadric.
        summed = np.zeros((clusters, 4, 4))
        np.add.at(summed, cluster, quadrics)
        error = np.einsum("vi,vij,vj->v", homogeneous, summed[cluster], homogeneous)
        order = np.lexsort((error, cluster))
        first = np.ones(n, dtype=bool)
        first[1:] = cluster[order][1:] != cluster[order][:-1]
        representative = np.empty(clusters, dtype=np.int64)
        representative[cluster[order][first]] = order[first]
        mapped = cluster[faces]
        keep = (mapped[:, 0] != mapped[:, 1]) & (mapped[:, 1] != mapped[:, 2]) & (mapped[:, 0] != mapped[:, 2])
        mapped = mapped[keep]
        _, unique_rows = np.unique(np.sort(mapped, axis=1), axis=0, return_index=True)
        mapped = mapped[np.sort(unique_rows)]
        means = neighbour_means(cells, cluster, mapped, depth, q)
        splits_on_paths, agreeing, by_neighbours = rep_path_splits(
            cells, representative, depth, max(EXTRA_BITS), q, axes, means)
        for extra in EXTRA_BITS:
            finer = min(depth + extra, q)
            sub = cells[representative] >> (q - finer)
            shown = origin + (sub + 0.5) * cell * (1 << (q - finer))
            write_obj(work / "probe.obj", shown, mapped)
            bits = level_bits[depth] + 3 * extra * clusters
            rms = rms_relative(full, work / "probe.obj")
            majority = majority_cells(cells, cluster, depth, finer - depth, q, axes)
            write_obj(work / "majority.obj",
                      origin + (majority + 0.5) * cell * (1 << (q - finer)), mapped)
            rms_majority = rms_relative(full, work / "majority.obj")
            at_splits = int(splits_on_paths[: 3 * (finer - depth)].sum())
            agree = int(agreeing[: 3 * (finer - depth)].sum())
            agree_neighbours = int(by_neighbours[: 3 * (finer - depth)].sum())
            points.append({"depth": depth, "extra_bits": extra, "clusters": int(clusters),
                           "bits": bits, "bits_per_vertex": bits / n, "rms": rms,
                           "rep_bits": 3 * (finer - depth) * int(clusters),
                           "rep_bits_at_splits": at_splits,
                           "rep_in_larger_half_at_splits": agree,
                           "rep_on_neighbours_side_at_splits": agree_neighbours,
                           "rms_majority": rms_majority})
            print(f"  depth {depth}, {extra} more bits an axis: {clusters} clusters, "
                  f"{bits / n:.3f} bits a vertex, RMS {rms:.3e}, "
                  f"{at_splits} of {3 * (finer - depth) * clusters} rep bits at splits "
                  f"({agree} in the larger half, {agree_neighbours} on the neighbours' side); "
                  f"majority path RMS {rms_majority:.3e}", flush=True)
    return n, points


def main():
    meshes = sys.argv[1:] or ["bunny"]
    for mesh in meshes:
        with tempfile.TemporaryDirectory() as tmp:
            print(f"{mesh}:", flush=True)
            n, points = probe(mesh, Path(tmp))
        emc, pm = curve("emc", mesh), curve("pm", mesh)
        valence = valence_curve() if mesh == "bunny" else None
        rows = []
        print(f"\n| level | bits/vertex | `emc` RMS | probe's best within the bits | pm | valence coder | probe / pm |")
        print("|---:|---:|---:|---:|---:|---:|---:|")
        for level, (bits, rms) in enumerate(emc, start=1):
            if level < 4 or level > 9:
                continue
            within = [p for p in points if p["bits"] <= bits]
            best = min(within, key=lambda p: p["rms"]) if within else None
            at_pm = loglog(pm, bits)
            at_valence = loglog(valence, bits) if valence else None
            rows.append({"level": level, "bits": bits, "emc_rms": rms, "probe": best,
                         "pm_rms": at_pm, "valence_rms": at_valence})
            cell = lambda x: f"{x:.3e}" if x else ""
            ratio = f"{best['rms'] / at_pm:.2f}" if best and at_pm else ""
            shown = f"{best['rms']:.3e} (depth {best['depth']}, +{best['extra_bits']})" if best else ""
            print(f"| {level} | {bits / n:.3f} | {rms:.3e} | {shown} | {cell(at_pm)} | {cell(at_valence)} | {ratio} |")
        out = ROOT / "results" / "emc" / f"prefix-probe-{mesh}.json"
        json.dump({"mesh": mesh, "vertices": n, "points": points, "at_emc_levels": rows,
                   "command": "python experiments/emc_prefix_probe.py " + " ".join(meshes)},
                  open(out, "w"), indent=1)
        print(f"wrote {out.relative_to(ROOT)}\n", flush=True)


if __name__ == "__main__":
    main()
