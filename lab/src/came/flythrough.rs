//! The CAME fly-through: a scripted camera path of [`FRAMES`] views around and into a mesh of
//! over a million triangles (the large mesh of the CAME tables), its `came` stream read from a
//! file meta-node by meta-node as the views need them (the loader thread). Per frame: active
//! faces, splits and collapses, adaptation time, bytes fetched so far, the share of the surface
//! in view, and the measured screen-space error against the tolerance.
//!
//! The path's front (one-sided, with the orientation guard) and the same front without the
//! guard are each timed along the whole path alone, as a client adapts its one front: nothing
//! runs between their frames ([`fly_alone`]). Then both fly the path again beside a third
//! front that follows the same views two-sided (no back-face culling), for what is measured of
//! each frame: fold-overs, the two-sided front's faces and bytes, and the measured error of a
//! frame — the two-sided front against the full mesh on the screen, both ways, over every
//! sample in the frustum (`crate::came::screen_error`, docs/CONTRACT.md §8). Fold-overs "in
//! view" are those spanning the tolerance in the frustum, what the orientation guard promises
//! to leave none of.
//!
//! Writes results/came/flythrough.{json,csv}, the series as a chart (flythrough.{png,svg}: faces,
//! fold-overs, work, the stream fetched so far and the bytes each frame read, the error), and
//! renders of the farthest and nearest frames, adapted and full.

use crate::came::extras::{table_mesh, QUANT_BITS, TABLE_MESHES};
use crate::came::screen_error::FullMesh;
use crate::came::vd::{nearest_depth, pixel_size};
use crate::plot::{Chart, Mark, Series};
use crate::render::{render_perspective, Perspective};
use glam::DVec3;
use meshcodec::codecs::came::refine::{Budget, Camera, View, ViewMesh};
use meshcodec::codecs::{self, EncodeOptions};
use meshcodec::error::{Error, Result};
use meshcodec::mesh::io::write_atomically;
use meshcodec::mesh::quantize::GridShape;
use meshcodec::mesh::{CanonicalMesh, TriMesh};
use plotters::prelude::SeriesLabelPosition;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Views along the path.
pub const FRAMES: usize = 100;
/// Frames orbiting the mesh before flying in.
pub const ORBIT_FRAMES: usize = 40;
/// Screen-space tolerance τ.
pub const TOLERANCE_PX: f64 = 1.0;
/// Viewport and field of view.
pub const WIDTH: u32 = 1024;
pub const HEIGHT: u32 = 768;
pub const FOV_DEGREES: f64 = 45.0;
/// The command that makes it.
pub const COMMAND: &str = "cargo run --release --bin experiment -- came-fly";

/// One view of the path.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Frame {
    pub frame: usize,
    pub eye: [f64; 3],
    pub target: [f64; 3],
    /// The path's front (one-sided, with the orientation guard), timed alone.
    #[serde(flatten)]
    pub front: Timed,
    /// Faces of the two-sided front (no back-face culling) in the same view, and its
    /// adaptation time (meta-node waits included).
    pub faces_two_sided: usize,
    pub settle_ms_two_sided: f64,
    /// Bytes the two-sided front has read so far.
    pub bytes_fetched_two_sided: u64,
    /// Share of the full mesh's surface (by area) inside the view frustum.
    pub surface_in_view: f64,
    /// Present faces turned over against the same triangle of the full mesh (their normals
    /// 90° or more apart): fold-overs. The orientation guard keeps them out of view.
    pub fold_overs: usize,
    /// Of those, the ones whose full-mesh triangle faces the eye.
    pub fold_overs_facing: usize,
    /// Of those, the ones meeting the view frustum (0 by the guard).
    pub fold_overs_in_view: usize,
    /// The same front without the orientation guard (`View::keep_orientation(false)`): faces,
    /// adaptation time (meta-node waits excluded), splits + collapses, fold-overs in view and
    /// those of them whose full-mesh triangle faces the eye.
    pub faces_unguarded: usize,
    pub adapt_ms_unguarded: f64,
    pub operations_unguarded: usize,
    pub fold_overs_in_view_unguarded: usize,
    pub fold_overs_in_view_facing_unguarded: usize,
    /// Samples in the frustum (both ways: the full mesh's vertices and face centroids, the
    /// two-sided front's face centroids and edge midpoints), and the measured screen-space
    /// error of the two-sided front over them (`crate::came::screen_error`).
    pub error_samples: usize,
    pub max_error_px: f64,
    pub mean_error_px: f64,
    /// A pixel's size at the least depth of the full mesh's vertices in view
    /// ([`crate::came::vd::nearest_depth`]): the tolerance a view-independent mesh keeps.
    #[serde(default)]
    pub pixel_at_nearest: f64,
}

/// One view from a cold start: what it alone fetches.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ColdView {
    /// The frame of the path it repeats.
    pub frame: usize,
    pub surface_in_view: f64,
    pub bytes_read: u64,
    pub units_loaded: usize,
    /// Bytes read over the stream's bytes.
    pub share_of_stream: f64,
    /// The same, two-sided (no back-face culling).
    pub bytes_read_two_sided: u64,
    pub share_of_stream_two_sided: f64,
}

/// The whole run.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Flythrough {
    pub command: String,
    pub mesh: String,
    pub subdivisions: u32,
    pub vertices: usize,
    pub triangles: usize,
    pub quant_bits: u8,
    pub stream_bytes: u64,
    pub units: usize,
    pub tolerance_px: f64,
    pub width: u32,
    pub height: u32,
    pub fov_degrees: f64,
    /// Splits plus collapses per second of adaptation over the path.
    pub operations_per_second: f64,
    /// The same without the orientation guard.
    pub operations_per_second_unguarded: f64,
    pub frames: Vec<Frame>,
    /// Frames where the fronts flown again for the measurements hold other face counts than
    /// the timed ones: a front numbers the nodes of the meta-nodes it takes in in the order the
    /// loader thread finished them, and its passes follow that order, so two fronts of one path
    /// may settle a few faces apart (frame 34 of one run: 32,668 against 32,672).
    #[serde(default)]
    pub fronts_differ: usize,
    /// The frame whose view holds the share of the surface nearest a tenth, from a cold start.
    pub tenth_of_surface: ColdView,
}

/// The camera of frame `i`: an orbit at three bounding radii, then a flight (geometric in
/// distance) to `close` above the surface point `spot`, the target gliding from the centre to it.
fn camera_at(i: usize, centre: DVec3, radius: f64, spot: DVec3) -> Camera {
    let lift = 0.3;
    let orbit =
        |angle: f64| centre + 3.0 * radius * DVec3::new(angle.sin(), lift, angle.cos()).normalize();
    let (eye, target) = if i < ORBIT_FRAMES {
        let angle = std::f64::consts::TAU * i as f64 / ORBIT_FRAMES as f64;
        (orbit(angle), centre)
    } else {
        let t = (i - ORBIT_FRAMES + 1) as f64 / (FRAMES - ORBIT_FRAMES) as f64;
        let start = orbit(0.0);
        let away = (start - spot).normalize();
        let (far, near) = ((start - spot).length(), 0.12 * radius);
        let distance = far * (near / far).powf(t);
        let smooth = t * t * (3.0 - 2.0 * t);
        (spot + away * distance, centre.lerp(spot, smooth))
    };
    Camera {
        eye,
        target,
        up: DVec3::Y,
        fov_degrees: FOV_DEGREES,
        width: WIDTH,
        height: HEIGHT,
    }
}

/// The path's [`FRAMES`] cameras around and into `full`: the orbit about its bounding box's
/// centre, then the flight to the surface point farthest along the orbit's first direction.
pub fn cameras(full: &TriMesh) -> Result<Vec<Camera>> {
    let (centre, diagonal, spot) = crate::came::vd::framing(full)?;
    let radius = diagonal / 2.0;
    Ok((0..FRAMES)
        .map(|i| camera_at(i, centre, radius, spot))
        .collect())
}

/// The full mesh's triangles as centroid and area, once for every frame's share in view.
fn centroids_and_areas(mesh: &TriMesh) -> Vec<(DVec3, f64)> {
    mesh.faces
        .iter()
        .map(|f| {
            let [a, b, c] = mesh.corners(*f);
            ((a + b + c) / 3.0, (b - a).cross(c - a).length())
        })
        .collect()
}

/// Share of the surface (`triangles`: centroids and areas) whose triangles' centroids `view`
/// sees.
fn surface_in_view(triangles: &[(DVec3, f64)], view: &View) -> f64 {
    let all: f64 = triangles.iter().map(|t| t.1).sum();
    let seen: f64 = triangles
        .iter()
        .filter(|t| view.sees(t.0, 0.0))
        .map(|t| t.1)
        .sum();
    if all > 0.0 {
        seen / all
    } else {
        0.0
    }
}

/// The full mesh's triangles by birth ([`meshcodec::codecs::came::refine::PresentTriangle`]'s,
/// the path packed), with their corners' positions.
type Counterparts = std::collections::HashMap<(u64, u32), [DVec3; 3]>;

/// Fold-overs of a front.
#[derive(Clone, Copy, Default)]
struct FoldOvers {
    all: usize,
    /// Whose full-resolution counterpart faces the eye.
    facing: usize,
    /// Meeting the view frustum ([`View::sees_triangle`], the guard's test).
    in_view: usize,
    in_view_facing: usize,
}

/// Present faces of `front` whose normal makes 90° or more with their full-resolution
/// counterpart's (`full`), seen from `view`.
fn fold_overs(front: &ViewMesh, full: &Counterparts, view: &View) -> FoldOvers {
    let normal = |p: [DVec3; 3]| (p[1] - p[0]).cross(p[2] - p[0]);
    let mut out = FoldOvers::default();
    for t in front.present_triangles() {
        let adapted = t.at;
        let key = (t.birth.0.packed(), t.birth.1);
        let full = full.get(&key).copied().unwrap_or([DVec3::ZERO; 3]);
        let n = normal(full);
        if normal(adapted).dot(n) <= 0.0 && n != DVec3::ZERO {
            let facing = (full[0] - view.eye()).dot(n) < 0.0;
            // In view: spanning the tolerance in the frustum (what the guard promises).
            let in_view = view.shows_triangle(adapted);
            out.all += 1;
            out.facing += facing as usize;
            out.in_view += in_view as usize;
            out.in_view_facing += (in_view && facing) as usize;
        }
    }
    out
}

/// The stream's path under the system's temporary folder (the stream is rebuilt each run and
/// not kept: it is 4 MB).
fn stream_path() -> PathBuf {
    std::env::temp_dir().join(format!("meshcodec-flythrough-{}.mc", std::process::id()))
}

/// The fly-through's mesh (bunny-closed-35k subdivided twice) on its grid, and its `came`
/// stream.
pub fn encode_stream() -> Result<(CanonicalMesh, Vec<u8>)> {
    let (name, subdivisions) = TABLE_MESHES[3];
    let (_, mesh) = table_mesh(name, subdivisions)?;
    let options = EncodeOptions {
        quant_bits: QUANT_BITS,
        grid: GridShape::Cubic,
    };
    let canonical = codecs::canonical_for(&mesh, &options)?;
    let stream = codecs::by_name("came")?.encode(&canonical)?.bytes;
    Ok((canonical, stream))
}

/// Runs the fly-through and writes its results under `results/came/`; `log` gets one line per
/// step and a line every ten frames.
pub fn run(results: &Path, log: &mut dyn FnMut(String)) -> Result<PathBuf> {
    let (name, subdivisions) = TABLE_MESHES[3];
    let started = Instant::now();
    let (canonical, stream) = encode_stream()?;
    log(format!(
        "{name} x{}: {} triangles, came stream {} bytes in {:.1} s",
        4u32.pow(subdivisions),
        canonical.face_count(),
        stream.len(),
        started.elapsed().as_secs_f64()
    ));
    // `came` is lossless: its full decode is the canonical mesh.
    let full = canonical.to_mesh();
    let path = stream_path();
    std::fs::write(&path, &stream)?;
    let outcome = fly(results, &path, &full, stream.len() as u64, log);
    let _ = std::fs::remove_file(&path);
    let mut report = outcome?;
    report.mesh = name.to_string();
    report.subdivisions = subdivisions;
    report.vertices = canonical.vertex_count();
    report.triangles = canonical.face_count();
    let out = results.join("came").join("flythrough.json");
    let json = serde_json::to_string_pretty(&report).map_err(|e| Error::Io(e.into()))?;
    write_atomically(&out, format!("{json}\n").as_bytes())?;
    write_atomically(&out.with_extension("csv"), csv(&report).as_bytes())?;
    Chart::draw_panels(&chart(&report), 2, &results.join("came").join("flythrough"))?;
    Ok(out)
}

/// One front's frame, adapted with nothing else running between its frames ([`fly_alone`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Timed {
    /// Faces and vertices once settled.
    pub faces: usize,
    pub vertices: usize,
    pub splits: usize,
    pub collapses: usize,
    /// Passes over the active nodes, and adaptations (one more after each wait).
    pub passes: usize,
    pub adaptations: usize,
    /// Time in adaptation, and waiting for meta-nodes.
    pub adapt_ms: f64,
    pub wait_ms: f64,
    /// Faces in view left not certain of their orientation (`Adapted::unsure`).
    pub unsure: usize,
    /// Bytes read from the stream's file so far, and meta-nodes decoded.
    pub bytes_fetched: u64,
    pub units_loaded: usize,
}

/// One front along the path, alone: adapt, wait for the meta-nodes it asked for, adapt again,
/// until it settles, frame after frame, with no other work between — as a client adapts its
/// front. (Measured between the error measurement and the other fronts, a front's records are
/// out of the cache when its frame starts, and on two cores the other fronts' loader threads
/// compete with it: `came_fly_adapt` measured the same front 2–3× faster alone.)
pub fn fly_alone(path: &Path, cameras: &[Camera], guard: bool) -> Result<Vec<Timed>> {
    let mut front = ViewMesh::open_file(path)?;
    let mut frames = Vec::with_capacity(cameras.len());
    for camera in cameras {
        let view = View::new(camera, TOLERANCE_PX)?.keep_orientation(guard);
        let mut timed = Timed::default();
        for _ in 0..256 {
            let started = Instant::now();
            let done = front.adapt(&view, Budget::UNLIMITED);
            timed.adapt_ms += started.elapsed().as_secs_f64() * 1e3;
            timed.splits += done.splits;
            timed.collapses += done.collapses;
            timed.passes += done.passes;
            timed.adaptations += 1;
            timed.unsure = done.unsure;
            if done.settled {
                break;
            }
            let started = Instant::now();
            front.wait_for_units();
            timed.wait_ms += started.elapsed().as_secs_f64() * 1e3;
        }
        let fetched = front.fetched();
        timed.faces = front.face_count();
        timed.vertices = front.vertex_count();
        timed.bytes_fetched = fetched.bytes_read;
        timed.units_loaded = fetched.units_loaded;
        frames.push(timed);
    }
    Ok(frames)
}

/// Splits plus collapses per second of adaptation over the path.
fn operations_per_second(frames: &[Timed]) -> f64 {
    let operations: usize = frames.iter().map(|f| f.splits + f.collapses).sum();
    let ms: f64 = frames.iter().map(|f| f.adapt_ms).sum();
    operations as f64 / (ms / 1e3).max(1e-9)
}

/// Adapts along the path with the stream read from `path`: the front with the orientation
/// guard and the one without, each timed alone ([`fly_alone`]), then the two again beside the
/// two-sided front for what is measured of each frame (fold-overs; faces and time are the timed
/// fronts'). The fronts flown again may differ by a few faces ([`Flythrough::fronts_differ`]).
fn fly(
    results: &Path,
    path: &Path,
    full: &TriMesh,
    stream_bytes: u64,
    log: &mut dyn FnMut(String),
) -> Result<Flythrough> {
    let cameras = cameras(full)?;
    let guarded = fly_alone(path, &cameras, true)?;
    let free = fly_alone(path, &cameras, false)?;
    // The reference for fold-overs: every triangle of the stream refined everywhere.
    let mut whole = ViewMesh::open_file(path)?;
    whole.settle(&View::everything(), Budget::UNLIMITED, 256);
    let at: Counterparts = whole
        .present_triangles()
        .map(|t| ((t.birth.0.packed(), t.birth.1), t.at))
        .collect();
    drop(whole);
    let triangles = centroids_and_areas(full);
    let reference = FullMesh::new(full);
    let mut front = ViewMesh::open_file(path)?;
    let mut two_sided = ViewMesh::open_file(path)?;
    let mut unguarded = ViewMesh::open_file(path)?;
    let units = front.fetched().units;
    let mut frames = Vec::with_capacity(FRAMES);
    let mut fronts_differ = 0;
    for (i, &camera) in cameras.iter().enumerate() {
        let view = View::new(&camera, TOLERANCE_PX)?;
        let free_view = view.clone().keep_orientation(false);
        front.settle(&view, Budget::UNLIMITED, 256);
        unguarded.settle(&free_view, Budget::UNLIMITED, 256);
        let (timed, timed_free) = (guarded[i], free[i]);
        if (front.face_count(), unguarded.face_count()) != (timed.faces, timed_free.faces) {
            fronts_differ += 1;
            log(format!(
                "frame {i}: the fronts flown again hold {} and {} faces, the timed ones {} and {}",
                front.face_count(),
                unguarded.face_count(),
                timed.faces,
                timed_free.faces
            ));
        }
        let started = Instant::now();
        two_sided.settle(&view.clone().two_sided(true), Budget::UNLIMITED, 256);
        let settle_ms_two_sided = started.elapsed().as_secs_f64() * 1e3;
        let folds = fold_overs(&front, &at, &view);
        let folds_unguarded = fold_overs(&unguarded, &at, &view);
        let error = reference.screen_error(&two_sided.mesh(), &camera, &view);
        let (max_error_px, mean_error_px, error_samples) =
            (error.max_px, error.mean_px, error.samples);
        let pixel_at_nearest = nearest_depth(full, &camera, &view)
            .map_or(0.0, |z| pixel_size(&camera, z) * TOLERANCE_PX);
        let frame = Frame {
            frame: i,
            eye: camera.eye.to_array(),
            target: camera.target.to_array(),
            front: timed,
            faces_two_sided: two_sided.face_count(),
            settle_ms_two_sided,
            bytes_fetched_two_sided: two_sided.fetched().bytes_read,
            surface_in_view: surface_in_view(&triangles, &view),
            fold_overs: folds.all,
            fold_overs_facing: folds.facing,
            fold_overs_in_view: folds.in_view,
            faces_unguarded: timed_free.faces,
            adapt_ms_unguarded: timed_free.adapt_ms,
            operations_unguarded: timed_free.splits + timed_free.collapses,
            fold_overs_in_view_unguarded: folds_unguarded.in_view,
            fold_overs_in_view_facing_unguarded: folds_unguarded.in_view_facing,
            error_samples,
            max_error_px,
            mean_error_px,
            pixel_at_nearest,
        };
        if i % 10 == 0 || i + 1 == FRAMES {
            log(format!(
                "frame {i}: {} faces ({} two-sided, {} without the orientation guard), {} folded over ({} in view; unguarded {} in view, {} of them facing the eye), {} splits, {} collapses, {} passes, {:.1} ms, {:.1}% of the stream fetched, error {:.2} px max ({:.2} mean) over {} samples",
                frame.front.faces,
                frame.faces_two_sided,
                frame.faces_unguarded,
                frame.fold_overs,
                frame.fold_overs_in_view,
                frame.fold_overs_in_view_unguarded,
                frame.fold_overs_in_view_facing_unguarded,
                timed.splits,
                timed.collapses,
                timed.passes,
                timed.adapt_ms,
                100.0 * timed.bytes_fetched as f64 / stream_bytes as f64,
                max_error_px,
                mean_error_px,
                error_samples
            ));
        }
        if i == 0 || i + 1 == FRAMES {
            let which = if i == 0 { "far" } else { "near" };
            let perspective = Perspective {
                eye: camera.eye,
                target: camera.target,
                up: camera.up,
                fov_degrees: camera.fov_degrees,
            };
            let folder = results.join("came");
            render_perspective(&front.mesh(), &perspective, WIDTH, HEIGHT)
                .save_png(&folder.join(format!("flythrough-{which}.png")))?;
            render_perspective(full, &perspective, WIDTH, HEIGHT)
                .save_png(&folder.join(format!("flythrough-{which}-full.png")))?;
        }
        frames.push(frame);
    }
    drop(front);
    drop(two_sided);
    drop(unguarded);
    // The view nearest a tenth of the surface, alone from a cold start.
    let tenth = frames
        .iter()
        .min_by(|a, b| {
            (a.surface_in_view - 0.1)
                .abs()
                .total_cmp(&(b.surface_in_view - 0.1).abs())
        })
        .ok_or_else(|| Error::mesh("no frames"))?;
    let camera = cameras[tenth.frame];
    let mut cold = ViewMesh::open_file(path)?;
    cold.settle(&View::new(&camera, TOLERANCE_PX)?, Budget::UNLIMITED, 256);
    let fetched = cold.fetched();
    drop(cold);
    let mut cold = ViewMesh::open_file(path)?;
    let two = View::new(&camera, TOLERANCE_PX)?.two_sided(true);
    cold.settle(&two, Budget::UNLIMITED, 256);
    let bytes_read_two_sided = cold.fetched().bytes_read;
    let tenth_of_surface = ColdView {
        frame: tenth.frame,
        surface_in_view: tenth.surface_in_view,
        bytes_read: fetched.bytes_read,
        units_loaded: fetched.units_loaded,
        share_of_stream: fetched.bytes_read as f64 / stream_bytes as f64,
        bytes_read_two_sided,
        share_of_stream_two_sided: bytes_read_two_sided as f64 / stream_bytes as f64,
    };
    log(format!(
        "frame {} alone ({:.1}% of the surface in view): {} bytes, {:.1}% of the stream ({:.1}% two-sided)",
        tenth.frame,
        100.0 * tenth.surface_in_view,
        fetched.bytes_read,
        100.0 * tenth_of_surface.share_of_stream,
        100.0 * tenth_of_surface.share_of_stream_two_sided
    ));
    Ok(Flythrough {
        command: COMMAND.to_string(),
        mesh: String::new(),
        subdivisions: 0,
        vertices: 0,
        triangles: full.face_count(),
        quant_bits: QUANT_BITS,
        stream_bytes,
        units,
        tolerance_px: TOLERANCE_PX,
        width: WIDTH,
        height: HEIGHT,
        fov_degrees: FOV_DEGREES,
        operations_per_second: operations_per_second(&guarded),
        operations_per_second_unguarded: operations_per_second(&free),
        frames,
        fronts_differ,
        tenth_of_surface,
    })
}

fn csv(report: &Flythrough) -> String {
    let mut out = String::from(
        "frame,faces,vertices,faces_two_sided,splits,collapses,passes,adaptations,adapt_ms,wait_ms,bytes_fetched,units_loaded,bytes_fetched_two_sided,surface_in_view,fold_overs,fold_overs_facing,fold_overs_in_view,unsure,faces_unguarded,adapt_ms_unguarded,operations_unguarded,fold_overs_in_view_unguarded,fold_overs_in_view_facing_unguarded,error_samples,max_error_px,mean_error_px,pixel_at_nearest\n",
    );
    for f in &report.frames {
        out += &format!(
            "{},{},{},{},{},{},{},{},{:.3},{:.3},{},{},{},{:.5},{},{},{},{},{},{:.3},{},{},{},{},{:.4},{:.4},{:.6e}\n",
            f.frame,
            f.front.faces,
            f.front.vertices,
            f.faces_two_sided,
            f.front.splits,
            f.front.collapses,
            f.front.passes,
            f.front.adaptations,
            f.front.adapt_ms,
            f.front.wait_ms,
            f.front.bytes_fetched,
            f.front.units_loaded,
            f.bytes_fetched_two_sided,
            f.surface_in_view,
            f.fold_overs,
            f.fold_overs_facing,
            f.fold_overs_in_view,
            f.front.unsure,
            f.faces_unguarded,
            f.adapt_ms_unguarded,
            f.operations_unguarded,
            f.fold_overs_in_view_unguarded,
            f.fold_overs_in_view_facing_unguarded,
            f.error_samples,
            f.max_error_px,
            f.mean_error_px,
            f.pixel_at_nearest
        );
    }
    out
}

/// The series against the frame: faces; operations; adaptation time; bytes fetched; the
/// measured error with the tolerance.
pub fn chart(report: &Flythrough) -> Vec<Chart> {
    let series = |label: &str, y: &dyn Fn(&Frame) -> f64| Series {
        label: label.to_string(),
        points: report
            .frames
            .iter()
            .map(|f| (f.frame as f64, y(f)))
            .collect(),
        mark: Mark::Line,
    };
    // What a frame read beyond the frames before it, in kB (a frame that read nothing sits at
    // the floor of the log axis, 0.01 kB).
    let per_frame = |label: &str, total: &dyn Fn(&Frame) -> u64| Series {
        label: label.to_string(),
        points: report
            .frames
            .iter()
            .scan(0u64, |before, f| {
                let now = total(f);
                let read = now.saturating_sub(*before);
                *before = now;
                Some((f.frame as f64, (read as f64 / 1e3).max(0.01)))
            })
            .collect(),
        mark: Mark::Line,
    };
    let panel = |title: &str, y_desc: &str, y_log: bool, series: Vec<Series>| Chart {
        title: title.to_string(),
        x_desc: format!("frame (orbit to {}, then flying in)", ORBIT_FRAMES - 1),
        y_desc: y_desc.to_string(),
        x_log: false,
        y_log,
        series,
        legend: SeriesLabelPosition::UpperLeft,
    };
    vec![
        panel(
            "Adapted mesh",
            "faces",
            false,
            vec![
                series("active faces", &|f| f.front.faces as f64),
                series("two-sided (no back-face culling)", &|f| {
                    f.faces_two_sided as f64
                }),
                series("without the orientation guard", &|f| {
                    f.faces_unguarded as f64
                }),
            ],
        ),
        panel(
            "Fold-overs in view",
            "faces",
            false,
            vec![
                series("with the orientation guard", &|f| {
                    f.fold_overs_in_view as f64
                }),
                series("without", &|f| f.fold_overs_in_view_unguarded as f64),
                series("without, facing the eye", &|f| {
                    f.fold_overs_in_view_facing_unguarded as f64
                }),
            ],
        ),
        panel(
            "Work per frame",
            "operations, or ms (log)",
            true,
            vec![
                series("splits", &|f| f.front.splits as f64),
                series("collapses", &|f| f.front.collapses as f64),
                series("adapt time (ms)", &|f| f.front.adapt_ms),
                series("adapt time without the guard (ms)", &|f| {
                    f.adapt_ms_unguarded
                }),
            ],
        ),
        panel(
            "Stream fetched",
            "% of the stream's bytes, or of the surface",
            false,
            vec![
                series("bytes fetched so far", &|f| {
                    100.0 * f.front.bytes_fetched as f64 / report.stream_bytes as f64
                }),
                series("two-sided", &|f| {
                    100.0 * f.bytes_fetched_two_sided as f64 / report.stream_bytes as f64
                }),
                series("surface in view", &|f| 100.0 * f.surface_in_view),
            ],
        ),
        panel(
            "Bytes read per frame",
            "kB (log)",
            true,
            vec![
                per_frame("one-sided", &|f| f.front.bytes_fetched),
                per_frame("two-sided", &|f| f.bytes_fetched_two_sided),
            ],
        ),
        panel(
            "Measured screen-space error",
            "pixels",
            false,
            vec![
                series("largest", &|f| f.max_error_px),
                series("mean", &|f| f.mean_error_px),
                series("tolerance", &|_| report.tolerance_px),
            ],
        ),
    ]
}
