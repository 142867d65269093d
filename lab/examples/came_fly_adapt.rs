//! The fly-through's path (`meshcodec_lab::came::flythrough::cameras`) over a `came` stream, with one
//! front alone: adaptation time per frame with the orientation guard and without, meta-node
//! waits apart — the fly-through experiment interleaves three fronts and the error measurement,
//! which leaves each front's data out of the cache.
//! Run: cargo run --release --example came_fly_adapt -- STREAM
//! (when STREAM does not exist, the fly-through's stream — bunny-closed-35k subdivided twice,
//! `came` at 12 bits — is encoded and written there first: about two minutes.)
use meshcodec::codecs::came::refine::{Budget, View, ViewMesh};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args()
        .nth(1)
        .ok_or("usage: came_fly_adapt STREAM")?;
    let path = std::path::Path::new(&path);
    if !path.exists() {
        eprintln!("encoding the fly-through's stream to {}", path.display());
        std::fs::write(path, meshcodec_lab::came::flythrough::encode_stream()?.1)?;
    }
    let mut full = ViewMesh::open_file(path)?;
    full.settle(&View::everything(), Budget::UNLIMITED, 256);
    let cameras = meshcodec_lab::came::flythrough::cameras(&full.mesh())?;
    drop(full);
    for guard in [true, false] {
        let mut front = ViewMesh::open_file(path)?;
        let mut adapting = Vec::new();
        let mut waiting = 0.0;
        for camera in &cameras {
            let view = View::new(camera, meshcodec_lab::came::flythrough::TOLERANCE_PX)?
                .keep_orientation(guard);
            let mut ms = 0.0;
            for _ in 0..256 {
                let started = Instant::now();
                let done = front.adapt(&view, Budget::UNLIMITED);
                ms += started.elapsed().as_secs_f64() * 1e3;
                if done.settled {
                    break;
                }
                let started = Instant::now();
                front.wait_for_units();
                waiting += started.elapsed().as_secs_f64() * 1e3;
            }
            adapting.push(ms);
        }
        let mut sorted = adapting.clone();
        sorted.sort_by(f64::total_cmp);
        let at = |q: f64| sorted[((sorted.len() - 1) as f64 * q).round() as usize];
        println!(
            "guard {guard}: adaptation median {:.1} ms, 95th percentile {:.1} ms, first frame {:.1} ms; {:.0} ms waiting for meta-nodes",
            at(0.5),
            at(0.95),
            adapting[0],
            waiting
        );
    }
    Ok(())
}
