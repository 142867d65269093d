//! Bulk operations of CAME's view-dependent mesh: every node refined from the root with every
//! meta-node loaded, then everything collapsed back to the root, twice, in-process (one
//! `adapt` each, no operation budget); splits and collapses per second, best of the rounds.
//! Run: cargo run --release --example came_bulk -- [MESH [SUBDIVISIONS]] (default: bunny)
use meshcodec::codecs::came::refine::{Budget, Camera, View, ViewMesh};
use meshcodec::codecs::{self, EncodeOptions};
use meshcodec::mesh::quantize::GridShape;
use meshcodec_lab::came::extras::table_mesh;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let name = args.get(1).map_or("bunny", |s| s.as_str());
    let subdivisions: u32 = args.get(2).map_or(Ok(0), |s| s.parse())?;
    let (_, mesh) = table_mesh(name, subdivisions)?;
    let options = EncodeOptions {
        quant_bits: 12,
        grid: GridShape::Cubic,
    };
    let canonical = codecs::canonical_for(&mesh, &options)?;
    let stream = codecs::by_name("came")?.encode(&canonical)?.bytes;
    let mut front = ViewMesh::from_stream(&stream)?;
    // From far off along +z, everything in view; a tolerance of 0 wants every split.
    let camera = |target_z: f64| Camera {
        eye: glam::DVec3::new(0.0, 0.0, 1e3),
        target: glam::DVec3::new(0.0, 0.0, target_z),
        up: glam::DVec3::Y,
        fov_degrees: 60.0,
        width: 1024,
        height: 768,
    };
    let everything = View::new(&camera(0.0), 0.0)?.two_sided(true);
    // Looking away: nothing in view, nothing wanted.
    let nothing = View::new(&camera(2e3), 1.0)?.two_sided(true);
    front.settle(&everything, Budget::UNLIMITED, 256);
    front.settle(&nothing, Budget::UNLIMITED, 256);
    let (mut split_rate, mut collapse_rate, mut splits) = (0f64, 0f64, 0);
    for _ in 0..2 {
        let started = Instant::now();
        let done = front.adapt(&everything, Budget::UNLIMITED);
        split_rate = split_rate.max(done.splits as f64 / started.elapsed().as_secs_f64());
        splits = done.splits;
        let started = Instant::now();
        let done = front.adapt(&nothing, Budget::UNLIMITED);
        collapse_rate = collapse_rate.max(done.collapses as f64 / started.elapsed().as_secs_f64());
    }
    println!(
        "{name} x{}: {} triangles, {splits} splits: {:.2} M splits/s, {:.2} M collapses/s",
        4usize.pow(subdivisions),
        canonical.face_count(),
        split_rate / 1e6,
        collapse_rate / 1e6
    );
    Ok(())
}
