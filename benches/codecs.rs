//! Codec throughput in vertices per second, one thread: encode (canonical mesh → bytes) and full
//! decode (bytes → mesh) of bunny.ply and armadillo-43k.obj at 12 and 24 levels, for both EMC
//! coders (`emc`, `emc-paper`).
//! Run: cargo bench --bench codecs

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use meshcodec::codecs::{self, EncodeOptions, Stop};
use meshcodec::mesh::io::{read_mesh, resolve};
use meshcodec::mesh::quantize::GridShape;
use std::time::Duration;

fn codec_throughput(c: &mut Criterion) {
    for codec in ["emc", "emc-paper"] {
        throughput_of(c, codec);
    }
}

fn throughput_of(c: &mut Criterion, codec: &str) {
    let mut group = c.benchmark_group(codec);
    group
        .sample_size(20)
        .measurement_time(Duration::from_secs(8));
    let emc = codecs::by_name(codec).unwrap();
    for name in ["bunny", "armadillo-43k"] {
        let mesh = read_mesh(&resolve(name).unwrap()).unwrap();
        for bits in [12u8, 24] {
            let options = EncodeOptions {
                quant_bits: bits,
                grid: GridShape::Cubic,
            };
            let canonical = codecs::canonical_for(&mesh, &options).unwrap();
            let bytes = emc.encode(&canonical).unwrap().bytes;
            group.throughput(Throughput::Elements(canonical.vertex_count() as u64));
            let id = format!("{name}/{bits} levels");
            group.bench_function(BenchmarkId::new("encode", &id), |b| {
                b.iter(|| emc.encode(&canonical).unwrap())
            });
            group.bench_function(BenchmarkId::new("decode", &id), |b| {
                b.iter(|| codecs::decode(&bytes, Stop::All).unwrap())
            });
        }
    }
    group.finish();
}

criterion_group!(benches, codec_throughput);
criterion_main!(benches);
