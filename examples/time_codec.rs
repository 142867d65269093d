//! The Rust library's encode and decode times of one mesh, best of N in-process runs, as one
//! JSON line: the anchor `python/benchmarks/overhead.py` measures the Python package against.
//! Run: cargo run --release --example time_codec -- MESH CODEC [N]
//! A stream alone (`time_codec STREAM.mc [N]`) is only decoded, on the threads rayon is given
//! (RAYON_NUM_THREADS).
use meshcodec::codecs::{self, Stop};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    if let Some(stream) = args.get(1).filter(|path| path.ends_with(".mc")) {
        return time_decode(stream, args.get(2));
    }
    let (Some(path), Some(name)) = (args.get(1), args.get(2)) else {
        return Err("usage: time_codec MESH CODEC [N] | time_codec STREAM.mc [N]".into());
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

/// Best of `repeats` (default 10) decodes of the stream at `path`.
fn time_decode(path: &str, repeats: Option<&String>) -> Result<(), Box<dyn std::error::Error>> {
    let repeats: usize = repeats.map_or(Ok(10), |n| n.parse())?;
    let bytes = std::fs::read(path)?;
    let mut decode = f64::INFINITY;
    for _ in 0..repeats {
        let started = Instant::now();
        let (decoded, _) = codecs::decode(&bytes, Stop::All)?;
        decode = decode.min(started.elapsed().as_secs_f64());
        std::hint::black_box(decoded);
    }
    println!(
        "{{\"decode_seconds\": {decode}, \"bytes\": {}, \"threads\": {}}}",
        bytes.len(),
        rayon::current_num_threads()
    );
    Ok(())
}
