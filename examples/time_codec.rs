//! The Rust library's encode and decode times of one mesh, best of N in-process runs, as one
//! JSON line: the anchor `python/benchmarks/overhead.py` measures the Python package against.
//! Run: cargo run --release --example time_codec -- MESH CODEC [N]
use meshcodec::codecs::{self, Stop};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let (Some(path), Some(name)) = (args.get(1), args.get(2)) else {
        return Err("usage: time_codec MESH CODEC [N]".into());
    };
    let repeats: usize = args.get(3).map_or(Ok(10), |n| n.parse())?;
    let mesh = meshcodec::mesh::io::read_mesh(std::path::Path::new(path))?;
    let codec = codecs::by_name(name)?;
    let options = codecs::EncodeOptions {
        quant_bits: 12,
        ..codec.default_options()
    };
    let (mut encode, mut decode) = (f64::INFINITY, f64::INFINITY);
    let mut bytes = Vec::new();
    for _ in 0..repeats {
        // What a Rust user does from a mesh in memory, as the package's encode(vertices, faces).
        let started = Instant::now();
        let canonical = codecs::canonical_for(&mesh, &options)?;
        bytes = codec.encode(&canonical)?.bytes;
        encode = encode.min(started.elapsed().as_secs_f64());
        let started = Instant::now();
        let (decoded, _) = codecs::decode(&bytes, Stop::All)?;
        decode = decode.min(started.elapsed().as_secs_f64());
        std::hint::black_box(decoded);
    }
    println!(
        "{{\"encode_seconds\": {encode}, \"decode_seconds\": {decode}, \"bytes\": {}}}",
        bytes.len()
    );
    Ok(())
}
