//! The order faces are visited in and what each face touches, built from connectivity alone so
//! that encoder and decoder derive the same from the decoded mesh.
//!
//! Faces are visited breadth first across shared edges (each component from its lowest-numbered
//! face), so every face but a component's first meets at least one face visited before it: its
//! wedges and values have a neighbour to continue or be predicted from.

use crate::mesh::{TriMesh, VertexId};
use std::collections::VecDeque;

/// Edge-sharing and vertex-sharing faces of a mesh, and the breadth-first face order.
pub struct Traversal {
    /// Faces in visiting order.
    pub order: Vec<u32>,
    /// Position of each face in `order`.
    rank: Vec<u32>,
    /// (undirected edge key, face), sorted: the faces on each edge.
    edges: Vec<(u64, u32)>,
    /// Faces around each vertex, as a compressed row list.
    vertex_start: Vec<u32>,
    vertex_faces: Vec<u32>,
}

fn edge_key(a: VertexId, b: VertexId) -> u64 {
    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
    (lo as u64) << 32 | hi as u64
}

impl Traversal {
    /// The traversal of `mesh` (faces referencing its vertices, checked by the caller).
    pub fn new(mesh: &TriMesh) -> Traversal {
        let faces = &mesh.faces;
        let mut edges: Vec<(u64, u32)> = faces
            .iter()
            .enumerate()
            .flat_map(|(f, face)| {
                (0..3).map(move |j| (edge_key(face[j], face[(j + 1) % 3]), f as u32))
            })
            .collect();
        edges.sort_unstable();
        let mut vertex_start = vec![0u32; mesh.positions.len() + 1];
        for face in faces {
            for &v in face {
                vertex_start[v as usize + 1] += 1;
            }
        }
        for i in 1..vertex_start.len() {
            vertex_start[i] += vertex_start[i - 1];
        }
        let mut fill = vertex_start.clone();
        let mut vertex_faces = vec![0u32; faces.len() * 3];
        for (f, face) in faces.iter().enumerate() {
            for &v in face {
                vertex_faces[fill[v as usize] as usize] = f as u32;
                fill[v as usize] += 1;
            }
        }
        let mut traversal = Traversal {
            order: Vec::with_capacity(faces.len()),
            rank: vec![u32::MAX; faces.len()],
            edges,
            vertex_start,
            vertex_faces,
        };
        let mut queue = VecDeque::new();
        for seed in 0..faces.len() {
            if traversal.rank[seed] != u32::MAX {
                continue;
            }
            traversal.visit(seed as u32, &mut queue);
            while let Some(f) = queue.pop_front() {
                let face = faces[f as usize];
                for j in 0..3 {
                    let key = edge_key(face[j], face[(j + 1) % 3]);
                    let from = traversal.edges.partition_point(|e| e.0 < key);
                    let mut i = from;
                    while i < traversal.edges.len() && traversal.edges[i].0 == key {
                        let g = traversal.edges[i].1;
                        if traversal.rank[g as usize] == u32::MAX {
                            traversal.visit(g, &mut queue);
                        }
                        i += 1;
                    }
                }
            }
        }
        traversal
    }

    fn visit(&mut self, f: u32, queue: &mut VecDeque<u32>) {
        self.rank[f as usize] = self.order.len() as u32;
        self.order.push(f);
        queue.push_back(f);
    }

    /// The earliest-visited face before `f` on the edge (a, b), if any.
    pub fn before_across(&self, f: u32, a: VertexId, b: VertexId) -> Option<u32> {
        let key = edge_key(a, b);
        let own = self.rank[f as usize];
        let from = self.edges.partition_point(|e| e.0 < key);
        self.edges[from..]
            .iter()
            .take_while(|e| e.0 == key)
            .map(|e| e.1)
            .filter(|&g| self.rank[g as usize] < own)
            .min_by_key(|&g| self.rank[g as usize])
    }

    /// The faces around vertex `v`.
    pub fn faces_at(&self, v: VertexId) -> &[u32] {
        let v = v as usize;
        &self.vertex_faces[self.vertex_start[v] as usize..self.vertex_start[v + 1] as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn every_face_but_a_components_first_follows_a_neighbour() {
        let mesh = crate::mesh::generate::icosphere(2);
        let mut two = mesh.clone();
        two.append(&mesh, DVec3::new(5.0, 0.0, 0.0), 1.0);
        let t = Traversal::new(&two);
        assert_eq!(t.order.len(), two.faces.len());
        let mut seeds = 0;
        for &f in &t.order {
            let face = two.faces[f as usize];
            let met = (0..3).any(|j| t.before_across(f, face[j], face[(j + 1) % 3]).is_some());
            seeds += !met as usize;
        }
        assert_eq!(seeds, 2);
        assert!(t.faces_at(0).len() > 2);
    }
}
