"""The README as a newcomer meets it: at most 300 lines, none over 400 characters, exactly two
set-up commands, and its quick starts run as written — the command line's (with the binaries
cargo built for the tests standing for its `cargo install` line) and Python's, in a scratch
folder. The Rust quick start is a doctest (src/lib.rs includes the README); the JavaScript one
runs in web/test/package.test.mjs against the package installed from its tarball."""

import contextlib
import io
import os
import re
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
README = (ROOT / "README.md").read_text()


def block(heading, language):
    """The first fenced block of `language` under the heading `heading`."""
    section = README.split(f"\n{heading}\n", 1)[1]
    section = re.split(r"\n#{1,3} ", section, maxsplit=1)[0]
    found = re.search(rf"```{language}\n(.*?)```", section, re.S)
    assert found, f"no {language} block under {heading}"
    return found.group(1)


def test_the_readme_is_short_and_has_two_set_up_commands():
    lines = README.split("\n")
    assert len(lines) <= 300, len(lines)
    longest = max(lines, key=len)
    assert len(longest) <= 400, longest
    commands = [line for line in block("## Set-up", "sh").split("\n") if line.strip()]
    assert len(commands) == 2, commands
    assert commands[0].startswith("cargo run --release --bin experiment -- emc bunny")
    assert commands[1].startswith("bash tests/run.sh")


@pytest.fixture(scope="module")
def scratch(tmp_path_factory):
    return tmp_path_factory.mktemp("readme")


def environment():
    env = dict(os.environ)
    env["PATH"] = f"{ROOT / 'target' / 'release'}{os.pathsep}{env['PATH']}"
    shared = ROOT.parent / "shared" / "meshes"
    if "MESHCODEC_DATA" not in env and shared.is_dir():
        # What cargo sets for what it runs (.cargo/config.toml); the scratch folder has no
        # ../shared beside it.
        env["MESHCODEC_DATA"] = str(shared)
    return env


def test_the_command_line_quick_start_runs_as_written(scratch):
    lines = [line for line in block("### Command line", "sh").split("\n") if line.strip()]
    assert lines[0].startswith("cargo install --locked --path lab")
    for line in lines[1:]:
        command = line.split("  #")[0].strip()
        done = subprocess.run(["bash", "-c", command], cwd=scratch, env=environment(), capture_output=True, text=True)
        assert done.returncode == 0, f"{command}: {done.stderr}"
        if command.startswith("meshcodec info bunny.mc"):
            assert "levels" in done.stdout
    for written in ["bunny.mc", "coarse.ply", "spot.glb", "spot-full.glb"]:
        assert (scratch / written).stat().st_size > 0, written


def test_the_python_quick_start_runs_as_written(scratch, monkeypatch):
    import meshcodec

    for key, value in environment().items():
        monkeypatch.setenv(key, value)
    monkeypatch.chdir(scratch)
    said = io.StringIO()
    with contextlib.redirect_stdout(said):
        exec(block("### Python", "python"), {})
    printed = said.getvalue().split("\n")[:-1]
    levels = meshcodec.info(meshcodec.encode(*_bunny(meshcodec), codec="emc", quant_bits=12))["levels"]
    assert len(printed) == levels
    assert printed[-1].split()[0] == str(levels)


def _bunny(meshcodec):
    mesh = meshcodec.load("bunny")
    return mesh.vertices, mesh.faces


DOCUMENTS = ["README.md", "BENCHMARKS.md", "FUZZING.md", "ARCHITECTURE.md", "web/README.md", "python/README.md"]


@pytest.mark.parametrize(
    "document", DOCUMENTS + [str(p.relative_to(ROOT)) for p in sorted((ROOT / "docs").rglob("*.md"))]
)
def test_every_relative_link_names_a_file_of_the_repository(document):
    text = (ROOT / document).read_text()
    broken = []
    for target in re.findall(r"\]\(([^)\s]+)\)", text):
        if re.match(r"[a-z]+:", target) or target.startswith("#"):
            continue
        path = (ROOT / document).parent / target.split("#")[0]
        if not path.exists():
            broken.append(target)
    assert broken == [], f"{document}: {broken}"
