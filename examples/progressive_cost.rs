//! What handing over the levels costs on top of one decode, natively: a stream decoded whole
//! against the same stream fed to `codecs::Progressive` in chunks (as a download hands them
//! over), each level handed over as its bytes complete it, and against decoding each of those
//! levels again from the first (what a decoder that cannot go on from the level before costs);
//! best of N, one thread unless RAYON_NUM_THREADS says otherwise, as one JSON line. The
//! WebAssembly package's figure is web/bench/progressive.mjs's.
//! Run: cargo run --release --example progressive_cost -- STREAM.mc [CHUNK] [N]
use meshcodec::codecs::{self, Progressive, Stop};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let Some(path) = args.get(1) else {
        return Err("usage: progressive_cost STREAM.mc [CHUNK] [N]".into());
    };
    let chunk: usize = args.get(2).map_or(Ok(16384), |n| n.parse())?;
    let repeats: usize = args.get(3).map_or(Ok(5), |n| n.parse())?;
    let bytes = std::fs::read(path)?;
    let (mut whole, mut fed, mut again) = (f64::INFINITY, f64::INFINITY, f64::INFINITY);
    let (mut handed, mut incremental) = (0, false);
    for _ in 0..repeats {
        let started = Instant::now();
        codecs::decode(&bytes, Stop::All)?;
        whole = whole.min(started.elapsed().as_secs_f64());
        let started = Instant::now();
        let mut progressive = Progressive::new();
        let mut stops = Vec::new();
        for (k, piece) in bytes.chunks(chunk).enumerate() {
            if let Some((_, level)) = progressive.push(piece)? {
                stops.push((((k + 1) * chunk).min(bytes.len()), level));
            }
        }
        fed = fed.min(started.elapsed().as_secs_f64());
        incremental = progressive.incremental();
        handed = stops.len();
        let started = Instant::now();
        for &(received, level) in &stops {
            codecs::decode(&bytes[..received], Stop::Levels(level))?;
        }
        again = again.min(started.elapsed().as_secs_f64());
    }
    println!(
        "{{\"stream\": {path:?}, \"chunk\": {chunk}, \"whole_ms\": {:.2}, \"fed_ms\": {:.2}, \
         \"levels_handed\": {handed}, \"incremental\": {incremental}, \"fed_over_whole\": {:.3}, \
         \"each_level_from_the_first_over_whole\": {:.3}}}",
        whole * 1e3,
        fed * 1e3,
        fed / whole,
        again / whole
    );
    Ok(())
}
