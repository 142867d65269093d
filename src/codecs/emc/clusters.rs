//! The encoders' view of the hierarchy: which mesh vertices each vertex of the decoder's list
//! stands for (a range of the key trie), and what a split does to its edges. Both EMC encoders
//! read every decision off this; only how they code it differs.

use super::state::{EdgeCode, EmcState};
use crate::hierarchy::octree::KeyTrie;
use crate::mesh::CanonicalMesh;
use std::ops::Range;

/// What a split does, as the encoder works it out from the mesh.
#[derive(Clone, Debug, Default)]
pub struct SplitPlan {
    /// Mesh vertices (trie positions) of the lower half.
    pub lower: Range<usize>,
    /// Mesh vertices (trie positions) of the upper half.
    pub upper: Range<usize>,
    /// An edge joins the two halves.
    pub connecting: bool,
    /// Code of each neighbour of the splitting vertex, in its adjacency order.
    pub codes: Vec<EdgeCode>,
}

/// Clusters of the hierarchy over the trie.
pub struct Clusters {
    /// The key trie of the mesh's cells.
    pub trie: KeyTrie,
    /// Trie range of each list vertex.
    pub ranges: Vec<Range<usize>>,
    /// The mesh's edges, per mesh vertex.
    neighbours: Vec<Vec<u32>>,
    /// List vertex each mesh vertex belongs to now.
    cluster_of: Vec<u32>,
    stamp_lower: Vec<u32>,
    stamp_upper: Vec<u32>,
    stamp: u32,
}

impl Clusters {
    /// One cluster holding every vertex of `mesh`.
    pub fn new(mesh: &CanonicalMesh, trie: KeyTrie) -> Clusters {
        let n = mesh.vertex_count();
        Clusters {
            trie,
            ranges: std::iter::once(0..n).collect(),
            neighbours: crate::hierarchy::cliques::adjacency(n, &mesh.faces),
            cluster_of: vec![0; n],
            stamp_lower: vec![0],
            stamp_upper: vec![0],
            stamp: 0,
        }
    }

    /// The step at which list vertex `v` splits next, if it does.
    pub fn next_split(&self, v: usize) -> Option<usize> {
        self.trie.next_split(self.ranges[v].clone())
    }

    /// The bit list vertex `v` takes at `step` when it does not split.
    pub fn bit(&self, v: usize, step: usize) -> u32 {
        self.trie
            .order
            .bit(self.trie.keys[self.ranges[v].start], step)
    }

    /// Works out the split of `v` at `step` (which must be its next split) into `plan`, and
    /// assigns the upper half's mesh vertices to the list vertex the split will create.
    pub fn plan(&mut self, state: &EmcState, v: usize, step: usize, plan: &mut SplitPlan) {
        let range = self.ranges[v].clone();
        let mid = self.trie.partition(range.clone(), step);
        plan.lower = range.start..mid;
        plan.upper = mid..range.end;
        let r = state.len() as u32;
        for &u in &self.trie.vertices[plan.upper.clone()] {
            self.cluster_of[u as usize] = r;
        }
        // Which clusters each half touches.
        self.stamp += 1;
        self.stamp_lower.resize(state.len() + 1, 0);
        self.stamp_upper.resize(state.len() + 1, 0);
        plan.connecting = false;
        for (half, stamps) in [
            (plan.lower.clone(), &mut self.stamp_lower),
            (plan.upper.clone(), &mut self.stamp_upper),
        ] {
            let is_lower = half.start == range.start;
            for &u in &self.trie.vertices[half] {
                for &w in &self.neighbours[u as usize] {
                    let c = self.cluster_of[w as usize];
                    stamps[c as usize] = self.stamp;
                    plan.connecting |= is_lower && c == r;
                }
            }
        }
        plan.codes.clear();
        for &nb in &state.adjacency[v] {
            let lower = self.stamp_lower[nb as usize] == self.stamp;
            let upper = self.stamp_upper[nb as usize] == self.stamp;
            debug_assert!(lower || upper, "neighbour {nb} lost by both halves");
            plan.codes.push(match (lower, upper) {
                (true, true) => EdgeCode::Duplicate,
                (false, true) => EdgeCode::Move,
                _ => EdgeCode::Stay,
            });
        }
    }

    /// Frees what only splits need (the mesh's edges, the cluster of each vertex), once every
    /// cluster is a single vertex: the face corrections that follow are the encoder's peak of
    /// memory, and these are a third of it on a large mesh.
    pub fn release_edges(&mut self) {
        self.neighbours = Vec::new();
        self.cluster_of = Vec::new();
        self.stamp_lower = Vec::new();
        self.stamp_upper = Vec::new();
    }

    /// Records the split of `v` by `plan`: `v` keeps the lower half, the new vertex the upper.
    pub fn commit(&mut self, v: usize, plan: &SplitPlan) {
        self.ranges[v] = plan.lower.clone();
        self.ranges.push(plan.upper.clone());
    }
}
