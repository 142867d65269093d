"""The Python package over the Rust core: round trips, levels, prefixes, errors, threads.

Lossless is checked here independently of the library's own check: both the decoded mesh and
the package's canonical mesh are brought to cells (through the stream's grid) and compared in a
normal form — vertices sorted by cell, faces rotated to their smallest vertex and sorted.
"""

import io
import os
import random
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import meshcodec

ROOT = Path(__file__).resolve().parents[2]
MESHES = Path(os.environ.get("MESHCODEC_DATA", ROOT.parent / "shared" / "meshes"))
LOSSLESS = [c["name"] for c in meshcodec.codecs() if c["lossless"]]


def shared(name):
    return meshcodec.load(MESHES / name, drop_attributes=True)


def normal_form(mesh, grid):
    """Cells sorted, faces over the sorted order rotated to their smallest index, sorted."""
    origin, cell = np.array(grid["origin"]), np.array(grid["cell"])
    cells = np.floor((mesh.vertices - origin) / cell).astype(np.int64)
    order = np.lexsort(cells.T[::-1])
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    faces = rank[mesh.faces.astype(np.int64)]
    turns = np.argmin(faces, axis=1)
    rotated = np.stack([np.roll(f, -t) for f, t in zip(faces, turns)]) if len(faces) else faces
    return cells[order], rotated[np.lexsort(rotated.T[::-1])]


def assert_lossless(original, stream, quant_bits=12):
    grid = meshcodec.info(stream)
    decoded = meshcodec.decode(stream)
    expected = meshcodec.canonical(original.vertices, original.faces, quant_bits)
    ours, theirs = normal_form(decoded, grid), normal_form(expected, grid)
    assert decoded.vertex_count == expected.vertex_count
    assert decoded.face_count == expected.face_count
    assert np.array_equal(ours[0], theirs[0]), "decoded cells differ"
    assert np.array_equal(ours[1], theirs[1]), "decoded faces differ"


def test_every_codec_is_listed_with_its_defaults():
    names = {c["name"] for c in meshcodec.codecs()}
    assert {"raw", "emc", "emc-ahead", "emc-paper", "pm", "pm-reordered", "came", "came-paper"} <= names
    for c in meshcodec.codecs():
        assert c["quant_bits"] >= 1 and c["summary"]


@pytest.mark.parametrize("codec", LOSSLESS)
def test_round_trips_of_the_bunny_are_lossless(codec):
    bunny = shared("bunny.ply")
    stream = meshcodec.encode(bunny.vertices, bunny.faces, codec=codec)
    assert_lossless(bunny, stream)


@pytest.mark.parametrize("name", ["bunny-3k-libigl.off", "fandisk.m", "cad-featuretype.stl", "eight.off"])
@pytest.mark.parametrize("codec", ["emc", "came"])
def test_shared_meshes_round_trip_losslessly_at_12_and_16_bits(name, codec):
    mesh = shared(name)
    for bits in (12, 16):
        stream = meshcodec.encode(mesh.vertices, mesh.faces, codec=codec, quant_bits=bits)
        assert_lossless(mesh, stream, bits)


def test_came_paper_is_lossy_and_said_so():
    (entry,) = [c for c in meshcodec.codecs() if c["name"] == "came-paper"]
    assert not entry["lossless"]
    bunny = shared("bunny.ply")
    decoded = meshcodec.decode(meshcodec.encode(bunny.vertices, bunny.faces, codec="came-paper"))
    error = meshcodec.distance(bunny, decoded)["hausdorff"]
    assert 0 < error < 0.01


@pytest.mark.parametrize("codec", ["emc", "pm", "came", "raw"])
def test_every_level_decodes_coarse_to_fine_and_the_last_is_the_whole(codec):
    mesh = shared("bunny-3k-libigl.off")
    stream = meshcodec.encode(mesh.vertices, mesh.faces, codec=codec)
    levels = list(meshcodec.levels(stream))
    total = meshcodec.info(stream)["levels"]
    assert [l.level for l in levels] == list(range(1, total + 1))
    assert all(l.levels == total for l in levels)
    counts = [l.vertex_count for l in levels]
    assert counts == sorted(counts)
    whole = meshcodec.decode(stream)
    assert np.array_equal(levels[-1].vertices, whole.vertices)
    assert np.array_equal(levels[-1].faces, whole.faces)
    for l in levels:
        at = meshcodec.decode(stream, level=l.level)
        assert np.array_equal(at.faces, l.faces) and np.array_equal(at.vertices, l.vertices)


@pytest.mark.parametrize("codec", [c["name"] for c in meshcodec.codecs() if "partial_levels" not in c["capabilities"] and c["name"] != "raw"])
def test_a_cut_stream_gives_its_last_complete_level(codec):
    mesh = shared("bunny-3k-libigl.off")
    stream = meshcodec.encode(mesh.vertices, mesh.faces, codec=codec)
    ends = meshcodec.level_ends(stream)
    assert ends == sorted(ends) and ends[-1] == len(stream)
    levels = list(meshcodec.levels(stream))
    for k in range(1, len(ends)):
        # One byte short of level k + 1: level k, exactly as the whole stream decodes it.
        if ends[k] == ends[k - 1]:
            continue
        cut = meshcodec.decode(stream[: ends[k] - 1])
        assert cut.level == k
        assert np.array_equal(cut.faces, levels[k - 1].faces)
        assert np.array_equal(meshcodec.decode(stream, nbytes=ends[k] - 1).faces, cut.faces)


def test_emc_decodes_part_of_the_level_it_was_cut_in():
    mesh = shared("bunny-3k-libigl.off")
    stream = meshcodec.encode(mesh.vertices, mesh.faces, codec="emc")
    ends = meshcodec.level_ends(stream)
    k = len(ends) // 2
    cut = meshcodec.decode(stream, nbytes=(ends[k - 1] + ends[k]) // 2)
    assert cut.level == k
    assert cut.vertex_count >= meshcodec.decode(stream, level=k).vertex_count


@pytest.mark.parametrize("codec", ["emc", "came"])
@pytest.mark.parametrize("chunk", [1, 997, 1 << 16])
def test_levels_of_a_stream_still_arriving_match_the_whole_streams(codec, chunk):
    mesh = shared("bunny-3k-libigl.off")
    stream = meshcodec.encode(mesh.vertices, mesh.faces, codec=codec)
    if chunk == 1:
        stream_source = io.BytesIO(stream)
        reads = []
        original = stream_source.read

        def counting(n):
            data = original(n)
            reads.append(len(data))
            return data

        stream_source.read = counting
    else:
        stream_source = io.BytesIO(stream)
    arriving = list(meshcodec.levels(stream_source, chunk_size=chunk))
    whole = list(meshcodec.levels(stream))
    assert [m.level for m in arriving] == [m.level for m in whole]
    for a, w in zip(arriving, whole):
        assert np.array_equal(a.faces, w.faces) and np.array_equal(a.vertices, w.vertices)
    if chunk == 1:
        # Level 1 was yielded before the rest arrived: the reader stopped at the last level.
        assert sum(reads) <= len(stream) + 1


def test_a_stream_cut_while_arriving_yields_the_levels_it_holds():
    mesh = shared("bunny-3k-libigl.off")
    stream = meshcodec.encode(mesh.vertices, mesh.faces, codec="pm")
    ends = meshcodec.level_ends(stream)
    got = list(meshcodec.levels(io.BytesIO(stream[: ends[2] + 3]), chunk_size=100))
    assert [m.level for m in got] == [1, 2, 3]
    with pytest.raises(meshcodec.TruncatedStreamError):
        list(meshcodec.levels(io.BytesIO(stream[:10])))


def test_info_reads_the_header_and_index():
    mesh = shared("bunny-3k-libigl.off")
    stream = meshcodec.encode(mesh.vertices, mesh.faces, codec="came", quant_bits=14)
    about = meshcodec.info(stream)
    assert about["codec"] == "came" and about["quant_bits"] == 14
    assert about["format_version"] == meshcodec.FORMAT_VERSION and about["syntax"] == 9
    assert about["appearance"] is None
    assert about["bytes"] == about["stream_bytes"] == len(stream)
    assert not about["layered"] and not about["truncated"]
    units = about["units"]
    assert units[0]["first_byte"] == about["payload_start"]
    assert units[-1]["end_byte"] == len(stream)
    assert all(u["present"] for u in units)
    assert len(about["level_ends"]) == about["levels"]
    assert meshcodec.info(stream[: units[1]["end_byte"]])["truncated"]


def test_view_refines_a_came_stream_where_the_camera_looks():
    bunny = shared("bunny.ply")
    stream = meshcodec.encode(bunny.vertices, bunny.faces, codec="came")
    centre = (bunny.vertices.min(axis=0) + bunny.vertices.max(axis=0)) / 2
    eye = centre + np.array([0.0, 0.0, 0.25])
    near, stats = meshcodec.view(stream, eye, centre, size=(640, 480))
    assert stats["back_faces_culled"] and stats["settled"] and stats["unsure"] == 0
    free, free_stats = meshcodec.view(stream, eye, centre, size=(640, 480), keep_orientation=False)
    assert free_stats["settled"] and free.face_count <= near.face_count
    assert 0 < near.face_count < bunny.face_count
    assert stats["bytes_read"] <= stats["stream_bytes"]
    both, _ = meshcodec.view(stream, eye, centre, size=(640, 480), two_sided=True)
    assert near.face_count < both.face_count
    far, _ = meshcodec.view(stream, centre + np.array([0.0, 0.0, 5.0]), centre, size=(640, 480))
    assert far.face_count < near.face_count
    capped, capped_stats = meshcodec.view(stream, eye, centre, size=(640, 480), faces=2000)
    assert capped.face_count <= 2000 and capped_stats["tolerance"] > 1.0
    # Every vertex of the adapted mesh is a vertex of the full decode.
    full = meshcodec.decode(stream)
    cells = {tuple(v) for v in np.round(full.vertices, 9)}
    assert all(tuple(v) in cells for v in np.round(near.vertices, 9))


def test_view_refuses_streams_without_a_hierarchy_and_bad_cameras():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
    f = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    with pytest.raises(meshcodec.MeshcodecError, match="came"):
        meshcodec.view(meshcodec.encode(v, f, codec="emc"), (0, 0, 3), (0, 0, 0))
    stream = meshcodec.encode(v, f, codec="came")
    with pytest.raises(meshcodec.MeshcodecError, match="camera"):
        meshcodec.view(stream, (0, 0, 0), (0, 0, 0))
    with pytest.raises(meshcodec.MeshcodecError, match="size"):
        meshcodec.view(stream, (0, 0, 3), (0, 0, 0), size=(0, 480))
    with pytest.raises(meshcodec.MeshcodecError, match="eye"):
        meshcodec.view(stream, (0, 0), (0, 0, 0))


def test_load_and_save_round_trip(tmp_path):
    mesh = shared("bunny-3k-libigl.off")
    for ext in ("ply", "obj"):
        path = tmp_path / f"m.{ext}"
        meshcodec.save(mesh, path)
        again = meshcodec.load(path)
        assert again.face_count == mesh.face_count
        # Corner positions face by face (an OBJ reader may number vertices anew); OBJ holds
        # six significant digits.
        corners, expected = again.vertices[again.faces], mesh.vertices[mesh.faces]
        assert np.allclose(corners, expected, rtol=0, atol=0 if ext == "ply" else 1e-6)
    meshcodec.save((mesh.vertices.tolist(), mesh.faces.tolist()), tmp_path / "lists.ply")
    assert meshcodec.load(tmp_path / "lists.ply").face_count == mesh.face_count


def test_appearance_is_loaded_coded_decoded_and_saved(tmp_path):
    mesh = meshcodec.load(MESHES / "bunny-10k-textured.obj")
    a = mesh.appearance
    assert a is not None and a.wedge_count == 6451 and a.uvs.shape == (6451, 2)
    assert a.corners.shape == (mesh.face_count, 3) and a.material_names == ["01_-_Default"]
    assert meshcodec.load(MESHES / "bunny-10k-textured.obj", drop_attributes=True).appearance is None
    # emc codes the appearance with its levels: every level shows it.
    stream = meshcodec.encode(mesh.vertices, mesh.faces, codec="emc", appearance=a)
    about = meshcodec.info(stream)
    assert about["appearance"]["unit"] is None and not about["appearance"]["in_levels"]
    assert len(about["appearance"]["level_parts"]) == about["levels"]
    plain = meshcodec.encode(mesh.vertices, mesh.faces, codec="emc")
    assert len(plain) < len(stream) and meshcodec.info(plain)["appearance"] is None
    levels = list(meshcodec.levels(stream))
    assert all(l.appearance is not None for l in levels)
    # In one unit after the last level instead: the levels before it have none.
    unit = meshcodec.encode(mesh.vertices, mesh.faces, codec="emc", appearance=a,
                            attributes="unit")
    assert meshcodec.info(unit)["appearance"]["unit"] is not None
    assert all(l.appearance is None for l in list(meshcodec.levels(unit))[:-1])
    full = meshcodec.decode(stream)
    assert full.appearance is not None and full.appearance.wedge_count == 6451
    # Each decoded corner's uv is the original's to within half a cell of the 12-bit grid.
    span = (a.uvs.max(0) - a.uvs.min(0)).max()
    decoded_corner_uvs = full.appearance.uvs[full.appearance.corners]
    assert decoded_corner_uvs.shape == (full.face_count, 3, 2)
    assert np.all(decoded_corner_uvs >= a.uvs.min(0) - span / 4096)
    # Written as glTF and read back: the same wedges.
    meshcodec.save(full, tmp_path / "bunny.glb")
    again = meshcodec.load(tmp_path / "bunny.glb")
    assert again.appearance.wedge_count == 6451
    assert np.allclose(again.appearance.uvs[again.appearance.corners],
                       decoded_corner_uvs, atol=1e-6)
    # pm can carry the appearance inside its splits: every level then has it.
    in_levels = meshcodec.encode(mesh.vertices, mesh.faces, codec="pm-reordered", appearance=a,
                                 attributes="keep")
    about = meshcodec.info(in_levels)
    assert about["appearance"]["in_levels"] and about["appearance"]["unit"] is None
    pm_levels = list(meshcodec.levels(in_levels))
    assert len(pm_levels) > 1 and all(l.appearance is not None for l in pm_levels)
    assert pm_levels[-1].appearance.wedge_count == 6451
    with pytest.raises(meshcodec.MeshcodecError, match="is for pm"):
        meshcodec.encode(mesh.vertices, mesh.faces, codec="emc", appearance=a, attributes="fit")
    # came-paper's full level is lossy: it refuses appearance.
    with pytest.raises(meshcodec.MeshcodecError, match="cannot carry"):
        meshcodec.encode(mesh.vertices, mesh.faces, codec="came-paper", appearance=a)
    with pytest.raises(meshcodec.MeshcodecError, match="Appearance"):
        meshcodec.encode(mesh.vertices, mesh.faces, appearance={"uvs": a.uvs})
    # Wedges that do not fit the faces are refused in one line.
    bad = meshcodec.Appearance(a.corners[:-1], a.wedge_vertex, uvs=a.uvs)
    with pytest.raises(meshcodec.MeshcodecError):
        meshcodec.encode(mesh.vertices, mesh.faces, appearance=bad)


def test_pm_derives_normals_from_geometry_when_asked():
    mesh = meshcodec.load(MESHES / "feline-26k.obj")
    a = mesh.appearance
    assert a is not None and a.normals is not None
    coded = meshcodec.encode(mesh.vertices, mesh.faces, codec="pm-reordered", appearance=a,
                             attributes="keep")
    derived = meshcodec.encode(mesh.vertices, mesh.faces, codec="pm-reordered", appearance=a,
                               attributes="keep", derive_normals=True)
    # No normal value in the splits: a smaller stream, every level with normals.
    assert len(derived) < 0.8 * len(coded)
    assert meshcodec.info(derived)["appearance"]["normals"] == "derived"
    assert meshcodec.info(coded)["appearance"]["normals"] == "predicted"
    assert meshcodec.info(coded)["appearance"]["in_levels"]
    levels = list(meshcodec.levels(derived))
    assert len(levels) > 3 and all(l.appearance.normals is not None for l in levels)

    # The derived normals are near the file's (a smooth surface), not equal to them.
    def normal_at(m):
        corners = m.appearance.normals[m.appearance.corners].reshape(-1, 3)
        at = m.vertices[m.faces].reshape(-1, 3)
        return {tuple(np.round(p, 9)): n for p, n in zip(at, corners)}

    ours, theirs = normal_at(levels[-1]), normal_at(meshcodec.decode(coded))
    assert ours.keys() == theirs.keys()
    cosines = np.array([np.dot(ours[k], theirs[k]) for k in ours])
    mean_degrees = np.degrees(np.arccos(np.clip(cosines, -1, 1))).mean()
    assert 0.1 < mean_degrees < 5, mean_degrees


def test_distance_is_zero_to_itself_and_grows_as_levels_coarsen():
    mesh = shared("bunny-3k-libigl.off")
    # The BVH measures in float32 about the mesh's centre.
    assert meshcodec.distance(mesh, mesh)["hausdorff"] < 1e-6
    stream = meshcodec.encode(mesh.vertices, mesh.faces, codec="emc")
    errors = [meshcodec.distance(mesh, l)["hausdorff"] for l in list(meshcodec.levels(stream))[2:]]
    assert errors[0] > errors[-1]
    d = meshcodec.distance(mesh, meshcodec.decode(stream, level=4), samples=3, seed=7)
    assert d["hausdorff_absolute"] == pytest.approx(d["hausdorff"] * d["diagonal"])
    assert d == meshcodec.distance(mesh, meshcodec.decode(stream, level=4), samples=3, seed=7)


def test_distance_takes_a_sample_budget_and_says_how_precise_it_is():
    mesh = shared("bunny-3k-libigl.off")
    level = meshcodec.decode(meshcodec.encode(mesh.vertices, mesh.faces, codec="emc"), level=5)
    full = meshcodec.distance(mesh, level)
    assert full["samples"][0] == len(mesh.vertices) + 10 * len(mesh.faces)
    capped = meshcodec.distance(mesh, level, max_samples=2000)
    assert capped["samples"][0] == len(mesh.vertices) + 2000
    assert capped["max_samples"] == 2000
    # A capped run estimates the same figures, its uncertainty wider.
    assert 0 < full["rms_uncertainty"] < capped["rms_uncertainty"] < 0.05
    assert capped["rms"] == pytest.approx(full["rms"], rel=10 * capped["rms_uncertainty"])
    assert 0 <= capped["hausdorff_uncertainty"] < 1
    with pytest.raises(meshcodec.MeshcodecError, match="max_samples"):
        meshcodec.distance(mesh, level, max_samples=0)


def test_decoded_arrays_are_the_decoders_buffers_and_any_dtype_goes_in():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float32)
    f = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]], dtype=np.uint8)
    mesh = meshcodec.decode(meshcodec.encode(v, f, codec="emc"))
    assert mesh.vertices.dtype == np.float64 and mesh.faces.dtype == np.uint32
    assert mesh.vertices.shape == (4, 3) and mesh.faces.shape == (4, 3)
    assert not mesh.vertices.flags.owndata and not mesh.faces.flags.owndata
    # Fortran order and views are taken too.
    assert meshcodec.encode(np.asfortranarray(v), f[:, :], codec="raw")


BAD_ARRAYS = [
    (np.zeros((4, 2)), [[0, 1, 2]], "(n, 3)"),
    ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1]], "(m, 3)"),
    ([[0, 0, 0], [1, 0, 0], [np.nan, 1, 0]], [[0, 1, 2]], "non-finite"),
    ([[0, 0, 0], [1, 0, 0], [np.inf, 1, 0]], [[0, 1, 2]], "non-finite"),
    ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 3]], "out of range"),
    ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, -1, 2]], "out of range"),
    ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2.0]], "integers"),
    ([["a", "b", "c"]], [[0, 0, 0]], "numbers"),
    (np.zeros((0, 3)), np.zeros((0, 3), dtype=int), "empty"),
]


@pytest.mark.parametrize("vertices,faces,message", BAD_ARRAYS)
def test_bad_arrays_raise_value_error_with_the_librarys_message(vertices, faces, message):
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(")", r"\)")):
        meshcodec.encode(vertices, faces)


def test_pm_takes_a_mesh_that_is_no_manifold():
    # Three faces on one edge, two of them running it the same way: pm cuts the mesh to a
    # manifold and its full decode is the mesh itself, orientation included.
    fin = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1]], dtype=float)
    faces = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]])
    for codec in ("pm", "pm-reordered"):
        decoded = meshcodec.decode(meshcodec.encode(fin, faces, codec=codec, quant_bits=12))
        assert decoded.vertices.shape == (5, 3)
        canonical = meshcodec.canonical(fin, faces, quant_bits=12)

        def oriented(m):
            out = []
            for f in m.faces:
                corners = [tuple(np.round(m.vertices[v], 9)) for v in f]
                k = corners.index(min(corners))
                out.append(tuple(corners[k:] + corners[:k]))
            return sorted(out)

        assert oriented(decoded) == oriented(canonical)


def test_bad_arguments_raise_value_error():
    v, f = np.eye(3), np.array([[0, 1, 2]])
    with pytest.raises(ValueError, match="unknown codec"):
        meshcodec.encode(v, f, codec="zip")
    with pytest.raises(ValueError, match="unknown option"):
        meshcodec.encode(v, f, levels=3)
    with pytest.raises(ValueError, match="grid"):
        meshcodec.encode(v, f, grid="hex")
    with pytest.raises(ValueError, match="bits"):
        meshcodec.encode(v, f, quant_bits=40)
    with pytest.raises(ValueError, match="bits"):
        meshcodec.encode(v, f, quant_bits=-1)
    with pytest.raises(ValueError, match="levels"):
        meshcodec.decode(meshcodec.encode(v, f, codec="emc"), level=99)
    with pytest.raises(FileNotFoundError):
        meshcodec.load("/no/such/mesh.ply")
    with pytest.raises(ValueError, match="stream is bytes"):
        meshcodec.decode("not bytes")


def test_corrupt_streams_raise_value_error_and_never_anything_else():
    mesh = shared("bunny-3k-libigl.off")
    streams = {c: meshcodec.encode(mesh.vertices, mesh.faces, codec=c) for c in ("emc", "pm", "came")}
    with pytest.raises(ValueError, match="bad magic"):
        meshcodec.decode(b"garbage that is no stream")
    with pytest.raises(meshcodec.TruncatedStreamError):
        meshcodec.decode(streams["emc"][:7])
    rng = random.Random(5)
    outcomes = {"decoded": 0, "refused": 0}
    for case in range(300):
        codec = rng.choice(sorted(streams))
        data = bytearray(streams[codec])
        for _ in range(rng.randint(1, 8)):
            data[rng.randrange(len(data))] = rng.randrange(256)
        if rng.random() < 0.3:
            data = data[: rng.randrange(len(data))]
        try:
            meshcodec.decode(bytes(data))
            list(meshcodec.levels(bytes(data)))
            outcomes["decoded"] += 1
        except ValueError:
            outcomes["refused"] += 1
    assert outcomes["refused"] > 0


def test_the_interpreter_lock_is_released_while_encoding():
    bunny = shared("bunny.ply")
    started = time.perf_counter()
    meshcodec.encode(bunny.vertices, bunny.faces, codec="pm")
    one = time.perf_counter() - started
    worker = threading.Thread(target=meshcodec.encode, args=(bunny.vertices, bunny.faces, "pm"))
    gaps, last = [], time.perf_counter()
    worker.start()
    while worker.is_alive():
        time.sleep(0.001)
        now = time.perf_counter()
        gaps.append(now - last)
        last = now
    worker.join()
    # Holding the lock, the encode would stop this loop for its whole length.
    assert max(gaps) < one / 2, (max(gaps), one)


def test_a_glb_packs_and_unpacks_to_the_canonical_mesh(tmp_path):
    """pack: spot's one primitive coded, with a fallback of about 2% of its faces; unpack: the
    full level back, spot's canonical mesh at 12 bits (as single-precision floats), its uvs too."""
    packed = tmp_path / "spot.glb"
    report = meshcodec.pack(MESHES / "spot.obj", packed)
    assert len(report) == 1 and report[0]["faces"] == 5856, report
    assert 256 <= report[0]["fallback_faces"] < 5856 / 10
    assert packed.read_bytes()[:4] == b"glTF"
    full = tmp_path / "spot-full.glb"
    assert meshcodec.unpack(packed, full) == 1
    back = meshcodec.load(full)
    spot = shared("spot.obj")
    original = meshcodec.canonical(spot.vertices, spot.faces, quant_bits=12)
    assert len(back.faces) == len(original.faces) == 5856
    as_f32 = lambda v: sorted(map(tuple, np.asarray(v, dtype=np.float32).tolist()))
    assert as_f32(np.unique(back.vertices, axis=0)) == as_f32(np.unique(original.vertices, axis=0))
    assert back.appearance is not None and back.appearance.uvs is not None


def test_pack_refuses_what_it_cannot_read_in_one_line(tmp_path):
    bad = tmp_path / "bad.gltf"
    bad.write_text('{"asset": ')
    with pytest.raises(meshcodec.MeshcodecError) as error:
        meshcodec.pack(bad, tmp_path / "out.glb")
    assert "\n" not in str(error.value)
