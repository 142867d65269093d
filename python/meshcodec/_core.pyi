"""Type stubs of the compiled core (python/src/lib.rs); use the wrappers in meshcodec."""

from typing import Any, Dict, Iterator, List, Optional, Tuple

import numpy as np
import numpy.typing as npt

FORMAT_VERSION: int
APPEARANCE_UNIT_VERSION: int

class MeshcodecError(ValueError): ...
class TruncatedStreamError(MeshcodecError): ...

_Arrays = Tuple[npt.NDArray[np.float64], npt.NDArray[np.uint32], npt.NDArray[np.uint32]]
# corners, wedge_vertex, normals, uvs, colours, face_material, material_names, material_library
_Appearance = Dict[str, Any]

def encode(
    vertices: npt.NDArray[np.float64],
    faces: npt.NDArray[np.int64],
    codec_name: str,
    quant_bits: int,
    grid: Optional[str] = None,
    appearance: Optional[_Appearance] = None,
    uv_bits: int = 12,
    normal_bits: int = 10,
    attributes: Optional[str] = None,
    derive_normals: bool = False,
) -> bytes: ...
def canonical(
    vertices: npt.NDArray[np.float64],
    faces: npt.NDArray[np.int64],
    quant_bits: int,
    grid: Optional[str] = None,
) -> _Arrays: ...
def decode(
    stream: bytes, level: Optional[int] = None, nbytes: Optional[int] = None
) -> Tuple[_Arrays, Optional[_Appearance], int, int]: ...

def view(
    stream: bytes,
    eye: Tuple[float, float, float],
    target: Tuple[float, float, float],
    up: Tuple[float, float, float],
    fov: float,
    width: int,
    height: int,
    tolerance: float,
    faces: Optional[int] = None,
    two_sided: bool = False,
    keep_orientation: bool = True,
) -> Tuple[_Arrays, Dict[str, Any]]: ...

class LevelIterator(Iterator[Tuple[_Arrays, Optional[_Appearance], int]]):
    def __init__(self, stream: bytes) -> None: ...
    @property
    def levels(self) -> int: ...
    def __iter__(self) -> "LevelIterator": ...
    def __next__(self) -> Tuple[_Arrays, Optional[_Appearance], int]: ...

def level_ends(stream: bytes) -> List[int]: ...
def info(stream: bytes) -> str: ...
def load(path: str, drop_attributes: bool = False) -> Tuple[_Arrays, Optional[_Appearance]]: ...
def save(
    vertices: npt.NDArray[np.float64],
    faces: npt.NDArray[np.int64],
    path: str,
    appearance: Optional[_Appearance] = None,
) -> None: ...
def pack(
    input: str,
    output: str,
    codec_name: str,
    quant_bits: int,
    uv_bits: int,
    normal_bits: int,
    fallback_share: Optional[float],
    fallback_faces: int,
    external: bool,
) -> str: ...
def unpack(input: str, output: str) -> int: ...
def distance(
    a_vertices: npt.NDArray[np.float64],
    a_faces: npt.NDArray[np.int64],
    b_vertices: npt.NDArray[np.float64],
    b_faces: npt.NDArray[np.int64],
    b_edges: npt.NDArray[np.int64],
    samples: int = 10,
    seed: int = ...,
) -> Dict[str, float]: ...
def codec_list() -> List[Dict[str, Any]]: ...
