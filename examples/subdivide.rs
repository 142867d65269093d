//! Writes a shared mesh subdivided at edge midpoints, for runs on large meshes: the
//! 1.1M-triangle mesh of BENCHMARKS.md is `subdivide bunny-closed-35k 2 OUT.ply`.
//! Run: cargo run --release --example subdivide -- MESH TIMES OUT.ply|OUT.obj
use meshcodec::mesh::{generate, io};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let (Some(name), Some(times), Some(out)) = (args.get(1), args.get(2), args.get(3)) else {
        return Err("usage: subdivide MESH TIMES OUT.ply|OUT.obj".into());
    };
    let times: u32 = times.parse()?;
    let mut mesh = io::read_mesh(&io::resolve(name)?)?;
    for _ in 0..times {
        mesh = generate::subdivide(&mesh);
    }
    io::write_mesh(&mesh, std::path::Path::new(out))?;
    println!(
        "{out}: {} vertices, {} triangles",
        mesh.vertex_count(),
        mesh.face_count()
    );
    Ok(())
}
