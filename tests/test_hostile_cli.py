"""Hostile input through the command line, as a server decoding streams from a network would meet it.

1. 1,000 random mutations each of valid `emc`, `emc-paper` and `pm` streams, and 1,000 random byte
   strings: `meshcodec decode` must exit 0 with a valid mesh, or 1 with one line on stderr.
2. 200 mutations each of a shared mesh in every format the readers take (1,000 in all), read by
   `meshcodec encode --codec raw`: the same two outcomes.

Every run must end within 2 s and 1 GiB (peak resident memory of the process, from wait4), never
with a panic (exit 101), an abort or a signal. The mutations are seeded: a failure names the seed
and case, and writes the input to tests/hostile-failures/ to be replayed.

Run by tests/run.sh; needs the release binary (MESHCODEC_BIN to use another).
"""

import math
import os
import random
import subprocess
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
MESHES = Path(os.environ.get("MESHCODEC_DATA", ROOT.parent / "shared" / "meshes"))
BIN = Path(os.environ.get("MESHCODEC_BIN", ROOT / "target" / "release" / "meshcodec"))
FAILURES = ROOT / "tests" / "hostile-failures"

SECONDS = 2.0
MEMORY_BYTES = 1 << 30
CASES = 1000
# One shared mesh per reader: (file, cases).
READER_MESHES = [
    ("bunny-3k-closed.obj", 200),
    ("bunny-res4.ply", 100),
    ("beethoven.ply", 100),
    ("eight.off", 200),
    ("cad-featuretype.stl", 200),
    ("fandisk.m", 200),
]


def run(args, workdir):
    """Runs meshcodec; returns (exit code or -signal, stderr text, seconds, peak RSS bytes)."""
    err_path = workdir / "stderr"
    with open(err_path, "wb") as err:
        start = time.monotonic()
        proc = subprocess.Popen([str(BIN), *map(str, args)], stdout=subprocess.DEVNULL, stderr=err)
        _, status, usage = os.wait4(proc.pid, 0)
        seconds = time.monotonic() - start
    proc.returncode = 0  # reaped by wait4 above
    code = os.waitstatus_to_exitcode(status)
    return code, err_path.read_text(errors="replace"), seconds, usage.ru_maxrss * 1024


def check_outcome(what, args, data, suffix, workdir):
    """Runs one case and asserts the promise; keeps the input when it is broken."""
    code, stderr, seconds, peak = run(args, workdir)
    problems = []
    if code not in (0, 1):
        problems.append(f"exit {code}")
    if code == 1 and (stderr.count("\n") != 1 or not stderr.strip()):
        problems.append(f"stderr is not one line: {stderr[:300]!r}")
    if seconds > SECONDS:
        problems.append(f"{seconds:.2f} s")
    if peak > MEMORY_BYTES:
        problems.append(f"{peak >> 20} MiB")
    if problems:
        FAILURES.mkdir(exist_ok=True)
        kept = FAILURES / f"{what}{suffix}"
        kept.write_bytes(data)
        pytest.fail(f"{what}: {', '.join(problems)} (input kept in {kept})")
    return code, seconds, peak


def check_obj(path):
    """A decoded OBJ: finite positions, faces indexing them, at least one face."""
    vertices, faces = 0, 0
    for line in path.read_text().splitlines():
        words = line.split()
        if not words:
            continue
        if words[0] == "v":
            assert all(math.isfinite(float(x)) for x in words[1:4]), line
            vertices += 1
        elif words[0] == "f":
            indices = [int(w.split("/")[0]) for w in words[1:]]
            assert len(indices) == 3 and all(1 <= i <= vertices for i in indices), line
            faces += 1
    assert vertices > 0 and faces > 0


def mutate(data, rng):
    """One random edit of a byte string: flips, sets, a cut, an insertion, a deletion or a
    splice of the stream into itself."""
    b = bytearray(data)
    kind = rng.randrange(6)
    if kind == 0:
        for _ in range(rng.randint(1, 8)):
            b[rng.randrange(len(b))] ^= 1 << rng.randrange(8)
    elif kind == 1:
        for _ in range(rng.randint(1, 4)):
            b[rng.randrange(len(b))] = rng.randrange(256)
    elif kind == 2:
        del b[rng.randrange(len(b)) :]
    elif kind == 3:
        at = rng.randrange(len(b) + 1)
        b[at:at] = rng.randbytes(rng.randint(1, 64))
    elif kind == 4:
        at = rng.randrange(len(b))
        del b[at : at + rng.randint(1, 256)]
    else:
        at, src = rng.randrange(len(b)), rng.randrange(len(b))
        b[at:at] = b[src : src + rng.randint(1, 512)]
    return bytes(b)


def mutate_text(data, rng):
    """A token-level edit of a text mesh file: a number made huge, negative, zero, fractional
    or not a number; a line deleted or repeated; or a byte-level edit."""
    lines = data.split(b"\n")
    kind = rng.randrange(4)
    i = rng.randrange(len(lines))
    if kind == 0:
        words = lines[i].split(b" ")
        j = rng.randrange(len(words))
        words[j] = rng.choice(
            [b"4294967296", b"-1", b"0", b"-999999", b"1e308", b"nan", b"inf", b"2.5", b"", b"99999999999999999999"]
        )
        lines[i] = b" ".join(words)
    elif kind == 1:
        del lines[i]
    elif kind == 2:
        lines.insert(i, lines[rng.randrange(len(lines))])
    else:
        return mutate(data, rng)
    return b"\n".join(lines)


@pytest.fixture(scope="module")
def streams(tmp_path_factory):
    """Valid streams of the bunny (3,301 vertices) from the three progressive codecs."""
    out = {}
    workdir = tmp_path_factory.mktemp("streams")
    for codec in ["emc", "emc-paper", "pm"]:
        path = workdir / f"{codec}.mc"
        subprocess.run(
            # Its geometry (the file also holds normals).
            [BIN, "encode", "--codec", codec, "--drop-attributes", MESHES / "bunny-3k-closed.obj", path],
            check=True,
            stdout=subprocess.DEVNULL,
        )
        out[codec] = path.read_bytes()
    return out


@pytest.mark.parametrize("codec", ["emc", "emc-paper", "pm"])
def test_mutated_streams_decode_or_fail_in_one_line(codec, streams, tmp_path):
    rng = random.Random(f"stream-{codec}")
    valid = streams[codec]
    stream, mesh = tmp_path / "in.mc", tmp_path / "out.obj"
    decoded, slowest, largest = 0, 0.0, 0
    for case in range(CASES):
        data = mutate(valid, rng)
        stream.write_bytes(data)
        mesh.unlink(missing_ok=True)
        code, seconds, peak = check_outcome(
            f"{codec}-case{case}", ["decode", stream, mesh], data, ".mc", tmp_path
        )
        if code == 0:
            check_obj(mesh)
            decoded += 1
        slowest, largest = max(slowest, seconds), max(largest, peak)
    print(f"{codec}: {decoded}/{CASES} decoded, slowest {slowest:.3f} s, peak {largest >> 20} MiB")
    # Cuts and late flips leave decodable prefixes: both outcomes must have been exercised.
    assert 0 < decoded < CASES


def test_random_bytes_fail_in_one_line(tmp_path):
    rng = random.Random("random-bytes")
    stream, mesh = tmp_path / "in.mc", tmp_path / "out.obj"
    decoded, slowest, largest = 0, 0.0, 0
    for case in range(CASES):
        # Half of them start like a stream of this format version, a codec and its syntax
        # (docs/FORMAT.md §1), so that they reach the header's fields, the index and the levels.
        data = rng.randbytes(rng.randint(0, 4096))
        if case % 2:
            data = b"MshC\x06" + bytes([case % 7, 1]) + data
        stream.write_bytes(data)
        code, seconds, peak = check_outcome(
            f"random-case{case}", ["decode", stream, mesh], data, ".mc", tmp_path
        )
        if code == 0:
            check_obj(mesh)
            decoded += 1
        slowest, largest = max(slowest, seconds), max(largest, peak)
    print(f"random bytes: {decoded}/{CASES} decoded, slowest {slowest:.3f} s, peak {largest >> 20} MiB")


@pytest.mark.parametrize("name,cases", READER_MESHES)
def test_mutated_mesh_files_read_or_fail_in_one_line(name, cases, tmp_path):
    rng = random.Random(f"mesh-{name}")
    original = (MESHES / name).read_bytes()
    suffix = Path(name).suffix
    textual = suffix in (".obj", ".off", ".m") or original.startswith(b"ply\nformat ascii")
    path, out = tmp_path / f"in{suffix}", tmp_path / "out.mc"
    read, slowest, largest = 0, 0.0, 0
    for case in range(cases):
        data = mutate_text(original, rng) if textual and case % 2 else mutate(original, rng)
        path.write_bytes(data)
        code, seconds, peak = check_outcome(
            f"{Path(name).stem}-case{case}", ["encode", "--codec", "raw", "--drop-attributes", path, out], data, suffix, tmp_path
        )
        read += code == 0
        slowest, largest = max(slowest, seconds), max(largest, peak)
    print(f"{name}: {read}/{cases} read, slowest {slowest:.3f} s, peak {largest >> 20} MiB")
