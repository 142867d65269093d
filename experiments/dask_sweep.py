"""Runs an experiment set on a Dask distributed cluster: one task per shard
(`experiment run SET --shard I/N`), then `experiment merge` — the results folder is what a single
`experiment run SET` writes.

    python experiments/dask_sweep.py SET.toml --scheduler tcp://host:8786 [--shards N] [--out results]
    python experiments/dask_sweep.py SET.toml --local 2                    # a LocalCluster of 2 workers

The workers run the `experiment` binary (--experiment, default target/release/experiment) and
write into --work (default: OUT.shards); both must be on a filesystem every worker and this
driver see, as on a cluster with a shared home. Each shard's output is kept in
WORK/shard-I-of-N, with its log; a failed shard names itself and the merge is not attempted.
"""

import argparse
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def run_shard(experiment, set_file, index, count, out, env):
    """One shard on a worker; returns (index, exit code, log tail)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "log.txt", "w") as log:
        code = subprocess.call(
            [experiment, "run", set_file, "--shard", f"{index}/{count}", "--out", str(out)],
            stdout=log, stderr=subprocess.STDOUT, env={**os.environ, **env},
        )
    tail = (out / "log.txt").read_text(errors="replace").splitlines()[-3:]
    return index, code, "\n".join(tail)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("set", help="the experiment set (experiments/*.toml)")
    where = parser.add_mutually_exclusive_group(required=True)
    where.add_argument("--scheduler", help="address of a running Dask scheduler")
    where.add_argument("--local", type=int, metavar="WORKERS", help="start a LocalCluster of this many workers")
    parser.add_argument("--shards", type=int, help="shards (default: the cluster's workers)")
    parser.add_argument("--out", default="results", help="merged results folder")
    parser.add_argument("--work", help="shard folders (default: OUT.shards)")
    parser.add_argument("--experiment", default=str(ROOT / "target" / "release" / "experiment"))
    args = parser.parse_args(argv)

    from dask.distributed import Client, LocalCluster

    if args.local is not None:
        cluster = LocalCluster(n_workers=args.local, threads_per_worker=1, processes=True,
                               dashboard_address=None)
        client = Client(cluster)
    else:
        cluster, client = None, Client(args.scheduler)
    try:
        workers = len(client.scheduler_info()["workers"])
        count = args.shards or max(workers, 1)
        set_file = str(Path(args.set).resolve())
        work = Path(args.work or f"{args.out}.shards").resolve()
        # Where the meshes are, as this driver sees them (the workers' filesystem is shared).
        env = {k: v for k, v in os.environ.items() if k == "MESHCODEC_DATA"}
        folders = [work / f"shard-{i}-of-{count}" for i in range(1, count + 1)]
        print(f"{Path(set_file).name}: {count} shards on {workers} workers, into {work}")
        futures = [
            client.submit(run_shard, args.experiment, set_file, i, count, str(folder), env,
                          key=f"shard-{i}-of-{count}", pure=False)
            for i, folder in enumerate(folders, start=1)
        ]
        failed = []
        for index, code, tail in client.gather(futures):
            print(f"shard {index}/{count}: {'done' if code == 0 else f'exit {code}'}")
            if code != 0:
                failed.append(f"shard {index}/{count} (exit {code}): {tail}")
        if failed:
            print("\n".join(failed), file=sys.stderr)
            return 1
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    return subprocess.call([args.experiment, "merge", set_file, *map(str, folders), "--out", args.out])


if __name__ == "__main__":
    sys.exit(main())
