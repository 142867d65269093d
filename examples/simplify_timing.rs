//! Times QEM simplification and PM construction on one mesh, subdivided n times (×4 faces each).
//! Run: cargo run --release --example simplify_timing -- bunny-closed-35k 2
use meshcodec::codecs::{self, EncodeOptions};
use meshcodec::hierarchy::simplify::{progressive_mesh, simplify, Placement};
use meshcodec::mesh::quantize::GridShape;
use std::time::Instant;

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let name = args.next().unwrap_or_else(|| "bunny-closed-35k".into());
    let times: u32 = args.next().and_then(|s| s.parse().ok()).unwrap_or(2);
    let mut mesh = meshcodec::mesh::io::read_mesh(&meshcodec::mesh::io::resolve(&name)?)?;
    for _ in 0..times {
        mesh = meshcodec::mesh::generate::subdivide(&mesh);
    }
    if let Ok(path) = std::env::var("WRITE_MESH") {
        meshcodec::mesh::io::write_mesh(&mesh, std::path::Path::new(&path))?;
    }
    let options = EncodeOptions {
        quant_bits: 24,
        grid: GridShape::Cubic,
    };
    let canonical = codecs::canonical_for(&mesh, &options)?;
    let cells: Vec<[i32; 3]> = canonical
        .cells
        .iter()
        .map(|c| c.map(|x| x as i32))
        .collect();
    let faces = &canonical.faces;
    let started = Instant::now();
    let simplified = simplify(&cells, faces, Placement::Optimal);
    let simplify_seconds = started.elapsed().as_secs_f64();
    let pm = progressive_mesh(faces, &simplified);
    let total = started.elapsed().as_secs_f64();
    let faces = canonical.face_count();
    println!(
        "{name} x{}: {faces} faces, base {} vertices; simplify {simplify_seconds:.3} s, PM {:.3} s, {:.0} faces/s",
        4u32.pow(times),
        pm.base.positions.len(),
        total - simplify_seconds,
        faces as f64 / total
    );
    Ok(())
}
