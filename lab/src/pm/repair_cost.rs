//! What cutting to a manifold costs `pm`: every shared mesh that is none, at 12 and 16 bits,
//! both orderings, against the same mesh's other codecs' sizes. Writes
//! results/pm/repair-cost.json (`experiment repair-cost`).

use crate::data::resolve;
use crate::progress::Progress;
use anyhow::{Context, Result};
use meshcodec::codecs;
use meshcodec::mesh::io::mesh_name;
use meshcodec::mesh::quantize::GridShape;
use std::path::{Path, PathBuf};

/// Measures and writes results/pm/repair-cost.json under `out`.
pub fn run(out: &Path) -> Result<()> {
    use meshcodec::codecs::pm::{Ordering, Pm};
    let dir = meshcodec::mesh::io::data_dirs()
        .into_iter()
        .find(|d| d.join("MANIFEST.md").is_file())
        .context("no folder of shared meshes (MESHCODEC_DATA, ../shared/meshes)")?;
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| meshcodec::mesh::io::read_mesh(p).is_ok())
        .collect();
    files.sort();
    // (file, subdivisions, bits): every shared mesh, and the one the welding at 16 bits makes
    // non-manifold once subdivided twice.
    let mut jobs: Vec<(PathBuf, u32, Vec<u8>)> =
        files.into_iter().map(|p| (p, 0, vec![12, 16])).collect();
    jobs.push((resolve("bunny-closed-35k")?, 2, vec![16]));
    let mut rows = Vec::new();
    crate::outln!(
        "{:<22} {:>4} {:<13} {:>8} {:>7} {:>6} {:>6} {:>10} {:>10} {:>8}",
        "mesh",
        "Q",
        "codec",
        "defects",
        "copies",
        "flips",
        "cut",
        "bytes",
        "manifold",
        "cost"
    );
    let progress = Progress::on_terminal();
    for (path, times, all_bits) in &jobs {
        progress.step(format!("repair-cost: {}", mesh_name(path)));
        let mut mesh = meshcodec::mesh::io::read_mesh(path)?;
        let mut name = path
            .file_stem()
            .unwrap_or_default()
            .to_string_lossy()
            .to_string();
        for _ in 0..*times {
            mesh = meshcodec::mesh::generate::subdivide(&mesh);
        }
        if *times > 0 {
            name = format!("{name} ×{}", 4u32.pow(*times));
        }
        for &bits in all_bits {
            let options = codecs::EncodeOptions {
                quant_bits: bits,
                grid: GridShape::Cubic,
            };
            let canonical = codecs::canonical_for(&mesh, &options)?;
            let report = meshcodec::mesh::topology::analyze(&canonical.to_mesh());
            for ordering in [Ordering::Natural, Ordering::Reordered] {
                let pm = Pm { ordering };
                let Some(cost) = pm.repair_cost(&canonical)? else {
                    continue;
                };
                let share =
                    report.defects() as f64 / (report.edges + canonical.vertex_count()) as f64;
                let extra = cost.repaired_bytes as f64 / cost.manifold_bytes as f64 - 1.0;
                let line = format!(
                    "{:<22} {:>4} {:<13} {:>7.3}% {:>7} {:>6} {:>6} {:>10} {:>10} {:>+7.2}%\n",
                    name,
                    bits,
                    codecs::Codec::name(&pm),
                    100.0 * share,
                    cost.copies,
                    cost.flips,
                    cost.cut_edges,
                    cost.repaired_bytes,
                    cost.manifold_bytes,
                    100.0 * extra
                );
                progress.suspend(|| crate::cli::write_stdout(&line))?;
                rows.push(serde_json::json!({
                    "mesh": name,
                    "quant_bits": bits,
                    "codec": codecs::Codec::name(&pm),
                    "vertices": canonical.vertex_count(),
                    "faces": canonical.face_count(),
                    "non_manifold_edges": report.non_manifold_edges,
                    "non_manifold_vertices": report.non_manifold_vertices,
                    "edges_used_twice_one_way": report.edges_used_twice_one_way,
                    "defect_share": share,
                    "cost": cost,
                    "extra_share": extra,
                }));
            }
        }
    }
    let dir = out.join("pm");
    std::fs::create_dir_all(&dir)?;
    let path = dir.join("repair-cost.json");
    meshcodec::mesh::io::write_atomically(
        &path,
        format!(
            "{}\n",
            serde_json::to_string_pretty(&serde_json::json!({ "rows": rows }))?
        )
        .as_bytes(),
    )?;
    crate::outln!("wrote {}", path.display());
    Ok(())
}
