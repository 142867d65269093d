//! Derives EMC's fixed split-distance Huffman table from the distance histogram pooled over a
//! training set of shared meshes that are *not* in the paper's Table 1 (no bunny, Beethoven or
//! car), at 24 levels on the cubic grid, and prints the code lengths in the form of
//! src/codecs/emc/paper/split_distance_lengths.in.
//!
//! Run: cargo run --release --example emc_split_distance_table > src/codecs/emc/paper/split_distance_lengths.in

use meshcodec::codecs::{self, EncodeOptions};
use meshcodec::coding::huffman::Huffman;
use meshcodec::mesh::io::{read_mesh, resolve};
use meshcodec::mesh::quantize::GridShape;

const TRAINING: [&str; 12] = [
    "spot",
    "cow",
    "fandisk",
    "elephant",
    "max-planck-12k",
    "camelhead",
    "rocker-arm",
    "eight",
    "feline-26k",
    "armadillo-43k",
    "dragon-50k",
    "terrain-mountain",
];

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let emc = codecs::by_name("emc-paper")?;
    let mut counts = vec![0u64; codecs::emc::paper::syntax::MAX_DISTANCE + 1];
    for name in TRAINING {
        let mesh = read_mesh(&resolve(name)?)?;
        for grid in [GridShape::Cubic, GridShape::PerAxis] {
            let options = EncodeOptions {
                quant_bits: 24,
                grid,
            };
            let canonical = codecs::canonical_for(&mesh, &options)?;
            let encoded = emc.encode(&canonical)?;
            for (key, value) in encoded.stats.iter() {
                let Some(d) = key.strip_prefix("distance_") else {
                    continue;
                };
                let symbol = if d == "none" { 0 } else { d.parse::<usize>()? };
                counts[symbol] += value as u64;
            }
        }
        eprintln!("{name}: pooled");
    }
    let lengths = Huffman::lengths_for(&counts);
    eprintln!("counts: {counts:?}");
    let text: Vec<String> = lengths.iter().map(|l| l.to_string()).collect();
    println!("[{}]", text.join(", "));
    Ok(())
}
