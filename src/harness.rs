//! Runs a codec on a mesh the way every experiment does: encode, decode every level, check
//! losslessness (DESIGN.md A2), measure each level against the original (A4), and write the
//! result files of A5 with their plots.

use crate::codecs::{self, Codec, EncodeOptions, LevelDecoder};
use crate::error::{Error, Result};
use crate::mesh::io::{mesh_name, read_mesh};
use crate::mesh::quantize::GridShape;
use crate::metrics::{Reference, DEFAULT_SAMPLES_PER_TRIANGLE, DEFAULT_SEED};
use crate::plot;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// One level of a run (DESIGN.md A5).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LevelRow {
    /// Level number, from 1 (level 0 would be the empty stream).
    pub level: usize,
    /// Bits from the stream's first byte to the end of this level.
    pub bits: u64,
    /// Connectivity bits up to this level.
    pub connectivity_bits: u64,
    /// Geometry bits up to this level.
    pub geometry_bits: u64,
    /// Vertices of the decoded level.
    pub vertices: usize,
    /// Triangles of the decoded level.
    pub triangles: usize,
    /// `bits` over the full mesh's vertex count.
    pub bits_per_vertex: f64,
    /// `bits` over the full mesh's triangle count.
    pub bits_per_triangle: f64,
    /// Symmetric Hausdorff distance over the original's bounding-box diagonal.
    pub hausdorff: Option<f64>,
    /// RMS distance over both directions' samples, over the diagonal.
    pub rms: Option<f64>,
    /// Largest original-vertex-to-level distance, over the diagonal (EMC's measure).
    pub hausdorff_paper: Option<f64>,
}

/// One codec on one mesh (DESIGN.md A5), as stored in results/<codec>/<mesh>.json.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunResult {
    /// Codec name.
    pub codec: String,
    /// Mesh name (file stem).
    pub mesh: String,
    /// Path the mesh was read from.
    pub source: String,
    /// Vertices of the canonical mesh at `quant_bits`.
    pub vertices: usize,
    /// Triangles of the canonical mesh at `quant_bits`.
    pub triangles: usize,
    /// Quantization bits per axis.
    pub quant_bits: u8,
    /// Stream size.
    pub bytes: usize,
    /// Wall-clock time of the encoder (canonical mesh in, bytes out).
    pub encode_seconds: f64,
    /// Wall-clock time to decode every level (best of a few runs for short decodes).
    pub decode_seconds: f64,
    /// Whether the full decode equals the canonical mesh exactly.
    pub lossless: bool,
    /// What differed, when not lossless.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lossless_error: Option<String>,
    /// Grid shape used.
    #[serde(default)]
    pub grid: GridShape,
    /// Random samples per original triangle used by the metrics.
    #[serde(default)]
    pub samples_per_triangle: usize,
    /// Codec-specific counts: bits per syntax element, operation counts.
    #[serde(default, skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub codec_stats: std::collections::BTreeMap<String, f64>,
    /// Per-level rows.
    pub levels: Vec<LevelRow>,
}

impl RunResult {
    /// Whole-stream bits per vertex of the canonical mesh.
    pub fn bits_per_vertex(&self) -> f64 {
        self.bytes as f64 * 8.0 / self.vertices as f64
    }

    /// Whole-stream bits per triangle of the canonical mesh.
    pub fn bits_per_triangle(&self) -> f64 {
        self.bytes as f64 * 8.0 / self.triangles as f64
    }
}

/// What to run with; `None` fields take the codec's defaults.
#[derive(Clone, Debug, PartialEq)]
pub struct RunOptions {
    /// Quantization bits.
    pub quant_bits: Option<u8>,
    /// Grid shape.
    pub grid: Option<GridShape>,
    /// Random samples per original triangle.
    pub samples_per_triangle: usize,
    /// Show a progress bar.
    pub progress: bool,
}

impl Default for RunOptions {
    fn default() -> Self {
        RunOptions {
            quant_bits: None,
            grid: None,
            samples_per_triangle: DEFAULT_SAMPLES_PER_TRIANGLE,
            progress: false,
        }
    }
}

/// The encode options a run uses.
pub fn encode_options(codec: &dyn Codec, options: &RunOptions) -> EncodeOptions {
    let mut encode = codec.default_options();
    if let Some(bits) = options.quant_bits {
        encode.quant_bits = bits;
    }
    if let Some(grid) = options.grid {
        encode.grid = grid;
    }
    encode
}

/// A run's result and the stream it measured.
pub struct RunOutput {
    /// What was measured.
    pub result: RunResult,
    /// The encoded stream.
    pub stream: Vec<u8>,
}

/// Runs `codec` on the mesh file at `path`.
pub fn run(codec: &dyn Codec, path: &Path, options: &RunOptions) -> Result<RunOutput> {
    let original = read_mesh(path)?;
    let encode = encode_options(codec, options);
    let canonical = codecs::canonical_for(&original, &encode)?;

    let started = Instant::now();
    let encoded = codec.encode(&canonical, &encode)?;
    let encode_seconds = started.elapsed().as_secs_f64();

    // Time the bare decode (no metrics); repeat short ones so the figure is not timer noise.
    let mut decode_seconds = f64::INFINITY;
    let mut spent = 0.0;
    let mut final_mesh = None;
    for _ in 0..5 {
        let started = Instant::now();
        let (mesh, _) = codecs::decode(&encoded.bytes, codecs::Stop::All)?;
        let took = started.elapsed().as_secs_f64();
        decode_seconds = decode_seconds.min(took);
        spent += took;
        final_mesh = Some(mesh);
        if spent > 1.0 {
            break;
        }
    }
    let final_mesh = final_mesh.expect("decoded at least once");
    let lossless_error = canonical.check_lossless(&final_mesh.mesh).err();

    let reference = Reference::new(&original, options.samples_per_triangle, DEFAULT_SEED);
    let bar = progress_bar(options.progress, encoded.levels.len(), codec.name(), path);
    let mut decoder = codecs::open(&encoded.bytes)?;
    let (v, t) = (
        canonical.vertex_count() as f64,
        canonical.face_count() as f64,
    );
    let mut levels = Vec::with_capacity(encoded.levels.len());
    for record in &encoded.levels {
        if !decoder.advance()? {
            return Err(Error::Truncated(format!(
                "{} decoded only {} of its {} levels",
                codec.name(),
                decoder.levels_decoded(),
                encoded.levels.len()
            )));
        }
        levels.push(measure_level(decoder.as_ref(), record, &reference, v, t)?);
        bar.inc(1);
    }
    bar.finish_and_clear();
    drop(decoder);

    let mut codec_stats = encoded.stats;
    codec_stats.extend(codec.measure(&encoded.bytes)?);
    let result = RunResult {
        codec: codec.name().to_string(),
        mesh: mesh_name(path),
        source: path.display().to_string(),
        vertices: canonical.vertex_count(),
        triangles: canonical.face_count(),
        quant_bits: encode.quant_bits,
        bytes: encoded.bytes.len(),
        encode_seconds,
        decode_seconds,
        lossless: lossless_error.is_none(),
        lossless_error,
        grid: encode.grid,
        samples_per_triangle: options.samples_per_triangle,
        codec_stats,
        levels,
    };
    Ok(RunOutput {
        result,
        stream: encoded.bytes,
    })
}

fn measure_level(
    decoder: &dyn LevelDecoder,
    record: &codecs::LevelRecord,
    reference: &Reference,
    full_vertices: f64,
    full_triangles: f64,
) -> Result<LevelRow> {
    let level = decoder.mesh()?;
    let distance = reference.compare(&level);
    let bits = record.end_byte as u64 * 8;
    Ok(LevelRow {
        level: decoder.levels_decoded(),
        bits,
        connectivity_bits: record.connectivity_bits,
        geometry_bits: record.geometry_bits,
        vertices: level.mesh.vertex_count(),
        triangles: level.mesh.face_count(),
        bits_per_vertex: bits as f64 / full_vertices,
        bits_per_triangle: bits as f64 / full_triangles,
        hausdorff: distance.map(|d| d.hausdorff),
        rms: distance.map(|d| d.rms),
        hausdorff_paper: distance.map(|d| d.hausdorff_paper),
    })
}

fn progress_bar(show: bool, levels: usize, codec: &str, path: &Path) -> indicatif::ProgressBar {
    if !show {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new(levels as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{msg} [{elapsed_precise}] {wide_bar} level {pos}/{len} (eta {eta})",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    bar.set_message(format!("{codec} {}: measuring levels", mesh_name(path)));
    bar
}

/// File stem of a run's results: the mesh name, with `-q<bits>` when the quantization is not the
/// codec's default and `-per-axis` / `-cubic` when the grid is not.
pub fn result_stem(codec: &dyn Codec, result: &RunResult) -> String {
    let defaults = codec.default_options();
    let mut stem = result.mesh.clone();
    if result.quant_bits != defaults.quant_bits {
        stem.push_str(&format!("-q{}", result.quant_bits));
    }
    if result.grid != defaults.grid {
        stem.push_str(match result.grid {
            GridShape::Cubic => "-cubic",
            GridShape::PerAxis => "-per-axis",
        });
    }
    stem
}

/// Writes `<out>/<codec>/<stem>.json`, `.csv` and the two plots (PNG and SVG); returns the
/// paths written.
pub fn write_result(result: &RunResult, stem: &str, out: &Path) -> Result<Vec<PathBuf>> {
    let dir = out.join(&result.codec);
    std::fs::create_dir_all(&dir)?;
    let json_path = dir.join(format!("{stem}.json"));
    let json = serde_json::to_string_pretty(result).map_err(std::io::Error::other)?;
    crate::mesh::io::write_atomically(&json_path, format!("{json}\n").as_bytes())?;
    let csv_path = dir.join(format!("{stem}.csv"));
    crate::mesh::io::write_atomically(&csv_path, levels_csv(result).as_bytes())?;
    let mut written = vec![json_path, csv_path];
    let title = format!(
        "{} on {} ({} bits)",
        result.codec, result.mesh, result.quant_bits
    );
    let runs = std::slice::from_ref(result);
    written.extend(
        plot::rate_resolution(runs, &title).draw(&dir.join(format!("{stem}-rate-resolution")))?,
    );
    written.extend(
        plot::rate_distortion(runs, &title).draw(&dir.join(format!("{stem}-rate-distortion")))?,
    );
    Ok(written)
}

/// The level rows as CSV.
pub fn levels_csv(result: &RunResult) -> String {
    let opt = |v: Option<f64>| v.map(|x| format!("{x:e}")).unwrap_or_default();
    let mut csv = String::from(
        "level,bits,connectivity_bits,geometry_bits,vertices,triangles,bits_per_vertex,\
         bits_per_triangle,hausdorff,rms,hausdorff_paper\n",
    );
    for r in &result.levels {
        csv.push_str(&format!(
            "{},{},{},{},{},{},{:.4},{:.4},{},{},{}\n",
            r.level,
            r.bits,
            r.connectivity_bits,
            r.geometry_bits,
            r.vertices,
            r.triangles,
            r.bits_per_vertex,
            r.bits_per_triangle,
            opt(r.hausdorff),
            opt(r.rms),
            opt(r.hausdorff_paper)
        ));
    }
    csv
}

/// The level table printed by `experiment`.
pub fn level_table(result: &RunResult) -> String {
    let opt = |v: Option<f64>| v.map(|x| format!("{x:.3e}")).unwrap_or_else(|| "-".into());
    let mut out = format!(
        "{:>5} {:>9} {:>9} {:>11} {:>8} {:>8} {:>9} {:>9} {:>10} {:>10} {:>10}\n",
        "level",
        "vertices",
        "triangles",
        "bits",
        "bpv",
        "bpt",
        "conn bpv",
        "geom bpv",
        "hausdorff",
        "rms",
        "paper"
    );
    let v = result.vertices as f64;
    for r in &result.levels {
        out.push_str(&format!(
            "{:>5} {:>9} {:>9} {:>11} {:>8.3} {:>8.3} {:>9.3} {:>9.3} {:>10} {:>10} {:>10}\n",
            r.level,
            r.vertices,
            r.triangles,
            r.bits,
            r.bits_per_vertex,
            r.bits_per_triangle,
            r.connectivity_bits as f64 / v,
            r.geometry_bits as f64 / v,
            opt(r.hausdorff),
            opt(r.rms),
            opt(r.hausdorff_paper)
        ));
    }
    out
}

/// Reads a result file.
pub fn read_result(path: &Path) -> Result<RunResult> {
    let text = std::fs::read_to_string(path)?;
    serde_json::from_str(&text).map_err(|e| Error::Unsupported(format!("not a result file: {e}")))
}
