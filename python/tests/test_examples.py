"""The examples in examples/python run and do what they say (trimesh, Open3D, matplotlib)."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples" / "python"
MESHES = Path(os.environ.get("MESHCODEC_DATA", ROOT.parent / "shared" / "meshes"))


def run(script, *args):
    done = subprocess.run([sys.executable, str(EXAMPLES / script), *map(str, args)],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return done.stdout


def test_trimesh_levels(tmp_path):
    out = run("trimesh_levels.py", MESHES / "bunny-3k-closed.obj", "--out", tmp_path)
    assert "12 levels" in out
    assert (tmp_path / "finest.ply").stat().st_size > 0 and (tmp_path / "stream.mc").exists()


def test_open3d_levels(tmp_path):
    out = run("open3d_levels.py", MESHES / "bunny-3k-libigl.off", "--out", tmp_path)
    assert "first 100% of the stream" in out
    assert len(list(tmp_path.glob("received-*.ply"))) == 4


def test_rate_distortion_chart(tmp_path):
    chart = tmp_path / "rd.png"
    out = run("rate_distortion.py", MESHES / "bunny-3k-libigl.off", "--codecs", "emc,pm", "--out", chart)
    assert "emc:" in out and "pm:" in out
    assert chart.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
