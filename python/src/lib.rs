//! `meshcodec._core`: the Rust codec core seen from Python. The package's `__init__.py` wraps
//! these functions with numpy conversions, keyword checks and the `Mesh` class; everything here
//! takes C-contiguous float64 (n, 3) positions and int64 (m, 3) faces and hands back numpy
//! arrays that own the decoder's buffers (no copy).
//!
//! Every library error becomes a `MeshcodecError` (a `ValueError`) carrying the library's
//! one-line message — `TruncatedStreamError` for a stream or file that ends too soon, `OSError`
//! for the operating system's failures — and the GIL is released while meshes are encoded,
//! decoded, read, written or measured.

use meshcodec::codecs::{self, Capability, Codec, EncodeOptions, LevelDecoder, LevelMesh, Stop};
use meshcodec::container::{StreamReader, FORMAT_VERSION};
use meshcodec::mesh::io;
use meshcodec::mesh::quantize::GridShape;
use meshcodec::mesh::TriMesh;
use meshcodec::metrics::{Reference, DEFAULT_SAMPLES_PER_TRIANGLE, DEFAULT_SEED};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray2, PyReadonlyArray2};
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

/// Encodes a mesh; returns the stream.
#[pyfunction]
#[pyo3(signature = (vertices, faces, codec_name, quant_bits, grid=None))]
fn encode<'py>(
    py: Python<'py>,
    vertices: PyReadonlyArray2<'py, f64>,
    faces: PyReadonlyArray2<'py, i64>,
    codec_name: &str,
    quant_bits: u8,
    grid: Option<&str>,
) -> PyResult<Bound<'py, PyBytes>> {
    let codec = codec(codec_name)?;
    let options = EncodeOptions {
        quant_bits,
        grid: grid_shape(grid, codec.default_options().grid)?,
    };
    let mesh = mesh_of(&vertices, &faces)?;
    let bytes = py
        .detach(|| {
            let canonical = codecs::canonical_for(&mesh, &options)?;
            codec.encode(&canonical).map(|e| e.bytes)
        })
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
/// returns the arrays, the levels decoded and the levels the whole stream holds.
#[pyfunction]
#[pyo3(signature = (stream, level=None, nbytes=None))]
fn decode<'py>(
    py: Python<'py>,
    stream: &[u8],
    level: Option<usize>,
    nbytes: Option<usize>,
) -> PyResult<(MeshArrays<'py>, usize, usize)> {
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
    Ok((arrays(py, mesh), decoded, total))
}

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

    fn __next__<'py>(&self, py: Python<'py>) -> PyResult<Option<(MeshArrays<'py>, usize)>> {
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
        Ok(next.map(|(mesh, level)| (arrays(py, mesh), level)))
    }
}

/// The bytes each level of a stream needs, from a prefix holding its header and index.
#[pyfunction]
fn level_ends(stream: &[u8]) -> PyResult<Vec<u64>> {
    codecs::level_ends(stream).map_err(to_py)
}

/// What a stream's header and index say, without decoding it.
#[pyfunction]
fn info<'py>(py: Python<'py>, stream: &[u8]) -> PyResult<Bound<'py, PyDict>> {
    let reader = StreamReader::open(stream).map_err(to_py)?;
    let header = reader.header();
    let codec = codecs::by_id(header.codec_id).map_err(to_py)?;
    let index = reader.index();
    let start = reader.payload_start() as u64;
    let units = PyList::empty(py);
    for (i, u) in index.units.iter().enumerate() {
        let unit = PyDict::new(py);
        unit.set_item("unit", i)?;
        unit.set_item("parent", u.parent)?;
        unit.set_item("first_byte", start + u.offset)?;
        unit.set_item("end_byte", start + u.end())?;
        unit.set_item("bytes", u.length)?;
        unit.set_item("present", reader.unit(i).is_some())?;
        units.append(unit)?;
    }
    let d = PyDict::new(py);
    d.set_item("codec", codec.name())?;
    d.set_item("format_version", FORMAT_VERSION)?;
    d.set_item("bytes", stream.len())?;
    d.set_item("stream_bytes", start + index.payload_bytes)?;
    d.set_item("truncated", reader.truncated())?;
    d.set_item("quant_bits", header.grid.bits)?;
    d.set_item("origin", header.grid.origin.to_vec())?;
    d.set_item("cell", header.grid.cell.to_vec())?;
    d.set_item("vertices", header.vertices)?;
    d.set_item("triangles", header.triangles)?;
    // One end a level: the count without opening a decoder.
    let ends = codec.level_ends(&reader).map_err(to_py)?;
    d.set_item("levels", ends.len())?;
    d.set_item("level_ends", ends)?;
    d.set_item("payload_start", start)?;
    d.set_item("layered", index.is_layered())?;
    d.set_item("units", units)?;
    Ok(d)
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

/// Reads a mesh file (PLY, OBJ, OFF, .m, STL); refuses one holding normals, texture
/// coordinates, colours or materials unless `drop_attributes`.
#[pyfunction]
#[pyo3(signature = (path, drop_attributes=false))]
fn load(py: Python<'_>, path: PathBuf, drop_attributes: bool) -> PyResult<MeshArrays<'_>> {
    let (mesh, appearance) = py
        .detach(|| io::read_mesh_and_appearance(&path))
        .map_err(|e| about_file(e, &path))?;
    if !appearance.is_empty() && !drop_attributes {
        return Err(refuse(format!(
            "{}: holds {appearance}, which meshcodec does not carry; \
             load(..., drop_attributes=True) reads positions and faces only",
            path.display()
        )));
    }
    Ok(arrays(
        py,
        LevelMesh {
            mesh,
            loose_edges: Vec::new(),
            attributes: None,
        },
    ))
}

/// Writes a mesh as PLY, OBJ or VRML by the path's extension.
#[pyfunction]
fn save<'py>(
    py: Python<'py>,
    vertices: PyReadonlyArray2<'py, f64>,
    faces: PyReadonlyArray2<'py, i64>,
    path: PathBuf,
) -> PyResult<()> {
    let mesh = mesh_of(&vertices, &faces)?;
    py.detach(|| io::write_mesh(&mesh, &path))
        .map_err(|e| about_file(e, &path))
}

/// Distances both ways between mesh `a` (the reference) and mesh `b` — a decoded level, which
/// may have loose edges and even no face yet — over samples of both (docs/CONTRACT.md §5).
#[pyfunction]
#[pyo3(signature = (a_vertices, a_faces, b_vertices, b_faces, b_edges, samples=DEFAULT_SAMPLES_PER_TRIANGLE, seed=DEFAULT_SEED))]
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
) -> PyResult<Bound<'py, PyDict>> {
    if samples == 0 {
        return Err(refuse("samples must be at least 1 a triangle"));
    }
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
        let reference = Reference::new(&a, samples, seed);
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
    m.add_function(wrap_pyfunction!(canonical, m)?)?;
    m.add_function(wrap_pyfunction!(level_ends, m)?)?;
    m.add_function(wrap_pyfunction!(info, m)?)?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(save, m)?)?;
    m.add_function(wrap_pyfunction!(distance, m)?)?;
    m.add_function(wrap_pyfunction!(codec_list, m)?)?;
    Ok(())
}
