//! The state that EMC's encoder and decoder update identically: the vertex list with each
//! vertex's cell prefix, its next split step and its edge list, and the triangles rebuilt from
//! the edges.

use crate::codecs::LevelMesh;
use crate::container::Header;
use crate::hierarchy::cliques::{
    loose_edges, oriented, propagate_orientation, triangles as list_triangles, Cliques, Listing,
};
use crate::hierarchy::octree::KeyTrie;
use crate::hierarchy::octree::StepOrder;
use crate::limits;
use crate::mesh::canonical::rotate_to_smallest;
use crate::mesh::CanonicalMesh;
use crate::mesh::{Grid, TriMesh};
use glam::DVec3;
use rayon::prelude::*;
use std::ops::Range;

/// What happens to an edge of a splitting vertex.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EdgeCode {
    /// Stays with the old vertex.
    Stay,
    /// Moves to the new vertex.
    Move,
    /// Both vertices keep an edge to the neighbour.
    Duplicate,
}

/// A vertex's sorted neighbour ids. Most vertices of a mesh have at most eight neighbours: they
/// are kept inline, beside the others', rather than in an allocation of their own.
pub type Neighbours = smallvec::SmallVec<[u32; 8]>;

/// "No further split".
pub const NO_SPLIT: u16 = u16::MAX;

/// The decoder's view of the mesh after some steps.
#[derive(Clone, Debug)]
pub struct EmcState {
    /// Step order of the stream.
    pub order: StepOrder,
    /// Cell index bits taken so far on each axis (a prefix of the full cell index).
    pub cells: Vec<[u32; 3]>,
    /// Steps applied to each vertex (all equal between passes; differ inside a cut pass).
    pub depth: Vec<u16>,
    /// Step of each vertex's next split, or [`NO_SPLIT`].
    pub next_split: Vec<u16>,
    /// Sorted neighbour lists (ids are positions in the vertex list).
    pub adjacency: Vec<Neighbours>,
    /// Edges of the graph (each counted once).
    edges: u64,
}

impl EmcState {
    /// One vertex at the centre of the box. It splits at step 0 when the mesh has two or more
    /// vertices: the longest axis spans the whole grid, so its extremes lie in opposite halves.
    pub fn new(order: StepOrder, total_vertices: u64) -> EmcState {
        EmcState {
            order,
            cells: vec![[0; 3]],
            depth: vec![0],
            next_split: vec![if total_vertices >= 2 { 0 } else { NO_SPLIT }],
            adjacency: vec![Neighbours::new()],
            edges: 0,
        }
    }

    /// Makes room for `vertices` in all, so that the per-vertex lists never grow by doubling
    /// (the encoder knows the count; a decoder's header could lie).
    pub fn reserve(&mut self, vertices: usize) {
        let more = vertices.saturating_sub(self.len());
        self.cells.reserve_exact(more);
        self.depth.reserve_exact(more);
        self.next_split.reserve_exact(more);
        self.adjacency.reserve_exact(more);
    }

    /// Number of vertices (never zero: the list starts with one).
    #[allow(clippy::len_without_is_empty)]
    pub fn len(&self) -> usize {
        self.cells.len()
    }

    /// RF: vertex `v` takes `bit` at `step`.
    pub fn refine(&mut self, v: usize, step: usize, bit: u32) {
        let axis = self.order.axis(step);
        self.cells[v][axis] = (self.cells[v][axis] << 1) | bit;
        self.depth[v] += 1;
    }

    /// VS of `v` at `step`: `v` keeps the left half and the edges coded STAY or DUPLICATE; a new
    /// vertex takes the right half and the edges coded MOVE or DUPLICATE, plus the connecting
    /// edge if `connecting`. `codes[i]` is the code of `v`'s i-th neighbour (ascending ids).
    /// Returns the new vertex.
    pub fn split(
        &mut self,
        v: usize,
        step: usize,
        connecting: bool,
        codes: &[EdgeCode],
        next: [u16; 2],
    ) -> usize {
        let r = self.cells.len() as u32;
        let mut cell = self.cells[v];
        let axis = self.order.axis(step);
        self.cells[v][axis] = cell[axis] << 1;
        cell[axis] = (cell[axis] << 1) | 1;
        self.cells.push(cell);
        self.depth[v] += 1;
        self.depth.push(self.depth[v]);
        self.next_split[v] = next[0];
        self.next_split.push(next[1]);

        self.adjacency.push(Neighbours::new());
        self.edges += split_edges(&mut self.adjacency, v, r as usize, connecting, codes);
        r as usize
    }

    /// Edges of the graph (each counted once).
    pub fn edge_count(&self) -> u64 {
        self.edges
    }

    /// Counts `added` edges that a split made outside [`Self::split`] (a slab of a sliced
    /// pass).
    pub fn add_edges(&mut self, added: u64) {
        self.edges += added;
    }

    /// An error once the graph has more edges than a mesh of `triangles` (the header's count)
    /// can have ([`limits::graph_edges`]): a decoder's bound on what a stream may build.
    pub fn check_edges(&self, triangles: u64) -> Result<(), String> {
        check_edge_count(self.edges, triangles)
    }

    /// What a decoder shows after the levels decoded so far: `full` once the last level's
    /// corrections are read, else the level's cliques (bounded by the header's triangles).
    pub fn shown_mesh(
        &self,
        full: Option<&LevelMesh>,
        header: &Header,
    ) -> crate::Result<LevelMesh> {
        match full {
            Some(mesh) => Ok(mesh.clone()),
            None => self
                .level_mesh(&header.grid, header.triangles)
                .map_err(crate::Error::Limit),
        }
    }

    /// Position of every vertex: the centre of its cell at the resolution it has reached.
    pub fn positions(&self, grid: &Grid) -> Vec<DVec3> {
        // Vertices share few depths: work out each depth's cell shifts once.
        let shifts: Vec<[u8; 3]> = (0..=self.order.steps())
            .map(|d| self.order.bits_per_axis(d).map(|b| grid.bits - b))
            .collect();
        (0..self.len())
            .into_par_iter()
            .map(|v| grid.coarse_centre(self.cells[v], shifts[self.depth[v] as usize]))
            .collect()
    }

    /// The 3-cliques of the edge graph, ascending triples in lexicographic order; an error if
    /// there are more than a stream of `triangles` (the header's count) may show
    /// ([`limits::level_triangles`]).
    pub fn cliques(&self, triangles: u64, listing: Listing) -> Result<Cliques, String> {
        let limit = limits::level_triangles(triangles);
        list_triangles(&self.adjacency, limit, listing).ok_or_else(|| {
            format!("the edge graph has more than {limit} triangles ({triangles} declared)")
        })
    }

    /// The cliques of the final state, once every vertex is decoded (`vertices`, `triangles`:
    /// the header's counts); the face-correction lists index them.
    pub fn final_cliques(&self, vertices: u64, triangles: u64) -> Result<Cliques, String> {
        if self.len() as u64 != vertices {
            return Err(format!(
                "{} vertices decoded, the header declares {vertices}",
                self.len()
            ));
        }
        self.cliques(triangles, Listing::OnThreads)
    }

    /// The full mesh: `cliques` (from [`Self::final_cliques`]) with `corrections` applied,
    /// checked against the header's `triangles`.
    pub fn corrected_mesh(
        &self,
        grid: &Grid,
        cliques: &Cliques,
        corrections: &FaceCorrections,
        triangles: u64,
    ) -> Result<LevelMesh, String> {
        if corrections
            .false_triangles
            .iter()
            .any(|t| corrections.double_sided.binary_search(t).is_ok())
        {
            return Err("a triangle is listed both false and double-sided".into());
        }
        let positions = self.positions(grid);
        // The orientation's walk is serial: the loose edges are found beside it.
        let (faces, loose_edges) = rayon::join(
            || final_faces(cliques, &positions, corrections),
            || {
                let mut is_false = vec![false; cliques.len()];
                for &i in &corrections.false_triangles {
                    is_false[i as usize] = true;
                }
                loose_edges(&self.adjacency, cliques, Some(&is_false))
            },
        );
        if faces.len() as u64 != triangles {
            return Err(format!(
                "{} triangles decoded, the header declares {triangles}",
                faces.len()
            ));
        }
        Ok(LevelMesh {
            loose_edges,
            mesh: TriMesh::new(positions, faces),
            attributes: None,
        })
    }

    /// The mesh as the paper's decoder shows it between levels: every 3-clique a triangle,
    /// oriented by propagation from outward-facing guesses (no bits are spent on it).
    /// `triangles`: the header's count, which bounds the cliques listed.
    pub fn level_mesh(&self, grid: &Grid, triangles: u64) -> Result<LevelMesh, String> {
        self.level_mesh_at(self.positions(grid), triangles)
    }

    /// [`Self::level_mesh`] with the vertices shown at `positions` (one per vertex).
    pub fn level_mesh_at(
        &self,
        positions: Vec<DVec3>,
        triangles: u64,
    ) -> Result<LevelMesh, String> {
        let cliques = self.cliques(triangles, Listing::OnThreads)?;
        let skipped = vec![false; cliques.len()];
        let centre = centroid(&positions);
        let flipped = propagate_orientation(&cliques, &skipped, &positions, centre, |_, _, p| p);
        let faces = cliques
            .tris
            .iter()
            .zip(&flipped)
            .map(|(&t, &f)| oriented(t, f))
            .collect();
        Ok(LevelMesh {
            loose_edges: loose_edges(&self.adjacency, &cliques, None),
            mesh: TriMesh::new(positions, faces),
            attributes: None,
        })
    }
}

/// An error if a graph of `edges` edges has more than a mesh of `triangles` (the header's
/// count) can have ([`limits::graph_edges`]).
pub fn check_edge_count(edges: u64, triangles: u64) -> Result<(), String> {
    if edges > limits::graph_edges(triangles) {
        return Err(format!(
            "more edges than the {triangles} triangles the header declares can have"
        ));
    }
    Ok(())
}

/// Where the neighbour lists a split edits are kept: the state's own vector, or the raw view
/// the slabs of a sliced pass share (`modelled::walk`).
pub trait NeighbourLists {
    /// `v`'s sorted neighbour list.
    fn list(&mut self, v: usize) -> &mut Neighbours;
}

impl NeighbourLists for Vec<Neighbours> {
    fn list(&mut self, v: usize) -> &mut Neighbours {
        &mut self[v]
    }
}

/// The edge updates of VS (see [`EmcState::split`]): `v` keeps the edges coded STAY or
/// DUPLICATE, `r` (whose list is empty) takes those coded MOVE or DUPLICATE and, if
/// `connecting`, an edge to `v`; each neighbour's list follows. `r` must be larger than every
/// id in the lists it joins (so they stay sorted). Returns the edges added.
pub fn split_edges<L: NeighbourLists>(
    lists: &mut L,
    v: usize,
    r: usize,
    connecting: bool,
    codes: &[EdgeCode],
) -> u64 {
    let old = std::mem::take(lists.list(v));
    let mut kept = Neighbours::new();
    let mut moved = Neighbours::new();
    let mut added = 0;
    for (&n, &code) in old.iter().zip(codes) {
        let around = lists.list(n as usize);
        match code {
            EdgeCode::Stay => kept.push(n),
            EdgeCode::Move => {
                if let Ok(i) = around.binary_search(&(v as u32)) {
                    around.remove(i);
                }
                around.push(r as u32);
                moved.push(n);
            }
            EdgeCode::Duplicate => {
                around.push(r as u32);
                kept.push(n);
                moved.push(n);
                added += 1;
            }
        }
    }
    if connecting {
        added += 1;
        kept.push(r as u32);
        let at = moved.partition_point(|&x| x < v as u32);
        moved.insert(at, v as u32);
    }
    *lists.list(v) = kept;
    *lists.list(r) = moved;
    added
}

/// Mean of the positions (the guess for outward orientation looks away from it).
pub fn centroid(positions: &[DVec3]) -> DVec3 {
    if positions.is_empty() {
        return DVec3::ZERO;
    }
    positions.iter().copied().sum::<DVec3>() / positions.len() as f64
}

/// What the last level adds to make the clique triangles exactly the mesh's faces.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct FaceCorrections {
    /// Positions in the clique list of 3-cliques that are not faces.
    pub false_triangles: Vec<u32>,
    /// Positions in the clique list of triangles that are faces in both orientations.
    pub double_sided: Vec<u32>,
    /// Visits (in propagation order) whose predicted orientation is wrong.
    pub orientation_exceptions: Vec<u32>,
}

impl FaceCorrections {
    /// Which of `n` cliques the orientation propagation leaves out: false triangles and
    /// double-sided faces.
    pub fn skipped(&self, n: usize) -> Vec<bool> {
        let mut skipped = vec![false; n];
        for &i in self.false_triangles.iter().chain(&self.double_sided) {
            skipped[i as usize] = true;
        }
        skipped
    }
}

/// Applies `corrections` to the cliques of the final state: the faces of the full mesh.
pub fn final_faces(
    cliques: &Cliques,
    positions: &[DVec3],
    corrections: &FaceCorrections,
) -> Vec<[u32; 3]> {
    let skipped = corrections.skipped(cliques.len());
    let mut exceptions = corrections.orientation_exceptions.iter().peekable();
    let flipped = propagate_orientation(
        cliques,
        &skipped,
        positions,
        centroid(positions),
        |visit, _, predicted| {
            if exceptions.peek() == Some(&&(visit as u32)) {
                exceptions.next();
                !predicted
            } else {
                predicted
            }
        },
    );
    let mut double = vec![false; cliques.len()];
    for &i in &corrections.double_sided {
        double[i as usize] = true;
    }
    let mut faces = Vec::with_capacity(cliques.len() + corrections.double_sided.len());
    for (i, &t) in cliques.tris.iter().enumerate() {
        if double[i] {
            faces.push(oriented(t, false));
            faces.push(oriented(t, true));
        } else if !skipped[i] {
            faces.push(oriented(t, flipped[i]));
        }
    }
    faces
}

/// Compares the cliques of the final edge graph with the mesh's faces and lists what the decoder
/// must correct: false triangles, faces present in both orientations, and orientations that the
/// propagation predicts wrongly.
/// Refuses a mesh whose edge graph has more 3-cliques than a decoder accepts
/// ([`limits::level_triangles`]).
pub fn face_corrections(
    mesh: &CanonicalMesh,
    state: &EmcState,
    ranges: &[Range<usize>],
    trie: &KeyTrie,
) -> crate::Result<FaceCorrections> {
    // Every cluster is a single mesh vertex by now.
    let mut list_id = vec![0u32; mesh.vertex_count()];
    for (v, range) in ranges.iter().enumerate() {
        debug_assert_eq!(range.len(), 1);
        list_id[trie.vertices[range.start] as usize] = v as u32;
    }
    // Oriented faces in list ids by their ascending triple, sorted as the cliques are (a sort
    // and one merge: a hash map of a million faces costs twice the memory and far more time).
    let mut faces: Vec<([u32; 3], u8)> = mesh
        .faces
        .iter()
        .map(|f| {
            let f = f.map(|u| list_id[u as usize]);
            let mut sorted = f;
            sorted.sort_unstable();
            let unflipped = rotate_to_smallest(f) == sorted;
            (sorted, if unflipped { 1 } else { 2 }) // bit 0: unflipped, bit 1: flipped
        })
        .collect();
    faces.sort_unstable();
    let cliques = state
        // In place: the encoder's memory peaks here.
        .cliques(mesh.face_count() as u64, Listing::InPlace)
        .map_err(|why| crate::Error::Unsupported(format!("EMC cannot code this mesh: {why}")))?;
    // Per clique: how the mesh has it (0: not at all).
    let mut sides = vec![0u8; cliques.len()];
    let mut next = faces.iter().peekable();
    for (t, side) in cliques.tris.iter().zip(&mut sides) {
        while let Some((key, flags)) = next.next_if(|(key, _)| key <= t) {
            if key == t {
                *side |= flags;
            }
        }
    }
    let mut corrections = FaceCorrections::default();
    for (i, side) in sides.iter().enumerate() {
        match side {
            0 => corrections.false_triangles.push(i as u32),
            3 => corrections.double_sided.push(i as u32),
            _ => {}
        }
    }
    debug_assert_eq!(
        cliques.len() - corrections.false_triangles.len(),
        // Distinct faces (a face in both orientations is one key twice).
        faces.len() - faces.windows(2).filter(|w| w[0].0 == w[1].0).count(),
        "every face is a 3-clique of its own edges"
    );
    let skipped = corrections.skipped(cliques.len());
    // The decoder's positions when it reads the corrections: its cells' centres (at the last
    // level, the vertices' own cells).
    let positions = state.positions(&mesh.grid);
    // Let the propagation follow the true orientations and note where they were not predicted.
    let is_flipped = |t: usize| sides[t] == 2;
    let centre = centroid(&positions);
    propagate_orientation(
        &cliques,
        &skipped,
        &positions,
        centre,
        |visit, t, predicted| {
            if is_flipped(t) != predicted {
                corrections.orientation_exceptions.push(visit as u32);
            }
            is_flipped(t)
        },
    );
    debug_assert_eq!(
        {
            let mut got: Vec<_> = final_faces(&cliques, &positions, &corrections)
                .into_iter()
                .map(rotate_to_smallest)
                .collect();
            got.sort_unstable();
            got
        },
        {
            let mut want: Vec<_> = mesh
                .faces
                .iter()
                .map(|f| rotate_to_smallest(f.map(|u| list_id[u as usize])))
                .collect();
            want.sort_unstable();
            want
        }
    );
    Ok(corrections)
}
