//! `emc` against the other coders: lossless sizes beside the published anchors, intermediate
//! levels and the rate–distortion curve beside the valence coder's measured one.

use super::*;
use crate::plot;
use meshcodec::error::{Error, Result};
use std::path::{Path, PathBuf};

/// Command that regenerates paper-tables/emc-vs-anchors.md and emc-rate-distortion.{png,svg}.
pub(crate) const ANCHORS_COMMAND: &str = "bash experiments/anchors.sh";

/// Connectivity, geometry and total bits per vertex, where published.
pub(crate) type Rates = (Option<f64>, Option<f64>, Option<f64>);

/// Published progressive coders on bunny.ply at 12 bits: (coder, rates).
pub(crate) const PUBLISHED_ANCHORS: [(&str, Rates); 3] = [
    (
        "Lee, Lavoué & Dupont 2012, valence-driven progressive coder (MEPP2, measured on this bunny)",
        (Some(4.23), Some(14.58), Some(18.81)),
    ),
    ("CPM (compressed progressive meshes)", (None, None, Some(22.6))),
    (
        "Peng & Kuo, geometry-guided octree coding (geometry, average)",
        (None, Some(16.6), None),
    ),
];

pub(crate) fn optional(x: Option<f64>, digits: usize) -> String {
    x.map_or("—".into(), |x| format!("{x:.digits$}"))
}

/// The meshes of emc-vs-anchors.md (experiments/anchors.toml): bunny.ply, which the published
/// coders report, and two larger scans.
const MESHES: [&str; 3] = ["bunny", "armadillo-43k", "dragon-50k"];

/// Writes paper-tables/emc-vs-anchors.md: connectivity, geometry and total bits per vertex at 12
/// bits on [`MESHES`], ours and Draco measured here, and published progressive coders.
pub fn emc_vs_anchors(results: &Path, out: &Path) -> Result<PathBuf> {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# EMC against the anchors: lossless bits per vertex at 12 bits\n"
    );
    let _ = writeln!(md, "Regenerate: `{ANCHORS_COMMAND}` (our codecs, then Draco through DracoPy in the same run, then this table).\n");
    let _ = writeln!(md, "Every row of ours is the full decode of the stream on the 12-bit cubic grid of docs/CONTRACT.md §1 (bits over the canonical mesh's vertex count; bunny.ply has 34,834 referenced vertices). Draco (DracoPy, compression_level 10, quantization_bits 12) is single-rate, quantizes on its own grid and is not checked for losslessness; its split between connectivity and geometry is not reported by DracoPy. Decode rates are one thread on this machine (Draco's from Python, best of five).\n");
    for mesh in MESHES {
        let _ = writeln!(md, "## {mesh}\n");
        let _ = writeln!(
            md,
            "| coder | progressive | connectivity | geometry | total | lossless | decode M v/s |"
        );
        let _ = writeln!(md, "|---|---|---:|---:|---:|---|---:|");
        for (codec, progressive) in [
            ("emc", true),
            ("emc-ahead", true),
            ("emc-paper", true),
            ("pm", true),
            ("raw", false),
            ("draco", false),
        ] {
            let r = load_at(results, codec, mesh, 12)?;
            let v = r.vertices as f64;
            let last = r.levels.last();
            let (conn, geom) = if codec == "draco" {
                (None, None)
            } else {
                (
                    last.map(|l| l.connectivity_bits as f64 / v),
                    last.map(|l| l.geometry_bits as f64 / v),
                )
            };
            let total = r.bytes as f64 * 8.0 / v;
            let name = if codec == "emc" {
                "**emc**".to_string()
            } else {
                format!("`{codec}`")
            };
            let _ = writeln!(
                md,
                "| {name} | {} | {} | {} | {} | {} | {:.2} |",
                if progressive { "yes" } else { "no" },
                optional(conn, 2),
                optional(geom, 2),
                if codec == "emc" {
                    format!("**{total:.2}**")
                } else {
                    format!("{total:.2}")
                },
                if codec == "draco" {
                    "not checked"
                } else if r.lossless {
                    "yes"
                } else {
                    "no"
                },
                v / r.decode_seconds.max(1e-12) / 1e6,
            );
        }
        if mesh == "bunny" {
            for (name, (conn, geom, total)) in PUBLISHED_ANCHORS {
                let _ = writeln!(
                    md,
                    "| {name} (published) | yes | {} | {} | {} | | |",
                    optional(conn, 2),
                    optional(geom, 2),
                    optional(total, 2)
                );
            }
        }
        let _ = writeln!(md);
    }
    intermediate_levels(results, &mut md)?;
    let _ = writeln!(md, "Connectivity and geometry of our arithmetic-coded streams are split in proportion to the coder's own estimate of each class's bits; `emc` books the split and leaf questions (which cells are occupied) as geometry, the edge questions and the face corrections as connectivity, as the paper books split distances and edge codes.\n");
    let _ = writeln!(md, "RMS error against bits a vertex on the three meshes (every level of `emc`, `emc-ahead`, `pm` and `pm-reordered` at 12 bits, Draco at quantization 8 to 16, the valence coder on bunny): [emc-rms-rate-distortion.png](emc-rms-rate-distortion.png). Hausdorff error on bunny.ply: [emc-rate-distortion.png](emc-rate-distortion.png). What a client sees: bunny.ply's `emc` and `emc-ahead` levels nearest 2 and 5 bits a vertex beside `pm` cut at the same bytes, with their RMS errors: [emc-levels-beside-pm.png](emc-levels-beside-pm.png). The valence-driven coder's curve is MEPP2's Compression_Valence (commit d977d05, adaptive quantization on, 12 bits, base mesh of at most 100 vertices) measured on this bunny outside the project, read from `../shared/anchors/{VALENCE_ANCHOR}` (its provenance and how each level's bits and errors were measured are in that file).");
    std::fs::create_dir_all(out)?;
    let path = out.join("emc-vs-anchors.md");
    std::fs::write(&path, md)?;
    Ok(path)
}

/// The section of emc-vs-anchors.md that compares every level of `emc` with `pm`'s and the
/// valence-driven coder's RMS error at the same cumulative bits (interpolated on log–log axes
/// between their levels, where both have levels on either side).
pub(crate) fn intermediate_levels(results: &Path, md: &mut String) -> Result<()> {
    let _ = writeln!(md, "## Intermediate levels: RMS error at the same bits\n");
    let _ = writeln!(md, "Each level of `emc` and of `emc-ahead` (every vertex's position coded two levels ahead of the octree's splits: docs/FORMAT.md §7.1) at 12 bits beside `pm`'s and the valence-driven coder's RMS error at the same cumulative bits, interpolated on log–log axes between their own levels (blank where they have no level on one side). RMS is relative to the bounding box's diagonal, both ways between the level and the original (docs/CONTRACT.md §5). `emc` shows each vertex where its neighbours predict it inside its cell (`codecs::emc::modelled::placement`; BENCHMARKS.md compares it with the cell centres). The target of the last column: the level's RMS no higher than the lower of the others'.\n");
    let valence = valence_anchor()?;
    for (mesh, codec) in MESHES
        .iter()
        .flat_map(|&mesh| [(mesh, "emc"), (mesh, "emc-ahead")])
    {
        let emc = load_at(results, codec, mesh, 12)?;
        let pm = rms_curve(&load_at(results, "pm", mesh, 12)?);
        let others: Vec<(&str, Vec<(f64, f64)>)> = if mesh == "bunny" {
            vec![("pm", pm), ("valence coder", valence.rms.clone())]
        } else {
            vec![("pm", pm)]
        };
        let _ = writeln!(md, "### {mesh}, `{codec}`\n");
        let mut head = format!("| level | bits/vertex | `{codec}` RMS |");
        let mut rule = "|---:|---:|---:|".to_string();
        for (name, _) in &others {
            head += &format!(" {name} |");
            rule += "---:|";
        }
        let _ = writeln!(md, "{head} `{codec}` / lower | met |\n{rule}---:|---|");
        let v = emc.vertices as f64;
        for level in &emc.levels {
            let (Some(rms), x) = (level.rms, level.bits as f64) else {
                continue;
            };
            let theirs: Vec<Option<f64>> = others
                .iter()
                .map(|(_, points)| log_log_interpolate(points, x))
                .collect();
            let lower = theirs.iter().flatten().copied().reduce(f64::min);
            let mut row = format!("| {} | {:.3} | {rms:.3e} |", level.level, x / v);
            for t in &theirs {
                row += &format!(" {} |", t.map_or(String::new(), |t| format!("{t:.3e}")));
            }
            let (ratio, met) = match lower {
                Some(lower) if rms > 0.0 => (
                    format!("{:.2}", rms / lower),
                    if rms <= lower { "yes" } else { "**no**" },
                ),
                _ => (String::new(), ""),
            };
            let _ = writeln!(md, "{row} {ratio} | {met} |");
        }
        let _ = writeln!(md);
    }
    Ok(())
}

/// `points`' y at `x`, interpolated on log–log axes between the two points around it (sorted by
/// x); `None` outside their range.
pub fn log_log_interpolate(points: &[(f64, f64)], x: f64) -> Option<f64> {
    let mut sorted = points.to_vec();
    sorted.sort_by(|a, b| a.0.total_cmp(&b.0));
    sorted.windows(2).find_map(|w| {
        let ((x0, y0), (x1, y1)) = (w[0], w[1]);
        if !(x0 <= x && x <= x1 && x0 > 0.0 && y0 > 0.0 && y1 > 0.0) {
            return None;
        }
        if x1 == x0 {
            return Some(y0.min(y1));
        }
        let t = (x / x0).ln() / (x1 / x0).ln();
        Some((y0.ln() + t * (y1 / y0).ln()).exp())
    })
}

/// The anchor file of the valence-driven coder's levels on bunny.ply (measured outside the
/// project; looked up, never copied).
pub(crate) const VALENCE_ANCHOR: &str = "valence-rd-bunny.json";

/// The valence-driven progressive coder of Lee, Lavoué & Dupont 2012 measured on bunny.ply at
/// 12 bits: each level's cumulative bits and Hausdorff error (relative to the bounding box's
/// diagonal, as ours).
pub(crate) struct ValenceAnchor {
    /// MEPP2 commit measured (short).
    commit: String,
    /// (cumulative bits, Hausdorff) per level.
    levels: Vec<(f64, f64)>,
    /// (cumulative bits, RMS) per level.
    rms: Vec<(f64, f64)>,
}

/// Folders the anchor files are looked up in: `$MESHCODEC_ANCHORS`, then `anchors` beside each
/// mesh folder of [`meshcodec::mesh::io::data_dirs`] (../shared/anchors).
pub(crate) fn anchor_dirs() -> Vec<PathBuf> {
    let mut dirs: Vec<PathBuf> = std::env::var_os("MESHCODEC_ANCHORS")
        .map(PathBuf::from)
        .into_iter()
        .collect();
    dirs.extend(
        meshcodec::mesh::io::data_dirs()
            .iter()
            .filter_map(|d| d.parent().map(|p| p.join("anchors"))),
    );
    dirs
}

pub(crate) fn valence_anchor() -> Result<ValenceAnchor> {
    let path = anchor_dirs()
        .into_iter()
        .map(|d| d.join(VALENCE_ANCHOR))
        .find(|p| p.is_file())
        .ok_or_else(|| {
            Error::Unsupported(format!(
                "no {VALENCE_ANCHOR} in ../shared/anchors (or $MESHCODEC_ANCHORS)"
            ))
        })?;
    let bad = |what: &str| Error::Unsupported(format!("{}: {what}", path.display()));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path)?).map_err(|e| bad(&e.to_string()))?;
    // (cumulative bits, `field`) of every level.
    let series = |field: &str| {
        json["levels"]
            .as_array()
            .ok_or_else(|| bad("no levels"))?
            .iter()
            .map(|l| Some((l["bits"].as_f64()?, l[field].as_f64()?)))
            .collect::<Option<Vec<_>>>()
            .filter(|l| !l.is_empty())
            .ok_or_else(|| bad(&format!("a level without bits or {field}")))
    };
    let levels = series("hausdorff_relative")?;
    let rms = series("rms_relative")?;
    let commit = json["commit"]
        .as_str()
        .unwrap_or("?")
        .chars()
        .take(7)
        .collect();
    Ok(ValenceAnchor {
        commit,
        levels,
        rms,
    })
}

/// Writes paper-tables/emc-rms-rate-distortion.{png,svg}: on each of bunny.ply, armadillo-43k
/// and dragon-50k at 12 bits, bits a vertex against RMS error for every level of `emc`,
/// `emc-ahead`, `pm` and `pm-reordered`, the valence-driven coder's levels (bunny) and Draco's
/// single-rate points at quantization 8 to 16 (those present).
pub fn emc_rms_rate_distortion(results: &Path, out: &Path) -> Result<Vec<PathBuf>> {
    let mut charts = Vec::new();
    for mesh in MESHES {
        let runs = ["emc", "emc-ahead", "pm", "pm-reordered"]
            .iter()
            .map(|codec| load_at(results, codec, mesh, 12))
            .collect::<Result<Vec<_>>>()?;
        let mut chart = plot::rate_rms(&runs, &format!("{mesh}, 12 bits: RMS error"));
        let draco: Vec<(f64, f64)> = (8..=16)
            .filter_map(|q| load_at(results, "draco", mesh, q).ok())
            .filter_map(|r| {
                Some((
                    r.bytes as f64 * 8.0 / r.vertices as f64,
                    r.levels.last()?.rms?,
                ))
            })
            .collect();
        if !draco.is_empty() {
            chart.series.push(plot::Series {
                label: "Draco q8–q16 (single-rate)".into(),
                points: draco,
                mark: plot::Mark::Points,
            });
        }
        if mesh == "bunny" {
            let valence = valence_anchor()?;
            let vertices = runs[0].vertices as f64;
            chart.series.push(plot::Series {
                label: format!("valence coder (MEPP2 {})", valence.commit),
                points: valence
                    .rms
                    .iter()
                    .map(|&(bits, rms)| (bits / vertices, rms))
                    .collect(),
                mark: plot::Mark::Line,
            });
        }
        charts.push(chart);
    }
    plot::Chart::draw_panels(&charts, 1, &out.join("emc-rms-rate-distortion"))
}

/// Writes paper-tables/emc-rate-distortion.{png,svg}: bits against Hausdorff error on bunny.ply
/// for every level of `emc`, `emc-paper` and `pm` at 12 bits and of the valence-driven coder
/// (the anchor file's measurement), and Draco's single-rate points at quantization 8 to 16.
pub fn emc_rate_distortion(results: &Path, out: &Path) -> Result<Vec<PathBuf>> {
    let runs = ["emc", "emc-ahead", "emc-paper", "pm"]
        .iter()
        .map(|codec| load_at(results, codec, "bunny", 12))
        .collect::<Result<Vec<_>>>()?;
    let mut chart = plot::rate_distortion(&runs, "bunny.ply, 12 bits");
    let draco: Vec<(f64, f64)> = (8..=16)
        .filter_map(|q| load_at(results, "draco", "bunny", q).ok())
        .filter_map(|r| {
            let last = r.levels.last()?;
            Some((r.bytes as f64 * 8.0, last.hausdorff?))
        })
        .collect();
    if draco.is_empty() {
        return Err(Error::Unsupported(format!(
            "no Draco results in {} (make them with: {ANCHORS_COMMAND})",
            results.join("draco").display()
        )));
    }
    chart.series.push(plot::Series {
        label: "Draco q8–q16 (single-rate)".into(),
        points: draco,
        mark: plot::Mark::Points,
    });
    let valence = valence_anchor()?;
    chart.series.push(plot::Series {
        label: format!("valence coder, Lee et al. 2012 (MEPP2 {})", valence.commit),
        points: valence.levels,
        mark: plot::Mark::Line,
    });
    chart.title =
        "Rate vs distortion — bunny.ply: progressive levels at 12 bits, Draco at 8–16 bits".into();
    chart.draw(&out.join("emc-rate-distortion"))
}
