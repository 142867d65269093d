//! Triangle meshes without any notion of bits: the indexed mesh, its appearance (wedges and
//! materials), its file formats, validation, quantization to a grid, the canonical mesh that
//! "lossless" is judged against, and generators.

pub mod attribute_quantization;
pub mod attributes;
pub mod canonical;
pub mod canonical_attributes;
pub mod derived_normals;
pub mod generate;
pub mod io;
pub mod manifold;
pub mod meshopt_views;
pub mod quantize;
pub mod scene;
pub mod topology;

pub use canonical::CanonicalMesh;
pub use quantize::Grid;

use crate::error::{Error, Result};
use glam::DVec3;

/// A vertex index.
pub type VertexId = u32;

/// An indexed triangle mesh with double-precision positions. Faces are oriented (counter-clockwise
/// seen from the front); unreferenced vertices are allowed here and dropped by [`CanonicalMesh`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriMesh {
    /// Vertex positions.
    pub positions: Vec<DVec3>,
    /// Oriented triangles as indices into `positions`.
    pub faces: Vec<[VertexId; 3]>,
}

/// An axis-aligned box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Smallest corner.
    pub min: DVec3,
    /// Largest corner.
    pub max: DVec3,
}

impl Aabb {
    /// The box around `points`, or `None` when there are none.
    pub fn around(points: impl IntoIterator<Item = DVec3>) -> Option<Aabb> {
        let mut points = points.into_iter();
        let first = points.next()?;
        Some(points.fold(
            Aabb {
                min: first,
                max: first,
            },
            |b, p| Aabb {
                min: b.min.min(p),
                max: b.max.max(p),
            },
        ))
    }

    /// Length of the box diagonal.
    pub fn diagonal(&self) -> f64 {
        (self.max - self.min).length()
    }

    /// Extent along each axis.
    pub fn extent(&self) -> DVec3 {
        self.max - self.min
    }
}

impl TriMesh {
    /// A mesh from positions and faces, unchecked (see [`TriMesh::validate`]).
    pub fn new(mut positions: Vec<DVec3>, mut faces: Vec<[VertexId; 3]>) -> Self {
        // Readers and builders grow these by doubling; a mesh is kept long after (a million
        // faces could hold 12 MB they never use).
        positions.shrink_to_fit();
        faces.shrink_to_fit();
        TriMesh { positions, faces }
    }

    /// Adds `part` as a component of its own, scaled by `scale` and moved by `offset`.
    pub fn append(&mut self, part: &TriMesh, offset: DVec3, scale: f64) {
        let base = self.positions.len() as VertexId;
        self.positions
            .extend(part.positions.iter().map(|&p| p * scale + offset));
        self.faces
            .extend(part.faces.iter().map(|f| f.map(|v| v + base)));
    }

    /// Number of vertices stored (referenced or not).
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Number of triangles.
    pub fn face_count(&self) -> usize {
        self.faces.len()
    }

    /// Which vertices some face uses.
    pub fn referenced(&self) -> Vec<bool> {
        let mut used = vec![false; self.positions.len()];
        for face in &self.faces {
            for &v in face {
                if let Some(slot) = used.get_mut(v as usize) {
                    *slot = true;
                }
            }
        }
        used
    }

    /// Bounding box of the vertices that faces reference (all vertices when there are no faces).
    pub fn referenced_bounds(&self) -> Option<Aabb> {
        if self.faces.is_empty() {
            return Aabb::around(self.positions.iter().copied());
        }
        let used = self.referenced();
        Aabb::around(
            self.positions
                .iter()
                .zip(&used)
                .filter(|(_, &u)| u)
                .map(|(p, _)| *p),
        )
    }

    /// The three corners of face `f`.
    pub fn corners(&self, face: [VertexId; 3]) -> [DVec3; 3] {
        face.map(|v| self.positions[v as usize])
    }

    /// Checks the rules every mesh entering a codec must keep: at least one face, finite
    /// coordinates, indices in range.
    pub fn validate(&self) -> Result<()> {
        if self.positions.is_empty() {
            return Err(Error::mesh("empty mesh: no vertices"));
        }
        if self.faces.is_empty() {
            return Err(Error::mesh("empty mesh: no faces"));
        }
        if let Some((i, p)) = self
            .positions
            .iter()
            .enumerate()
            .find(|(_, p)| !p.is_finite())
        {
            return Err(Error::mesh(format!(
                "vertex {i} has a non-finite coordinate ({}, {}, {})",
                p.x, p.y, p.z
            )));
        }
        let n = self.positions.len();
        for (i, face) in self.faces.iter().enumerate() {
            if let Some(&v) = face.iter().find(|&&v| v as usize >= n) {
                return Err(Error::mesh(format!(
                    "face {i} index {v} out of range ({n} vertices)"
                )));
            }
        }
        Ok(())
    }
}
