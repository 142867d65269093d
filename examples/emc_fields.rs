//! Bits per vertex of each syntax field of a codec's stream at 12 bits (cubic grid), per mesh:
//! the measurements behind the context choices documented in `src/codecs/emc/modelled`; and the
//! full decode's time, best of ten, one thread.
//! Run: cargo run --release --example emc_fields -- [codec] [mesh…]

use meshcodec::codecs::{self, EncodeOptions, Stop};
use meshcodec::mesh::io::{read_mesh, resolve};
use meshcodec::mesh::quantize::GridShape;

fn main() -> anyhow::Result<()> {
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
        let encoded = codec.encode(&canonical, &options)?;
        let mut seconds = f64::INFINITY;
        let mut decoded = None;
        for _ in 0..std::env::var("REPS").ok().and_then(|s| s.parse().ok()).unwrap_or(10) {
            let start = std::time::Instant::now();
            decoded = Some(codecs::decode(&encoded.bytes, Stop::All)?.0);
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
        for (field, value) in encoded.stats.iter().filter(|(k, _)| k.ends_with("_bits")) {
            println!("  {field:<28} {:>8.3}", value / v);
        }
    }
    Ok(())
}
