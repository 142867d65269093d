//! `meshcodec._core`: the Rust codec core seen from Python. The package's `__init__.py` wraps
//! these functions with numpy conversions, keyword checks and the `Mesh` class; everything here
//! takes C-contiguous float64 (n, 3) positions and int64 (m, 3) faces and hands back numpy
//! arrays that own the decoder's buffers (no copy).
//!
//! Every library error becomes a `MeshcodecError` (a `ValueError`) carrying the library's
//! one-line message — `TruncatedStreamError` for a stream or file that ends too soon, `OSError`
//! for the operating system's failures — and the GIL is released while meshes are encoded,
//! decoded, read, written or measured.

use meshcodec::codecs::{
    self, Capability, Codec, EncodeOptions, EncodeRequest, LevelDecoder, LevelMesh, Stop,
};
use meshcodec::container::FORMAT_VERSION;
use meshcodec::mesh::attribute_quantization::AttributeBits;
use meshcodec::mesh::attributes::{AttributedMesh, Attributes, Materials};
use meshcodec::mesh::io;
use meshcodec::mesh::quantize::GridShape;
use meshcodec::mesh::TriMesh;
use meshcodec::metrics::{
    Reference, SampleBudget, DEFAULT_MAX_SAMPLES, DEFAULT_SAMPLES_PER_TRIANGLE, DEFAULT_SEED,
};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::create_exception;
use pyo3::exceptions::{PyFileNotFoundError, PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList};
use std::path::PathBuf;
use std::sync::Mutex;

create_exception!(
    _core,
    MeshcodecError,
    PyValueError,
    "A mesh, stream or argument meshcodec refuses, with the library's one-line reason."
);
create_exception!(
    _core,
    TruncatedStreamError,
    MeshcodecError,
    "Input that ends before something that must be there (a stream's header or index)."
);

/// The Python exception for a library error.
fn to_py(e: meshcodec::Error) -> PyErr {
    match e {
        meshcodec::Error::Io(io) => io.into(),
        meshcodec::Error::Truncated(_) => TruncatedStreamError::new_err(e.to_string()),
        other => MeshcodecError::new_err(other.to_string()),
    }
}

fn refuse(what: impl Into<String>) -> PyErr {
    MeshcodecError::new_err(what.into())
}

/// The mesh of `vertices` and `faces`, checked as the readers check a file's: finite
/// coordinates, corners within the vertices.
fn mesh_of(vertices: &PyReadonlyArray2<f64>, faces: &PyReadonlyArray2<i64>) -> PyResult<TriMesh> {
    let mesh = level_of(vertices, faces)?;
    mesh.validate().map_err(to_py)?;
    Ok(mesh)
}

/// `vertices` and `faces` as a decoded level may be: corners within the vertices, but perhaps
/// no face yet (the caller checks the coordinates).
fn level_of(vertices: &PyReadonlyArray2<f64>, faces: &PyReadonlyArray2<i64>) -> PyResult<TriMesh> {
    let (v, f) = (vertices.as_array(), faces.as_array());
    if v.ncols() != 3 || f.ncols() != 3 {
        return Err(refuse(format!(
            "vertices must be (n, 3) and faces (m, 3), not {:?} and {:?}",
            v.shape(),
            f.shape()
        )));
    }
    let positions = match v.as_slice() {
        // Row after row in memory (the package hands over C-contiguous arrays).
        Some(flat) => flat
            .chunks_exact(3)
            .map(|c| glam::DVec3::new(c[0], c[1], c[2]))
            .collect(),
        None => v
            .rows()
            .into_iter()
            .map(|r| glam::DVec3::new(r[0], r[1], r[2]))
            .collect(),
    };
    let n = v.nrows() as i64;
    let corner = |i: usize, index: i64| {
        if (0..n).contains(&index) {
            Ok(index as u32)
        } else {
            Err(refuse(format!(
                "face {i} index {index} out of range ({n} vertices)"
            )))
        }
    };
    let triangles = match f.as_slice() {
        Some(flat) => flat
            .chunks_exact(3)
            .enumerate()
            .map(|(i, c)| Ok([corner(i, c[0])?, corner(i, c[1])?, corner(i, c[2])?]))
            .collect::<PyResult<Vec<_>>>()?,
        None => f
            .rows()
            .into_iter()
            .enumerate()
            .map(|(i, r)| Ok([corner(i, r[0])?, corner(i, r[1])?, corner(i, r[2])?]))
            .collect::<PyResult<Vec<_>>>()?,
    };
    Ok(TriMesh::new(positions, triangles))
}

/// Edges on no face, (k, 2), within `vertices` vertices.
fn edges_of(edges: &PyReadonlyArray2<i64>, vertices: usize) -> PyResult<Vec<[u32; 2]>> {
    let e = edges.as_array();
    if e.ncols() != 2 {
        return Err(refuse(format!(
            "loose edges must be (k, 2), not {:?}",
            e.shape()
        )));
    }
    e.rows()
        .into_iter()
        .enumerate()
        .map(|(i, r)| {
            let ends = [r[0], r[1]];
            if ends.iter().any(|&x| !(0..vertices as i64).contains(&x)) {
                return Err(refuse(format!(
                    "loose edge {i} {ends:?} out of range ({vertices} vertices)"
                )));
            }
            Ok(ends.map(|x| x as u32))
        })
        .collect()
}

/// Positions (n, 3) float64, faces (m, 3) uint32 and loose edges (k, 2) uint32 as numpy arrays
/// over the decoder's own buffers.
type MeshArrays<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<u32>>,
    Bound<'py, PyArray2<u32>>,
);

fn arrays(py: Python<'_>, level: LevelMesh) -> MeshArrays<'_> {
    let LevelMesh {
        mesh, loose_edges, ..
    } = level;
    let (n, m, k) = (mesh.positions.len(), mesh.faces.len(), loose_edges.len());
    // Reinterpreted in place: a DVec3 is three f64s, a face three u32s.
    let positions: Vec<f64> = bytemuck::allocation::cast_vec(mesh.positions);
    let faces: Vec<u32> = bytemuck::allocation::cast_vec(mesh.faces);
    let edges: Vec<u32> = bytemuck::allocation::cast_vec(loose_edges);
    (
        shaped(py, n, 3, positions),
        shaped(py, m, 3, faces),
        shaped(py, k, 2, edges),
    )
}

/// A (rows, cols) numpy array owning `values` (rows · cols of them).
fn shaped<T: numpy::Element>(
    py: Python<'_>,
    rows: usize,
    cols: usize,
    values: Vec<T>,
) -> Bound<'_, PyArray2<T>> {
    Array2::from_shape_vec((rows, cols), values)
        .expect("rows times cols values")
        .into_pyarray(py)
}

/// A mesh's appearance as a dict of numpy arrays (Hoppe's wedges): `corners` (m, 3) uint32
/// wedge ids, `wedge_vertex` (w,) uint32, `normals` (w, 3), `uvs` (w, 2) and `colours` (w, 4)
/// float64 or None, `face_material` (m,) uint32 or None, `material_names`, `material_library`.
/// `None` for a mesh without appearance.
fn appearance_dict(py: Python<'_>, a: Option<Attributes>) -> PyResult<Option<Bound<'_, PyDict>>> {
    let Some(a) = a.filter(|a| !a.is_empty()) else {
        return Ok(None);
    };
    let d = PyDict::new(py);
    let m = a.corners.len();
    let w = a.wedge_vertex.len();
    d.set_item(
        "corners",
        shaped(
            py,
            m,
            3,
            bytemuck::allocation::cast_vec::<[u32; 3], u32>(a.corners),
        ),
    )?;
    d.set_item("wedge_vertex", a.wedge_vertex.into_pyarray(py))?;
    let flat3 = |v: Vec<glam::DVec3>| {
        v.into_iter()
            .flat_map(|x| x.to_array())
            .collect::<Vec<f64>>()
    };
    let flat2 = |v: Vec<glam::DVec2>| {
        v.into_iter()
            .flat_map(|x| x.to_array())
            .collect::<Vec<f64>>()
    };
    d.set_item("normals", a.normals.map(|n| shaped(py, w, 3, flat3(n))))?;
    d.set_item("uvs", a.uvs.map(|t| shaped(py, w, 2, flat2(t))))?;
    d.set_item(
        "colours",
        a.colours
            .map(|c| shaped(py, w, 4, c.into_iter().flatten().collect())),
    )?;
    match a.materials {
        Some(materials) => {
            d.set_item("face_material", materials.face.into_pyarray(py))?;
            d.set_item("material_names", materials.names)?;
            d.set_item("material_library", materials.library)?;
        }
        None => {
            d.set_item("face_material", py.None())?;
            d.set_item("material_names", Vec::<String>::new())?;
            d.set_item("material_library", py.None())?;
        }
    }
    Ok(Some(d))
}

/// An (n, cols) float64 array of a dict entry as rows, `None` when absent or None.
fn rows<const N: usize>(d: &Bound<'_, PyDict>, key: &str) -> PyResult<Option<Vec<[f64; N]>>> {
    let Some(item) = d.get_item(key)?.filter(|i| !i.is_none()) else {
        return Ok(None);
    };
    let array: PyReadonlyArray2<f64> = item.extract().map_err(|_| {
        refuse(format!(
            "appearance['{key}'] must be a float64 (n, {N}) array"
        ))
    })?;
    let view = array.as_array();
    if view.ncols() != N {
        return Err(refuse(format!(
            "appearance['{key}'] must be an (n, {N}) array, not {:?}",
            view.shape()
        )));
    }
    Ok(Some(
        view.rows()
            .into_iter()
            .map(|r| std::array::from_fn(|k| r[k]))
            .collect(),
    ))
}

/// A dict of [`appearance_dict`]'s shape as the library's wedges, checked against `mesh`.
fn attributes_of(d: &Bound<'_, PyDict>, mesh: &TriMesh) -> PyResult<Attributes> {
    let uint = |key: &str| -> PyResult<Vec<u32>> {
        let item = d
            .get_item(key)?
            .ok_or_else(|| refuse(format!("appearance has no '{key}'")))?;
        let array: PyReadonlyArray1<u32> = item
            .extract()
            .map_err(|_| refuse(format!("appearance['{key}'] must be a uint32 (n,) array")))?;
        Ok(array.as_array().to_vec())
    };
    let corners_item = d
        .get_item("corners")?
        .ok_or_else(|| refuse("appearance has no 'corners'"))?;
    let corners: PyReadonlyArray2<u32> = corners_item
        .extract()
        .map_err(|_| refuse("appearance['corners'] must be a uint32 (m, 3) array"))?;
    let view = corners.as_array();
    if view.ncols() != 3 {
        return Err(refuse("appearance['corners'] must be an (m, 3) array"));
    }
    let corners: Vec<[u32; 3]> = view
        .rows()
        .into_iter()
        .map(|r| [r[0], r[1], r[2]])
        .collect();
    let materials = match d.get_item("face_material")?.filter(|i| !i.is_none()) {
        None => None,
        Some(_) => Some(Materials {
            face: uint("face_material")?,
            names: d
                .get_item("material_names")?
                .map(|n| n.extract())
                .transpose()?
                .unwrap_or_default(),
            library: d
                .get_item("material_library")?
                .filter(|l| !l.is_none())
                .map(|l| l.extract())
                .transpose()?,
        }),
    };
    let attributes = Attributes {
        corners,
        wedge_vertex: uint("wedge_vertex")?,
        normals: rows::<3>(d, "normals")?.map(|n| n.into_iter().map(glam::DVec3::from).collect()),
        uvs: rows::<2>(d, "uvs")?.map(|t| t.into_iter().map(glam::DVec2::from).collect()),
        colours: rows::<4>(d, "colours")?,
        materials,
    };
    attributes.validate(mesh).map_err(to_py)?;
    Ok(attributes)
}

fn codec(name: &str) -> PyResult<&'static dyn Codec> {
    codecs::by_name(name).map_err(to_py)
}

/// The grid named, `default` when none is.
fn grid_shape(grid: Option<&str>, default: GridShape) -> PyResult<GridShape> {
    match grid {
        None => Ok(default),
        Some("cubic") => Ok(GridShape::Cubic),
        Some("per-axis") => Ok(GridShape::PerAxis),
        Some(other) => Err(refuse(format!("unknown grid '{other}' (cubic, per-axis)"))),
    }
}

/// Encodes a mesh, with its appearance when given (uvs on `uv_bits`, normals octahedral on
/// `normal_bits`, or derived from the positions with `derive_normals`; inside the levels by
/// the rule `attributes`, "fit" or "keep", for pm);
/// returns the stream.
#[pyfunction]
#[pyo3(signature = (vertices, faces, codec_name, quant_bits, grid=None, appearance=None, uv_bits=12, normal_bits=10, attributes=None, derive_normals=false))]
#[allow(clippy::too_many_arguments)]
fn encode<'py>(
    py: Python<'py>,
    vertices: PyReadonlyArray2<'py, f64>,
    faces: PyReadonlyArray2<'py, i64>,
    codec_name: &str,
    quant_bits: u8,
    grid: Option<&str>,
    appearance: Option<Bound<'py, PyDict>>,
    uv_bits: u8,
    normal_bits: u8,
    attributes: Option<&str>,
    derive_normals: bool,
) -> PyResult<Bound<'py, PyBytes>> {
    let codec = codec(codec_name)?;
    let appearance_unit = attributes == Some("unit");
    let in_levels = attributes
        .filter(|_| !appearance_unit)
        .map(codecs::AttributeFit::by_name)
        .transpose()
        .map_err(to_py)?;
    let options = EncodeOptions {
        quant_bits,
        grid: grid_shape(grid, codec.default_options().grid)?,
    };
    let mesh = mesh_of(&vertices, &faces)?;
    let attributes = appearance
        .as_ref()
        .map(|d| attributes_of(d, &mesh))
        .transpose()?
        .filter(|a| !a.is_empty());
    let bits = AttributeBits {
        uv: uv_bits,
        normal: normal_bits,
        derive_normals,
    };
    let request = EncodeRequest {
        codec,
        options,
        appearance: attributes.is_some().then_some(bits),
        in_levels,
        appearance_unit,
    };
    let mesh = AttributedMesh {
        mesh,
        attributes: attributes.unwrap_or_default(),
    };
    let bytes = py
        .detach(|| request.encode(mesh).map(|made| made.encoded.bytes))
        .map_err(to_py)?;
    Ok(PyBytes::new(py, &bytes))
}

/// The canonical mesh of `vertices` and `faces` at `quant_bits` (docs/CONTRACT.md §2): what a
/// lossless codec's full decode is, positions at cell centres.
#[pyfunction]
#[pyo3(signature = (vertices, faces, quant_bits, grid=None))]
fn canonical<'py>(
    py: Python<'py>,
    vertices: PyReadonlyArray2<'py, f64>,
    faces: PyReadonlyArray2<'py, i64>,
    quant_bits: u8,
    grid: Option<&str>,
) -> PyResult<MeshArrays<'py>> {
    let options = EncodeOptions {
        quant_bits,
        grid: grid_shape(grid, GridShape::Cubic)?,
    };
    let mesh = mesh_of(&vertices, &faces)?;
    let canonical = py
        .detach(|| codecs::canonical_for(&mesh, &options).map(|c| c.to_mesh()))
        .map_err(to_py)?;
    Ok(arrays(
        py,
        LevelMesh {
            mesh: canonical,
            loose_edges: Vec::new(),
            attributes: None,
        },
    ))
}

/// Decodes a stream (or its first `nbytes`) up to `level` levels (all present when `None`);
/// returns the arrays, the appearance, the levels decoded and the levels the whole stream holds.
#[pyfunction]
#[pyo3(signature = (stream, level=None, nbytes=None))]
fn decode<'py>(
    py: Python<'py>,
    stream: &[u8],
    level: Option<usize>,
    nbytes: Option<usize>,
) -> PyResult<DecodedLevel<'py>> {
    let bytes = &stream[..nbytes.unwrap_or(stream.len()).min(stream.len())];
    let stop = level.map_or(Stop::All, Stop::Levels);
    let (mesh, decoded, total) = py
        .detach(|| {
            let mut decoder = codecs::open(bytes)?;
            let total = decoder.levels();
            let (mesh, decoded) = codecs::decode_with(decoder.as_mut(), stop)?;
            Ok::<_, meshcodec::Error>((mesh, decoded, total))
        })
        .map_err(to_py)?;
    let appearance = appearance_dict(py, mesh.attributes.clone())?;
    Ok((arrays(py, mesh), appearance, decoded, total))
}

/// Adapts the vertex hierarchy of a `came` or `came-paper` stream to a camera
/// (view-dependent refinement, reading only the meta-nodes the view needs): the adapted mesh's
/// arrays and a dict of what it took.
#[pyfunction]
#[pyo3(signature = (stream, eye, target, up, fov, width, height, tolerance, faces=None, two_sided=false, keep_orientation=true))]
#[allow(clippy::too_many_arguments)]
fn view<'py>(
    py: Python<'py>,
    stream: &[u8],
    eye: [f64; 3],
    target: [f64; 3],
    up: [f64; 3],
    fov: f64,
    width: u32,
    height: u32,
    tolerance: f64,
    faces: Option<usize>,
    two_sided: bool,
    keep_orientation: bool,
) -> PyResult<(MeshArrays<'py>, Bound<'py, PyDict>)> {
    use meshcodec::codecs::came::refine::{Budget, Camera, View, ViewMesh};
    let camera = Camera {
        eye: glam::DVec3::from_array(eye),
        target: glam::DVec3::from_array(target),
        up: glam::DVec3::from_array(up),
        fov_degrees: fov,
        width,
        height,
    };
    let (mesh, done, fetched, scale, culled) = py
        .detach(|| {
            let view = View::new(&camera, tolerance)?
                .two_sided(two_sided)
                .keep_orientation(keep_orientation);
            let mut front = ViewMesh::from_stream(stream)?;
            let budget = Budget {
                operations: usize::MAX,
                faces,
            };
            let done = front.settle(&view, budget, 64);
            let culled = !two_sided && front.has_normal_cones();
            Ok::<_, meshcodec::Error>((
                front.mesh(),
                done,
                front.fetched(),
                front.tolerance_scale(),
                culled,
            ))
        })
        .map_err(to_py)?;
    let d = PyDict::new(py);
    d.set_item("splits", done.splits)?;
    d.set_item("collapses", done.collapses)?;
    d.set_item("settled", done.settled)?;
    d.set_item("unsure", done.unsure)?;
    d.set_item("tolerance", tolerance * scale)?;
    d.set_item("back_faces_culled", culled)?;
    d.set_item("bytes_read", fetched.bytes_read)?;
    d.set_item("stream_bytes", fetched.stream_bytes)?;
    d.set_item("units_loaded", fetched.units_loaded)?;
    d.set_item("units_refused", fetched.units_refused)?;
    d.set_item("units", fetched.units)?;
    let level = LevelMesh {
        mesh,
        loose_edges: Vec::new(),
        attributes: None,
    };
    Ok((arrays(py, level), d))
}

/// A decoded level: its arrays, its appearance (at the full level of a stream with an
/// appearance unit), the levels decoded and the levels the stream holds.
type DecodedLevel<'py> = (MeshArrays<'py>, Option<Bound<'py, PyDict>>, usize, usize);

type Decoder<'a> = Box<dyn LevelDecoder + 'a>;

self_cell::self_cell!(
    /// A stream and the decoder walking it.
    struct OwnedDecoder {
        owner: Vec<u8>,
        #[not_covariant]
        dependent: Decoder,
    }
);

/// The meshes of a stream's successive levels, each decoded from the one before.
#[pyclass(module = "meshcodec._core")]
struct LevelIterator {
    decoder: Mutex<OwnedDecoder>,
    levels: usize,
}

#[pymethods]
impl LevelIterator {
    #[new]
    fn new(py: Python<'_>, stream: Vec<u8>) -> PyResult<LevelIterator> {
        let decoder = py
            .detach(|| OwnedDecoder::try_new(stream, |bytes| codecs::open(bytes)))
            .map_err(to_py)?;
        let levels = decoder.with_dependent(|_, d| d.levels());
        Ok(LevelIterator {
            decoder: Mutex::new(decoder),
            levels,
        })
    }

    /// Levels the whole stream holds.
    #[getter]
    fn levels(&self) -> usize {
        self.levels
    }

    fn __iter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    #[allow(clippy::type_complexity)]
    fn __next__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<Option<(MeshArrays<'py>, Option<Bound<'py, PyDict>>, usize)>> {
        let next = py
            .detach(|| {
                let mut decoder = self.decoder.lock().unwrap_or_else(|e| e.into_inner());
                decoder.with_dependent_mut(|_, d| {
                    if !d.advance()? {
                        return Ok(None);
                    }
                    Ok::<_, meshcodec::Error>(Some((d.mesh()?, d.levels_decoded())))
                })
            })
            .map_err(to_py)?;
        match next {
            None => Ok(None),
            Some((mesh, level)) => {
                let appearance = appearance_dict(py, mesh.attributes.clone())?;
                Ok(Some((arrays(py, mesh), appearance, level)))
            }
        }
    }
}

/// The bytes each level of a stream needs, from a prefix holding its header and index.
#[pyfunction]
fn level_ends(stream: &[u8]) -> PyResult<Vec<u64>> {
    codecs::level_ends(stream).map_err(to_py)
}

/// What a stream's header and index say, without decoding it: the JSON of the library's
/// `StreamInfo`, which `meshcodec.info` loads.
#[pyfunction]
fn info(py: Python<'_>, stream: &[u8]) -> PyResult<String> {
    // The library's one description of a stream, in the keys `meshcodec info --json` prints.
    py.detach(|| {
        let info = codecs::StreamInfo::of(stream).map_err(to_py)?;
        serde_json::to_string(&info).map_err(|e| PyValueError::new_err(e.to_string()))
    })
}

/// A library error about the file at `path`, its name first as the command line prints it.
fn about_file(e: meshcodec::Error, path: &std::path::Path) -> PyErr {
    let message = format!("{}: {e}", path.display());
    match e {
        meshcodec::Error::Io(io) if io.kind() == std::io::ErrorKind::NotFound => {
            PyFileNotFoundError::new_err(message)
        }
        meshcodec::Error::Io(_) => PyOSError::new_err(message),
        meshcodec::Error::Truncated(_) => TruncatedStreamError::new_err(message),
        _ => MeshcodecError::new_err(message),
    }
}

/// Reads a mesh file (PLY, OBJ, OFF, .m, STL, glTF) with its appearance; with
/// `drop_attributes`, positions and faces only. A path that names no file is looked up as a
/// test mesh's name (`bunny`, `spot.obj`) in the data folders, as the commands do.
#[pyfunction]
#[pyo3(signature = (path, drop_attributes=false))]
#[allow(clippy::type_complexity)]
fn load(
    py: Python<'_>,
    path: PathBuf,
    drop_attributes: bool,
) -> PyResult<(MeshArrays<'_>, Option<Bound<'_, PyDict>>)> {
    // Not found as a name either: the error names the path as given.
    let path = match path.is_file() {
        true => path,
        false => io::resolve(&path.to_string_lossy()).unwrap_or(path),
    };
    let read = py
        .detach(|| {
            if drop_attributes {
                io::read_mesh(&path).map(|mesh| AttributedMesh {
                    mesh,
                    attributes: Attributes::default(),
                })
            } else {
                io::read_attributed(&path)
            }
        })
        .map_err(|e| about_file(e, &path))?;
    let appearance = appearance_dict(py, Some(read.attributes))?;
    Ok((
        arrays(
            py,
            LevelMesh {
                mesh: read.mesh,
                loose_edges: Vec::new(),
                attributes: None,
            },
        ),
        appearance,
    ))
}

/// Writes a mesh, with its appearance when given, by the path's extension (PLY, OBJ, glTF;
/// VRML without appearance); a format that cannot hold the appearance is refused.
#[pyfunction]
#[pyo3(signature = (vertices, faces, path, appearance=None))]
fn save<'py>(
    py: Python<'py>,
    vertices: PyReadonlyArray2<'py, f64>,
    faces: PyReadonlyArray2<'py, i64>,
    path: PathBuf,
    appearance: Option<Bound<'py, PyDict>>,
) -> PyResult<()> {
    let mesh = mesh_of(&vertices, &faces)?;
    let attributes = appearance
        .as_ref()
        .map(|d| attributes_of(d, &mesh))
        .transpose()?;
    py.detach(|| match attributes {
        None => io::write_mesh(&mesh, &path),
        Some(attributes) => io::write_attributed(&AttributedMesh { mesh, attributes }, &path),
    })
    .map_err(|e| about_file(e, &path))
}

/// Packs a glTF scene or mesh file into a GLB whose triangle primitives are progressive
/// streams (docs/GLTF.md); returns the report as JSON (one entry a primitive).
#[pyfunction]
#[pyo3(signature = (input, output, codec_name, quant_bits, uv_bits, normal_bits, fallback_share, fallback_faces, external))]
#[allow(clippy::too_many_arguments)]
fn pack(
    py: Python<'_>,
    input: PathBuf,
    output: PathBuf,
    codec_name: &str,
    quant_bits: u8,
    uv_bits: u8,
    normal_bits: u8,
    fallback_share: Option<f64>,
    fallback_faces: usize,
    external: bool,
) -> PyResult<String> {
    let options = meshcodec::packing::PackOptions {
        codec: codec(codec_name)?,
        quant_bits,
        bits: AttributeBits {
            uv: uv_bits,
            normal: normal_bits,
            derive_normals: false,
        },
        fallback: fallback_share.map(|share| meshcodec::packing::Fallback {
            share,
            min_faces: fallback_faces,
        }),
    };
    let streams_path = output.with_extension("streams.bin");
    let uri = streams_path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let report = py
        .detach(|| -> meshcodec::Result<_> {
            let scene = meshcodec::mesh::scene::Scene::open(&input)?;
            let packed =
                meshcodec::packing::pack(&scene, &options, external.then_some(uri.as_str()))?;
            io::write_atomically(&output, &packed.glb)?;
            if let Some(streams) = &packed.streams {
                io::write_atomically(&streams_path, streams)?;
            }
            Ok(packed.report)
        })
        .map_err(|e| about_file(e, &input))?;
    let entries: Vec<serde_json::Value> = report
        .iter()
        .map(|p| {
            let mut entry = serde_json::json!({
                "mesh": p.mesh,
                "primitive": p.primitive,
                "name": p.name,
            });
            match &p.outcome {
                meshcodec::packing::Outcome::Packed {
                    stream_bytes,
                    levels,
                    fallback_level,
                    fallback_faces,
                    faces,
                } => {
                    entry["stream_bytes"] = (*stream_bytes).into();
                    entry["levels"] = (*levels).into();
                    entry["fallback_level"] = (*fallback_level).into();
                    entry["fallback_faces"] = (*fallback_faces).into();
                    entry["faces"] = (*faces).into();
                }
                meshcodec::packing::Outcome::Kept(why) => entry["kept"] = why.clone().into(),
            }
            entry
        })
        .collect();
    Ok(serde_json::Value::Array(entries).to_string())
}

/// Every progressive stream of a packed GLB back into ordinary accessors; returns how many.
#[pyfunction]
fn unpack(py: Python<'_>, input: PathBuf, output: PathBuf) -> PyResult<usize> {
    py.detach(|| -> meshcodec::Result<usize> {
        let bytes = std::fs::read(&input)?;
        let scene = meshcodec::mesh::scene::Scene::read(&bytes, input.parent())?;
        let unpacked = meshcodec::packing::unpack(&scene)?;
        io::write_atomically(&output, &unpacked.glb)?;
        Ok(unpacked.primitives)
    })
    .map_err(|e| about_file(e, &input))
}

/// Distances both ways between mesh `a` (the reference) and mesh `b` — a decoded level, which
/// may have loose edges and even no face yet — over samples of both (docs/CONTRACT.md §5).
#[pyfunction]
#[pyo3(signature = (a_vertices, a_faces, b_vertices, b_faces, b_edges, samples=DEFAULT_SAMPLES_PER_TRIANGLE, seed=DEFAULT_SEED, max_samples=DEFAULT_MAX_SAMPLES))]
#[allow(clippy::too_many_arguments)]
fn distance<'py>(
    py: Python<'py>,
    a_vertices: PyReadonlyArray2<'py, f64>,
    a_faces: PyReadonlyArray2<'py, i64>,
    b_vertices: PyReadonlyArray2<'py, f64>,
    b_faces: PyReadonlyArray2<'py, i64>,
    b_edges: PyReadonlyArray2<'py, i64>,
    samples: usize,
    seed: u64,
    max_samples: usize,
) -> PyResult<Bound<'py, PyDict>> {
    if samples == 0 {
        return Err(refuse("samples must be at least 1 a triangle"));
    }
    if max_samples == 0 {
        return Err(refuse("max_samples must be at least 1"));
    }
    let budget = SampleBudget {
        per_triangle: samples,
        max: max_samples,
    };
    let a = mesh_of(&a_vertices, &a_faces)?;
    let mesh = level_of(&b_vertices, &b_faces)?;
    if let Some(i) = mesh.positions.iter().position(|p| !p.is_finite()) {
        return Err(refuse(format!(
            "vertex {i} of b has a non-finite coordinate"
        )));
    }
    let loose_edges = edges_of(&b_edges, mesh.positions.len())?;
    let b = LevelMesh {
        mesh,
        loose_edges,
        attributes: None,
    };
    let (measured, diagonal) = py.detach(|| {
        let reference = Reference::new(&a, budget, seed);
        let diagonal = a.referenced_bounds().map_or(0.0, |b| b.diagonal());
        (reference.measure(&b), diagonal)
    });
    let m = measured.ok_or_else(|| refuse("mesh b has no vertex"))?;
    let d = PyDict::new(py);
    let relative = if diagonal > 0.0 { diagonal } else { 1.0 };
    d.set_item("hausdorff", m.hausdorff() / relative)?;
    d.set_item("rms", m.rms() / relative)?;
    d.set_item("hausdorff_paper", m.paper / relative)?;
    d.set_item("hausdorff_absolute", m.hausdorff())?;
    d.set_item("rms_absolute", m.rms())?;
    d.set_item("diagonal", diagonal)?;
    d.set_item("samples_per_triangle", samples)?;
    d.set_item("max_samples", max_samples)?;
    let uncertainty = m.uncertainty();
    d.set_item("samples", uncertainty.samples.to_vec())?;
    d.set_item("rms_uncertainty", uncertainty.rms)?;
    d.set_item("hausdorff_uncertainty", uncertainty.hausdorff)?;
    Ok(d)
}

/// Every codec: name, id, summary, default quantization, whether lossless, capabilities.
#[pyfunction]
fn codec_list(py: Python<'_>) -> PyResult<Bound<'_, PyList>> {
    let list = PyList::empty(py);
    for c in codecs::registry() {
        let d = PyDict::new(py);
        d.set_item("name", c.name())?;
        d.set_item("id", c.id())?;
        d.set_item("summary", c.summary())?;
        d.set_item("quant_bits", c.default_options().quant_bits)?;
        d.set_item(
            "grid",
            match c.default_options().grid {
                GridShape::Cubic => "cubic",
                GridShape::PerAxis => "per-axis",
            },
        )?;
        d.set_item("lossless", c.lossless())?;
        let capabilities: Vec<&str> = c
            .capabilities()
            .iter()
            .map(|cap| match cap {
                Capability::PassStops => "pass_stops",
                Capability::PartialLevels => "partial_levels",
                Capability::SelectiveRefinement => "selective_refinement",
                Capability::Attributes => "attributes",
                Capability::AppearanceInLevels => "appearance_in_levels",
                Capability::AppearanceWithLevels => "appearance_with_levels",
            })
            .collect();
        d.set_item("capabilities", capabilities)?;
        list.append(d)?;
    }
    Ok(list)
}

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("MeshcodecError", m.py().get_type::<MeshcodecError>())?;
    m.add(
        "TruncatedStreamError",
        m.py().get_type::<TruncatedStreamError>(),
    )?;
    m.add("FORMAT_VERSION", FORMAT_VERSION)?;
    m.add_class::<LevelIterator>()?;
    m.add_function(wrap_pyfunction!(encode, m)?)?;
    m.add_function(wrap_pyfunction!(decode, m)?)?;
    m.add_function(wrap_pyfunction!(view, m)?)?;
    m.add_function(wrap_pyfunction!(canonical, m)?)?;
    m.add_function(wrap_pyfunction!(level_ends, m)?)?;
    m.add_function(wrap_pyfunction!(info, m)?)?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(save, m)?)?;
    m.add_function(wrap_pyfunction!(distance, m)?)?;
    m.add_function(wrap_pyfunction!(pack, m)?)?;
    m.add_function(wrap_pyfunction!(unpack, m)?)?;
    m.add_function(wrap_pyfunction!(codec_list, m)?)?;
    Ok(())
}
