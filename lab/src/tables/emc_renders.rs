//! paper-tables/emc-levels-beside-pm.png: what a client reading bunny.ply in part sees. The
//! `emc` and `emc-ahead` levels nearest 2 and 5 bits a vertex, and `pm` cut at the bytes of
//! `emc-ahead`'s level, flat-shaded from one camera, each captioned with its bytes and its RMS
//! error measured as `experiment` measures it.

use super::{draw_caption, draw_panel, load_at, source_path, view_of};
use crate::render::render;
use meshcodec::codecs::{self, EncodeOptions, LevelMesh, Stop};
use meshcodec::error::{Error, Result};
use meshcodec::mesh::io::read_mesh;
use meshcodec::mesh::quantize::GridShape;
use meshcodec::metrics::{Reference, SampleBudget, DEFAULT_SEED};
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// Bits a vertex the rows are nearest to.
const TARGETS: [f64; 2] = [2.0, 5.0];
/// Pixels a panel's side.
const PANEL: u32 = 380;
const CAPTION: u32 = 52;
const TITLE: u32 = 44;

/// One panel: its mesh and caption.
struct Panel {
    mesh: LevelMesh,
    caption: [String; 2],
}

/// Writes the figure (see the module docs) from the source mesh of `results`' `emc` bunny run,
/// encoded again at 12 bits (the codecs are deterministic: the streams of results/).
pub fn emc_levels_beside_pm(results: &Path, out: &Path) -> Result<PathBuf> {
    let result = load_at(results, "emc", "bunny", 12)?;
    let original = read_mesh(&source_path(&result)?)?;
    let frame = original
        .referenced_bounds()
        .ok_or_else(|| Error::mesh("empty mesh"))?;
    let options = EncodeOptions {
        quant_bits: 12,
        grid: GridShape::Cubic,
    };
    let canonical = codecs::canonical_for(&original, &options)?;
    let vertices = canonical.vertex_count() as f64;
    let reference = Reference::new(&original, SampleBudget::default(), DEFAULT_SEED);
    let streams = ["emc", "emc-ahead", "pm"]
        .map(|codec| codecs::by_name(codec).and_then(|c| c.encode(&canonical)));
    let [Ok(emc), Ok(ahead), Ok(pm)] = streams else {
        return Err(Error::Unsupported("bunny.ply did not encode".into()));
    };
    let rms = |level: &LevelMesh| reference.compare(level).map_or(f64::NAN, |d| d.rms);
    let mut rows = Vec::new();
    for target in TARGETS {
        let mut row = Vec::new();
        let mut ahead_end = 0;
        for (name, encoded) in [("emc", &emc), ("emc-ahead", &ahead)] {
            // The level whose bits a vertex are nearest the target, on log axes.
            let (index, record) = encoded
                .levels
                .iter()
                .enumerate()
                .min_by(|(_, a), (_, b)| {
                    let off = |end: usize| ((end as f64 * 8.0 / vertices) / target).ln().abs();
                    off(a.end_byte).total_cmp(&off(b.end_byte))
                })
                .ok_or_else(|| Error::Unsupported(format!("{name}: no level")))?;
            let (mesh, _) = codecs::decode(&encoded.bytes, Stop::Levels(index + 1))?;
            ahead_end = record.end_byte;
            row.push(Panel {
                caption: [
                    format!("{name} level {}: {} bytes", index + 1, record.end_byte),
                    format!(
                        "{:.2} bits/vertex, RMS {:.2e}",
                        record.end_byte as f64 * 8.0 / vertices,
                        rms(&mesh)
                    ),
                ],
                mesh,
            });
        }
        // `pm` cut where `emc-ahead`'s level ends: what the same bytes give it.
        let cut = ahead_end.min(pm.bytes.len());
        let (mesh, level) = codecs::decode(&pm.bytes[..cut], Stop::All)?;
        row.push(Panel {
            caption: [
                format!("pm, its first {cut} bytes (level {level})"),
                format!(
                    "{} vertices, RMS {:.2e}",
                    mesh.mesh.positions.len(),
                    rms(&mesh)
                ),
            ],
            mesh,
        });
        rows.push(row);
    }
    let columns = rows[0].len() as u32;
    let (width, height) = (
        PANEL * columns,
        TITLE + (PANEL + CAPTION) * rows.len() as u32,
    );
    let path = out.join("emc-levels-beside-pm.png");
    let root = BitMapBackend::new(&path, (width, height)).into_drawing_area();
    let fail = |e: &dyn std::fmt::Display| Error::Io(std::io::Error::other(format!("plot: {e}")));
    root.fill(&WHITE).map_err(|e| fail(&e))?;
    draw_caption(
        &root,
        "bunny.ply at 12 bits: levels nearest 2 and 5 bits a vertex, and pm at the same bytes",
        22,
        (12, 12),
    )?;
    let view = view_of("bunny");
    for (r, row) in rows.iter().enumerate() {
        for (c, panel) in row.iter().enumerate() {
            let picture = render(&panel.mesh.mesh, &frame, view, PANEL, PANEL);
            let (x0, y0) = (c as u32 * PANEL, TITLE + r as u32 * (PANEL + CAPTION));
            draw_panel(&root, &picture.pixels, PANEL, (x0, y0))?;
            for (k, line) in panel.caption.iter().enumerate() {
                draw_caption(&root, line, 17, (x0 + 10, y0 + PANEL + 2 + 22 * k as u32))?;
            }
        }
    }
    root.present().map_err(|e| fail(&e))?;
    drop(root);
    Ok(path)
}
