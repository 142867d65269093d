//! The fly-through's path (`meshcodec_lab::came::flythrough::cameras`) over a `came` stream, with one
//! front alone (`meshcodec_lab::came::flythrough::fly_alone`, as the fly-through experiment times
//! it): adaptation time per frame with the orientation guard and without, meta-node waits apart.
//! Run: cargo run --release --example came_fly_adapt -- STREAM [on|off]
//! (`on` or `off` flies once, with the guard or without, for a profiler; both by default.)
//! (when STREAM does not exist, the fly-through's stream — bunny-closed-35k subdivided twice,
//! `came` at 12 bits — is encoded and written there first: about three minutes.)
use meshcodec::codecs::came::refine::{Budget, View, ViewMesh};
use meshcodec_lab::came::flythrough::{cameras, encode_stream, fly_alone};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args()
        .nth(1)
        .ok_or("usage: came_fly_adapt STREAM")?;
    let path = std::path::Path::new(&path);
    if !path.exists() {
        eprintln!("encoding the fly-through's stream to {}", path.display());
        std::fs::write(path, encode_stream()?.1)?;
    }
    let mut full = ViewMesh::open_file(path)?;
    full.settle(&View::everything(), Budget::UNLIMITED, 256);
    let cameras = cameras(&full.mesh())?;
    drop(full);
    let guards = match std::env::args().nth(2).as_deref() {
        None => vec![true, false],
        Some("on") => vec![true],
        Some("off") => vec![false],
        Some(other) => return Err(format!("expected on or off, not {other}").into()),
    };
    for guard in guards {
        let frames = fly_alone(path, &cameras, guard)?;
        let mut sorted: Vec<f64> = frames.iter().map(|f| f.adapt_ms).collect();
        sorted.sort_by(f64::total_cmp);
        let at = |q: f64| sorted[((sorted.len() - 1) as f64 * q).round() as usize];
        let waiting: f64 = frames.iter().map(|f| f.wait_ms).sum();
        let adapting: f64 = frames.iter().map(|f| f.adapt_ms).sum();
        println!(
            "guard {guard}: adaptation median {:.1} ms, 95th percentile {:.1} ms, first frame {:.1} ms, {:.0} ms over the path; {:.0} ms waiting for meta-nodes",
            at(0.5),
            at(0.95),
            frames[0].adapt_ms,
            adapting,
            waiting
        );
    }
    Ok(())
}
