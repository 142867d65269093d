//! Bits per vertex of each syntax field of a codec's stream at 12 bits (cubic grid), per mesh:
//! the measurements behind the context choices documented in `src/codecs/emc/modelled`; and the
//! full decode's time, best of ten, one thread, and each level's.
//! Run: cargo run --release --example emc_fields -- [codec] [mesh…]

use meshcodec::codecs::{self, EncodeOptions};
use meshcodec::mesh::io::{read_mesh, resolve};
use meshcodec::mesh::quantize::GridShape;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let codec = codecs::by_name(&args.next().unwrap_or_else(|| "emc".into()))?;
    let mut meshes: Vec<String> = args.collect();
    if meshes.is_empty() {
        meshes = vec!["bunny".into(), "armadillo-43k".into()];
    }
    let options = EncodeOptions {
        quant_bits: 12,
        grid: GridShape::Cubic,
    };
    for name in meshes {
        let mesh = read_mesh(&resolve(&name)?)?;
        let canonical = codecs::canonical_for(&mesh, &options)?;
        let v = canonical.vertex_count() as f64;
        let encoded = codec.encode(&canonical)?;
        // Best of ten full decodes, and each level's best (the last level's includes the
        // final faces).
        let mut seconds = f64::INFINITY;
        let mut level_seconds: Vec<f64> = Vec::new();
        let mut decoded = None;
        for _ in 0..10 {
            let start = std::time::Instant::now();
            let mut decoder = codecs::open(&encoded.bytes)?;
            let mut level = 0;
            loop {
                let level_start = std::time::Instant::now();
                if !decoder.advance()? {
                    break;
                }
                let elapsed = level_start.elapsed().as_secs_f64();
                match level_seconds.get_mut(level) {
                    Some(best) => *best = best.min(elapsed),
                    None => level_seconds.push(elapsed),
                }
                level += 1;
            }
            decoded = Some(decoder.mesh()?);
            seconds = seconds.min(start.elapsed().as_secs_f64());
        }
        let decoded = decoded.expect("decoded ten times");
        let last = encoded.levels.last().expect("a level");
        println!(
            "{name}: {} v, {:.3} bits/vertex (connectivity {:.3}, geometry {:.3}), decode {:.1} ms ({:.2} M v/s), {} faces",
            v,
            encoded.bytes.len() as f64 * 8.0 / v,
            last.connectivity_bits as f64 / v,
            last.geometry_bits as f64 / v,
            seconds * 1e3,
            v / seconds / 1e6,
            decoded.mesh.faces.len()
        );
        let levels: Vec<String> = level_seconds
            .iter()
            .map(|s| format!("{:.1}", s * 1e3))
            .collect();
        println!(
            "  decode ms by level (last: with the faces): {}",
            levels.join(" ")
        );
        for (field, value) in encoded.stats.iter().filter(|(k, _)| k.ends_with("_bits")) {
            println!("  {field:<28} {:>8.3}", value / v);
        }
    }
    Ok(())
}
