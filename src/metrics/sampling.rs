//! Seeded, area-weighted sampling of a mesh surface.
//!
//! Samples are the mesh's referenced vertices followed by `count` random points. The random
//! points are stratified along the cumulative area (one uniform draw in each of `count` equal
//! slices), so they are area-weighted, reproducible for a seed, and come out grouped by
//! triangle — which lets distance queries reuse the previous answer as a bound.

use crate::mesh::TriMesh;
use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

/// Points on a surface.
#[derive(Clone, Debug, Default)]
pub struct Samples {
    /// The points: vertices first, then random points.
    pub points: Vec<DVec3>,
    /// How many of `points` are vertices.
    pub vertices: usize,
}

/// The referenced vertices of `mesh` (all of them if it has no faces) plus `count`
/// area-weighted random points on its triangles (none if it has no area).
pub fn sample_surface(mesh: &TriMesh, count: usize, seed: u64) -> Samples {
    let used = mesh.referenced();
    let no_faces = mesh.faces.is_empty();
    let mut points: Vec<DVec3> = mesh
        .positions
        .iter()
        .zip(&used)
        .filter(|(_, &u)| u || no_faces)
        .map(|(p, _)| *p)
        .collect();
    let vertices = points.len();
    points.extend(
        sample_faces(mesh, count, seed)
            .into_iter()
            .map(|s| s.position(mesh)),
    );
    Samples { points, vertices }
}

/// A point on one face: `a + (b − a)·u + (c − a)·v` of the face's corners a, b, c.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FacePoint {
    /// The face.
    pub face: u32,
    /// Weight of the second corner.
    pub u: f64,
    /// Weight of the third corner.
    pub v: f64,
}

impl FacePoint {
    /// The corners' weights (barycentric coordinates).
    pub fn weights(&self) -> [f64; 3] {
        [1.0 - self.u - self.v, self.u, self.v]
    }

    /// Where the point lies on `mesh`.
    pub fn position(&self, mesh: &TriMesh) -> DVec3 {
        let [a, b, c] = mesh.corners(mesh.faces[self.face as usize]);
        a + (b - a) * self.u + (c - a) * self.v
    }
}

/// `count` area-weighted random points on the triangles of `mesh` (none if it has no area),
/// stratified along the cumulative area, in face order.
pub fn sample_faces(mesh: &TriMesh, count: usize, seed: u64) -> Vec<FacePoint> {
    let mut cumulative = Vec::with_capacity(mesh.faces.len());
    let mut total = 0.0;
    for f in &mesh.faces {
        let [a, b, c] = mesh.corners(*f);
        total += 0.5 * (b - a).cross(c - a).length();
        cumulative.push(total);
    }
    let mut points = Vec::new();
    if total > 0.0 && count > 0 {
        let mut rng = Pcg64::seed_from_u64(seed);
        points.reserve(count);
        let mut face = 0;
        let slice = total / count as f64;
        for k in 0..count {
            let target = (k as f64 + rng.gen::<f64>()) * slice;
            while face + 1 < cumulative.len() && cumulative[face] < target {
                face += 1;
            }
            let (mut u, mut v): (f64, f64) = (rng.gen(), rng.gen());
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            points.push(FacePoint {
                face: face as u32,
                u,
                v,
            });
        }
    }
    points
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_follow_area() {
        // Two triangles, the second with three times the area.
        let mesh = TriMesh::new(
            vec![
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(0.0, 1.0, 0.0),
                DVec3::new(10.0, 0.0, 0.0),
                DVec3::new(13.0, 0.0, 0.0),
                DVec3::new(10.0, 1.0, 0.0),
            ],
            vec![[0, 1, 2], [3, 4, 5]],
        );
        let samples = sample_surface(&mesh, 4000, 1);
        assert_eq!(samples.vertices, 6);
        let on_second = samples.points[6..].iter().filter(|p| p.x >= 10.0).count();
        assert!((on_second as f64 / 4000.0 - 0.75).abs() < 0.01);
        assert_eq!(
            sample_surface(&mesh, 100, 9).points,
            sample_surface(&mesh, 100, 9).points
        );
    }
}
