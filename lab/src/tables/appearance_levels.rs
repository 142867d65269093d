//! paper-tables/appearance-levels.md and appearance-rate-distortion.{png,svg}: each level's
//! appearance error against the bits spent up to it, for every codec that carries appearance
//! at every level — `emc` and `emc-ahead` with their levels (docs/FORMAT.md §10), `pm` and
//! `pm-reordered` in their splits (§6.3) — with Draco's single-rate file as one point, from
//! the results `bash experiments/attributes.sh` makes.

use super::attributes::{read_draco, ATTRIBUTE_MESHES};
use super::{log_log_interpolate, optional};
use crate::plot;
use crate::results::{self, read_result, LevelRow, RunResult, APPEARANCE_SUFFIX};
use meshcodec::error::{Error, Result};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The codecs compared, the stem suffix of their 12-bit results and where their appearance
/// goes (`None`: the codec's own way).
const CURVES: [(&str, &str, Option<&str>); 5] = [
    ("emc", "", None),
    ("emc-ahead", "", None),
    ("emc", "", Some("unit")),
    ("pm", "-q12", Some("fit")),
    ("pm-reordered", "-q12", Some("fit")),
];

/// What a level's appearance error is measured in, for a mesh: uv distance where it has uvs,
/// else the normal's angle, else colour steps; the RMS of the uv distance beside its mean.
#[derive(Clone, Copy)]
enum Measure {
    Uv,
    Normal,
    Colour,
}

impl Measure {
    fn of(result: &RunResult) -> Measure {
        let last = result.levels.last().map(|l| l.appearance);
        match last {
            Some(a) if a.uv_texels.is_some() => Measure::Uv,
            Some(a) if a.normal_degrees.is_some() => Measure::Normal,
            _ => Measure::Colour,
        }
    }

    /// The error the comparison is made on (the uv distance's RMS).
    fn value(self, level: &LevelRow) -> Option<f64> {
        let a = &level.appearance;
        match self {
            Measure::Uv => a.uv_rms_texels,
            Measure::Normal => a.normal_degrees,
            Measure::Colour => a.colour_steps,
        }
    }

    fn unit(self) -> &'static str {
        match self {
            Measure::Uv => "uv RMS, texels of 1024²",
            Measure::Normal => "normal, degrees",
            Measure::Colour => "colour, steps of 1/255",
        }
    }
}

fn load(results_dir: &Path, codec: &str, stem: &str) -> Result<RunResult> {
    let path = results::path(results_dir, codec, stem, ".json");
    read_result(&path).map_err(|e| {
        Error::Unsupported(format!(
            "{}: {e} (make it with: {})",
            path.display(),
            super::ATTRIBUTES_COMMAND
        ))
    })
}

fn label(codec: &str, rule: Option<&str>) -> String {
    match rule {
        None if codec.starts_with("emc") => format!("`{codec}`, with the levels"),
        None => format!("`{codec}`"),
        Some("unit") => format!("`{codec}`, appearance unit"),
        Some(rule) => format!("`{codec}`, in the splits, {rule}"),
    }
}

/// Writes the table and the chart.
pub fn appearance_levels(results_dir: &Path, out: &Path) -> Result<Vec<PathBuf>> {
    let mut md = String::new();
    let _ = writeln!(md, "# Appearance at every level\n");
    let _ = writeln!(md, "Regenerate: `{}` (the runs of paper-tables/attributes.md; this table and the chart read their per-level results).\n", super::ATTRIBUTES_COMMAND);
    let _ = writeln!(md, "Positions at 12 bits, uvs at 12, normals at 10, colours at 8 a channel (docs/CONTRACT.md §2.1). Each level's appearance error is measured as §5.1 says, at sample points of the original surface projected onto the level: for a mesh with uvs the root mean square of the uv distance in texels of a 1024² texture (its mean in brackets), else the normal's angle or the colour's steps. `emc` and `emc-ahead` code the appearance with their levels (docs/FORMAT.md §10): each level's vertices show the wedges of the vertices of the full mesh they stand for, coded where those first get a vertex of their own in the levels holding up to a quarter of the vertices, by which of their neighbours' charts each wedge lies in after, and the full appearance, exactly, from the level whose faces are the full mesh's. `emc`, appearance unit, is the same geometry with all of the appearance in one unit after the last level: its earlier levels have none. `pm` and `pm-reordered` carry the appearance in their vertex splits (§6.3) and their simplifier keeps the seams. *pm at the same bits* is `pm-reordered`'s error at the level's bits, interpolated log-log between its levels (— where `pm-reordered` has no level that coarse or that fine). Draco is single-rate: one point, its full decode.\n");
    let mut charts = Vec::new();
    for (mesh, what) in ATTRIBUTE_MESHES {
        let stem = |suffix: &str, rule: Option<&str>| {
            let rule = rule.map_or(String::new(), |r| format!("-{r}"));
            format!("{mesh}{suffix}{APPEARANCE_SUFFIX}{rule}")
        };
        let mut runs = Vec::new();
        for (codec, suffix, rule) in CURVES {
            match load(results_dir, codec, &stem(suffix, rule)) {
                Ok(r) => runs.push((codec, rule, r)),
                // pm refuses some meshes (not a manifold): the table says so where it reads it.
                Err(_) if super::refused(results_dir, codec, mesh).is_some() => {}
                Err(e) => return Err(e),
            }
        }
        let (draco, _) = read_draco(&results::path(
            results_dir,
            "draco",
            &format!("{mesh}{APPEARANCE_SUFFIX}"),
            ".json",
        ))?;
        let Some((_, _, first)) = runs.first() else {
            continue;
        };
        let measure = Measure::of(first);
        let vertices = first.vertices as f64;
        let pm: Vec<(f64, f64)> = runs
            .iter()
            .find(|(c, rule, _)| *c == "pm-reordered" && rule.is_some())
            .map(|(_, _, r)| {
                r.levels
                    .iter()
                    .filter_map(|l| Some((l.bits_per_vertex, measure.value(l)?)))
                    .collect()
            })
            .unwrap_or_default();
        let _ = writeln!(md, "## {mesh} ({what}; {})\n", measure.unit());
        for codec in ["emc", "emc-ahead"] {
            let Some((_, _, r)) = runs
                .iter()
                .find(|(c, rule, _)| *c == codec && rule.is_none())
            else {
                continue;
            };
            let _ = writeln!(md, "{}:\n", label(codec, None));
            let _ = writeln!(
                md,
                "| level | vertices | bits/vertex | error | pm at the same bits | error / pm's |"
            );
            let _ = writeln!(md, "|---:|---:|---:|---:|---:|---:|");
            for l in &r.levels {
                let error = measure.value(l);
                let at_pm = log_log_interpolate(&pm, l.bits_per_vertex);
                let mean = match measure {
                    Measure::Uv => l
                        .appearance
                        .uv_texels
                        .map_or(String::new(), |m| format!(" ({m:.2})")),
                    _ => String::new(),
                };
                let _ = writeln!(
                    md,
                    "| {} | {} | {:.2} | {}{mean} | {} | {} |",
                    l.level,
                    l.vertices,
                    l.bits_per_vertex,
                    optional(error, 2),
                    optional(at_pm, 2),
                    optional(error.zip(at_pm).map(|(e, p)| e / p), 2),
                );
            }
            let _ = writeln!(md);
        }
        let draco_error = draco.levels.last().and_then(|l| measure.value(l));
        let _ = writeln!(
            md,
            "Draco (single-rate): {:.2} bits/vertex, error {}.\n",
            draco.bytes as f64 * 8.0 / vertices,
            optional(draco_error, 2)
        );
        let mut series: Vec<plot::Series> = runs
            .iter()
            .map(|(codec, rule, r)| plot::Series {
                label: label(codec, *rule).replace('`', ""),
                points: r
                    .levels
                    .iter()
                    .filter_map(|l| Some((l.bits_per_vertex, measure.value(l)?)))
                    .filter(|&(b, e)| b > 0.0 && e > 0.0)
                    .collect(),
                mark: plot::Mark::Line,
            })
            .collect();
        if let Some(e) = draco_error {
            series.push(plot::Series {
                label: "Draco (single-rate)".into(),
                points: vec![(draco.bytes as f64 * 8.0 / vertices, e)],
                mark: plot::Mark::Points,
            });
        }
        charts.push(plot::Chart {
            title: format!("{mesh}: appearance error by level"),
            x_desc: "cumulative bits per vertex (log)".into(),
            y_desc: format!("{} (log)", measure.unit()),
            x_log: true,
            y_log: true,
            legend: plotters::prelude::SeriesLabelPosition::LowerLeft,
            series,
        });
    }
    let _ = writeln!(
        md,
        "![appearance error against bits for every level](appearance-rate-distortion.png)"
    );
    std::fs::create_dir_all(out)?;
    let path = out.join("appearance-levels.md");
    meshcodec::mesh::io::write_atomically(&path, md.as_bytes())?;
    let mut written = vec![path];
    written.extend(plot::Chart::draw_panels(
        &charts,
        2,
        &out.join("appearance-rate-distortion"),
    )?);
    Ok(written)
}
