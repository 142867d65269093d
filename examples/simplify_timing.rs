//! Times simplification and PM construction on a subdivided shared mesh.
//! Run: cargo run --release --example simplify_timing -- bunny-closed-35k 2
use meshcodec::codecs::{self, EncodeOptions};
use meshcodec::hierarchy::simplify::{progressive_mesh, simplify, Placement};
use meshcodec::mesh::generate::subdivide;
use meshcodec::mesh::io::{read_mesh, resolve};
use meshcodec::mesh::quantize::GridShape;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let mut mesh = read_mesh(&resolve(&args[1]).unwrap()).unwrap();
    for _ in 0..args[2].parse::<u32>().unwrap() {
        mesh = subdivide(&mesh);
    }
    let options = EncodeOptions {
        quant_bits: 24,
        grid: GridShape::Cubic,
    };
    let canonical = codecs::canonical_for(&mesh, &options).unwrap();
    let cells: Vec<[i32; 3]> = canonical
        .cells
        .iter()
        .map(|c| c.map(|x| x as i32))
        .collect();
    let t = Instant::now();
    let s = simplify(&cells, &canonical.faces, Placement::Optimal);
    let t1 = t.elapsed().as_secs_f64();
    let pm = progressive_mesh(&canonical.faces, &s);
    let t2 = t.elapsed().as_secs_f64();
    let f = canonical.faces.len() as f64;
    println!(
        "{} faces: simplify {t1:.2} s, + PM {t2:.2} s = {:.0} faces/s; base {} v",
        f,
        f / t2,
        pm.base.positions.len()
    );
}
