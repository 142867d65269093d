//! How fast simplification and PM construction run on meshes from 5k to 3M faces (shared meshes,
//! subdivided), beside the time to check or cut the mesh to an oriented manifold. Writes
//! results/pm/decimation.json (`experiment decimation`).

use crate::data::resolve;
use crate::progress::Progress;
use anyhow::{Context, Result};
use meshcodec::codecs;
use meshcodec::mesh::quantize::GridShape;
use std::path::Path;

/// Meshes of the decimation table: a shared mesh and how many times it is subdivided (×4 faces).
/// cow and teapot (×16: as many faces as the paper's czajnik, Polish for teapot) are no oriented
/// manifolds: they are cut to one first, as `pm` does, and the cut is timed with the rest.
const DECIMATION_MESHES: [(&str, u32); 8] = [
    ("cow", 0),
    ("spot", 0),
    ("teapot", 2),
    ("dragon-50k", 0),
    ("fandisk", 2),
    ("bunny-closed-35k", 2),
    ("armadillo-43k", 2),
    ("feline-26k", 3),
];

/// Measures and writes results/pm/decimation.json under `out`.
pub fn run(out: &Path) -> Result<()> {
    use meshcodec::codecs::pm::ManifoldInput;
    use meshcodec::hierarchy::simplify::{
        progressive_mesh, simplify, simplify_constrained, Placement,
    };
    let mut rows = Vec::new();
    let progress = Progress::on_terminal();
    for (name, times) in DECIMATION_MESHES {
        progress.step(format!("decimation: {name} x{}", 4u32.pow(times)));
        let path = resolve(name).with_context(|| name.to_string())?;
        let mut mesh =
            meshcodec::mesh::io::read_mesh(&path).with_context(|| path.display().to_string())?;
        for _ in 0..times {
            mesh = meshcodec::mesh::generate::subdivide(&mesh);
        }
        // 24 bits: fine enough that subdivision midpoints never weld.
        let options = codecs::EncodeOptions {
            quant_bits: 24,
            grid: GridShape::Cubic,
        };
        let canonical = codecs::canonical_for(&mesh, &options)?;
        // The check that the mesh is an oriented manifold (or its cut to one) is pm's step, not
        // the decimation's: timed apart.
        let started = std::time::Instant::now();
        let input = ManifoldInput::of(&canonical)?;
        let manifold_seconds = started.elapsed().as_secs_f64();
        let started = std::time::Instant::now();
        let simplified = match &input.cut {
            None => simplify(&input.cells, &input.faces, Placement::Optimal),
            Some(_) => simplify_constrained(
                &input.cells,
                &input.faces,
                Placement::Optimal,
                input.constraints(),
            ),
        };
        let simplify_seconds = started.elapsed().as_secs_f64();
        let pm = progressive_mesh(&input.faces, &simplified);
        let total_seconds = started.elapsed().as_secs_f64();
        let faces = canonical.face_count();
        let line = format!(
            "{name} x{}: {faces} faces -> base {} vertices; manifold check or cut {manifold_seconds:.2} s; simplify {simplify_seconds:.2} s, with PM construction {total_seconds:.2} s ({:.0} faces/s)\n",
            4u32.pow(times),
            pm.base.positions.len(),
            faces as f64 / total_seconds
        );
        progress.suspend(|| crate::cli::write_stdout(&line))?;
        rows.push(serde_json::json!({
            "mesh": name,
            "cut_to_a_manifold": input.cut.is_some(),
            "subdivisions": times,
            "faces": faces,
            "vertices": canonical.vertex_count(),
            "base_vertices": pm.base.positions.len(),
            "vsplits": pm.vsplits.len(),
            "manifold_seconds": manifold_seconds,
            "simplify_seconds": simplify_seconds,
            "total_seconds": total_seconds,
            "faces_per_second": faces as f64 / total_seconds,
        }));
    }
    let dir = out.join("pm");
    std::fs::create_dir_all(&dir)?;
    let report = serde_json::json!({ "threads": rayon::current_num_threads(), "rows": rows });
    let path = dir.join("decimation.json");
    meshcodec::mesh::io::write_atomically(
        &path,
        format!("{}\n", serde_json::to_string_pretty(&report)?).as_bytes(),
    )?;
    crate::outln!("wrote {}", path.display());
    Ok(())
}
