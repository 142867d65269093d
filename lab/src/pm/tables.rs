//! Hoppe's progressive meshes: Tables 2–4 (bits per vertex split by field) and the wedge table
//! of Hoppe 1998, beside the papers' figures.

use crate::results::{self, RunResult};
use crate::tables::*;
use meshcodec::codecs::stats::{PmField, Stat};
use meshcodec::error::Result;
use meshcodec::mesh::io::write_atomically;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Hoppe's Tables 2–4 on these meshes (result stems under results/pm and results/pm-reordered).
pub(crate) const HOPPE_MESHES: [&str; 5] = [
    "bunny-closed-35k",
    "dragon-50k",
    "armadillo-43k",
    "fandisk",
    "cow",
];

/// The command that makes the PM results.
pub const HOPPE_COMMAND: &str = "cargo run --release --bin experiment -- run experiments/hoppe-pm.toml && cargo run --release --bin experiment -- run experiments/attributes-in-splits.toml && cargo run --release --bin experiment -- run experiments/derived-normals.toml && cargo run --release --bin experiment -- decimation && cargo run --release --bin experiment -- tables";

/// Hoppe's Table 3 rows of meshes with wedges: model, avg |wad|, flclw, vs_index, vlr_rot,
/// corners+ii+matid_pred, fl_matid+fr_matid, vad_l, vad_s, Δnormal, Δuv, Σ.
pub(crate) const HOPPE_WEDGE_ROWS: [(&str, [f64; 11]); 7] = [
    (
        "garethman",
        [1.49, 8.4, 1.6, 1.6, 4.6, 0.1, 36.2, 21.7, 31.4, 0.0, 105.5],
    ),
    (
        "cessna",
        [1.42, 11.3, 1.6, 1.9, 4.1, 0.1, 29.1, 12.5, 24.3, 0.0, 85.0],
    ),
    (
        "bigship",
        [
            1.02, 11.6, 1.6, 2.0, 1.2, 0.0, 30.2, 18.0, 18.3, 22.2, 105.1,
        ],
    ),
    (
        "dunebuggy",
        [1.03, 12.2, 1.6, 2.0, 0.6, 0.0, 27.5, 20.0, 20.6, 0.0, 84.5],
    ),
    (
        "gameguy",
        [1.18, 13.0, 1.6, 1.7, 2.5, 0.0, 26.3, 13.7, 21.2, 0.0, 80.1],
    ),
    (
        "drumset",
        [1.74, 13.8, 1.6, 2.2, 4.6, 0.7, 25.3, 15.6, 32.0, 0.0, 95.8],
    ),
    (
        "chandelier",
        [1.46, 14.0, 1.6, 2.1, 1.9, 0.0, 23.9, 15.1, 28.6, 0.0, 87.3],
    ),
];

/// The shared meshes with appearance that pm takes, for the wedge table.
pub(crate) const WEDGE_MESHES: [&str; 4] = [
    "bunny-10k-textured",
    "spot",
    "airplane-colored",
    "feline-26k",
];

/// The shared manifolds with normals, for the wedge table's rows with derived normals.
pub(crate) const DERIVED_NORMAL_MESHES: [&str; 2] = ["feline-26k", "bunny-3k-closed"];

/// Hoppe's Tables 3–4 with their wedge fields: his meshes with wedges beside ours, pm and
/// pm-reordered with appearance in their splits at 16-bit positions, by either collapse rule.
pub(crate) fn wedge_table(md: &mut String, results: &Path) -> Result<()> {
    use meshcodec::codecs::stats::WedgeField;
    let _ = writeln!(
        md,
        "\n## Tables 3–4 with wedges: appearance inside the vertex splits\n"
    );
    let _ = writeln!(md, "Hoppe's Table 3 rows of his meshes with wedges (normals 8-bit Cartesian, uvs 16 bits; his Table 4 keeps the same wedge columns but recomputes normals from the wedges, Δnormal 0, and sets vad_s = 0), beside `pm` (collapse order, the Table 3 layout) and `pm-reordered` (Δflclw and vad_s = 0, the Table 4 layout) coding every level's uvs, normals, colours and materials inside the splits (`--appearance --attributes fit|keep`; docs/FORMAT.md §6.3), positions at 16 bits, uvs at 12 bits, colours 8 bits a channel. `fit` gives a collapsed wedge the values interpolated to where the vertex went, `keep` the survivor's (the fast-QEM rule). Our `corners+ii` is ii plus which value each changed corner takes; `fl/fr matid` is the new faces' material flags and ids; Δcolour is ours alone. Bits per vsplit over the splits, the base mesh apart (its vertices are coded plainly, appearance included). We do not count |wad|.\n");
    let _ = writeln!(md, "| model | codec, rule | avg \\|wad\\| | flclw / Δflclw | vs_index | vlr_rot | corners+ii (+matid_pred) | fl/fr matid | vad_l | vad_s | Δnormal | Δuv | Δcolour | Σ |");
    let _ = writeln!(
        md,
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for (name, f) in HOPPE_WEDGE_ROWS {
        let _ = writeln!(
            md,
            "| {name} (Hoppe) | Table 3 | {:.2} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | — | {:.1} |",
            f[0], f[1], f[2], f[3], f[4], f[5], f[6], f[7], f[8], f[9], f[10]
        );
    }
    let rows = WEDGE_MESHES
        .iter()
        .map(|&m| (m, false))
        .chain(DERIVED_NORMAL_MESHES.iter().map(|&m| (m, true)));
    let mut derived_errors = Vec::new();
    for (mesh, derived) in rows {
        for codec in ["pm", "pm-reordered"] {
            for rule in ["fit", "keep"] {
                let (suffix, how) = if derived {
                    (results::DERIVED_NORMALS_SUFFIX, ", normals derived")
                } else {
                    ("", "")
                };
                let stem = format!("{mesh}{}-{rule}{suffix}", results::APPEARANCE_SUFFIX);
                let Ok(r) = load(results, codec, &stem) else {
                    let why = refused(results, codec, mesh)
                        .unwrap_or_else(|| format!("no result (make it with: {HOPPE_COMMAND})"));
                    let _ = writeln!(
                        md,
                        "| {mesh} (ours) | `{codec}` {rule}{how}: {why} | | | | | | | | | | | | |"
                    );
                    continue;
                };
                if stat(&r, Stat::Vsplits).unwrap_or(0.0) < 1.0 {
                    let _ = writeln!(
                        md,
                        "| {mesh} (ours) | `{codec}` {rule}{how}: no vertex split, the seams pin every vertex in the base mesh ({} bits a vertex) | | | | | | | | | | | | |",
                        format_args!("{:.1}", r.bits_per_vertex())
                    );
                    continue;
                }
                let splits = stat(&r, Stat::Vsplits)?.max(1.0);
                let bits = |w: WedgeField| {
                    r.codec_stats
                        .get_named(&format!("bits_{}", w.name()))
                        .map(|b| b / splits)
                };
                let wedge = |w: WedgeField| bits(w).unwrap_or(0.0);
                // A field the mesh does not have is no column of its.
                let cell = |w: WedgeField| bits(w).map_or("—".to_string(), |b| format!("{b:.1}"));
                let normal = if derived {
                    if let Some(degrees) = r.levels.last().and_then(|l| l.appearance.normal_degrees)
                    {
                        derived_errors.push(format!("{mesh} {degrees:.2}°"));
                    }
                    "0".to_string()
                } else {
                    cell(WedgeField::Normal)
                };
                use PmField::{Flclw, Ii, VadL, VadS, VlrRot, VsIndex};
                let ([flclw, vs_index, vlr_rot, ii, vad_l], geometry) =
                    per_split_fields(&r, [Flclw, VsIndex, VlrRot, Ii, VadL])?;
                // pm-reordered places on endpoints and midpoints: no vad_s at all.
                let vad_s = per_split(&r, VadS).unwrap_or(0.0);
                let geometry = geometry + vad_s;
                let corners = ii + wedge(WedgeField::Corners);
                let appearance: f64 = WedgeField::ALL.iter().map(|&w| wedge(w)).sum();
                let _ = writeln!(
                    md,
                    "| {mesh} (ours) | `{codec}` {rule}{how} | — | {flclw:.1} | {vs_index:.1} | {vlr_rot:.1} | {corners:.1} | {} | {vad_l:.1} | {vad_s:.1} | {normal} | {} | {} | **{:.1}** |",
                    cell(WedgeField::Material),
                    cell(WedgeField::Uv),
                    cell(WedgeField::Colour),
                    geometry + appearance,
                );
            }
        }
    }
    let _ = writeln!(md, "\nWhy ours differ: a new uv is predicted by the affine map fitted to its coarse chart around vs and its residual arithmetic-coded, where Hoppe stores the delta from the parent wedge with order-0 bit lengths; a wedge that continues across the collapsed edge costs a candidate choice, not a delta. But the simplifier keeps seams (a removed vertex lies on no seam, or inside one seam curve that the collapsed edge follows), so the base mesh keeps what the seams pin (bunny-10k-textured 8% of its vertices, spot 0.9%), coded plainly and not counted here, and `fit` re-codes the survivor's values at every split that moved them. Hoppe's bigship is the only one of his meshes with uvs (16 bits, Δuv 22.2).");
    derived_errors.dedup();
    let _ = writeln!(md, "\nRows with **normals derived** (`--derive-normals`, docs/CONTRACT.md §2.1, FORMAT.md §6.3) are Hoppe's Table 4 mode: the splits code which corners share a normal (in corners+ii), no normal value, and every level's normals are derived from its own positions; the full level is lossless against the canonical mesh with derived normals, which differ from the file's by a mean angle of {} (normal_degrees of the last level, against the file's normals). bunny-3k-closed is flat-shaded: a crease at every edge, so the seams pin almost every vertex in the base mesh, with or without derived normals.", if derived_errors.is_empty() { "—".to_string() } else { derived_errors.join(", ") });
    Ok(())
}

/// One of Hoppe's published rows: (model, vertices, goto(Mⁿ) v/s, goto(M⁰) v/s, PMesh arith
/// bits/vertex, Table 3 fields flclw, vs_index, vlr_rot, corners+ii+matid, vad_l, vad_s, Δnormal,
/// Σ, Table 4 fields Δflclw, vs_index, vlr_rot, corners+ii+matid, vad_l, Σ).
pub(crate) type HoppeRow = (&'static str, u64, u64, u64, u64, [f64; 8], [f64; 6]);

pub(crate) const HOPPE_ROWS: [HoppeRow; 2] = [
    (
        "bunny",
        34835,
        80_000,
        107_000,
        74,
        [13.6, 1.6, 1.4, 0.1, 28.2, 15.3, 13.7, 74.0],
        [6.3, 1.6, 1.4, 0.1, 28.2, 37.7],
    ),
    (
        "dragon",
        429_753,
        76_000,
        101_000,
        64,
        [17.3, 1.6, 2.0, 0.0, 21.6, 8.9, 12.9, 64.2],
        [6.7, 1.6, 2.0, 0.0, 21.5, 31.8],
    ),
];

pub(crate) fn per_split(r: &RunResult, field: PmField) -> Result<f64> {
    Ok(stat(r, Stat::FieldBits(field))? / stat(r, Stat::Vsplits)?.max(1.0))
}

/// Bits per vsplit of each field, and their sum.
pub(crate) fn per_split_fields<const N: usize>(
    r: &RunResult,
    fields: [PmField; N],
) -> Result<([f64; N], f64)> {
    let mut bits = [0.0; N];
    for (b, f) in bits.iter_mut().zip(fields) {
        *b = per_split(r, f)?;
    }
    Ok((bits, bits.iter().sum()))
}

/// Writes paper-tables/hoppe-pm.md: Tables 2, 3 and 4 of Hoppe's paper beside ours, and the
/// decimation-time table of the fast QEM PM encoder.
pub fn hoppe_tables(results: &Path, out: &Path) -> Result<PathBuf> {
    let mut md = String::new();
    let _ = writeln!(md, "# Progressive meshes — Hoppe, *Efficient Implementation of Progressive Meshes*, Tables 2–4\n");
    let _ = writeln!(md, "Regenerate: `{HOPPE_COMMAND}`\n");
    let _ = writeln!(md, "Ours: codecs `pm` (collapse order, QEM-optimal placement, vad_s coded — Table 3) and `pm-reordered` (dependency-graph reordering, Δflclw, endpoint/midpoint placement so vad_s = 0 — Table 4), positions on the 16-bit cubic grid as Hoppe §6.2, adaptive binary arithmetic coding. The meshes of Tables 2–4 carry no normals, texture coordinates or materials, so their wedge fields are absent (Hoppe's Σ in Table 3 includes Δnormal); the wedge fields are in the last table, on the shared meshes that have appearance. Iteration rates are ours on this machine (2 cores, one thread) against Hoppe's 200 MHz Pentium Pro.\n");
    let _ = writeln!(md, "## Table 2: iteration rates and space\n");
    let _ = writeln!(md, "| model | vertices | base vertices / faces | goto(Mⁿ) v/s | goto(M⁰) v/s | stream decode v/s | pm bits/vertex | pm-reordered bits/vertex |");
    let _ = writeln!(md, "|---|---:|---:|---:|---:|---:|---:|---:|");
    for (name, v, fwd, back, bpv, _, _) in HOPPE_ROWS {
        let _ = writeln!(
            md,
            "| {name} (Hoppe) | {v} | | {fwd} | {back} | | {bpv} (arith.) | |"
        );
    }
    let mut t3 = String::new();
    let mut t4 = String::new();
    for mesh in HOPPE_MESHES {
        let natural = load(results, "pm", mesh).ok();
        let reordered = load(results, "pm-reordered", mesh).ok();
        let (Some(n), Some(r)) = (natural, reordered) else {
            let why = refused(results, "pm", mesh).unwrap_or_else(|| "no result".into());
            let _ = writeln!(md, "| {mesh} (ours) | refused: {why} | | | | | | |");
            let _ = writeln!(t3, "| {mesh} (ours) | refused | | | | | | | |");
            let _ = writeln!(t4, "| {mesh} (ours) | refused | | | | | |");
            continue;
        };
        let _ = writeln!(
            md,
            "| {mesh} (ours) | {} | {} / {} | {:.0} | {:.0} | {:.0} | {:.1} | {:.1} |",
            n.vertices,
            stat(&n, Stat::BaseVertices)?,
            stat(&n, Stat::BaseFaces)?,
            stat(&n, Stat::GotoFullVerticesPerSecond)?,
            stat(&n, Stat::GotoBaseVerticesPerSecond)?,
            stat(&n, Stat::StreamDecodeVerticesPerSecond)?,
            n.bytes as f64 * 8.0 / n.vertices as f64,
            r.bytes as f64 * 8.0 / r.vertices as f64
        );
        use PmField::{Flclw, Ii, VadL, VadS, VlrRot, VsIndex};
        let (b, total) = per_split_fields(&n, [Flclw, VsIndex, VlrRot, Ii, VadL, VadS])?;
        let _ = writeln!(
            t3,
            "| {mesh} (ours) | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | — | **{total:.1}** |",
            b[0], b[1], b[2], b[3], b[4], b[5]
        );
        let (b, total) = per_split_fields(&r, [Flclw, VsIndex, VlrRot, Ii, VadL])?;
        let _ = writeln!(
            t4,
            "| {mesh} (ours) | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | **{total:.1}** |",
            b[0], b[1], b[2], b[3], b[4]
        );
    }
    let _ = writeln!(md, "\n## Table 3: bits per vsplit, collapse order (`pm`)\n");
    let _ = writeln!(md, "| model | flclw | vs_index | vlr_rot | ii (+corners, matid) | vad_l | vad_s | Δnormal | Σ |");
    let _ = writeln!(md, "|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    for (name, _, _, _, _, f, _) in HOPPE_ROWS {
        let _ = writeln!(
            md,
            "| {name} (Hoppe) | {} | {} | {} | {} | {} | {} | {} | {} |",
            f[0], f[1], f[2], f[3], f[4], f[5], f[6], f[7]
        );
    }
    md.push_str(&t3);
    let _ = writeln!(
        md,
        "\n## Table 4: bits per vsplit, reordered, vad_s = 0 (`pm-reordered`)\n"
    );
    let _ = writeln!(
        md,
        "| model | Δflclw | vs_index | vlr_rot | ii (+corners, matid) | vad_l | Σ |"
    );
    let _ = writeln!(md, "|---|---:|---:|---:|---:|---:|---:|");
    for (name, _, _, _, _, _, f) in HOPPE_ROWS {
        let _ = writeln!(
            md,
            "| {name} (Hoppe) | {} | {} | {} | {} | {} | {} |",
            f[0], f[1], f[2], f[3], f[4], f[5]
        );
    }
    md.push_str(&t4);
    let _ = writeln!(md, "\nWhy ours differ: vad_l is coded in the tangent frame at vs (the normal component predicted from the tangent plane) with the ring-centroid difference as prediction; in `pm` the QEM-optimal placement is snapped to 1/32 of the split length (vad_s step), which keeps the full mesh exact and the intermediate positions within 1/64 of an edge. Hoppe's bunny is the 34,835-vertex one (bunny-closed-35k); his dragon is the 430k-vertex original, ours the 50k decimation.");
    wedge_table(&mut md, results)?;

    // Decimation times (paper 001, Table 1).
    let _ = writeln!(
        md,
        "\n## Decimation time — the fast QEM PM encoder's Table 1\n"
    );
    let path = results.join("pm").join("decimation.json");
    match std::fs::read_to_string(&path)
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
    {
        Some(report) => {
            let _ = writeln!(md, "Ours: simplification to the smallest base mesh plus PM construction, on {} threads: meshes of 200k faces or more collapse first in regions of 16k-32k faces in parallel (two rounds, the second across the seams of the first), then in one greedy loop; smaller ones in one greedy loop throughout. Meshes are shared meshes, subdivided at edge midpoints (×4 faces each time). cow and teapot (marked †) are no oriented manifolds: they are cut to one first, as `pm` does, and simplified in one greedy loop with the copied vertices pinned. The check that a mesh is an oriented manifold, or its cut to one, is `pm`'s step before simplification, in a column of its own. Theirs (Intel Q6600 2.4 GHz), reducing to 10% of the faces:\n", report["threads"]);
            let _ = writeln!(
                md,
                "| their mesh | faces | their time | | our mesh | faces | our time | faces/s | check or cut |"
            );
            let _ = writeln!(md, "|---|---:|---:|---|---|---:|---:|---:|---:|");
            // Beside ours of the same size; cow and teapot are the paper's own meshes.
            let theirs = [
                ("cow.obj", 5804, "<1 s"),
                ("", 0, ""),
                ("czajnik.obj", 107_890, "8 s"),
                ("", 0, ""),
                ("abel.obj", 203_202, "14 s"),
                ("", 0, ""),
                ("sabinki.obj", 1_348_030, "102 s"),
                ("krolowa.obj", 2_999_990, "480 s"),
            ];
            let rows = report["rows"].as_array().cloned().unwrap_or_default();
            for (i, row) in rows.iter().enumerate() {
                let (tn, tf, tt) = theirs.get(i).copied().unwrap_or(("", 0, ""));
                let times = row["subdivisions"].as_u64().unwrap_or(0);
                let mut ours = if times == 0 {
                    row["mesh"].as_str().unwrap_or("").to_string()
                } else {
                    format!(
                        "{} ×{}",
                        row["mesh"].as_str().unwrap_or(""),
                        4u64.pow(times as u32)
                    )
                };
                if row["cut_to_a_manifold"].as_bool() == Some(true) {
                    ours.push_str(" †");
                }
                let tf = if tf == 0 {
                    String::new()
                } else {
                    tf.to_string()
                };
                let _ = writeln!(
                    md,
                    "| {tn} | {tf} | {tt} | | {ours} | {} | {:.2} s | {:.0} | {:.2} s |",
                    row["faces"],
                    row["total_seconds"].as_f64().unwrap_or(0.0),
                    row["faces_per_second"].as_f64().unwrap_or(0.0),
                    row["manifold_seconds"].as_f64().unwrap_or(0.0)
                );
            }
        }
        None => {
            let _ = writeln!(
                md,
                "No results: run `cargo run --release --bin experiment -- decimation`."
            );
        }
    }
    let path = out.join("hoppe-pm.md");
    write_atomically(&path, md.as_bytes())?;
    Ok(path)
}
