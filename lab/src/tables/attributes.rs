//! paper-tables/attributes.md: whole meshes with their appearance — our lossless codecs against
//! Draco's single-rate files measured in the same run (`bash experiments/attributes.sh`).

use crate::results::{self, read_result, RunResult, APPEARANCE_SUFFIX};
use meshcodec::error::{Error, Result};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The command that makes the results this table reads, and the table.
pub const ATTRIBUTES_COMMAND: &str = "bash experiments/attributes.sh";

/// The shared meshes with appearance, and what each carries.
pub const ATTRIBUTE_MESHES: [(&str, &str); 4] = [
    ("bunny-10k-textured", "uvs with seams, one material"),
    ("spot", "uvs with seams"),
    ("airplane-colored", "per-vertex colours"),
    ("dragon-res3", "per-vertex normals; non-manifold"),
];

/// Our codecs in the table, the stem suffix of their 12-bit results (`pm`'s default is 16 bits,
/// so its stem names the quantization), and where the appearance goes when not the codec's own
/// way: `fit`/`keep` inside `pm`'s splits (`experiments/attributes-in-splits.toml`), `unit` in an
/// appearance unit (`experiments/attributes-unit.toml`).
const OURS: [(&str, &str, Option<&str>); 12] = [
    ("emc", "", None),
    ("emc", "", Some("unit")),
    ("emc-ahead", "", None),
    ("emc-ahead", "", Some("unit")),
    ("pm", "-q12", None),
    ("pm", "-q12", Some("fit")),
    ("pm", "-q12", Some("keep")),
    ("pm-reordered", "-q12", None),
    ("pm-reordered", "-q12", Some("fit")),
    ("pm-reordered", "-q12", Some("keep")),
    ("came", "", None),
    ("raw", "", None),
];

/// Draco's figures that its result file keeps beyond the common schema.
pub(super) struct DracoExtras {
    geometry_bytes: f64,
    split_vertices: f64,
}

/// Draco's result file, read once: the common schema and the extras beside it.
pub(super) fn read_draco(path: &Path) -> Result<(RunResult, DracoExtras)> {
    let text = std::fs::read_to_string(path).map_err(|e| missing(path, e))?;
    let value: serde_json::Value = serde_json::from_str(&text).map_err(|e| missing(path, e))?;
    let get = |key: &str| {
        value["draco"][key]
            .as_f64()
            .ok_or_else(|| missing(path, format!("no draco.{key}")))
    };
    let extras = DracoExtras {
        geometry_bytes: get("geometry_bytes")?,
        split_vertices: get("split_vertices")?,
    };
    let result = serde_json::from_value(value).map_err(|e| missing(path, e))?;
    Ok((result, extras))
}

fn missing(path: &Path, e: impl std::fmt::Display) -> Error {
    Error::Unsupported(format!(
        "{}: {e} (make it with: {ATTRIBUTES_COMMAND})",
        path.display()
    ))
}

/// The appearance error of a full level, as the table prints it.
fn error_cell(row: &crate::results::LevelRow) -> String {
    let a = &row.appearance;
    let mut parts = Vec::new();
    if let Some(t) = a.uv_texels {
        parts.push(format!("uv {t:.3} texel"));
    }
    if let Some(n) = a.normal_degrees {
        parts.push(format!("normal {n:.3}°"));
    }
    if let Some(c) = a.colour_steps {
        parts.push(format!("colour {c:.3}/255"));
    }
    if let Some(m) = a.wrong_material.filter(|m| *m > 0.0) {
        parts.push(format!("material {:.2}%", m * 100.0));
    }
    if parts.is_empty() {
        "—".into()
    } else {
        parts.join(", ")
    }
}

/// Writes paper-tables/attributes.md.
pub fn attributes_table(results_dir: &Path, out: &Path) -> Result<PathBuf> {
    let mut md = String::new();
    let _ = writeln!(md, "# Appearance: whole meshes against Draco\n");
    let _ = writeln!(md, "Regenerate: `{ATTRIBUTES_COMMAND}` (our codecs with `--appearance`, then Draco through DracoPy in the same run, then this table).\n");
    let _ = writeln!(md, "Positions at 12 bits (docs/CONTRACT.md §1), uvs at Qt = 12 bits over their bounding box, normals octahedral at Qn = 10 bits a coordinate, colours 8 bits a channel (§2.1), for us and for Draco (DracoPy, compression_level 10, quantization_bits 12, tex_coord_quantization_bits 12, normal_quantization_bits 10; colours as 8-bit channels). Bits per vertex are over the canonical mesh's vertex count. Our streams are progressive and their full decode is checked lossless, appearance included (§3). Where the appearance goes: *with the levels* (`emc`, `emc-ahead`; docs/FORMAT.md §10), a part after each level, so that every level shows it — its first levels coding the vertices they stand for, the later ones which chart each lies in, the level whose faces are the full mesh's the whole appearance; *appearance unit*, one unit after the last level, so that no level before it has any (the same geometry: the difference is what showing it at every level costs); *in the splits* (`pm`'s vertex splits, §6.3; `fit` gives a collapsed wedge the values interpolated to where the vertex went, `keep` the survivor's), every level has it and the simplifier keeps seams, which costs geometry bits too; `came` and `raw` carry it in a unit. Each level's appearance error: [appearance-levels.md](appearance-levels.md). Draco is single-rate, fed the mesh with its vertices split at every seam (one vertex per wedge, as Draco needs; written by `meshcodec convert` as glTF), and its decode is not checked for losslessness. Draco's geometry column is a second file of the welded geometry alone; its appearance column is the difference. Appearance error (§5.1) is the mean over sample points of the original surface: uv distance in texels of a 1024² texture, normal angle, colour steps; it is the cost of quantization, since both full decodes keep every wedge. Draco carries no material ids here (DracoPy has no per-face attribute).\n");
    for (mesh, what) in ATTRIBUTE_MESHES {
        let draco_path = results::path(
            results_dir,
            "draco",
            &format!("{mesh}{APPEARANCE_SUFFIX}"),
            ".json",
        );
        let (draco, extras) = read_draco(&draco_path)?;
        let _ = writeln!(md, "## {mesh} ({what})\n");
        let _ = writeln!(
            md,
            "| coder | progressive | geometry bits/vertex | appearance bits/wedge | total bits/vertex | vs Draco | appearance error | lossless | decode ms |"
        );
        let _ = writeln!(md, "|---|---|---:|---:|---:|---:|---|---|---:|");
        let draco_total = draco.bits_per_vertex();
        let mut rows: Vec<(String, RunResult)> = Vec::new();
        for (codec, suffix, rule) in OURS {
            let rule_suffix = rule.map_or(String::new(), |r| format!("-{r}"));
            let stem = format!("{mesh}{suffix}{APPEARANCE_SUFFIX}{rule_suffix}");
            let path = results::path(results_dir, codec, &stem, ".json");
            let label = match rule {
                Some("unit") => format!("`{codec}`, appearance unit"),
                Some(rule) => format!("`{codec}`, in the splits, {rule}"),
                None if codec.starts_with("emc") => format!("`{codec}`, with the levels"),
                None => format!("`{codec}`"),
            };
            let Ok(r) = read_result(&path) else {
                let reason = super::refused(results_dir, codec, mesh)
                    .ok_or_else(|| missing(&path, "no result and no refusal"))?;
                if rule.is_none() {
                    let _ = writeln!(md, "| {label} | refused: {reason} | | | | | | | |");
                }
                continue;
            };
            rows.push((label.clone(), r.clone()));
            let codec = &codec.to_string();
            let Some(appearance) = &r.appearance else {
                return Err(Error::Unsupported(format!(
                    "{codec} on {mesh}: the result coded no appearance"
                )));
            };
            let v = r.vertices as f64;
            let total = r.bits_per_vertex();
            let last = r.levels.last().ok_or_else(|| {
                Error::Unsupported(format!("{codec} on {mesh}: a result without levels"))
            })?;
            let _ = writeln!(
                md,
                "| {label} | {} | {:.2} | {:.2} | {} | {:+.1}% | {} | {} | {:.1} |",
                if r.levels.len() > 1 { "yes" } else { "no" },
                (r.bytes as f64 * 8.0 - appearance.bits as f64) / v,
                appearance.bits as f64 / appearance.wedges.max(1) as f64,
                if total < draco_total {
                    format!("**{total:.2}**")
                } else {
                    format!("{total:.2}")
                },
                (total / draco_total - 1.0) * 100.0,
                error_cell(last),
                if r.lossless { "yes" } else { "**no**" },
                r.decode_seconds * 1e3,
            );
        }
        let v = draco.vertices as f64;
        let last = draco
            .levels
            .last()
            .ok_or_else(|| missing(&draco_path, "no level"))?;
        let _ = writeln!(
            md,
            "| Draco (single-rate) | no | {:.2} | {:.2} | {draco_total:.2} | | {} | not checked | {:.1} |\n",
            extras.geometry_bytes * 8.0 / v,
            (draco.bytes as f64 - extras.geometry_bytes) * 8.0 / extras.split_vertices.max(1.0),
            error_cell(last),
            draco.decode_seconds * 1e3,
        );
        for (label, r) in rows.iter().filter(|(l, _)| l.contains("in the splits")) {
            let last: Vec<String> = r
                .levels
                .iter()
                .rev()
                .take(5)
                .rev()
                .map(|l| {
                    let a = &l.appearance;
                    a.uv_texels
                        .or(a.normal_degrees)
                        .or(a.colour_steps)
                        .map_or("—".into(), |e| format!("{e:.2}"))
                })
                .collect();
            let unit = if r
                .levels
                .last()
                .is_some_and(|l| l.appearance.uv_texels.is_some())
            {
                "texels"
            } else if r
                .levels
                .last()
                .is_some_and(|l| l.appearance.normal_degrees.is_some())
            {
                "degrees"
            } else {
                "colour steps"
            };
            let _ = writeln!(
                md,
                "Appearance error of the last {} levels of {label} ({unit}): {}.\n",
                last.len(),
                last.join(" / ")
            );
        }
        let best = rows
            .iter()
            .filter(|(c, _)| c != "`raw`")
            .min_by(|a, b| a.1.bytes.cmp(&b.1.bytes));
        if let Some((codec, r)) = best {
            let _ = writeln!(
                md,
                "Smallest progressive stream: {codec}, {} bytes against Draco's {} ({:+.1}%); {} wedges on {} vertices.\n",
                r.bytes,
                draco.bytes,
                (r.bytes as f64 / draco.bytes as f64 - 1.0) * 100.0,
                r.appearance.as_ref().map_or(0, |a| a.wedges),
                r.vertices
            );
        }
    }
    let _ = writeln!(md, "## Pictures\n");
    let _ = writeln!(md, "![bunny-10k-textured and spot with a checker through the file's uvs and through emc's full decode](attributes-checker.png)\n");
    let _ = writeln!(md, "Intermediate levels, each textured with a checker through its own uvs; rows for bunny-10k-textured, then spot: `pm-reordered` in the splits, `fit` and `keep`, at 12%, 25% and 50% of the vertices, then `emc` and `emc-ahead` with their levels, each panel the level whose bits are nearest the `fit` panel's above it; captions give each level's vertices (v) and its stream's bits per vertex of the full mesh (b/v). `keep` stretches the checker where a collapsed vertex's uv stays put while its position moves; the `emc` levels carry more vertices for the same bits, but their faces cross the seams, which `pm`'s simplifier keeps:\n");
    let _ = writeln!(md, "![intermediate levels of pm-reordered in the splits and of emc and emc-ahead with their levels, with a checker](attributes-levels.png)");
    std::fs::create_dir_all(out)?;
    let path = out.join("attributes.md");
    meshcodec::mesh::io::write_atomically(&path, md.as_bytes())?;
    Ok(path)
}

/// The meshes of the checker figure.
const CHECKER_MESHES: [&str; 2] = ["bunny-10k-textured", "spot"];

/// Each face corner's uv, face by face; `None` without uvs.
fn corner_uvs(a: &meshcodec::mesh::attributes::Attributes) -> Option<Vec<[glam::DVec2; 3]>> {
    let uvs = a.uvs.as_ref()?;
    Some(
        a.corners
            .iter()
            .map(|c| c.map(|w| uvs[w as usize]))
            .collect(),
    )
}

/// Writes paper-tables/attributes-checker.png: the textured meshes with a checker through their
/// uvs, as the file holds them and as `emc`'s kept stream decodes them (uvs at 12 bits).
pub fn attributes_checker(results_dir: &Path, out: &Path) -> Result<PathBuf> {
    use crate::render::{render_textured, View};
    use plotters::prelude::*;
    const PANEL: u32 = 420;
    const CAPTION: u32 = 30;
    let width = PANEL * 2;
    let height = (PANEL + CAPTION) * CHECKER_MESHES.len() as u32;
    std::fs::create_dir_all(out)?;
    let path = out.join("attributes-checker.png");
    let root = BitMapBackend::new(&path, (width, height)).into_drawing_area();
    let fail = |e: &dyn std::fmt::Display| Error::Io(std::io::Error::other(format!("plot: {e}")));
    root.fill(&WHITE).map_err(|e| fail(&e))?;
    for (row, mesh) in CHECKER_MESHES.iter().enumerate() {
        // Spot looks along −z: turn it to face the camera.
        let view = View {
            up: 1,
            yaw: if *mesh == "spot" { 210.0 } else { 30.0 },
            pitch: 20.0,
        };
        let stem = format!("{mesh}{APPEARANCE_SUFFIX}");
        let result_path = results::path(results_dir, "emc", &stem, ".json");
        let result = read_result(&result_path).map_err(|e| missing(&result_path, e))?;
        let stream_path = results::path(results_dir, "emc", &stem, ".mc");
        let stream = std::fs::read(&stream_path).map_err(|e| missing(&stream_path, e))?;
        let original = meshcodec::mesh::io::read_attributed(&crate::tables::source_path(&result)?)?;
        let (decoded, _) = meshcodec::codecs::decode(&stream, meshcodec::codecs::Stop::All)?;
        let frame = original
            .mesh
            .referenced_bounds()
            .ok_or_else(|| Error::mesh("empty mesh"))?;
        let panels = [
            (
                &original.mesh,
                corner_uvs(&original.attributes),
                format!("{mesh}: the file's uvs"),
            ),
            (
                &decoded.mesh,
                decoded.attributes.as_ref().and_then(corner_uvs),
                format!("emc, full decode: {} bytes", stream.len()),
            ),
        ];
        for (col, (m, uvs, caption)) in panels.into_iter().enumerate() {
            let uvs = uvs.ok_or_else(|| Error::Unsupported(format!("{mesh}: no uvs")))?;
            let picture = render_textured(m, &uvs, &frame, view, PANEL, PANEL);
            let (x0, y0) = (col as u32 * PANEL, row as u32 * (PANEL + CAPTION));
            super::draw_panel(&root, &picture.pixels, PANEL, (x0, y0))?;
            super::draw_caption(&root, &caption, 20, (x0 + 12, y0 + PANEL + 2))?;
        }
    }
    root.present().map_err(|e| fail(&e))?;
    drop(root);
    Ok(path)
}

/// Shares of the full vertex count at which the levels figure shows each in-split stream.
const LEVEL_SHARES: [f64; 3] = [0.12, 0.25, 0.5];

/// One row of the levels figure: a mesh, a codec and where its appearance goes.
struct LevelRow {
    mesh: &'static str,
    codec: &'static str,
    rule: Option<&'static str>,
}

/// Writes paper-tables/attributes-levels.png: intermediate levels of `pm-reordered` with
/// appearance in its splits, by either collapse rule, and of `emc` and `emc-ahead` with their
/// levels, each textured with a checker through the level's own uvs — so that what each rule
/// does to the charts and the seams shows, and what each codec shows for the same bits: the
/// `emc` panels are the levels whose bits are nearest those of the `pm-reordered`, `fit`, panel
/// above.
pub fn attributes_levels(results_dir: &Path, out: &Path) -> Result<PathBuf> {
    use crate::render::{render_textured, View};
    use meshcodec::codecs::pm::iter::PMeshIter;
    use plotters::prelude::*;
    const PANEL: u32 = 300;
    const CAPTION: u32 = 26;
    let rows: Vec<LevelRow> = CHECKER_MESHES
        .iter()
        .flat_map(|&mesh| {
            [
                ("pm-reordered", Some("fit")),
                ("pm-reordered", Some("keep")),
                ("emc", None),
                ("emc-ahead", None),
            ]
            .map(|(codec, rule)| LevelRow { mesh, codec, rule })
        })
        .collect();
    let width = PANEL * LEVEL_SHARES.len() as u32;
    let height = (PANEL + CAPTION) * rows.len() as u32;
    std::fs::create_dir_all(out)?;
    let path = out.join("attributes-levels.png");
    let root = BitMapBackend::new(&path, (width, height)).into_drawing_area();
    let fail = |e: &dyn std::fmt::Display| Error::Io(std::io::Error::other(format!("plot: {e}")));
    root.fill(&WHITE).map_err(|e| fail(&e))?;
    // The bits per vertex of each mesh's `fit` panels, which the emc panels match.
    let mut fit_bits: Vec<(&str, Vec<f64>)> = Vec::new();
    for (row, line) in rows.iter().enumerate() {
        let view = View {
            up: 1,
            yaw: if line.mesh == "spot" { 210.0 } else { 30.0 },
            pitch: 20.0,
        };
        let quant = if line.codec == "pm-reordered" {
            "-q12"
        } else {
            ""
        };
        let rule = line.rule.map_or(String::new(), |r| format!("-{r}"));
        let stem = format!("{}{quant}{APPEARANCE_SUFFIX}{rule}", line.mesh);
        let stream_path = results::path(results_dir, line.codec, &stem, ".mc");
        let stream = std::fs::read(&stream_path).map_err(|e| missing(&stream_path, e))?;
        let result_path = results::path(results_dir, line.codec, &stem, ".json");
        let result = read_result(&result_path).map_err(|e| missing(&result_path, e))?;
        let mut frame = None;
        // Each panel: the level's mesh, its uvs and caption.
        let mut panels = Vec::new();
        if line.codec == "pm-reordered" {
            let mut iter = PMeshIter::from_stream(&stream)?;
            let full = iter.header().vertices as f64;
            let mut bits = Vec::new();
            for share in LEVEL_SHARES {
                iter.goto_nvertices((full * share).round() as usize)?;
                let n = iter.nvertices() as f64;
                // The stream's bits at n vertices, between its levels' (vertices, bits).
                let at: Vec<(f64, f64)> = result
                    .levels
                    .iter()
                    .map(|l| (l.vertices as f64, l.bits_per_vertex))
                    .collect();
                let bpv = super::log_log_interpolate(&at, n).unwrap_or(f64::NAN);
                bits.push(bpv);
                let caption = format!(
                    "{} {}: {n} v, {bpv:.1} b/v",
                    line.codec,
                    line.rule.unwrap_or("")
                );
                panels.push((iter.level_mesh(), caption));
            }
            if line.rule == Some("fit") {
                fit_bits.push((line.mesh, bits));
            }
        } else {
            let wanted = fit_bits
                .iter()
                .find(|(m, _)| *m == line.mesh)
                .map(|(_, b)| b.clone())
                .ok_or_else(|| Error::Unsupported("the fit row comes first".into()))?;
            let mut decoder = meshcodec::codecs::open(&stream)?;
            let mut levels = Vec::new();
            while decoder.advance()? {
                let bpv = result
                    .levels
                    .get(decoder.levels_decoded() - 1)
                    .map_or(f64::NAN, |l| l.bits_per_vertex);
                levels.push((bpv, decoder.mesh()?));
            }
            for bits in wanted {
                let (bpv, level) = levels
                    .iter()
                    .min_by(|a, b| (a.0 - bits).abs().total_cmp(&(b.0 - bits).abs()))
                    .ok_or_else(|| Error::Unsupported(format!("{stem}: no level")))?;
                let caption = format!(
                    "{}: {} v, {bpv:.1} b/v",
                    line.codec,
                    level.mesh.positions.len()
                );
                panels.push((level.clone(), caption));
            }
        }
        for (col, (level, caption)) in panels.iter().enumerate() {
            // Every panel of a row in the frame of its first level, so that they line up.
            let frame = *frame.get_or_insert(
                level
                    .mesh
                    .referenced_bounds()
                    .ok_or_else(|| Error::mesh("empty mesh"))?,
            );
            let uvs = level
                .attributes
                .as_ref()
                .and_then(corner_uvs)
                .ok_or_else(|| Error::Unsupported(format!("{stem}: a level without uvs")))?;
            let picture = render_textured(&level.mesh, &uvs, &frame, view, PANEL, PANEL);
            let (x0, y0) = (col as u32 * PANEL, row as u32 * (PANEL + CAPTION));
            super::draw_panel(&root, &picture.pixels, PANEL, (x0, y0))?;
            super::draw_caption(&root, caption, 14, (x0 + 6, y0 + PANEL + 4))?;
        }
    }
    root.present().map_err(|e| fail(&e))?;
    drop(root);
    Ok(path)
}
