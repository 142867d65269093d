//! The canonical mesh at Q bits (docs/CONTRACT.md §2) and the one test of losslessness.
//!
//! Canonical mesh: drop unreferenced vertices; quantize; weld vertices that share a cell; drop
//! faces that then repeat a vertex; drop repeated faces (the same oriented triangle up to
//! rotation). A face and its reverse are two faces. A decoded mesh is lossless when it equals the
//! canonical mesh of the input: same cells, same oriented faces up to rotation and vertex order.
//!
//! The steps run in the contract's order, so a vertex whose every face collapses when it is
//! welded stays as an isolated point: it was referenced when unreferenced vertices were dropped.
//! Codecs carry such points like any other vertex.

use super::{Grid, TriMesh, VertexId};
use crate::error::Result;
use std::collections::{HashMap, HashSet};

/// A mesh on a grid: one vertex per occupied cell, no degenerate or repeated faces.
#[derive(Clone, Debug, PartialEq)]
pub struct CanonicalMesh {
    /// The grid the cells index.
    pub grid: Grid,
    /// Cell of each vertex; all distinct.
    pub cells: Vec<[u32; 3]>,
    /// Oriented triangles; none repeats a vertex, none repeats another up to rotation.
    pub faces: Vec<[VertexId; 3]>,
}

/// A face rotated so that its smallest index comes first; orientation is kept.
pub fn rotate_to_smallest(face: [VertexId; 3]) -> [VertexId; 3] {
    let [a, b, c] = face;
    if a <= b && a <= c {
        [a, b, c]
    } else if b <= a && b <= c {
        [b, c, a]
    } else {
        [c, a, b]
    }
}

impl CanonicalMesh {
    /// The canonical mesh of `mesh` on `grid`. Vertices keep the order of their first
    /// appearance in the input's vertex list, faces the order of their first appearance.
    pub fn new(mesh: &TriMesh, grid: Grid) -> Result<CanonicalMesh> {
        Ok(CanonicalMesh::with_origins(mesh, grid)?.0)
    }

    /// [`CanonicalMesh::new`], with the input face each canonical face comes from (the first of
    /// the repeats it stands for), so attributes can follow their faces.
    pub fn with_origins(mesh: &TriMesh, grid: Grid) -> Result<(CanonicalMesh, Vec<u32>)> {
        mesh.validate()?;
        let used = mesh.referenced();
        let mut cell_vertex: HashMap<[u32; 3], VertexId> = HashMap::new();
        let mut cells = Vec::new();
        let mut remap = vec![VertexId::MAX; mesh.positions.len()];
        for (i, p) in mesh.positions.iter().enumerate() {
            if !used[i] {
                continue;
            }
            let q = grid.quantize(*p);
            remap[i] = *cell_vertex.entry(q).or_insert_with(|| {
                cells.push(q);
                (cells.len() - 1) as VertexId
            });
        }
        let mut seen = HashSet::new();
        let (mut faces, mut origins): (Vec<_>, Vec<_>) = mesh
            .faces
            .iter()
            .enumerate()
            .map(|(i, f)| (f.map(|v| remap[v as usize]), i as u32))
            .filter(|([a, b, c], _)| a != b && b != c && a != c)
            .filter(|(f, _)| seen.insert(rotate_to_smallest(*f)))
            .unzip();
        // Grown by doubling: give back what the dropped faces left unused.
        faces.shrink_to_fit();
        origins.shrink_to_fit();
        Ok((CanonicalMesh { grid, cells, faces }, origins))
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.cells.len()
    }

    /// Number of triangles.
    pub fn face_count(&self) -> usize {
        self.faces.len()
    }

    /// The mesh with every vertex at its cell centre.
    pub fn to_mesh(&self) -> TriMesh {
        TriMesh::new(
            self.cells
                .iter()
                .map(|&q| self.grid.dequantize(q))
                .collect(),
            self.faces.clone(),
        )
    }

    /// Vertices sorted by cell and faces rotated and sorted: two meshes are the same mesh exactly
    /// when their normal forms are equal.
    pub fn normal_form(&self) -> (Vec<[u32; 3]>, Vec<[VertexId; 3]>) {
        normal_form(&self.cells, &self.faces)
    }

    /// Checks that `decoded` (positions at cell centres of this grid) is exactly this mesh:
    /// distinct cells, the same cells, and the same oriented faces. Returns what differs.
    pub fn check_lossless(&self, decoded: &TriMesh) -> Result<(), String> {
        let cells: Vec<[u32; 3]> = decoded
            .positions
            .iter()
            .map(|&p| self.grid.quantize(p))
            .collect();
        let mut distinct = HashSet::new();
        if let Some(dup) = cells.iter().find(|c| !distinct.insert(**c)) {
            return Err(format!("two decoded vertices share cell {dup:?}"));
        }
        if decoded.positions.len() != self.cells.len() {
            return Err(format!(
                "{} vertices decoded, {} expected",
                decoded.positions.len(),
                self.cells.len()
            ));
        }
        if decoded.faces.len() != self.faces.len() {
            return Err(format!(
                "{} faces decoded, {} expected",
                decoded.faces.len(),
                self.faces.len()
            ));
        }
        let (ours_cells, ours_faces) = self.normal_form();
        let (their_cells, their_faces) = normal_form(&cells, &decoded.faces);
        if ours_cells != their_cells {
            return Err("decoded vertex cells differ from the canonical mesh".into());
        }
        if ours_faces != their_faces {
            let expected: HashSet<_> = ours_faces.iter().collect();
            let missing = their_faces.iter().filter(|f| !expected.contains(f)).count();
            return Err(format!(
                "{missing} decoded faces are not faces of the canonical mesh"
            ));
        }
        Ok(())
    }
}

fn normal_form(cells: &[[u32; 3]], faces: &[[VertexId; 3]]) -> (Vec<[u32; 3]>, Vec<[VertexId; 3]>) {
    let mut order: Vec<usize> = (0..cells.len()).collect();
    order.sort_unstable_by_key(|&i| cells[i]);
    let mut rank = vec![0 as VertexId; cells.len()];
    for (r, &i) in order.iter().enumerate() {
        rank[i] = r as VertexId;
    }
    let sorted_cells = order.iter().map(|&i| cells[i]).collect();
    let mut sorted_faces: Vec<[VertexId; 3]> = faces
        .iter()
        .map(|f| rotate_to_smallest(f.map(|v| rank[v as usize])))
        .collect();
    sorted_faces.sort_unstable();
    (sorted_cells, sorted_faces)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::quantize::GridShape;
    use glam::DVec3;

    fn square() -> TriMesh {
        TriMesh::new(
            vec![
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(1.0, 1.0, 0.0),
                DVec3::new(0.0, 1.0, 0.0),
                DVec3::new(0.0, 1.0, 1e-9), // welds onto vertex 3
                DVec3::new(9.0, 9.0, 9.0),  // unreferenced
            ],
            vec![[0, 1, 2], [2, 4, 0], [1, 2, 0], [0, 2, 1], [3, 4, 0]],
        )
    }

    #[test]
    fn welds_drops_and_keeps_reversed_faces() {
        let mesh = square();
        let grid = Grid::fit(&mesh, 8, GridShape::Cubic).unwrap();
        let canon = CanonicalMesh::new(&mesh, grid).unwrap();
        assert_eq!(canon.vertex_count(), 4);
        // [1,2,0] repeats [0,1,2]; [0,2,1] is its reverse and stays; [3,4,0] degenerates.
        assert_eq!(canon.faces, vec![[0, 1, 2], [2, 3, 0], [0, 2, 1]]);
    }

    #[test]
    fn lossless_check_accepts_a_permutation_and_rejects_a_flip() {
        let mesh = square();
        let grid = Grid::fit(&mesh, 8, GridShape::Cubic).unwrap();
        let canon = CanonicalMesh::new(&mesh, grid).unwrap();
        let mut decoded = canon.to_mesh();
        decoded.positions.reverse();
        let n = decoded.positions.len() as u32;
        for f in &mut decoded.faces {
            *f = [n - 1 - f[1], n - 1 - f[2], n - 1 - f[0]];
        }
        decoded.faces.reverse();
        assert_eq!(canon.check_lossless(&decoded), Ok(()));
        decoded.faces[0].swap(1, 2);
        assert!(canon.check_lossless(&decoded).is_err());
    }
}
