//! The papers' tables and figures, regenerated from the result files in results/ beside the
//! papers' own figures. Nothing here encodes: tables read `RunResult`s, and the rendered figures
//! decode the streams that the experiments kept: EMC's in `emc.rs`, Hoppe's in `hoppe.rs`, `emc`
//! against the other coders in `anchors.rs`, Grabner's CAME in `came.rs` and `came_vd.rs`,
//! appearance in `attributes.rs`; here, what they share.

use crate::plot;
use crate::render::View;
use crate::results::{self, read_result, RunResult};
use meshcodec::codecs::stats::Stat;
use meshcodec::codecs::EncodeOptions;
use meshcodec::error::{Error, Result};
use meshcodec::mesh::quantize::GridShape;
use plotters::prelude::*;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

mod anchors;
mod appearance_levels;
mod attributes;
mod emc_renders;

use crate::came;
pub use crate::emc::tables::{emc_fig4, emc_fig5, emc_table1, EMC_TABLE1_COMMAND};
pub use crate::pm::tables::{hoppe_tables, HOPPE_COMMAND};
pub use anchors::{
    emc_rate_distortion, emc_rms_rate_distortion, emc_vs_anchors, log_log_interpolate,
};
pub(crate) use anchors::{optional, ANCHORS_COMMAND};
pub use attributes::{ATTRIBUTES_COMMAND, ATTRIBUTE_MESHES};
pub use emc_renders::emc_levels_beside_pm;

/// A statistic a table reads; one the result lacks is an error naming the file's codec and mesh.
pub(crate) fn stat(result: &RunResult, stat: Stat) -> Result<f64> {
    result
        .codec_stats
        .require(stat)
        .map_err(|e| Error::Unsupported(format!("{} on {}: {e}", result.codec, result.mesh)))
}

pub(crate) fn load(results: &Path, codec: &str, stem: &str) -> Result<RunResult> {
    let path = results::path(results, codec, stem, ".json");
    read_result(&path).map_err(|e| {
        Error::Unsupported(format!(
            "{}: {e} (make it with: {EMC_TABLE1_COMMAND})",
            path.display()
        ))
    })
}

/// Where the mesh a result was measured on is now: its `source` as recorded (relative to where
/// the experiment ran), else the file of that name among the shared meshes, so that tables made
/// from another folder (the lab's tests run in lab/) find it.
pub(crate) fn source_path(result: &RunResult) -> Result<PathBuf> {
    let recorded = Path::new(&result.source);
    if recorded.is_file() {
        return Ok(recorded.to_path_buf());
    }
    recorded
        .file_name()
        .and_then(|name| {
            meshcodec::mesh::io::data_dirs()
                .into_iter()
                .map(|dir| dir.join(name))
                .find(|path| path.is_file())
        })
        .ok_or_else(|| {
            Error::Io(std::io::Error::new(
                std::io::ErrorKind::NotFound,
                format!(
                    "{}: not found, nor among the shared meshes (the mesh of the {} result on {})",
                    result.source, result.codec, result.mesh
                ),
            ))
        })
}

/// Views that show each model from the front, as the paper's Fig. 5.
pub(crate) fn view_of(mesh: &str) -> View {
    match mesh {
        "beethoven" => View {
            up: 1,
            yaw: 0.0,
            pitch: 0.0,
        },
        "bunny-3k-closed" => View {
            up: 1,
            yaw: 0.0,
            pitch: 0.0,
        },
        _ => View {
            up: 1,
            yaw: 30.0,
            pitch: 20.0,
        },
    }
}

/// Draws `text` in black at `origin` (its top left), `size` pixels high.
pub(crate) fn draw_caption<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    text: &str,
    size: u32,
    (x, y): (u32, u32),
) -> Result<()> {
    root.draw_text(
        text,
        &("sans-serif", size).into_font().color(&BLACK),
        (x as i32, y as i32),
    )
    .map_err(|e| Error::Io(std::io::Error::other(format!("plot: {e}"))))
}

/// Draws a rendered panel of `width`-pixel rows at `origin`, its white background left out.
pub(crate) fn draw_panel<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    pixels: &[[u8; 3]],
    width: u32,
    (x0, y0): (u32, u32),
) -> Result<()> {
    for (i, px) in pixels.iter().enumerate() {
        if *px == [255, 255, 255] {
            continue;
        }
        let (x, y) = (x0 + i as u32 % width, y0 + i as u32 / width);
        root.draw_pixel((x as i32, y as i32), &RGBColor(px[0], px[1], px[2]))
            .map_err(|e| Error::Io(std::io::Error::other(format!("plot: {e}"))))?;
    }
    Ok(())
}

pub(crate) fn refused(results: &Path, codec: &str, mesh: &str) -> Option<String> {
    std::fs::read_to_string(results::refusal_path(results, codec, mesh))
        .ok()
        .map(|s| {
            s.trim()
                .rsplit("unsupported: ")
                .next()
                .unwrap_or("")
                .to_string()
        })
}

/// The result of `codec` on `mesh` at `quant` bits (cubic grid), by the harness's file naming.
pub fn load_at(results: &Path, codec: &str, mesh: &str, quant: u8) -> Result<RunResult> {
    // Other coders' results (Draco's) have no default quantization: their stems always name it.
    let defaults = meshcodec::codecs::by_name(codec)
        .map(|c| c.default_options())
        .unwrap_or(EncodeOptions {
            quant_bits: 0,
            grid: GridShape::Cubic,
        });
    let quantization = EncodeOptions {
        quant_bits: quant,
        grid: defaults.grid,
    };
    let stem = results::stem(&defaults, mesh, &quantization);
    let path = results::path(results, codec, &stem, ".json");
    read_result(&path).map_err(|e| {
        Error::Unsupported(format!(
            "{}: {e} (make it with: {ANCHORS_COMMAND})",
            path.display()
        ))
    })
}

/// Every level of `result` with an RMS above 0, as (cumulative bits, RMS): a rate–distortion
/// curve for [`log_log_interpolate`].
pub fn rms_curve(result: &RunResult) -> Vec<(f64, f64)> {
    result
        .levels
        .iter()
        .filter_map(|l| Some((l.bits as f64, l.rms?)))
        .filter(|&(_, rms)| rms > 0.0)
        .collect()
}

/// Regenerates every paper table and figure whose results are present; returns what it wrote
/// and, for each table it could not make, why.
pub fn regenerate(results: &Path, out: &Path) -> (Vec<PathBuf>, Vec<String>) {
    let mut written = Vec::new();
    let mut missing = Vec::new();
    plot::ensure_font().ok();
    let mut record = |name: &str, made: Result<Vec<PathBuf>>| match made {
        Ok(paths) => written.extend(paths),
        Err(e) => missing.push(format!("{name}: {e}")),
    };
    let one = |p: PathBuf| vec![p];
    record("emc-table1", emc_table1(results, out).map(one));
    record("emc-fig4", emc_fig4(results, out));
    record("emc-fig5", emc_fig5(results, out).map(one));
    record("hoppe-pm", hoppe_tables(results, out).map(one));
    record("emc-vs-anchors", emc_vs_anchors(results, out).map(one));
    record("emc-rate-distortion", emc_rate_distortion(results, out));
    record(
        "emc-rms-rate-distortion",
        emc_rms_rate_distortion(results, out),
    );
    record(
        "emc-levels-beside-pm",
        emc_levels_beside_pm(results, out).map(one),
    );
    record("came", came::tables::tables(results, out).map(one));
    record("came-fig4", came::tables::fig4(results, out).map(one));
    record(
        "came-rate-distortion",
        came::tables::rate_distortion(results, out),
    );
    record("came-vd", came::vd_table::table(results, out).map(one));
    record(
        "attributes",
        attributes::attributes_table(results, out).map(one),
    );
    record(
        "attributes-checker",
        attributes::attributes_checker(results, out).map(one),
    );
    record(
        "attributes-levels",
        attributes::attributes_levels(results, out).map(one),
    );
    record(
        "appearance-levels",
        appearance_levels::appearance_levels(results, out),
    );
    (written, missing)
}

/// `n` with its digits grouped by threes (12,345,678), as the tables and `meshcodec info` print
/// counts.
pub fn thousands(n: usize) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every table and figure of paper-tables/ is made from the committed results: none is
    /// skipped for a statistic, a result file or a stream it cannot find.
    #[test]
    fn every_paper_table_regenerates_from_the_committed_results() {
        let results = Path::new(env!("CARGO_MANIFEST_DIR")).join("../results");
        let out = tempfile::tempdir().unwrap();
        let (written, skipped) = regenerate(&results, out.path());
        assert!(skipped.is_empty(), "skipped: {skipped:?}");
        for name in [
            "emc-table1.md",
            "emc-vs-anchors.md",
            "hoppe-pm.md",
            "came.md",
            "came-fig4.png",
        ] {
            assert!(
                written.iter().any(|p| p.ends_with(name)),
                "{name} not written"
            );
        }
    }
}
