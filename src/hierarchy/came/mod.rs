//! CAME's binary vertex hierarchy (Grabner, *Compressed Adaptive Multiresolution Encoding*, §3),
//! built for any triangle mesh: non-manifold edges and vertices, several components, mixed
//! orientation, triangle soup.
//!
//! Glossary of the paper's symbols:
//! - v_s: an inner node; its split creates v_t (left child, path bit 0) and v_u (right, bit 1).
//! - node identifier: the bit path from the root ([`NodeId`]); relative identifiers go `up` to a
//!   junction v'_s, then down.
//! - n1, n2, n3: the corners of a triangle created by the split of v_s, as paths from v_s: n1
//!   under v_t, n2 under v_u, n3 (with n3.up) under the other subtree of the junction.
//! - E_q(i): the Garland–Heckbert quadric error of contraction i; d(i): depth of the subtree it
//!   creates; b: the balancing factor of E(i) = 2^(b·d(i))·E_q(i).
//! - dependencies: Hoppe 1997's condition that the faces fn0..fn3 next to the faces a split
//!   creates be present, written as the nodes whose splits create those faces.
//! - error sphere: a ball at v_s holding every vertex of its subtree ([`spheres`]).
//!
//! Nodes are numbered as they are created: leaves 0..n are the mesh's vertices, inner node n + i
//! is the i-th contraction. The left child of every inner node is its *representative*: the one
//! whose representative leaf the merged quadric prefers, so that following left children from
//! any node reaches a vertex of the mesh that stands for it (the `came` codec places inner nodes
//! there; `came-paper` at the quadric optimum).

mod build;
pub mod cones;
pub mod deviation;
pub mod face_normals;
mod grid;
pub mod node_id;
pub mod spheres;

pub use build::{build, BuildOptions};
pub use node_id::{NodeId, MAX_DEPTH};

/// A binary vertex hierarchy over the vertices of a mesh, with the triangles each split creates
/// and the splits each split depends on.
#[derive(Clone, Debug)]
pub struct VertexTree {
    /// Leaves: the mesh's vertices, nodes 0..leaves.
    pub leaves: usize,
    /// Children [v_t, v_u] of inner node `leaves + i`.
    pub children: Vec<[u32; 2]>,
    /// Parent of each node (`u32::MAX` at the root).
    pub parent: Vec<u32>,
    /// The root.
    pub root: u32,
    /// Position of each node: leaves at their cells, inner nodes at the quadric optimum.
    pub positions: Vec<[f64; 3]>,
    /// Path of each node from the root.
    pub ids: Vec<NodeId>,
    /// For each face of the mesh, the inner node whose split creates it.
    pub births: Vec<u32>,
    /// For each inner node, the splits it depends on beyond its ancestors, each once.
    pub dependencies: Vec<Vec<u32>>,
    /// Dependencies before the redundant ones (repeated, ancestors) were dropped.
    pub raw_dependencies: usize,
}

impl VertexTree {
    /// Every node.
    pub fn node_count(&self) -> usize {
        self.parent.len()
    }

    /// Whether `node` is a leaf (a vertex of the mesh).
    pub fn is_leaf(&self, node: u32) -> bool {
        (node as usize) < self.leaves
    }

    /// The children of `node`, if it is inner.
    pub fn children_of(&self, node: u32) -> Option<[u32; 2]> {
        (node as usize)
            .checked_sub(self.leaves)
            .map(|i| self.children[i])
    }

    /// Depth of the deepest leaf (0 for a single vertex).
    pub fn depth(&self) -> u8 {
        self.ids.iter().map(|id| id.len()).max().unwrap_or(0)
    }

    /// The leaf that stands for `node`: left children followed down.
    pub fn representative(&self, mut node: u32) -> u32 {
        while let Some([t, _]) = self.children_of(node) {
            node = t;
        }
        node
    }

    /// Inner nodes in breadth-first order from the root (by depth, then left to right).
    pub fn breadth_first(&self) -> Vec<u32> {
        let mut order = Vec::with_capacity(self.children.len());
        if self.is_leaf(self.root) {
            return order;
        }
        order.push(self.root);
        let mut at = 0;
        while at < order.len() {
            let [t, u] = self
                .children_of(order[at])
                .expect("only inner nodes are queued");
            at += 1;
            for c in [t, u] {
                if !self.is_leaf(c) {
                    order.push(c);
                }
            }
        }
        order
    }

    /// Mean number of dependencies per inner node, after the redundant ones are dropped.
    pub fn dependencies_per_node(&self) -> f64 {
        let total: usize = self.dependencies.iter().map(Vec::len).sum();
        total as f64 / self.children.len().max(1) as f64
    }
}
