//! One view of a `came` stream, with and without the orientation guard: faces, adaptation
//! time, bytes read, fold-overs in the frustum (and those spanning the tolerance), and the
//! measured screen-space error both ways (`meshcodec_lab::came::screen_error`), two-sided, 1280x720, 50°.
//! Run: cargo run --release --example came_vd_probe -- STREAM EYE TARGET [TOLERANCE]
//! (EYE and TARGET as x,y,z.)
use glam::DVec3;
use meshcodec::codecs::came::refine::{Budget, Camera, View, ViewMesh};
use meshcodec_lab::came::screen_error::FullMesh;
use std::collections::HashMap;
use std::time::Instant;

fn point(s: &str) -> Result<DVec3, Box<dyn std::error::Error>> {
    let v: Vec<f64> = s.split(',').map(str::parse).collect::<Result<_, _>>()?;
    match v[..] {
        [x, y, z] => Ok(DVec3::new(x, y, z)),
        _ => Err(format!("{s}: x,y,z expected").into()),
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 4 {
        return Err("usage: came_vd_probe STREAM EYE TARGET [TOLERANCE]".into());
    }
    let bytes = std::fs::read(&args[1])?;
    let camera = Camera {
        eye: point(&args[2])?,
        target: point(&args[3])?,
        up: DVec3::Y,
        fov_degrees: 50.0,
        width: 1280,
        height: 720,
    };
    let tolerance: f64 = args.get(4).map_or(Ok(1.0), |s| s.parse())?;
    let mut full = ViewMesh::from_stream(&bytes)?;
    full.settle(&View::everything(), Budget::UNLIMITED, 256);
    // The full mesh's triangles by birth, with their corners' positions.
    let counterparts: HashMap<(u64, u32), [DVec3; 3]> = full
        .present_triangles()
        .map(|t| ((t.birth.0.packed(), t.birth.1), t.at))
        .collect();
    let full_mesh = full.mesh();
    let reference = FullMesh::new(&full_mesh);
    for guard in [true, false] {
        let view = View::new(&camera, tolerance)?
            .two_sided(true)
            .keep_orientation(guard);
        let mut front = ViewMesh::from_stream(&bytes)?;
        let started = Instant::now();
        front.settle(&view, Budget::UNLIMITED, 256);
        let ms = started.elapsed().as_secs_f64() * 1e3;
        let normal = |p: [DVec3; 3]| (p[1] - p[0]).cross(p[2] - p[0]);
        let (mut folded, mut shown) = (0, 0);
        for t in front.present_triangles() {
            let at = t.at;
            let counterpart = counterparts[&(t.birth.0.packed(), t.birth.1)];
            let full_normal = normal(counterpart);
            // A zero-area triangle of the full mesh turns no way.
            if full_normal != DVec3::ZERO
                && view.sees_triangle(at)
                && normal(at).dot(full_normal) <= 0.0
            {
                folded += 1;
                shown += view.shows_triangle(at) as usize;
            }
        }
        let error = reference.screen_error(&front.mesh(), &camera, &view);
        let fetched = front.fetched();
        println!(
            "guard {guard}: {} faces, {ms:.1} ms, {} bytes read, {:.2}% of {} ({} of {} units), {folded} folded in the frustum ({shown} spanning the tolerance), error max {:.3} px, mean {:.3} px",
            front.face_count(),
            fetched.bytes_read,
            100.0 * fetched.bytes_read as f64 / fetched.stream_bytes as f64,
            fetched.stream_bytes,
            fetched.units_loaded,
            fetched.units,
            error.max_px,
            error.mean_px,
        );
        println!(
            "  largest error at {:?}, a sample of the {} mesh",
            error.worst_at,
            if error.worst_on_full {
                "full"
            } else {
                "adapted"
            }
        );
    }
    Ok(())
}
