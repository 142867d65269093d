//! The measured screen-space error of a view-dependent mesh: how far, in pixels, the adapted
//! mesh lies from the full one in a view — the figure a front's error bound promises to keep
//! under the tolerance (docs/CONTRACT.md §8).
//!
//! Both ways, over what the frustum holds (no occlusion test: hidden samples count too, and
//! back faces, as for a surface drawn two-sided): each vertex and face centroid of the full
//! mesh to the adapted mesh, and each centroid and edge midpoint of the adapted mesh's faces to
//! the full mesh. A distance d at depth z (along the view direction) counts d / s(z) pixels,
//! s(z) = 2·z·tan(φ/2) / H being a pixel's size there.

use glam::DVec3;
use meshcodec::codecs::came::refine::{Camera, View};
use meshcodec::mesh::TriMesh;
use meshcodec::metrics::distance::SurfaceIndex;

/// The measured error of one view.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ScreenError {
    /// Largest, either way, in pixels.
    pub max_px: f64,
    /// Mean over the samples of both ways, in pixels.
    pub mean_px: f64,
    /// Samples in the frustum.
    pub samples: usize,
    /// Where the largest error was measured, and whether that sample lies on the full mesh
    /// (else on the adapted one).
    pub worst_at: DVec3,
    pub worst_on_full: bool,
}

/// The full mesh, prepared once for every view measured against it.
pub struct FullMesh<'a> {
    mesh: &'a TriMesh,
    index: SurfaceIndex,
    samples: Vec<DVec3>,
}

impl<'a> FullMesh<'a> {
    pub fn new(mesh: &'a TriMesh) -> FullMesh<'a> {
        let mut samples = mesh.positions.clone();
        samples.extend(mesh.faces.iter().map(|&f| centroid(mesh, f)));
        FullMesh {
            mesh,
            index: SurfaceIndex::of_mesh(mesh, &[]),
            samples,
        }
    }

    /// The full mesh.
    pub fn mesh(&self) -> &TriMesh {
        self.mesh
    }

    /// The error of `adapted` seen by `camera` (whose frustum `view` holds).
    pub fn screen_error(&self, adapted: &TriMesh, camera: &Camera, view: &View) -> ScreenError {
        let forward = (camera.target - camera.eye).normalize_or_zero();
        let per_unit_depth =
            2.0 * (camera.fov_degrees.to_radians() / 2.0).tan() / camera.height as f64;
        let pixels = |p: DVec3, d: f64| {
            let depth = (p - camera.eye).dot(forward);
            if depth > 0.0 {
                d / (depth * per_unit_depth)
            } else {
                0.0
            }
        };
        let in_view = |p: &DVec3| view.sees(*p, 0.0);
        let there: Vec<DVec3> = self.samples.iter().copied().filter(in_view).collect();
        let index = SurfaceIndex::of_mesh(adapted, &[]);
        let mut back: Vec<DVec3> = Vec::with_capacity(adapted.faces.len() * 4);
        for &f in &adapted.faces {
            let [a, b, c] = f.map(|v| adapted.positions[v as usize]);
            back.extend([
                (a + b + c) / 3.0,
                (a + b) / 2.0,
                (b + c) / 2.0,
                (c + a) / 2.0,
            ]);
        }
        back.retain(in_view);
        let mut error = ScreenError::default();
        let mut sum = 0.0;
        for (points, surface, on_full) in [(&there, &index, true), (&back, &self.index, false)] {
            for (&p, d) in points.iter().zip(surface.distances(points)) {
                let px = pixels(p, d);
                if px > error.max_px {
                    error.max_px = px;
                    error.worst_at = p;
                    error.worst_on_full = on_full;
                }
                sum += px;
            }
        }
        error.samples = there.len() + back.len();
        error.mean_px = sum / error.samples.max(1) as f64;
        error
    }
}

fn centroid(mesh: &TriMesh, f: [u32; 3]) -> DVec3 {
    f.map(|v| mesh.positions[v as usize])
        .iter()
        .fold(DVec3::ZERO, |s, &p| s + p)
        / 3.0
}
