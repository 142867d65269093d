//! View-dependent refinement of a `came` stream: a front moved back and forth between two views
//! of dragon-50k at 12 bits (1 px, 1280×720, one core, the stream in memory, every meta-node
//! either view needs loaded before timing), with the orientation guard and without. Each
//! iteration adapts to the other view until the front settles and back, the same splits and
//! collapses every time, so that the cost of an operation is measured apart from the machine's
//! caches between frames and from meta-node fetches (the fly-through's figures include both:
//! docs/notes/benchmarks-history.md, "The fly-through's front timed alone").
//! Run: cargo bench --bench came_view

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use glam::DVec3;
use meshcodec::codecs::came::refine::{Adapted, Budget, Camera, View, ViewMesh};
use meshcodec::codecs::{self, EncodeOptions};
use meshcodec::mesh::io::{read_mesh, resolve};
use meshcodec::mesh::quantize::GridShape;
use std::time::Duration;

/// The two eyes: 1.5 diagonals from the centre, and 0.6 diagonals from a direction turned by
/// 40° about the vertical, both looking at the centre.
fn cameras(centre: DVec3, diagonal: f64) -> [Camera; 2] {
    let camera = |distance: f64, turn_degrees: f64| {
        let turn = turn_degrees.to_radians();
        let towards = DVec3::new(turn.sin(), 0.35, turn.cos()).normalize();
        Camera {
            eye: centre + towards * distance * diagonal,
            target: centre,
            up: DVec3::Y,
            fov_degrees: 50.0,
            width: 1280,
            height: 720,
        }
    };
    [camera(1.5, 0.0), camera(0.6, 40.0)]
}

fn settle(front: &mut ViewMesh, view: &View) -> Adapted {
    front.settle(view, Budget::UNLIMITED, 256)
}

fn view_changes(c: &mut Criterion) {
    let mesh = read_mesh(&resolve("dragon-50k").unwrap()).unwrap();
    let options = EncodeOptions {
        quant_bits: 12,
        grid: GridShape::Cubic,
    };
    let canonical = codecs::canonical_for(&mesh, &options).unwrap();
    let bytes = codecs::by_name("came")
        .unwrap()
        .encode(&canonical)
        .unwrap()
        .bytes;
    let bounds = canonical.to_mesh().referenced_bounds().unwrap();
    let [far, near] = cameras(
        (bounds.min + bounds.max) / 2.0,
        (bounds.max - bounds.min).length(),
    );
    let mut group = c.benchmark_group("came view change");
    group
        .sample_size(20)
        .measurement_time(Duration::from_secs(8));
    for guard in [true, false] {
        let views =
            [&far, &near].map(|camera| View::new(camera, 1.0).unwrap().keep_orientation(guard));
        let mut front = ViewMesh::from_stream(&bytes).unwrap();
        // Load what both views need, and reach the steady back-and-forth.
        for _ in 0..2 {
            settle(&mut front, &views[1]);
            settle(&mut front, &views[0]);
        }
        let there = settle(&mut front, &views[1]);
        let faces_there = front.face_count();
        let back = settle(&mut front, &views[0]);
        let operations = there.splits + there.collapses + back.splits + back.collapses;
        eprintln!(
            "guard {guard}: {faces_there} and {} faces, {operations} splits and collapses an iteration",
            front.face_count()
        );
        group.throughput(Throughput::Elements(operations as u64));
        let id = if guard { "guard on" } else { "guard off" };
        group.bench_function(BenchmarkId::new("dragon-50k there and back", id), |b| {
            b.iter(|| {
                settle(&mut front, &views[1]);
                settle(&mut front, &views[0])
            })
        });
    }
    group.finish();
}

criterion_group!(benches, view_changes);
criterion_main!(benches);
