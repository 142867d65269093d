//! Distance throughput: 1M samples against a 1M-triangle surface (a torus), and the BVH build.
//! Run: cargo bench --bench distance

use criterion::{criterion_group, criterion_main, Criterion};
use meshcodec::mesh::generate;
use meshcodec::metrics::{sample_surface, SurfaceIndex};
use std::time::Duration;

fn distance(c: &mut Criterion) {
    // 1000 × 500 quads = 1,000,000 triangles.
    let surface = generate::torus(1.0, 0.35, 1000, 500);
    // Samples of a coarser, slightly fatter torus: every query lands near, not on, the surface.
    let other = generate::torus(1.0, 0.36, 300, 120);
    let samples = sample_surface(&other, 1_000_000, 7).points;
    let mut group = c.benchmark_group("distance");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(20));
    group.bench_function("bvh build, 1M triangles", |b| {
        b.iter(|| SurfaceIndex::of_mesh(&surface, &[]))
    });
    let index = SurfaceIndex::of_mesh(&surface, &[]);
    group.bench_function("1M samples x 1M triangles", |b| {
        b.iter(|| index.distances(&samples[..1_000_000]))
    });
    group.finish();
}

criterion_group!(benches, distance);
criterion_main!(benches);
