//! Runs a codec on a mesh the way every experiment does: encode, decode every level, check
//! losslessness (docs/CONTRACT.md §3), measure each level against the original (§5), and write
//! the result files of §6 with their plots.

use crate::plot;
use crate::progress::Progress;
use crate::results::{self, levels_csv, AppearanceRun, LevelRow, RunResult};
use meshcodec::codecs::{self, Codec, EncodeOptions, EncodeRequest, LevelDecoder};
use meshcodec::error::{Error, Result};
use meshcodec::mesh::attribute_quantization::AttributeBits;
use meshcodec::mesh::attributes::AttributedMesh;
use meshcodec::mesh::canonical::CanonicalMesh;
use meshcodec::mesh::canonical_attributes::CanonicalAttributes;
use meshcodec::mesh::io::{mesh_name, read_attributed, read_mesh_and_appearance, Appearance};
use meshcodec::mesh::quantize::GridShape;
use meshcodec::metrics::appearance::AppearanceReference;
use meshcodec::metrics::{Reference, SampleBudget, DEFAULT_SEED};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// What to run with; `None` fields take the codec's defaults.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RunOptions {
    /// Quantization bits.
    pub quant_bits: Option<u8>,
    /// Grid shape.
    pub grid: Option<GridShape>,
    /// Random samples the metrics take on each surface.
    pub samples: SampleBudget,
    /// Show a progress bar.
    pub progress: bool,
    /// Code the file's appearance at these bits when the codec carries appearance
    /// (`None`: positions and triangles only, whatever the file holds).
    pub appearance: Option<AttributeBits>,
    /// With appearance, code it inside the levels by this rule for collapsed wedges, for codecs
    /// that can (`pm`; `None`: the codec's own way).
    pub appearance_in_levels: Option<codecs::AttributeFit>,
    /// With appearance, code it in an appearance unit after the last level whatever the
    /// codec's own way (`emc`, `emc-ahead` code it with their levels): results as
    /// STEM-appearance-unit.
    pub appearance_unit: bool,
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
    /// What the file holds beyond the geometry measured (not coded).
    pub appearance: meshcodec::mesh::io::Appearance,
}

/// The mesh a run measures, and the appearance it codes when it codes one.
struct Input {
    /// The file's mesh.
    original: AttributedMesh,
    /// What the file holds that the run does not code.
    uncoded: Appearance,
    canonical: CanonicalMesh,
    /// The canonical appearance the stream carries.
    appearance: Option<CanonicalAttributes>,
}

fn read_input(path: &Path, request: &EncodeRequest) -> Result<Input> {
    if request.appearance.is_some() {
        let original = read_attributed(path)?;
        let (canonical, appearance) = request.canonical(&original)?;
        return Ok(Input {
            original,
            uncoded: Appearance::default(),
            canonical,
            appearance,
        });
    }
    let (mesh, uncoded) = read_mesh_and_appearance(path)?;
    let original = AttributedMesh {
        mesh,
        attributes: Default::default(),
    };
    let (canonical, _) = request.canonical(&original)?;
    Ok(Input {
        original,
        uncoded,
        canonical,
        appearance: None,
    })
}

/// Runs `codec` on the mesh file at `path`.
pub fn run(codec: &dyn Codec, path: &Path, options: &RunOptions) -> Result<RunOutput> {
    let encode = encode_options(codec, options);
    // Appearance is read and coded when asked for and the codec carries it.
    let carries = codec
        .capabilities()
        .contains(&codecs::Capability::Attributes);
    let request = EncodeRequest {
        codec,
        options: encode,
        appearance: options.appearance.filter(|_| carries),
        in_levels: options.appearance_in_levels,
        appearance_unit: options.appearance_unit,
    };
    let progress = Progress::new(options.progress);
    let label = format!("{} {}", codec.name(), mesh_name(path));
    progress.step(format!("{label}: reading"));
    let Input {
        original,
        uncoded,
        canonical,
        appearance,
    } = read_input(path, &request)?;

    progress.step(format!("{label}: encoding"));
    let started = Instant::now();
    let encoded = request.encode_canonical(&canonical, appearance.as_ref())?;
    let encode_seconds = started.elapsed().as_secs_f64();

    // Time the bare decode (no metrics); repeat short ones so the figure is not timer noise.
    progress.step(format!("{label}: decoding"));
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
    let lossless_error = match &appearance {
        None => canonical.check_lossless(&final_mesh.mesh).err(),
        Some(a) => match &final_mesh.attributes {
            Some(decoded) => a
                .check_lossless(&canonical, &final_mesh.mesh, decoded)
                .err(),
            None => Some("the full decode has no appearance".into()),
        },
    };
    progress.step(format!(
        "{label}: sampling the original ({} points a direction)",
        options.samples.count(original.mesh.faces.len())
    ));
    let original_appearance = appearance.as_ref().and_then(|_| {
        AppearanceReference::new(
            &original,
            options.samples.count(original.mesh.faces.len()),
            DEFAULT_SEED ^ 2,
        )
    });
    let original = original.mesh;

    let reference = Reference::new(&original, options.samples, DEFAULT_SEED);
    progress.count(
        format!("{label}: measuring levels"),
        encoded.levels.len(),
        "level",
    );
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
        levels.push(measure_level(
            decoder.as_ref(),
            record,
            &reference,
            original_appearance.as_ref(),
            v,
            t,
        )?);
        progress.advance();
    }
    progress.finish();
    drop(decoder);

    let mut codec_stats = encoded.stats;
    codec_stats.extend(codec.measure(&encoded.bytes)?);
    let result = RunResult {
        codec: codec.name().to_string(),
        mesh: mesh_name(path),
        source: meshcodec::mesh::io::portable_source(path),
        vertices: canonical.vertex_count(),
        triangles: canonical.face_count(),
        quant_bits: encode.quant_bits,
        bytes: encoded.bytes.len(),
        encode_seconds,
        decode_seconds,
        lossless: lossless_error.is_none(),
        lossless_error,
        grid: encode.grid,
        samples_per_triangle: options.samples.per_triangle,
        max_samples: Some(options.samples.max),
        appearance: appearance.as_ref().map(|a| AppearanceRun {
            uv_bits: a.bits.uv,
            normal_bits: a.bits.normal,
            wedges: a.wedge_vertex.len(),
            fields: [
                ("normals", a.normals.is_some()),
                ("uvs", a.uvs.is_some()),
                ("colours", a.colours.is_some()),
                ("materials", a.materials.is_some()),
            ]
            .iter()
            .filter(|(_, present)| *present)
            .map(|(name, _)| name.to_string())
            .collect(),
            // An appearance unit's bytes, or what a codec that codes appearance in its levels
            // booked for it.
            bits: codec_stats
                .get_named("appearance_bytes")
                .map(|b| b * 8.0)
                .or_else(|| codec_stats.get_named("appearance_bits"))
                .map_or(0, |b| b.round() as u64),
            in_levels: options
                .appearance_in_levels
                .map(|f| f.name().to_string())
                .or_else(|| options.appearance_unit.then(|| "unit".to_string())),
            derived_normals: a.bits.derive_normals && a.normals.is_some(),
        }),
        codec_stats,
        levels,
    };
    Ok(RunOutput {
        result,
        stream: encoded.bytes,
        appearance: uncoded,
    })
}

fn measure_level(
    decoder: &dyn LevelDecoder,
    record: &codecs::LevelRecord,
    reference: &Reference,
    appearance: Option<&AppearanceReference>,
    full_vertices: f64,
    full_triangles: f64,
) -> Result<LevelRow> {
    let level = decoder.mesh()?;
    let distance = reference.compare(&level);
    let appearance = appearance.map_or_else(Default::default, |a| {
        a.compare(&level.mesh, level.attributes.as_ref())
    });
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
        samples: distance.map(|d| d.uncertainty.samples),
        rms_uncertainty: distance.map(|d| d.uncertainty.rms),
        hausdorff_uncertainty: distance.map(|d| d.uncertainty.hausdorff),
        appearance,
    })
}

/// Writes `<out>/<codec>/<stem>.json`, `.csv` and the two plots (PNG and SVG); returns the
/// paths written.
pub fn write_result(result: &RunResult, stem: &str, out: &Path) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(out.join(&result.codec))?;
    let file = |suffix: &str| results::path(out, &result.codec, stem, suffix);
    let json_path = file(".json");
    let json = serde_json::to_string_pretty(result).map_err(std::io::Error::other)?;
    meshcodec::mesh::io::write_atomically(&json_path, format!("{json}\n").as_bytes())?;
    let csv_path = file(".csv");
    meshcodec::mesh::io::write_atomically(&csv_path, levels_csv(result).as_bytes())?;
    let mut written = vec![json_path, csv_path];
    let title = format!(
        "{} on {} ({} bits)",
        result.codec, result.mesh, result.quant_bits
    );
    let runs = std::slice::from_ref(result);
    written.extend(plot::rate_resolution(runs, &title).draw(&file("-rate-resolution"))?);
    written.extend(plot::rate_distortion(runs, &title).draw(&file("-rate-distortion"))?);
    Ok(written)
}
