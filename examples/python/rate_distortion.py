# %% [markdown]
# # Rate–distortion of meshcodec's codecs, from the Python package alone
#
# Every level of a stream is a point: the bytes it needs (`level_ends`) against its symmetric
# Hausdorff distance to the original (`distance`, over the bounding-box diagonal). Run it as a
# script, or cell by cell (`# %%`) in an editor that knows the format:
#
#     python examples/python/rate_distortion.py [MESH] [--codecs emc,pm,came] [--out rd.png]

# %%
import argparse
import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import meshcodec  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
MESHES = Path(os.environ.get("MESHCODEC_DATA", ROOT.parent / "shared" / "meshes"))

parser = argparse.ArgumentParser(description="rate-distortion curves of meshcodec's codecs")
parser.add_argument("mesh", nargs="?", default=str(MESHES / "bunny.ply"))
parser.add_argument("--codecs", default="emc,pm,came")
parser.add_argument("--quant", type=int, default=12)
parser.add_argument("--samples", type=int, default=3, help="samples per triangle")
parser.add_argument("--out", default="rate-distortion.png")
args = parser.parse_args()

# %% The mesh, and each codec's stream.
original = meshcodec.load(args.mesh, drop_attributes=True)
streams = {
    codec: meshcodec.encode(original.vertices, original.faces, codec=codec, quant_bits=args.quant)
    for codec in args.codecs.split(",")
}
vertices = meshcodec.canonical(original.vertices, original.faces, args.quant).vertex_count

# %% One point a level: bits per vertex of the full mesh, Hausdorff over the diagonal.
curves = {}
for codec, stream in streams.items():
    ends = meshcodec.level_ends(stream)
    points = []
    for level in meshcodec.levels(stream):
        error = meshcodec.distance(original, level, samples=args.samples)["hausdorff"]
        points.append((8 * ends[level.level - 1] / vertices, error))
    curves[codec] = points
    print(f"{codec}: {len(stream)} bytes, {8 * len(stream) / vertices:.2f} bits/vertex, "
          f"{len(points)} levels, last Hausdorff {points[-1][1]:.2e}")

# %% The chart.
fig, ax = plt.subplots(figsize=(7, 4.5), dpi=120)
for codec, points in curves.items():
    rate, error = zip(*[(r, max(e, 1e-7)) for r, e in points])
    ax.plot(rate, error, marker="o", markersize=3, label=codec)
ax.set_yscale("log")
ax.set_xlabel("bits per vertex (of the full mesh) received")
ax.set_ylabel("Hausdorff distance / bounding-box diagonal")
ax.set_title(f"{Path(args.mesh).name} at {args.quant} bits")
ax.grid(True, which="both", alpha=0.3)
ax.legend()
fig.tight_layout()
fig.savefig(args.out)
print(f"wrote {args.out}")
