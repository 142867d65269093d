//! Exact point-to-surface distance through parry3d's BVH.
//!
//! parry3d works in f32, so the surface is moved to be centred on the origin first: the f32
//! rounding is then relative to the mesh's size, not to where it sits in space. Queries run in
//! parallel over chunks of consecutive samples; inside a chunk each answer bounds the next
//! (d(p) ≤ d(p′) + |p − p′|), which prunes most of the tree because consecutive samples lie on
//! the same triangle.

use crate::mesh::{TriMesh, VertexId};
use glam::{DVec3, Vec3};
use parry3d::shape::{CompositeShapeRef, Polyline, TriMesh as ParryMesh};
use rayon::prelude::*;

/// Samples handled by one task: large enough to amortize scheduling, small enough to balance.
const CHUNK: usize = 2048;

enum Shape {
    Triangles(ParryMesh),
    /// Edges, or points as zero-length edges, for levels that have no triangle.
    Segments(Polyline),
    Empty,
}

/// A surface prepared for distance queries.
pub struct SurfaceIndex {
    shape: Shape,
    centre: DVec3,
}

impl SurfaceIndex {
    /// The surface of `mesh`: its triangles; if it has none, `edges`; if none either, its
    /// vertices.
    pub fn of_mesh(mesh: &TriMesh, edges: &[[VertexId; 2]]) -> SurfaceIndex {
        let centre = mesh
            .referenced_bounds()
            .map(|b| (b.min + b.max) * 0.5)
            .unwrap_or(DVec3::ZERO);
        let vertices: Vec<Vec3> = mesh
            .positions
            .iter()
            .map(|&p| (p - centre).as_vec3())
            .collect();
        let shape = if !mesh.faces.is_empty() {
            match ParryMesh::new(vertices, mesh.faces.clone()) {
                Ok(m) => Shape::Triangles(m),
                Err(_) => Shape::Empty,
            }
        } else if !edges.is_empty() {
            Shape::Segments(Polyline::new(vertices, Some(edges.to_vec())))
        } else if !vertices.is_empty() {
            let points = (0..vertices.len() as u32).map(|i| [i, i]).collect();
            Shape::Segments(Polyline::new(vertices, Some(points)))
        } else {
            Shape::Empty
        };
        SurfaceIndex { shape, centre }
    }

    /// Distance from `p` to the surface, pruning with `bound` (a distance known not to be
    /// exceeded); infinite for an empty surface.
    fn distance_within(&self, p: DVec3, bound: f32) -> f64 {
        let local = (p - self.centre).as_vec3();
        let query = |bound: f32| match &self.shape {
            Shape::Triangles(m) => CompositeShapeRef(m)
                .project_local_point(local, bound, false)
                .map(|(_, proj)| proj.point),
            Shape::Segments(l) => CompositeShapeRef(l)
                .project_local_point(local, bound, false)
                .map(|(_, proj)| proj.point),
            Shape::Empty => None,
        };
        // A bound that f32 rounding made too tight finds nothing: ask again without it.
        let nearest = query(bound).or_else(|| query(f32::MAX));
        match nearest {
            Some(q) => (p - (q.as_dvec3() + self.centre)).length(),
            None => f64::INFINITY,
        }
    }

    /// Distance from `p` to the surface.
    pub fn distance(&self, p: DVec3) -> f64 {
        self.distance_within(p, f32::MAX)
    }

    /// The face of the surface nearest to `p` and the corners' weights of the nearest point on
    /// it; `None` for a surface without triangles.
    pub fn nearest_face(&self, p: DVec3) -> Option<(u32, [f64; 3])> {
        let Shape::Triangles(m) = &self.shape else {
            return None;
        };
        let local = (p - self.centre).as_vec3();
        let (face, _, location) =
            CompositeShapeRef(m).project_local_point_and_get_location(local, f32::MAX, false)?;
        let w = location.barycentric_coordinates()?;
        Some((face, w.map(f64::from)))
    }

    /// Distances from each of `points` to the surface, in parallel.
    pub fn distances(&self, points: &[DVec3]) -> Vec<f64> {
        let mut out = vec![0.0; points.len()];
        out.par_chunks_mut(CHUNK)
            .zip(points.par_chunks(CHUNK))
            .for_each(|(out, points)| {
                let mut previous: Option<(DVec3, f64)> = None;
                for (d, &p) in out.iter_mut().zip(points) {
                    let bound = match previous {
                        Some((q, dq)) => ((dq + (p - q).length()) * (1.0 + 1e-5) + 1e-12) as f32,
                        None => f32::MAX,
                    };
                    *d = self.distance_within(p, bound);
                    previous = Some((p, *d));
                }
            });
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate;

    #[test]
    fn distances_to_a_sphere_match_the_closed_form() {
        // A fine icosphere is within 0.1% of the unit sphere.
        let sphere = generate::icosphere(5);
        let index = SurfaceIndex::of_mesh(&sphere, &[]);
        let points: Vec<DVec3> = (0..500)
            .map(|i| {
                let t = i as f64 * 0.37;
                DVec3::new(t.sin() * t.cos(), t.cos(), (t * 1.3).sin()) * (0.2 + i as f64 * 0.004)
            })
            .collect();
        for (p, d) in points.iter().zip(index.distances(&points)) {
            assert!((d - (p.length() - 1.0).abs()).abs() < 2e-3, "{p} {d}");
        }
    }

    #[test]
    fn bounded_queries_equal_unbounded_ones() {
        let mesh = generate::terrain(300, 3);
        let index = SurfaceIndex::of_mesh(&mesh, &[]);
        let samples = crate::metrics::sample_surface(&generate::terrain(50, 4), 3000, 5);
        let fast = index.distances(&samples.points);
        for (p, d) in samples.points.iter().zip(fast) {
            assert_eq!(d, index.distance(*p));
        }
    }

    #[test]
    fn edges_and_points_stand_in_for_missing_triangles() {
        let mesh = TriMesh::new(vec![DVec3::ZERO, DVec3::X * 2.0], vec![]);
        let edge = SurfaceIndex::of_mesh(&mesh, &[[0, 1]]);
        assert!((edge.distance(DVec3::new(1.0, 1.0, 0.0)) - 1.0).abs() < 1e-6);
        let points = SurfaceIndex::of_mesh(&mesh, &[]);
        assert!((points.distance(DVec3::new(1.0, 1.0, 0.0)) - 2f64.sqrt()).abs() < 1e-6);
    }
}
