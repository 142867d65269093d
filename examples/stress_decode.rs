//! Decodes many mutated streams of every codec and reports panics and slow decodes.
//! Run: cargo run --release --example stress_decode -- 20000
use meshcodec::codecs::{self, EncodeOptions, Stop};
use meshcodec::mesh::generate;
use meshcodec::mesh::quantize::GridShape;
use std::time::Instant;

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(2000);
    let mesh = generate::torus(1.0, 0.4, 14, 9);
    let mut x = 0x2545_f491_4f6c_dd1d_u64;
    let mut rand = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    };
    for name in ["raw", "emc", "emc-paper", "pm", "pm-reordered"] {
        let codec = codecs::by_name(name).unwrap();
        let options = EncodeOptions {
            quant_bits: 12,
            grid: GridShape::Cubic,
        };
        let canonical = codecs::canonical_for(&mesh, &options).unwrap();
        let bytes = codec.encode(&canonical).unwrap().bytes;
        let (mut ok, mut err, mut slowest) = (0, 0, 0f64);
        for i in 0..n {
            let mut b = bytes.clone();
            match i % 4 {
                0 => {
                    for _ in 0..1 + rand() % 8 {
                        let k = rand() as usize % b.len();
                        b[k] = rand() as u8;
                    }
                }
                1 => b.truncate(rand() as usize % b.len()),
                2 => {
                    let k = rand() as usize % b.len();
                    let extra: Vec<u8> = (0..rand() % 64).map(|_| rand() as u8).collect();
                    b.splice(k..k, extra);
                }
                _ => {
                    let k = 6 + rand() as usize % (b.len() - 6);
                    b[k] ^= 1 << (rand() % 8);
                }
            }
            let t = Instant::now();
            let outcome = std::panic::catch_unwind(|| {
                codecs::decode(&b, Stop::All).map(|m| m.0.mesh.faces.len())
            });
            slowest = slowest.max(t.elapsed().as_secs_f64());
            match outcome {
                Ok(Ok(_)) => ok += 1,
                Ok(Err(_)) => err += 1,
                Err(_) => {
                    std::fs::write(format!("crash-{name}-{i}.mc"), &b).unwrap();
                    println!("{name}: PANIC on mutation {i}");
                }
            }
        }
        println!("{name}: {ok} decoded, {err} clean errors, slowest {slowest:.4} s");
    }
}
