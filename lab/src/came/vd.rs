//! CAME's view-dependent table: a far, a middle and a near view of bunny.ply, dragon-50k and the
//! million-triangle mesh (the large mesh of the CAME tables), each adapted from a cold start,
//! two-sided (no back-face culling, so that nothing is left coarse for turning away) with the
//! orientation guard, at 1 px: faces, bytes read, adaptation time with the meta-node waits
//! apart, and the measured screen-space error against the full mesh (`crate::came::screen_error`).
//!
//! Beside each view, the size of a pixel at the nearest point in view (the least depth of the
//! full mesh's vertices in the frustum): an error that small anywhere in view shows within a
//! pixel. `experiments/meshopt_vd.py` gives that tolerance to meshoptimizer's simplifier, which
//! knows nothing of the view and simplifies uniformly, for the count a view-independent mesh
//! needs.
//!
//! Writes results/came/vd.json, renders of the far and near views (ours; the far view drawn from
//! the middle view's eye, so that what it holds can be seen) under results/came/vd/, and each
//! mesh's full decode as `<work>/<mesh>.ply` for the script.

use crate::came::extras::{table_mesh, QUANT_BITS, TABLE_MESHES};
use crate::came::screen_error::FullMesh;
use crate::render::{render_perspective, Perspective};
use glam::DVec3;
use meshcodec::codecs::came::refine::{Budget, Camera, View, ViewMesh};
use meshcodec::codecs::{self, EncodeOptions};
use meshcodec::error::{Error, Result};
use meshcodec::mesh::io::{write_atomically, write_mesh};
use meshcodec::mesh::quantize::GridShape;
use meshcodec::mesh::{Aabb, TriMesh};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The meshes: a shared mesh and how often it is subdivided (×4 faces each).
pub const MESHES: [(&str, u32); 3] = [("bunny", 0), ("dragon-50k", 0), TABLE_MESHES[3]];
/// The views: a name and the eye's distance in bounding-box diagonals (from the centre for
/// "far" and "middle", from the surface point nearest the eye along the path for "near").
pub const VIEWS: [(&str, f64); 3] = [("far", 20.0), ("middle", 1.5), ("near", 0.1)];
/// The camera and tolerance of `meshcodec view`'s defaults.
pub const WIDTH: u32 = 1280;
pub const HEIGHT: u32 = 720;
pub const FOV_DEGREES: f64 = 50.0;
pub const TOLERANCE_PX: f64 = 1.0;
/// The direction the eyes lie in from the mesh (the fly-through's first), unit length.
pub fn towards() -> DVec3 {
    DVec3::new(0.0, 0.3, 1.0).normalize()
}

/// Where the views of `mesh` are set: its bounding box's centre and diagonal, and the surface
/// point farthest [`towards`] the eyes (the near view's, and the fly-through's last).
pub fn framing(mesh: &TriMesh) -> Result<(DVec3, f64, DVec3)> {
    let empty = || Error::mesh("an empty mesh");
    let bounds = Aabb::around(mesh.positions.iter().copied()).ok_or_else(empty)?;
    let centre = (bounds.min + bounds.max) / 2.0;
    let along = |p: DVec3| (p - centre).dot(towards());
    let spot = mesh
        .positions
        .iter()
        .copied()
        .max_by(|a, b| along(*a).total_cmp(&along(*b)))
        .ok_or_else(empty)?;
    Ok((centre, (bounds.max - bounds.min).length(), spot))
}
/// The camera of view `name` (of [`VIEWS`], `diagonals` away) of a mesh whose [`framing`] is
/// (`centre`, `diagonal`, `spot`).
pub fn view_camera(
    name: &str,
    diagonals: f64,
    (centre, diagonal, spot): (DVec3, f64, DVec3),
) -> Camera {
    let target = if name == "near" { spot } else { centre };
    Camera {
        eye: target + towards() * diagonals * diagonal,
        target,
        up: DVec3::Y,
        fov_degrees: FOV_DEGREES,
        width: WIDTH,
        height: HEIGHT,
    }
}

/// The command that makes it.
pub const COMMAND: &str = "cargo run --release --bin experiment -- came-vd";

/// One view of one mesh.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct VdView {
    pub view: String,
    /// Eye distance in diagonals.
    pub diagonals: f64,
    pub eye: [f64; 3],
    pub target: [f64; 3],
    /// Least depth of the full mesh's vertices in the frustum, and a pixel's size there (the
    /// tolerance in the mesh's units a view-independent mesh needs to keep).
    pub nearest_depth: f64,
    pub pixel_at_nearest: f64,
    /// The adapted mesh, two-sided, orientation guard on.
    pub faces: usize,
    pub vertices: usize,
    /// The same view without the orientation guard.
    pub faces_unguarded: usize,
    /// Bytes read from the stream's file (header, the index as far as the meta-nodes read, and
    /// those meta-nodes), and their share.
    pub bytes_read: u64,
    pub units_loaded: usize,
    pub share_of_stream: f64,
    /// Time adapting (splits, collapses, view tests, taking in meta-nodes), time waiting for
    /// the meta-nodes asked for, and adaptations made (one more after each wait).
    pub adapt_ms: f64,
    pub wait_ms: f64,
    pub adaptations: usize,
    /// Measured screen-space error of the adapted mesh against the full one, both ways.
    pub max_error_px: f64,
    pub mean_error_px: f64,
    pub error_samples: usize,
    /// The render of the adapted mesh, under results/came/ (none for the middle view), and the
    /// camera it is drawn from.
    pub render: String,
    pub render_eye: [f64; 3],
    pub render_target: [f64; 3],
}

/// One mesh and its views.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct VdMesh {
    pub mesh: String,
    pub subdivisions: u32,
    pub vertices: usize,
    pub triangles: usize,
    pub stream_bytes: u64,
    pub diagonal: f64,
    /// The full decode, for meshoptimizer (not kept in the repository).
    pub full_mesh: String,
    pub views: Vec<VdView>,
}

/// The whole run.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct VdReport {
    pub command: String,
    pub quant_bits: u8,
    pub width: u32,
    pub height: u32,
    pub fov_degrees: f64,
    pub tolerance_px: f64,
    pub meshes: Vec<VdMesh>,
}

/// A pixel's size in the mesh's units at depth `depth`, for `camera`.
pub fn pixel_size(camera: &Camera, depth: f64) -> f64 {
    2.0 * depth * (camera.fov_degrees.to_radians() / 2.0).tan() / camera.height as f64
}

/// Least depth along the view direction of `mesh`'s vertices that `view` sees.
pub fn nearest_depth(mesh: &TriMesh, camera: &Camera, view: &View) -> Option<f64> {
    let forward = (camera.target - camera.eye).normalize_or_zero();
    mesh.positions
        .iter()
        .filter(|&&p| view.sees(p, 0.0))
        .map(|&p| (p - camera.eye).dot(forward))
        .filter(|&z| z > 0.0)
        .min_by(f64::total_cmp)
}

/// Runs every mesh's views; `work` gets the full decodes.
pub fn run(results: &Path, work: &Path, log: &mut dyn FnMut(String)) -> Result<PathBuf> {
    let folder = results.join("came");
    std::fs::create_dir_all(folder.join("vd"))?;
    std::fs::create_dir_all(work)?;
    let mut meshes = Vec::new();
    for (name, subdivisions) in MESHES {
        meshes.push(one_mesh(&folder, work, name, subdivisions, log)?);
    }
    let report = VdReport {
        command: COMMAND.to_string(),
        quant_bits: QUANT_BITS,
        width: WIDTH,
        height: HEIGHT,
        fov_degrees: FOV_DEGREES,
        tolerance_px: TOLERANCE_PX,
        meshes,
    };
    let out = folder.join("vd.json");
    let json = serde_json::to_string_pretty(&report).map_err(|e| Error::Io(e.into()))?;
    write_atomically(&out, format!("{json}\n").as_bytes())?;
    Ok(out)
}

/// The stem a mesh's files are named by.
pub fn stem(name: &str, subdivisions: u32) -> String {
    if subdivisions == 0 {
        name.to_string()
    } else {
        format!("{name}-x{}", 4u32.pow(subdivisions))
    }
}

fn one_mesh(
    folder: &Path,
    work: &Path,
    name: &str,
    subdivisions: u32,
    log: &mut dyn FnMut(String),
) -> Result<VdMesh> {
    let (_, mesh) = table_mesh(name, subdivisions)?;
    let options = EncodeOptions {
        quant_bits: QUANT_BITS,
        grid: GridShape::Cubic,
    };
    let canonical = codecs::canonical_for(&mesh, &options)?;
    let stream = codecs::by_name("came")?.encode(&canonical)?.bytes;
    // `came` is lossless: its full decode is the canonical mesh.
    let full = canonical.to_mesh();
    let stem = stem(name, subdivisions);
    let full_path = work.join(format!("{stem}.ply"));
    write_mesh(&full, &full_path)?;
    let stream_path = work.join(format!("{stem}.mc"));
    std::fs::write(&stream_path, &stream)?;
    let framed = framing(&full)?;
    let reference = FullMesh::new(&full);
    let middle = view_camera(VIEWS[1].0, VIEWS[1].1, framed);
    let mut views = Vec::new();
    for (view_name, diagonals) in VIEWS {
        let camera = view_camera(view_name, diagonals, framed);
        let view = View::new(&camera, TOLERANCE_PX)?.two_sided(true);
        let (front, adapted) = adapt_cold(&stream_path, &view)?;
        let (unguarded, _) = adapt_cold(&stream_path, &view.clone().keep_orientation(false))?;
        let adapted_mesh = front.mesh();
        let error = reference.screen_error(&adapted_mesh, &camera, &view);
        let depth = nearest_depth(&full, &camera, &view)
            .ok_or_else(|| Error::mesh(format!("{name}: nothing in the {view_name} view")))?;
        let fetched = front.fetched();
        // The far view is drawn from the middle view's eye, where its faces can be told apart.
        let render_camera = if view_name == "far" { middle } else { camera };
        // The middle view is not drawn (the table shows far and near).
        let render = if view_name == "middle" {
            String::new()
        } else {
            format!("vd/{stem}-{view_name}.png")
        };
        if !render.is_empty() {
            render_perspective(
                &adapted_mesh,
                &Perspective {
                    eye: render_camera.eye,
                    target: render_camera.target,
                    up: render_camera.up,
                    fov_degrees: render_camera.fov_degrees,
                },
                WIDTH,
                HEIGHT,
            )
            .save_png(&folder.join(&render))?;
        }
        let row = VdView {
            view: view_name.to_string(),
            diagonals,
            eye: camera.eye.to_array(),
            target: camera.target.to_array(),
            nearest_depth: depth,
            pixel_at_nearest: pixel_size(&camera, depth) * TOLERANCE_PX,
            faces: front.face_count(),
            vertices: front.vertex_count(),
            faces_unguarded: unguarded.face_count(),
            bytes_read: fetched.bytes_read,
            units_loaded: fetched.units_loaded,
            share_of_stream: fetched.bytes_read as f64 / stream.len() as f64,
            adapt_ms: adapted.adapt_ms,
            wait_ms: adapted.wait_ms,
            adaptations: adapted.adaptations,
            max_error_px: error.max_px,
            mean_error_px: error.mean_px,
            error_samples: error.samples,
            render,
            render_eye: render_camera.eye.to_array(),
            render_target: render_camera.target.to_array(),
        };
        log(format!(
            "{stem} {view_name}: {} faces ({} unguarded), {:.1}% of the stream, {:.1} ms adapting + {:.1} ms waiting, error {:.2} px max ({:.3} mean)",
            row.faces,
            row.faces_unguarded,
            100.0 * row.share_of_stream,
            row.adapt_ms,
            row.wait_ms,
            row.max_error_px,
            row.mean_error_px
        ));
        views.push(row);
    }
    let _ = std::fs::remove_file(&stream_path);
    Ok(VdMesh {
        mesh: name.to_string(),
        subdivisions,
        vertices: canonical.vertex_count(),
        triangles: canonical.face_count(),
        stream_bytes: stream.len() as u64,
        diagonal: framed.1,
        full_mesh: full_path.display().to_string(),
        views,
    })
}

/// Time spent adapting a front from a cold start.
struct Timing {
    adapt_ms: f64,
    wait_ms: f64,
    adaptations: usize,
}

/// A front opened on the stream at `path` and adapted to `view` until it settles, waiting for
/// the meta-nodes it asks for (timed apart).
fn adapt_cold(path: &Path, view: &View) -> Result<(ViewMesh, Timing)> {
    let mut front = ViewMesh::open_file(path)?;
    let mut timing = Timing {
        adapt_ms: 0.0,
        wait_ms: 0.0,
        adaptations: 0,
    };
    for _ in 0..256 {
        let started = Instant::now();
        let done = front.adapt(view, Budget::UNLIMITED);
        timing.adapt_ms += started.elapsed().as_secs_f64() * 1e3;
        timing.adaptations += 1;
        if done.settled {
            return Ok((front, timing));
        }
        let started = Instant::now();
        front.wait_for_units();
        timing.wait_ms += started.elapsed().as_secs_f64() * 1e3;
    }
    Err(Error::mesh("the front did not settle in 256 adaptations"))
}
