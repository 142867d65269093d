"""experiments/dask_sweep.py on a Dask LocalCluster of 2 workers writes what one
`experiment run` writes: every file byte for byte, the results' timings aside.

Run by tests/run.sh; needs the release binaries (MESHCODEC_EXPERIMENT to use another).
"""

import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
MESHES = Path(os.environ.get("MESHCODEC_DATA", ROOT.parent / "shared" / "meshes"))
EXPERIMENT = Path(os.environ.get("MESHCODEC_EXPERIMENT", ROOT / "target" / "release" / "experiment"))

SET = """description = "dask sweep test"
codecs = ["raw", "emc", "pm"]
meshes = ["bunny-res4", "bunny-3k-libigl"]
quant = [10, 12]
samples = 2
"""


def blank_timings(value):
    if isinstance(value, dict):
        return {k: None if k.endswith(("_seconds", "_per_second")) else blank_timings(v)
                for k, v in value.items()}
    if isinstance(value, list):
        return [blank_timings(v) for v in value]
    return value


def tree(root):
    files = {}
    for path in sorted(root.rglob("*")):
        if path.is_file():
            data = path.read_bytes()
            if path.suffix == ".json":
                data = json.dumps(blank_timings(json.loads(data)), sort_keys=True).encode()
            files[path.relative_to(root)] = data
    return files


def test_a_sweep_on_a_local_cluster_equals_one_run(tmp_path):
    set_file = tmp_path / "tiny.toml"
    set_file.write_text(SET)
    env = {**os.environ, "MESHCODEC_DATA": str(MESHES)}
    subprocess.run([str(EXPERIMENT), "run", str(set_file), "--out", str(tmp_path / "one")],
                   check=True, capture_output=True, env=env, cwd=tmp_path)
    done = subprocess.run(
        [sys.executable, str(ROOT / "experiments" / "dask_sweep.py"), str(set_file), "--local", "2",
         "--shards", "3", "--out", str(tmp_path / "merged"), "--experiment", str(EXPERIMENT)],
        capture_output=True, text=True, env=env, cwd=tmp_path, timeout=600,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "3 shards on 2 workers" in done.stdout, done.stdout
    one, merged = tree(tmp_path / "one"), tree(tmp_path / "merged")
    assert sorted(one) == sorted(merged)
    differing = [str(p) for p in one if one[p] != merged[p]]
    assert not differing, differing
    assert (tmp_path / "merged.shards" / "shard-2-of-3" / "tiny.shard-2-of-3.json").exists()
