//! What the CAME tables need beyond the harness's runs (`experiment run experiments/came.toml`):
//! both CAME codecs on a mesh of over a million triangles (a shared mesh subdivided, as the
//! decimation table does), the plain and gzip'd VRML size of every table mesh, and `came-paper`
//! streams of the bunny at 3 and 5 bits per component for the Fig. 4 analogue. Writes
//! results/came/extras.json and the streams beside it.

use crate::data::resolve;
use meshcodec::codecs::came::paper::CamePaper;
use meshcodec::codecs::{self, Codec, EncodeOptions, Stop};
use meshcodec::error::{Error, Result};
use meshcodec::mesh::io::{read_mesh, vrml::write_vrml, write_atomically};
use meshcodec::mesh::quantize::GridShape;
use meshcodec::mesh::{generate, TriMesh};
use meshcodec::metrics::{Reference, SampleBudget, DEFAULT_SEED};
use serde::{Deserialize, Serialize};
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The meshes of Tables 2–3: a shared mesh and how often it is subdivided (×4 faces each).
pub const TABLE_MESHES: [(&str, u32); 4] = [
    ("bunny", 0),
    ("dragon-50k", 0),
    ("terrain-mountain", 0),
    ("bunny-closed-35k", 2),
];

/// Quantization of every table row.
pub const QUANT_BITS: u8 = 12;

/// Bits per component of the Fig. 4 renders.
pub const FIG4_BITS: [u8; 2] = [3, 5];

/// The command that makes every CAME result and table.
pub const COMMAND: &str = "bash experiments/came.sh";

/// A mesh's plain and gzip'd VRML sizes.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct VrmlSize {
    /// Mesh name.
    pub mesh: String,
    /// Times subdivided.
    pub subdivisions: u32,
    /// Triangles of the mesh as read (and subdivided).
    pub triangles: usize,
    /// Bytes of the plain VRML file.
    pub vrml_bytes: usize,
    /// Bytes of it gzip'd (flate2, default level).
    pub gzip_bytes: usize,
}

/// One codec on the large mesh.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct LargeRun {
    /// Codec name.
    pub codec: String,
    /// Stream bytes.
    pub bytes: usize,
    /// Encode time, hierarchy included (one thread but for the hierarchy's parallel setup).
    pub encode_seconds: f64,
    /// Best of two full decodes.
    pub decode_seconds: f64,
    /// Whether the full decode is the canonical mesh.
    pub lossless: bool,
    /// The codec's statistics.
    pub stats: codecs::Stats,
}

/// A came-paper stream of the bunny for Fig. 4.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Fig4Stream {
    /// Bits per component.
    pub component_bits: u8,
    /// The stream, relative to the results folder.
    pub stream: String,
    /// Stream bytes.
    pub bytes: usize,
    /// Hausdorff error of the full level over the bounding-box diagonal.
    pub hausdorff: f64,
}

/// results/came/extras.json.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Extras {
    /// Threads of the run.
    pub threads: usize,
    /// VRML sizes of every table mesh.
    pub vrml: Vec<VrmlSize>,
    /// The large mesh: name, subdivisions, canonical vertices and triangles.
    pub large_mesh: String,
    /// Times it is subdivided.
    pub large_subdivisions: u32,
    /// Its canonical vertices.
    pub large_vertices: usize,
    /// Its canonical triangles.
    pub large_triangles: usize,
    /// Both codecs on it.
    pub large: Vec<LargeRun>,
    /// The Fig. 4 streams.
    pub fig4: Vec<Fig4Stream>,
}

/// The path of extras.json under `results`.
pub fn path(results: &Path) -> PathBuf {
    results.join("came").join("extras.json")
}

/// Shared mesh `name` read and subdivided `subdivisions` times at edge midpoints.
pub fn table_mesh(name: &str, subdivisions: u32) -> Result<(PathBuf, TriMesh)> {
    let path = resolve(name).map_err(|e| Error::Unsupported(format!("{name}: {e:#}")))?;
    let mut mesh = read_mesh(&path)?;
    for _ in 0..subdivisions {
        mesh = generate::subdivide(&mesh);
    }
    Ok((path, mesh))
}

/// Plain and gzip'd VRML sizes of `mesh`.
pub fn vrml_sizes(mesh: &TriMesh) -> Result<(usize, usize)> {
    let mut plain = Vec::new();
    write_vrml(mesh, &mut plain)?;
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    gz.write_all(&plain)?;
    Ok((plain.len(), gz.finish()?.len()))
}

/// Runs everything and writes results/came/extras.json; `log` gets one line per step.
pub fn run(results: &Path, log: &mut dyn FnMut(String)) -> Result<PathBuf> {
    let options = EncodeOptions {
        quant_bits: QUANT_BITS,
        grid: GridShape::Cubic,
    };
    let mut vrml = Vec::new();
    let mut large = Vec::new();
    let (mut large_vertices, mut large_triangles) = (0, 0);
    let (large_name, large_subdivisions) = TABLE_MESHES[3];
    for (name, subdivisions) in TABLE_MESHES {
        let (_, mesh) = table_mesh(name, subdivisions)?;
        let (vrml_bytes, gzip_bytes) = vrml_sizes(&mesh)?;
        log(format!(
            "{name} x{}: {} triangles, VRML {vrml_bytes} bytes, gzip'd {gzip_bytes}",
            4u32.pow(subdivisions),
            mesh.face_count()
        ));
        vrml.push(VrmlSize {
            mesh: name.to_string(),
            subdivisions,
            triangles: mesh.face_count(),
            vrml_bytes,
            gzip_bytes,
        });
        if name != large_name {
            continue;
        }
        let canonical = codecs::canonical_for(&mesh, &options)?;
        (large_vertices, large_triangles) = (canonical.vertex_count(), canonical.face_count());
        for codec_name in ["came-paper", "came"] {
            let codec = codecs::by_name(codec_name)?;
            let started = Instant::now();
            let encoded = codec.encode(&canonical)?;
            let encode_seconds = started.elapsed().as_secs_f64();
            let mut decode_seconds = f64::INFINITY;
            let mut lossless = false;
            for _ in 0..2 {
                let started = Instant::now();
                let (decoded, _) = codecs::decode(&encoded.bytes, Stop::All)?;
                decode_seconds = decode_seconds.min(started.elapsed().as_secs_f64());
                lossless = canonical.check_lossless(&decoded.mesh).is_ok();
            }
            log(format!(
                "{codec_name} on {name} x{}: {} bytes, encode {encode_seconds:.2} s, decode {decode_seconds:.2} s, lossless {lossless}",
                4u32.pow(subdivisions),
                encoded.bytes.len()
            ));
            large.push(LargeRun {
                codec: codec_name.to_string(),
                bytes: encoded.bytes.len(),
                encode_seconds,
                decode_seconds,
                lossless,
                stats: encoded.stats,
            });
        }
    }
    let (_, bunny) = table_mesh("bunny", 0)?;
    let canonical = codecs::canonical_for(&bunny, &options)?;
    let reference = Reference::new(&bunny, SampleBudget::default(), DEFAULT_SEED);
    let mut fig4 = Vec::new();
    for component_bits in FIG4_BITS {
        let codec = CamePaper { component_bits };
        let encoded = codec.encode(&canonical)?;
        let (decoded, _) = codecs::decode(&encoded.bytes, Stop::All)?;
        let hausdorff = reference
            .compare(&decoded)
            .map(|d| d.hausdorff)
            .ok_or_else(|| Error::mesh("the decoded bunny has no surface"))?;
        let stream = format!("came-paper/bunny-b{component_bits}.mc");
        write_atomically(&results.join(&stream), &encoded.bytes)?;
        log(format!(
            "came-paper at {component_bits} bits per component on bunny: {} bytes, Hausdorff {hausdorff:.3e}",
            encoded.bytes.len()
        ));
        fig4.push(Fig4Stream {
            component_bits,
            stream,
            bytes: encoded.bytes.len(),
            hausdorff,
        });
    }
    let extras = Extras {
        threads: rayon::current_num_threads(),
        vrml,
        large_mesh: large_name.to_string(),
        large_subdivisions,
        large_vertices,
        large_triangles,
        large,
        fig4,
    };
    let out = path(results);
    let json = serde_json::to_string_pretty(&extras).map_err(|e| Error::Io(e.into()))?;
    write_atomically(&out, format!("{json}\n").as_bytes())?;
    Ok(out)
}

/// Reads results/came/extras.json.
pub fn read(results: &Path) -> Result<Extras> {
    let p = path(results);
    let text = std::fs::read_to_string(&p).map_err(|e| {
        Error::Unsupported(format!("{}: {e} (make it with: {COMMAND})", p.display()))
    })?;
    serde_json::from_str(&text).map_err(|e| Error::Unsupported(format!("{}: {e}", p.display())))
}
