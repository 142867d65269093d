//! Any face set as an oriented 2-manifold, and the little it takes to get back.
//!
//! Hoppe's progressive meshes need an oriented 2-manifold; real meshes are often not one (a fin
//! of three faces on an edge, two fans touching at a vertex, a face turned against its
//! neighbours, or all of these after welding at a coarse grid). Following the idea of Guéziec,
//! Taubin, Lazarus and Horn (*Cutting and Stitching: Converting Sets of Polygons to Manifold
//! Surfaces*, IEEE TVCG 7(2), 2001), the mesh is cut rather than repaired:
//!
//! 1. **Joins.** An edge used by exactly two faces joins them; an edge used by one face is a
//!    boundary, by three or more a **cut**: each of its faces keeps its own side.
//! 2. **Orientation.** Each component of faces over joins is walked breadth first, each face
//!    oriented to agree with the face it was reached from. A join that closes onto a face
//!    already oriented the other way (a Möbius band) becomes a cut. The component then keeps
//!    the orientation most of its faces had: the faces turned the other way are **flipped**.
//! 3. **Vertices.** Around each vertex, the faces joined through it form fans; the first fan
//!    keeps the vertex, every further fan gets a **copy** (a new vertex in the same cell).
//! 4. **Check.** Where two faces still share both ends of a cut edge (their fans met around the
//!    far side of both ends), the faces on it are also cut apart at one end, and step 3 runs
//!    again. Every round cuts more, and a mesh cut along all its edges is a manifold, so this
//!    ends; on real meshes it takes one round.
//!
//! Getting back needs no list of copies: a copy lies in its original's cell, and the canonical
//! mesh has one vertex a cell (docs/CONTRACT.md §2), so welding equal cells undoes step 3. What
//! must be told is which faces were flipped. Vertices no face uses (a canonical mesh keeps a
//! vertex all of whose faces became degenerate) stay as they are, isolated points of the
//! manifold that a progressive mesh keeps in its base mesh; a face set has no dangling edges.

use super::topology::DisjointSets;
use super::VertexId;
use rayon::prelude::*;

/// An oriented 2-manifold made from a face set, with how to get back.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ManifoldCut {
    /// The faces, in the input's order, over the manifold's vertices: the input's vertices
    /// first, then the copies; a flipped face has its last two corners swapped.
    pub faces: Vec<[VertexId; 3]>,
    /// The input vertex each copy stands for: vertex `n + i` is a copy of `copy_of[i]`.
    pub copy_of: Vec<VertexId>,
    /// Whether each face was flipped.
    pub flipped: Vec<bool>,
    /// Edges cut: used by three faces or more, closing a non-orientable loop, or cut to part
    /// faces whose fans met.
    pub cut_edges: usize,
}

/// One face's side of an edge.
#[derive(Clone, Copy)]
struct HalfEdge {
    key: (VertexId, VertexId),
    face: u32,
    /// The edge's index in its face: from corner `k` to corner `k + 1`.
    k: u8,
}

impl HalfEdge {
    /// Whether the face runs along the edge from its smaller end to its larger.
    fn forward(&self, faces: &[[VertexId; 3]]) -> bool {
        faces[self.face as usize][self.k as usize] == self.key.0
    }
}

impl ManifoldCut {
    /// Cuts the face set `faces` over `vertex_count` vertices (no face repeats a vertex).
    pub fn new(vertex_count: usize, faces: &[[VertexId; 3]]) -> ManifoldCut {
        let mut halves: Vec<HalfEdge> = faces
            .iter()
            .enumerate()
            .flat_map(|(f, t)| {
                (0..3u8).map(move |k| {
                    let (a, b) = (t[k as usize], t[(k as usize + 1) % 3]);
                    HalfEdge {
                        key: (a.min(b), a.max(b)),
                        face: f as u32,
                        k,
                    }
                })
            })
            .collect();
        halves.par_sort_unstable_by_key(|h| (h.key, h.face, h.k));
        // Edges as runs of `halves`; each face's three edges.
        let mut edge_start = Vec::with_capacity(halves.len() / 2 + 1);
        let mut face_edge = vec![[0u32; 3]; faces.len()];
        for (i, h) in halves.iter().enumerate() {
            if i == 0 || halves[i - 1].key != h.key {
                edge_start.push(i as u32);
            }
            face_edge[h.face as usize][h.k as usize] = edge_start.len() as u32 - 1;
        }
        edge_start.push(halves.len() as u32);
        let edges = edge_start.len() - 1;
        let sides = |e: usize| &halves[edge_start[e] as usize..edge_start[e + 1] as usize];
        let mut cut: Vec<bool> = (0..edges).map(|e| sides(e).len() > 2).collect();

        let flipped = orient(faces, &face_edge, &halves, &edge_start, &mut cut);

        loop {
            let (out, copy_of) =
                split_fans(vertex_count, faces, &halves, &edge_start, &cut, &flipped);
            // Only an edge that joins no faces can leave two sharing both its ends.
            let bad = if cut.contains(&true) {
                faces_on_bad_edges(&out)
            } else {
                Vec::new()
            };
            if bad.is_empty() {
                return ManifoldCut {
                    faces: out,
                    copy_of,
                    flipped,
                    cut_edges: cut.iter().filter(|&&c| c).count(),
                };
            }
            // Part the faces of each bad edge at its smaller end: cut their edges there.
            for (f, end) in bad {
                let t = faces[f as usize];
                let v = match (end as usize).checked_sub(vertex_count) {
                    Some(i) => copy_of[i],
                    None => end,
                };
                for k in 0..3 {
                    if t[k] == v || t[(k + 1) % 3] == v {
                        cut[face_edge[f as usize][k] as usize] = true;
                    }
                }
            }
        }
    }

    /// True when the input was an oriented manifold already: nothing copied, nothing flipped.
    pub fn is_identity(&self) -> bool {
        self.copy_of.is_empty() && !self.flipped.contains(&true)
    }

    /// Number of faces flipped.
    pub fn flip_count(&self) -> usize {
        self.flipped.iter().filter(|&&f| f).count()
    }

    /// The input vertex of manifold vertex `v`, for an input of `vertex_count` vertices.
    pub fn origin(&self, v: VertexId, vertex_count: usize) -> VertexId {
        match (v as usize).checked_sub(vertex_count) {
            Some(i) => self.copy_of[i],
            None => v,
        }
    }

    /// Whether each manifold vertex has a copy or is one (`vertex_count` input vertices):
    /// the vertices that must stay together.
    pub fn copied(&self, vertex_count: usize) -> Vec<bool> {
        let mut out = vec![false; vertex_count + self.copy_of.len()];
        for (i, &v) in self.copy_of.iter().enumerate() {
            out[v as usize] = true;
            out[vertex_count + i] = true;
        }
        out
    }
}

/// Orients each component over the joins (edges with two faces not cut), cutting the joins
/// that close a non-orientable loop; returns which faces flip, each component keeping the
/// orientation most of its faces had.
fn orient(
    faces: &[[VertexId; 3]],
    face_edge: &[[u32; 3]],
    halves: &[HalfEdge],
    edge_start: &[u32],
    cut: &mut [bool],
) -> Vec<bool> {
    let mut flipped = vec![false; faces.len()];
    let mut seen = vec![false; faces.len()];
    let mut component = Vec::new();
    for start in 0..faces.len() {
        if seen[start] {
            continue;
        }
        seen[start] = true;
        component.clear();
        component.push(start as u32);
        let mut next = 0;
        while next < component.len() {
            let f = component[next] as usize;
            next += 1;
            for &e in &face_edge[f] {
                let e = e as usize;
                if cut[e] {
                    continue;
                }
                let run = &halves[edge_start[e] as usize..edge_start[e + 1] as usize];
                if run.len() != 2 {
                    continue; // a boundary
                }
                let (mine, other) = if run[0].face as usize == f {
                    (run[0], run[1])
                } else {
                    (run[1], run[0])
                };
                // As oriented, f runs along the edge this way; the other face must run the other.
                let along = mine.forward(faces) != flipped[f];
                let g = other.face as usize;
                let wanted = other.forward(faces) == along;
                if !seen[g] {
                    seen[g] = true;
                    flipped[g] = wanted;
                    component.push(g as u32);
                } else if flipped[g] != wanted {
                    cut[e] = true;
                }
            }
        }
        let turned = component.iter().filter(|&&f| flipped[f as usize]).count();
        if 2 * turned > component.len() {
            for &f in &component {
                flipped[f as usize] = !flipped[f as usize];
            }
        }
    }
    flipped
}

/// The faces over one vertex a fan (the first fan of each input vertex keeps it), oriented as
/// `flipped` says, and the input vertex of each copy.
fn split_fans(
    vertex_count: usize,
    faces: &[[VertexId; 3]],
    halves: &[HalfEdge],
    edge_start: &[u32],
    cut: &[bool],
    flipped: &[bool],
) -> (Vec<[VertexId; 3]>, Vec<VertexId>) {
    // Corner 3f + k is vertex k of face f; corners joined across a join share a vertex.
    let mut fans = DisjointSets::new(faces.len() * 3);
    for e in 0..edge_start.len() - 1 {
        let run = &halves[edge_start[e] as usize..edge_start[e + 1] as usize];
        if cut[e] || run.len() != 2 {
            continue;
        }
        let (h, g) = (run[0], run[1]);
        let (ft, gt) = (faces[h.face as usize], faces[g.face as usize]);
        let (hk, gk) = (h.k as usize, g.k as usize);
        for (hc, v) in [(hk, ft[hk]), ((hk + 1) % 3, ft[(hk + 1) % 3])] {
            let gc = if gt[gk] == v { gk } else { (gk + 1) % 3 };
            fans.union(3 * h.face + hc as u32, 3 * g.face + gc as u32);
        }
    }
    let mut vertex_of_fan = vec![VertexId::MAX; faces.len() * 3];
    let mut has_fan = vec![false; vertex_count];
    let mut copy_of = Vec::new();
    let mut out = Vec::with_capacity(faces.len());
    for (f, t) in faces.iter().enumerate() {
        let mut o = [0; 3];
        for k in 0..3 {
            let root = fans.find(3 * f as u32 + k as u32) as usize;
            if vertex_of_fan[root] == VertexId::MAX {
                let v = t[k];
                vertex_of_fan[root] = if has_fan[v as usize] {
                    copy_of.push(v);
                    (vertex_count + copy_of.len() - 1) as VertexId
                } else {
                    has_fan[v as usize] = true;
                    v
                };
            }
            o[k] = vertex_of_fan[root];
        }
        out.push(if flipped[f] { [o[0], o[2], o[1]] } else { o });
    }
    (out, copy_of)
}

/// Faces on edges that are still not manifold (three faces or more, or two running the same
/// way), each with the edge's smaller end (a manifold vertex).
fn faces_on_bad_edges(faces: &[[VertexId; 3]]) -> Vec<(u32, VertexId)> {
    // (smaller end, larger end, face, whether the face runs from the smaller to the larger)
    let mut sides: Vec<(VertexId, VertexId, u32, bool)> = faces
        .iter()
        .enumerate()
        .flat_map(|(f, t)| {
            (0..3).map(move |k| {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                (a.min(b), a.max(b), f as u32, a < b)
            })
        })
        .collect();
    sides.par_sort_unstable();
    let mut bad = Vec::new();
    for run in sides.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        if run.len() > 2 || (run.len() == 2 && run[0].3 == run[1].3) {
            bad.extend(run.iter().map(|&(a, _, f, _)| (f, a)));
        }
    }
    bad
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::topology::analyze;
    use crate::mesh::TriMesh;

    /// The cut is an oriented manifold, and welding copies and unflipping gives the input.
    fn check(vertex_count: usize, faces: &[[VertexId; 3]]) -> ManifoldCut {
        let cut = ManifoldCut::new(vertex_count, faces);
        let n = vertex_count + cut.copy_of.len();
        let report = analyze(&TriMesh::new(vec![glam::DVec3::ZERO; n], cut.faces.clone()));
        assert!(report.is_oriented_manifold(), "{report:?} for {faces:?}");
        for (f, t) in cut.faces.iter().enumerate() {
            let mut back = t.map(|v| cut.origin(v, vertex_count));
            if cut.flipped[f] {
                back.swap(1, 2);
            }
            assert_eq!(back, faces[f]);
        }
        cut
    }

    #[test]
    fn an_oriented_manifold_is_left_as_it_is() {
        let sphere = crate::mesh::generate::icosphere(2);
        let cut = check(sphere.positions.len(), &sphere.faces);
        assert!(cut.is_identity());
        assert_eq!(cut.faces, sphere.faces);
    }

    #[test]
    fn a_fin_is_cut_off_and_a_bow_tie_gets_a_copy() {
        // Three faces on edge (0, 1).
        let fin = [[0, 1, 2], [1, 0, 3], [0, 1, 4]];
        let cut = check(5, &fin);
        assert!(cut.copy_of.len() >= 2, "{cut:?}");
        // Two fans touching at vertex 0.
        let bow_tie = [[0, 1, 2], [0, 3, 4]];
        let cut = check(5, &bow_tie);
        assert_eq!(cut.copy_of, vec![0]);
    }

    #[test]
    fn a_face_turned_against_its_neighbours_is_flipped_back() {
        let sphere = crate::mesh::generate::icosphere(2);
        let mut faces = sphere.faces.clone();
        faces[7].swap(1, 2);
        let cut = check(sphere.positions.len(), &faces);
        assert_eq!(cut.flip_count(), 1);
        assert!(cut.flipped[7]);
        assert!(cut.copy_of.is_empty());
    }

    #[test]
    fn a_double_sided_face_and_a_moebius_band_become_manifolds() {
        check(3, &[[0, 1, 2], [0, 2, 1]]);
        // A Möbius band: rungs (t_i, b_i) for t = 0, 1, 2 and b = 3, 4, 5, the last quad
        // joining rung 2 to rung 0 turned over.
        let quads = [[0, 1, 4, 3], [1, 2, 5, 4], [2, 3, 0, 5]];
        let band: Vec<[u32; 3]> = quads
            .iter()
            .flat_map(|&[a, b, c, d]| [[a, b, c], [a, c, d]])
            .collect();
        let cut = check(6, &band);
        assert!(cut.cut_edges >= 1, "a Möbius band cannot be oriented whole");
    }
}
