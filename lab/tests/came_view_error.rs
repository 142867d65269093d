//! The promise of `came`'s view-dependent refinement (docs/CONTRACT.md §8): in any view, the
//! adapted mesh lies within the tolerance of the full decode on the screen, both ways, measured
//! over every sample in the frustum (`meshcodec_lab::came::screen_error`) — and it is not far more exact
//! than asked (the front does not keep a vertex per pixel).

use glam::DVec3;
use meshcodec::codecs::came::refine::{Budget, Camera, View, ViewMesh};
use meshcodec::codecs::{self, EncodeOptions};
use meshcodec::mesh::io::{read_mesh, resolve};
use meshcodec::mesh::quantize::GridShape;
use meshcodec_lab::came::screen_error::FullMesh;

#[test]
fn random_views_stay_within_the_tolerance_of_the_full_decode() {
    let mesh = read_mesh(&resolve("bunny").unwrap()).unwrap();
    let options = EncodeOptions {
        quant_bits: 12,
        grid: GridShape::Cubic,
    };
    let canonical = codecs::canonical_for(&mesh, &options).unwrap();
    let stream = codecs::by_name("came")
        .unwrap()
        .encode(&canonical)
        .unwrap()
        .bytes;
    let mut full = ViewMesh::from_stream(&stream).unwrap();
    full.settle(&View::everything(), Budget::UNLIMITED, 256);
    let full_mesh = full.mesh();
    let full = FullMesh::new(&full_mesh);
    let bounds = full_mesh.referenced_bounds().unwrap();
    let (centre, diagonal) = (
        (bounds.min + bounds.max) / 2.0,
        (bounds.max - bounds.min).length(),
    );
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut means = Vec::new();
    for i in 0..10 {
        let z: f64 = 2.0 * next() - 1.0;
        let turn = std::f64::consts::TAU * next();
        let direction = DVec3::new(
            (1.0 - z * z).sqrt() * turn.cos(),
            z,
            (1.0 - z * z).sqrt() * turn.sin(),
        );
        let distance = diagonal * (0.7 + 12.0 * next() * next());
        let camera = Camera {
            eye: centre + direction * distance,
            target: centre + (DVec3::new(next(), next(), next()) - 0.5) * 0.3 * diagonal,
            up: DVec3::Y,
            fov_degrees: 50.0,
            width: 1280,
            height: 720,
        };
        let tolerance = if i % 3 == 2 { 3.0 } else { 1.0 };
        for guard in [false, true] {
            let view = View::new(&camera, tolerance)
                .unwrap()
                .two_sided(true)
                .keep_orientation(guard);
            let mut front = ViewMesh::from_stream(&stream).unwrap();
            assert!(front.settle(&view, Budget::UNLIMITED, 256).settled);
            front.check_invariants().unwrap();
            let error = full.screen_error(&front.mesh(), &camera, &view);
            assert!(
                error.max_px <= tolerance,
                "view {i} (eye {:?}, {tolerance} px, guard {guard}): {:.3} px over {} samples",
                camera.eye,
                error.max_px,
                error.samples
            );
            means.push(error.mean_px / tolerance);
        }
    }
    // Not a vertex per pixel: the error the tolerance allows is used.
    let mean = means.iter().sum::<f64>() / means.len() as f64;
    assert!(mean > 0.05, "mean error {mean:.3} of the tolerance");
}
