"""meshcodec: progressive triangle-mesh compression over numpy arrays.

The codecs of the Rust crate of the same name — EMC (Magnor & Girod's embedded mesh coding, as
published and context-modelled), Hoppe's progressive meshes, Grabner's CAME vertex hierarchy and
the uncompressed baseline — with the guarantees of its docs/CONTRACT.md: a mesh is quantized to
a grid of ``quant_bits`` bits per axis, every lossless codec's full decode is exactly that
quantized ("canonical") mesh, and any prefix of a stream decodes to the levels it holds.

>>> import numpy as np, meshcodec
>>> v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
>>> f = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
>>> stream = meshcodec.encode(v, f, codec="emc")
>>> mesh = meshcodec.decode(stream)
>>> mesh.faces.shape
(4, 3)

Errors in the input — arrays of the wrong shape or dtype, NaN, an index out of range, a
corrupt stream — raise :class:`MeshcodecError` (a :class:`ValueError`) with the library's
one-line message; a stream that ends too soon raises its subclass
:class:`TruncatedStreamError`. The interpreter's lock is released while meshes are encoded,
decoded, read, written or measured, so threads run codecs in parallel.
"""

from __future__ import annotations

import bisect
import json
import os
from dataclasses import dataclass, field
from typing import IO, Any, Dict, Iterator, List, Optional, Union

import numpy as np

from . import _core
from ._core import FORMAT_VERSION, MeshcodecError, TruncatedStreamError

__all__ = [
    "FORMAT_VERSION",
    "Appearance",
    "Mesh",
    "canonical",
    "MeshcodecError",
    "TruncatedStreamError",
    "codecs",
    "decode",
    "distance",
    "encode",
    "info",
    "level_ends",
    "levels",
    "load",
    "pack",
    "save",
    "unpack",
    "view",
]

Bytes = Union[bytes, bytearray, memoryview]
PathLike = Union[str, "os.PathLike[str]"]

# What `encode` accepts beyond the arrays, codec and quantization.
_CODEC_OPTIONS = ("grid", "uv_bits", "normal_bits", "attributes", "derive_normals")


@dataclass
class Appearance:
    """A mesh's appearance in Hoppe's wedges: each face corner names a wedge, each wedge a vertex
    and the attributes its corners share; a seam is several wedges at one vertex.

    Attributes:
        corners: uint32 array (m, 3): the wedge of each corner, face by face.
        wedge_vertex: uint32 array (w,): the vertex of each wedge.
        normals: float64 array (w, 3), or None.
        uvs: float64 array (w, 2), or None.
        colours: float64 array (w, 4), RGBA in [0, 1], or None.
        face_material: uint32 array (m,): each face's index into ``material_names``, or None.
        material_names: the materials' names.
        material_library: the material library the file named (OBJ's ``mtllib``), or None.
    """

    corners: np.ndarray
    wedge_vertex: np.ndarray
    normals: Optional[np.ndarray] = None
    uvs: Optional[np.ndarray] = None
    colours: Optional[np.ndarray] = None
    face_material: Optional[np.ndarray] = None
    material_names: List[str] = field(default_factory=list)
    material_library: Optional[str] = None

    @property
    def wedge_count(self) -> int:
        return int(self.wedge_vertex.shape[0])

    def _dict(self) -> Dict[str, Any]:
        def floats(a: Optional[np.ndarray], cols: int, name: str) -> Optional[np.ndarray]:
            if a is None:
                return None
            array = np.asarray(a)
            if array.ndim != 2 or array.shape[1] != cols:
                raise MeshcodecError(f"appearance {name} must be an (n, {cols}) array, not {array.shape}")
            return np.ascontiguousarray(array, dtype=np.float64)

        def uints(a: Any, name: str) -> np.ndarray:
            array = np.asarray(a)
            if array.dtype.kind not in "iu" or (array.size and array.min() < 0):
                raise MeshcodecError(f"appearance {name} must be non-negative integers")
            return np.ascontiguousarray(array, dtype=np.uint32)

        return {
            "corners": uints(self.corners, "corners"),
            "wedge_vertex": uints(self.wedge_vertex, "wedge_vertex"),
            "normals": floats(self.normals, 3, "normals"),
            "uvs": floats(self.uvs, 2, "uvs"),
            "colours": floats(self.colours, 4, "colours"),
            "face_material": None if self.face_material is None else uints(self.face_material, "face_material"),
            "material_names": list(self.material_names),
            "material_library": self.material_library,
        }

    def __repr__(self) -> str:
        held = [k for k in ("normals", "uvs", "colours") if getattr(self, k) is not None]
        if self.face_material is not None:
            held.append(f"{len(self.material_names)} material(s)")
        return f"Appearance({self.wedge_count} wedges: {', '.join(held)})"


def _appearance(d: Optional[Dict[str, Any]]) -> Optional[Appearance]:
    return None if d is None else Appearance(**d)


@dataclass
class Mesh:
    """A triangle mesh: positions, faces and, for a coarse level, edges on no face.

    Attributes:
        vertices: float64 array (n, 3).
        faces: uint32 array (m, 3), counter-clockwise seen from the front.
        loose_edges: uint32 array (k, 2): edges of a decoded level that belong to no face (an
            embedded coder's coarse levels may have edges before triangles); empty otherwise.
        level: the levels decoded (None for a mesh not decoded from a stream).
        levels: the levels the whole stream holds (None likewise).
        appearance: normals, uvs, colours and materials (:class:`Appearance`), or None: as a
            file holds them, or as a stream's full level decodes them (levels before the
            appearance unit have none).
    """

    vertices: np.ndarray
    faces: np.ndarray
    loose_edges: Optional[np.ndarray] = None
    level: Optional[int] = None
    levels: Optional[int] = None
    appearance: Optional[Appearance] = None

    def __post_init__(self) -> None:
        if self.loose_edges is None:
            self.loose_edges = np.zeros((0, 2), dtype=np.uint32)

    @property
    def vertex_count(self) -> int:
        return int(self.vertices.shape[0])

    @property
    def face_count(self) -> int:
        return int(self.faces.shape[0])

    def __repr__(self) -> str:
        at = "" if self.level is None else f", level {self.level} of {self.levels}"
        wedges = "" if self.appearance is None else f", {self.appearance.wedge_count} wedges"
        return f"Mesh({self.vertex_count} vertices, {self.face_count} faces{wedges}{at})"


def _mesh(
    arrays: Any,
    level: Optional[int] = None,
    levels: Optional[int] = None,
    appearance: Optional[Dict[str, Any]] = None,
) -> Mesh:
    vertices, faces, loose_edges = arrays
    return Mesh(vertices, faces, loose_edges, level, levels, _appearance(appearance))


def _vertices(vertices: Any, name: str = "vertices") -> np.ndarray:
    array = np.asarray(vertices)
    if array.dtype.kind not in "fiu":
        raise MeshcodecError(f"{name} must be numbers, not {array.dtype}")
    if array.ndim != 2 or array.shape[1] != 3:
        raise MeshcodecError(f"{name} must be an (n, 3) array, not {array.shape}")
    return np.ascontiguousarray(array, dtype=np.float64)


def _faces(faces: Any, name: str = "faces") -> np.ndarray:
    array = np.asarray(faces)
    if array.dtype.kind not in "iu":
        raise MeshcodecError(f"{name} must be integers, not {array.dtype}")
    if array.ndim != 2 or array.shape[1] != 3:
        raise MeshcodecError(f"{name} must be an (m, 3) array, not {array.shape}")
    if array.dtype == np.uint64 and array.size and array.max() > np.iinfo(np.int64).max:
        raise MeshcodecError(f"{name} holds an index beyond any vertex")
    return np.ascontiguousarray(array, dtype=np.int64)


def _bits(quant_bits: Any) -> int:
    if isinstance(quant_bits, bool) or not isinstance(quant_bits, (int, np.integer)):
        raise MeshcodecError(f"quant_bits must be an integer, not {quant_bits!r}")
    if not 0 <= quant_bits <= 255:
        # The library names the range it supports; this only keeps the value a byte.
        raise MeshcodecError(f"quantization of {quant_bits} bits is not supported")
    return int(quant_bits)


def _stream(stream: Any) -> bytes:
    if isinstance(stream, bytes):
        return stream
    if isinstance(stream, (bytearray, memoryview)):
        return bytes(stream)
    raise MeshcodecError(f"a stream is bytes, not {type(stream).__name__}")


def _arrays_of(mesh: Any, name: str) -> tuple:
    if isinstance(mesh, Mesh):
        return _vertices(mesh.vertices, name), _faces(mesh.faces, name)
    if isinstance(mesh, tuple) and len(mesh) == 2:
        return _vertices(mesh[0], name), _faces(mesh[1], name)
    raise MeshcodecError(f"{name} must be a Mesh or a (vertices, faces) pair")


def encode(
    vertices: Any,
    faces: Any,
    codec: str = "emc",
    quant_bits: int = 12,
    **codec_options: Any,
) -> bytes:
    """Encodes a mesh; returns the stream.

    Args:
        vertices: (n, 3) positions, any float or integer dtype.
        faces: (m, 3) vertex indices, any integer dtype, counter-clockwise.
        codec: a name from :func:`codecs` ("emc", "emc-ahead", "emc-paper", "pm", "pm-reordered",
            "came", "came-paper", "raw").
        quant_bits: bits per axis of the quantization grid (1 to 24 as the codec allows).
        grid: "cubic" (one cell size on every axis, the default) or "per-axis".
        appearance: an :class:`Appearance` over these faces (e.g. ``load(path).appearance``);
            every lossless codec carries it, ``came-paper`` refuses it. ``emc`` and
            ``emc-ahead`` code it with their levels, so that every level shows it
            (``info(stream)["appearance"]["level_parts"]``); the other codecs in an appearance
            unit decoded with the full level.
        uv_bits: bits per uv axis over the uvs' bounding box (default 12).
        normal_bits: bits per octahedral normal coordinate (default 10).
        derive_normals: True derives the normals from the positions over the appearance's
            normal wedges (its normals then say only where the creases are); with ``pm`` and
            ``attributes`` the stream codes no normal values at all.
        attributes: ``pm`` and ``pm-reordered`` only: "fit" or "keep" codes the appearance
            inside the vertex splits, so that every level carries it (a collapsed wedge takes
            the values interpolated to where its vertex went, or the survivor's); ``info``
            then says ``appearance["in_levels"]``. Any codec that carries appearance: "unit"
            codes it in an appearance unit after the last level whatever the codec's own way.

    Raises:
        MeshcodecError: bad arrays, an unknown codec or option, or appearance the codec
            cannot carry (``came-paper``). Every codec takes any mesh: ``pm`` and
            ``pm-reordered`` cut one that is no oriented 2-manifold to one and weld it back at
            the full level.
    """
    appearance = codec_options.pop("appearance", None)
    if appearance is not None and not isinstance(appearance, Appearance):
        raise MeshcodecError(f"appearance must be an Appearance, not {type(appearance).__name__}")
    unknown = sorted(set(codec_options) - set(_CODEC_OPTIONS))
    if unknown:
        raise MeshcodecError(
            f"unknown option {', '.join(unknown)} (options: {', '.join(_CODEC_OPTIONS)})"
        )
    return _core.encode(
        _vertices(vertices),
        _faces(faces),
        codec,
        _bits(quant_bits),
        codec_options.get("grid"),
        None if appearance is None else appearance._dict(),
        _bits(codec_options.get("uv_bits", 12)),
        _bits(codec_options.get("normal_bits", 10)),
        codec_options.get("attributes"),
        bool(codec_options.get("derive_normals", False)),
    )


def canonical(vertices: Any, faces: Any, quant_bits: int = 12, grid: str = "cubic") -> Mesh:
    """The canonical mesh at ``quant_bits`` (docs/CONTRACT.md §2): unreferenced vertices
    dropped, positions quantized to cell centres, vertices sharing a cell welded, faces that
    then repeat a vertex or another face dropped. A lossless codec's full decode is exactly
    this mesh, up to the order of vertices and faces and the rotation of each face."""
    return _mesh(_core.canonical(_vertices(vertices), _faces(faces), _bits(quant_bits), grid))


def decode(stream: Bytes, level: Optional[int] = None, nbytes: Optional[int] = None) -> Mesh:
    """Decodes a stream, or any prefix of it.

    Args:
        stream: the stream's bytes (a prefix decodes to the levels it holds; codecs that can
            also decode part of a cut level, as EMC, do so when ``level`` is None).
        level: stop after this many levels (None: every level present).
        nbytes: decode only the first ``nbytes`` bytes, as if the rest had not arrived.

    Returns:
        The :class:`Mesh`, with ``level`` the levels decoded and ``levels`` the stream's.
    """
    if level is not None and (isinstance(level, bool) or level < 0):
        raise MeshcodecError(f"level must be a count of levels, not {level!r}")
    if nbytes is not None and (isinstance(nbytes, bool) or nbytes < 0):
        raise MeshcodecError(f"nbytes must be a count of bytes, not {nbytes!r}")
    arrays, appearance, decoded, total = _core.decode(_stream(stream), level, nbytes)
    return _mesh(arrays, decoded, total, appearance)


def view(
    stream: Bytes,
    eye: Any,
    target: Any,
    up: Any = (0.0, 1.0, 0.0),
    fov: float = 50.0,
    size: Any = (1280, 720),
    tolerance: float = 1.0,
    faces: Optional[int] = None,
    two_sided: bool = False,
    keep_orientation: bool = True,
) -> "tuple[Mesh, Dict[str, Any]]":
    """The mesh a camera needs from a CAME stream (``came`` or ``came-paper``): its vertex
    hierarchy refined where a vertex could land ``tolerance`` pixels or more from where the mesh
    shows it, coarse elsewhere, reading only the meta-nodes that view needs.

    Args:
        stream: the stream's bytes.
        eye, target, up: the camera, three numbers each, in the mesh's units.
        fov: the vertical field of view in degrees.
        size: the viewport, (width, height) in pixels.
        tolerance: the screen-space tolerance in pixels.
        faces: a face budget (the tolerance is raised until the mesh holds at most this many).
        two_sided: refine the parts facing away from the eye too; by default a node whose
            normal cone turns every face away stays coarse (streams with normal cones).
        keep_orientation: keep every face in view turned as its full-mesh triangle (refining
            where the hierarchy cannot yet tell); ``False`` allows fold-overs for a few percent
            fewer faces and faster adaptation.

    Returns:
        The adapted :class:`Mesh` and a dict: ``splits``, ``collapses``, ``settled``,
        ``unsure`` (faces in view left unsure of their orientation: a face budget held their
        splits back, or their meta-nodes were refused), the
        ``tolerance`` reached, ``back_faces_culled``, ``bytes_read`` of ``stream_bytes``,
        ``units_loaded``, ``units_refused`` of ``units`` (meta-nodes).
    """

    def point(p: Any, name: str) -> "tuple[float, float, float]":
        a = np.asarray(p, dtype=np.float64)
        if a.shape != (3,):
            raise MeshcodecError(f"{name} must be three numbers, not {p!r}")
        return (float(a[0]), float(a[1]), float(a[2]))

    if len(size) != 2 or any(isinstance(x, bool) or int(x) != x or x <= 0 for x in size):
        raise MeshcodecError(f"size must be (width, height) in pixels, not {size!r}")
    if faces is not None and (isinstance(faces, bool) or faces < 0):
        raise MeshcodecError(f"faces must be a count of faces, not {faces!r}")
    arrays, stats = _core.view(
        _stream(stream),
        point(eye, "eye"),
        point(target, "target"),
        point(up, "up"),
        float(fov),
        int(size[0]),
        int(size[1]),
        float(tolerance),
        faces,
        bool(two_sided),
        bool(keep_orientation),
    )
    return _mesh(arrays), stats


def levels(stream: Union[Bytes, IO[bytes]], chunk_size: int = 1 << 16) -> Iterator[Mesh]:
    """The meshes of a stream's successive levels, coarse to fine.

    ``stream`` is either the stream's bytes — each level then decodes from the one before —
    or a binary file-like object (a file, a socket's ``makefile("rb")``, anything with
    ``read``) whose bytes may still be arriving: each level is yielded as soon as the bytes it
    needs (:func:`level_ends`) have been read, ``chunk_size`` bytes at a time. A stream that
    ends early yields the levels it holds and stops.
    """
    if isinstance(stream, (bytes, bytearray, memoryview)):
        return _levels_of_bytes(_stream(stream))
    if not hasattr(stream, "read"):
        raise MeshcodecError(f"levels() takes bytes or a file-like object, not {type(stream).__name__}")
    return _levels_arriving(stream, chunk_size)


def _levels_of_bytes(stream: bytes) -> Iterator[Mesh]:
    it = _core.LevelIterator(stream)
    for arrays, appearance, level in it:
        yield _mesh(arrays, level, it.levels, appearance)


def _levels_arriving(source: IO[bytes], chunk_size: int) -> Iterator[Mesh]:
    if chunk_size < 1:
        raise MeshcodecError("chunk_size must be at least 1")
    buffer = bytearray()
    ends: Optional[List[int]] = None
    done = 0
    while True:
        chunk = source.read(chunk_size)
        finished = not chunk
        buffer.extend(chunk or b"")
        if ends is None:
            try:
                ends = _core.level_ends(bytes(buffer))
            except TruncatedStreamError:
                if finished:
                    raise
                continue
        ready = bisect.bisect_right(ends, len(buffer))
        if ready > done:
            # A decoder over what has arrived walks up to the last level it completes (the
            # levels before are decoded again: a decoder cannot follow a growing buffer).
            it = _core.LevelIterator(bytes(buffer))
            for arrays, appearance, level in it:
                if level > done:
                    yield _mesh(arrays, level, it.levels, appearance)
                    done = level
                if level >= ready:
                    break
        if finished or done >= len(ends):
            return


def level_ends(stream: Bytes) -> List[int]:
    """Bytes of the stream, from its first, that decoding each level needs (entry k for level
    k + 1), from a prefix that holds at least the header and index."""
    return list(_core.level_ends(_stream(stream)))


def info(stream: Bytes) -> Dict[str, Any]:
    """What a stream's header and index say, without decoding it, in the keys ``meshcodec info
    --json`` prints: codec, format_version, syntax, bytes, stream_bytes, truncated, the quantization
    grid (quant_bits, origin, cell), vertices and triangles of the full mesh, levels and
    level_ends (the bytes each level needs), payload_start, layered, every unit (for CAME: every
    meta-node) with its parent and byte range, ``appearance``: None, or what the stream carries
    (normal_bits, normals "coded", "predicted" from geometry or "derived" from it, uv_bits,
    uv_origin, uv_cell, colours, materials, material_library, in_levels, and its unit), and what
    the codec reads of its header (vertex_copies for ``pm`` streams cut to a manifold,
    normal_cones for CAME streams; None otherwise)."""
    return json.loads(_core.info(_stream(stream)))


def load(path: PathLike, drop_attributes: bool = False) -> Mesh:
    """Reads a mesh file (PLY, OBJ, OFF, .m, STL, glTF) with its normals, texture coordinates,
    colours and materials as :attr:`Mesh.appearance` (None when it has none). A path naming no
    file is looked up as a test mesh's name (``"bunny"``, ``"spot.obj"``) in ``$MESHCODEC_DATA``,
    ``../shared/meshes`` and the per-user cache, as the commands do (``meshcodec data fetch``
    downloads one there).

    ``drop_attributes=True`` reads positions and faces only. A file holding appearance its
    reader cannot keep (OFF colours, ``.m`` normals) is refused, naming it, unless dropped.
    """
    arrays, appearance = _core.load(os.fspath(path), bool(drop_attributes))
    return _mesh(arrays, appearance=appearance)


def save(mesh: Union[Mesh, tuple], path: PathLike) -> None:
    """Writes a mesh (a :class:`Mesh` or a (vertices, faces) pair) by the extension of
    ``path``: binary PLY, OBJ, glTF (``.glb``, ``.gltf``) with the mesh's appearance, or VRML
    without; a format that cannot hold the appearance is refused. The file appears only when
    complete."""
    vertices, faces = _arrays_of(mesh, "mesh")
    appearance = mesh.appearance if isinstance(mesh, Mesh) else None
    _core.save(vertices, faces, os.fspath(path), None if appearance is None else appearance._dict())


def pack(
    input: PathLike,
    output: PathLike,
    codec: str = "emc",
    quant_bits: int = 12,
    uv_bits: int = 12,
    normal_bits: int = 10,
    fallback: Optional[float] = 0.02,
    fallback_faces: int = 256,
    external: bool = False,
) -> List[Dict[str, Any]]:
    """Packs a glTF scene (``.gltf`` with its files, ``.glb``) or any mesh file into the GLB
    ``output`` whose triangle primitives are progressive streams (docs/GLTF.md: the
    ``MESHCODEC_progressive`` extension), the rest of the scene kept.

    Each primitive's own accessors hold a coarse level — the one whose triangles are nearest
    ``fallback`` (a share) of its triangles and at least ``fallback_faces`` — that any glTF
    viewer draws; ``fallback=None`` stores none (the extension is then required).
    ``external=True`` writes the streams to ``output`` with the extension ``.streams.bin``,
    beside the GLB, for clients that fetch their levels by HTTP Range requests.

    Returns one dict a primitive: ``mesh``, ``primitive``, ``name`` and, for those coded,
    ``faces``, ``stream_bytes``, ``levels``, ``fallback_level``, ``fallback_faces``; for those
    kept as they are (points, lines, skinned, morphed, other attributes), ``kept``: why.
    """
    if fallback is not None and not (0.0 < float(fallback) <= 1.0):
        raise MeshcodecError("fallback must be a share in (0, 1], or None")
    report = _core.pack(
        os.fspath(input),
        os.fspath(output),
        str(codec),
        int(quant_bits),
        int(uv_bits),
        int(normal_bits),
        None if fallback is None else float(fallback),
        int(fallback_faces),
        bool(external),
    )
    return json.loads(report)


def unpack(input: PathLike, output: PathLike) -> int:
    """Decodes every progressive stream of the packed GLB ``input`` back into ordinary
    accessors (each primitive's full level, lossless at the stream's quantization) and writes
    the GLB ``output``; returns how many primitives it decoded."""
    return _core.unpack(os.fspath(input), os.fspath(output))


def distance(
    a: Union[Mesh, tuple],
    b: Union[Mesh, tuple],
    samples: int = 10,
    seed: Optional[int] = None,
    max_samples: int = 1_000_000,
) -> Dict[str, Any]:
    """Distances both ways between a reference mesh ``a`` and a mesh ``b`` (a decoded level
    counts its loose edges, and may have no face yet).

    Both surfaces are sampled (``samples`` random points per triangle of ``a``, at most
    ``max_samples``, plus its vertices; as many on ``b``) and each sample's exact distance to
    the other surface is taken through a BVH, as the experiment harness measures levels
    (docs/CONTRACT.md §5).

    Returns:
        ``hausdorff`` (symmetric), ``rms`` (over both directions) and ``hausdorff_paper``
        (largest distance of a vertex of ``a`` to ``b``, EMC's measure), each over the
        bounding-box diagonal of ``a``; the same absolute as ``hausdorff_absolute`` and
        ``rms_absolute``; ``diagonal``; ``samples`` taken each way (vertices included),
        ``rms_uncertainty`` (the RMS's relative standard error) and ``hausdorff_uncertainty``
        (what the Hausdorff distance gained from half the random samples to all of them,
        relative to it).
    """
    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or samples < 1:
        raise MeshcodecError(f"samples must be a positive integer, not {samples!r}")
    if isinstance(max_samples, bool) or not isinstance(max_samples, (int, np.integer)) or max_samples < 1:
        raise MeshcodecError(f"max_samples must be a positive integer, not {max_samples!r}")
    av, af = _arrays_of(a, "a")
    bv, bf = _arrays_of(b, "b")
    edges = b.loose_edges if isinstance(b, Mesh) else None
    be = np.zeros((0, 2), dtype=np.int64) if edges is None else np.ascontiguousarray(edges, dtype=np.int64)
    if seed is None:
        return _core.distance(av, af, bv, bf, be, int(samples), max_samples=int(max_samples))
    return _core.distance(av, af, bv, bf, be, int(samples), int(seed), int(max_samples))


def codecs() -> List[Dict[str, Any]]:
    """Every codec of this build: name, id, summary, default ``quant_bits`` and grid, whether
    its full decode is lossless, and what it does beyond level-by-level decoding."""
    return list(_core.codec_list())
