//! What a run measured: the result files of results/ (docs/CONTRACT.md §6), their names, and
//! their CSV and text forms. Harness, plots and tables all read these types; none of them
//! imports another for them.

use meshcodec::codecs::{EncodeOptions, Stats};
use meshcodec::error::{Error, Result};
use meshcodec::mesh::quantize::GridShape;
use meshcodec::metrics::appearance::AppearanceError;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// One level of a run (docs/CONTRACT.md §6).
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
    /// Samples the distances were measured at: original → level, level → original, vertices
    /// included (§5).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub samples: Option<[usize; 2]>,
    /// Relative standard error of `rms` from the samples (§5).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rms_uncertainty: Option<f64>,
    /// What `hausdorff` gained from half the random samples to all of them, relative to it:
    /// about what doubling them would still add (§5).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hausdorff_uncertainty: Option<f64>,
    /// Appearance error (§5.1) of a run that codes appearance, at the levels that carry it.
    #[serde(flatten, default)]
    pub appearance: AppearanceError,
}

/// One codec on one mesh (docs/CONTRACT.md §6), as stored in `results/<codec>/<mesh>.json`.
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
    /// Most random samples a direction the metrics took (absent in results measured before
    /// there was a cap: `samples_per_triangle` for every triangle).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_samples: Option<usize>,
    /// Codec-specific counts: bits per syntax element, operation counts.
    #[serde(default, skip_serializing_if = "Stats::is_empty")]
    pub codec_stats: Stats,
    /// What appearance the stream carries, when the run coded it (§2.1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub appearance: Option<AppearanceRun>,
    /// Per-level rows.
    pub levels: Vec<LevelRow>,
}

/// The appearance a run coded: its quantization and what the canonical mesh holds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AppearanceRun {
    /// Qt, bits per uv axis.
    pub uv_bits: u8,
    /// Qn, bits per octahedral normal coordinate.
    pub normal_bits: u8,
    /// Wedges of the canonical mesh (corners with equal quantized attributes at one vertex).
    pub wedges: usize,
    /// The attributes carried, of normals, uvs, colours, materials.
    pub fields: Vec<String>,
    /// Bits of the appearance: its unit's, or what the levels spent on it.
    pub bits: u64,
    /// Where the appearance went when not the codec's own way: the rule for collapsed wedges
    /// (`fit`, `keep`) when `pm`'s splits carry it (`--attributes fit|keep`), `unit` when an
    /// appearance unit follows the last level of a codec whose own way is another
    /// (`--attributes unit`); absent for the codec's own way (`pm`, `came`, `raw`: a unit after
    /// the last level; `emc`, `emc-ahead`: a part after each level).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub in_levels: Option<String>,
    /// Whether normals were derived from the positions over the input's normal wedges
    /// (`--derive-normals`) rather than carried as the input's.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub derived_normals: bool,
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

/// File stem of a run's results: the mesh name, with `-q<bits>` when the quantization is not the
/// codec's default (`defaults`) and `-per-axis` / `-cubic` when the grid is not.
pub fn stem(defaults: &EncodeOptions, mesh: &str, quantization: &EncodeOptions) -> String {
    let mut stem = mesh.to_string();
    if quantization.quant_bits != defaults.quant_bits {
        stem.push_str(&format!("-q{}", quantization.quant_bits));
    }
    if quantization.grid != defaults.grid {
        stem.push_str(match quantization.grid {
            GridShape::Cubic => "-cubic",
            GridShape::PerAxis => "-per-axis",
        });
    }
    stem
}

/// [`stem`] of a run's result, with `-appearance` when the run coded appearance.
pub fn result_stem(defaults: &EncodeOptions, result: &RunResult) -> String {
    let quantization = EncodeOptions {
        quant_bits: result.quant_bits,
        grid: result.grid,
    };
    let mut stem = stem(defaults, &result.mesh, &quantization);
    if let Some(appearance) = &result.appearance {
        stem.push_str(APPEARANCE_SUFFIX);
        if let Some(rule) = &appearance.in_levels {
            stem.push('-');
            stem.push_str(rule);
        }
        if appearance.derived_normals {
            stem.push_str(DERIVED_NORMALS_SUFFIX);
        }
    }
    stem
}

/// What [`result_stem`] appends for a run that coded appearance.
pub const APPEARANCE_SUFFIX: &str = "-appearance";

/// What [`result_stem`] appends for a run whose normals were derived from the positions.
pub const DERIVED_NORMALS_SUFFIX: &str = "-derived-normals";

/// `<results>/<codec>/<stem><suffix>`: where every file of a run lives (`.json`, `.csv`, `.mc`,
/// `-rate-resolution.png`, …).
pub fn path(results: &Path, codec: &str, stem: &str, suffix: &str) -> PathBuf {
    results.join(codec).join(format!("{stem}{suffix}"))
}

/// Where an experiment set leaves the reason `codec` refused `mesh`.
pub fn refusal_path(results: &Path, codec: &str, mesh: &str) -> PathBuf {
    path(results, codec, mesh, ".refused.txt")
}

/// The level rows as CSV.
pub fn levels_csv(result: &RunResult) -> String {
    let opt = |v: Option<f64>| v.map(|x| format!("{x:e}")).unwrap_or_default();
    let mut csv = String::from(
        "level,bits,connectivity_bits,geometry_bits,vertices,triangles,bits_per_vertex,\
         bits_per_triangle,hausdorff,rms,hausdorff_paper\n",
    );
    let appearance = result.appearance.is_some();
    if appearance {
        csv.pop();
        csv.push_str(",uv_texels,uv_rms_texels,normal_degrees,colour_steps,wrong_material\n");
    }
    for r in &result.levels {
        csv.push_str(&format!(
            "{},{},{},{},{},{},{:.4},{:.4},{},{},{}",
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
        if appearance {
            let a = &r.appearance;
            csv.push_str(&format!(
                ",{},{},{},{},{}",
                opt(a.uv_texels),
                opt(a.uv_rms_texels),
                opt(a.normal_degrees),
                opt(a.colour_steps),
                opt(a.wrong_material)
            ));
        }
        csv.push('\n');
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
    let appearance = result.appearance.is_some();
    if appearance {
        out.pop();
        out.push_str(&format!(
            " {:>9} {:>9} {:>9} {:>9}\n",
            "uv texel", "normal °", "colour", "wrong mat"
        ));
    }
    let v = result.vertices as f64;
    for r in &result.levels {
        out.push_str(&format!(
            "{:>5} {:>9} {:>9} {:>11} {:>8.3} {:>8.3} {:>9.3} {:>9.3} {:>10} {:>10} {:>10}",
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
        if appearance {
            let fixed = |v: Option<f64>| v.map(|x| format!("{x:.3}")).unwrap_or_else(|| "-".into());
            let a = &r.appearance;
            out.push_str(&format!(
                " {:>9} {:>9} {:>9} {:>9}",
                fixed(a.uv_texels),
                fixed(a.normal_degrees),
                fixed(a.colour_steps),
                fixed(a.wrong_material)
            ));
        }
        out.push('\n');
    }
    out
}

/// Reads a result file.
pub fn read_result(path: &Path) -> Result<RunResult> {
    let text = std::fs::read_to_string(path)?;
    serde_json::from_str(&text).map_err(|e| Error::Unsupported(format!("not a result file: {e}")))
}
