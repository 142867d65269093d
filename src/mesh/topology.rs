//! Counts that describe a mesh's topology: boundary and non-manifold edges, non-manifold
//! vertices, components. Codecs that need a manifold (PM) report these when they refuse a mesh.

use super::{TriMesh, VertexId};
use std::collections::HashMap;

/// Topology counts of a mesh, as MANIFEST.md of the shared meshes states them.
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct TopologyReport {
    /// Edges (each counted once, whatever its faces).
    pub edges: usize,
    /// Edges used by exactly one face.
    pub boundary_edges: usize,
    /// Edges used by more than two faces.
    pub non_manifold_edges: usize,
    /// Vertices whose incident faces form more than one edge-connected fan.
    pub non_manifold_vertices: usize,
    /// Edge-connected components over referenced vertices.
    pub components: usize,
    /// Directed edges that a second face runs the same way (faces that disagree in orientation).
    pub edges_used_twice_one_way: usize,
}

impl TopologyReport {
    /// True when every edge has one or two faces and every vertex one fan.
    pub fn is_manifold(&self) -> bool {
        self.non_manifold_edges == 0 && self.non_manifold_vertices == 0
    }

    /// True when the mesh is a manifold whose faces agree in orientation: what Hoppe's
    /// progressive meshes take without a cut (`mesh::manifold`).
    pub fn is_oriented_manifold(&self) -> bool {
        self.is_manifold() && self.edges_used_twice_one_way == 0
    }

    /// Edges and vertices that keep the mesh from being an oriented manifold.
    pub fn defects(&self) -> usize {
        self.non_manifold_edges + self.non_manifold_vertices + self.edges_used_twice_one_way
    }
}

/// Union-find over `n` elements.
pub(crate) struct DisjointSets(Vec<u32>);

impl DisjointSets {
    pub(crate) fn new(n: usize) -> Self {
        DisjointSets((0..n as u32).collect())
    }
    pub(crate) fn find(&mut self, mut x: u32) -> u32 {
        while self.0[x as usize] != x {
            let parent = self.0[self.0[x as usize] as usize];
            self.0[x as usize] = parent;
            x = parent;
        }
        x
    }
    pub(crate) fn union(&mut self, a: u32, b: u32) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            self.0[ra.max(rb) as usize] = ra.min(rb);
        }
    }
}

fn edge_key(a: VertexId, b: VertexId) -> (VertexId, VertexId) {
    (a.min(b), a.max(b))
}

/// Measures the topology of `mesh` (faces that repeat a vertex are ignored).
pub fn analyze(mesh: &TriMesh) -> TopologyReport {
    let faces: Vec<[VertexId; 3]> = mesh
        .faces
        .iter()
        .copied()
        .filter(|[a, b, c]| a != b && b != c && a != c)
        .collect();
    let mut edge_faces: HashMap<(VertexId, VertexId), u32> = HashMap::new();
    for f in &faces {
        for k in 0..3 {
            *edge_faces
                .entry(edge_key(f[k], f[(k + 1) % 3]))
                .or_default() += 1;
        }
    }
    let boundary_edges = edge_faces.values().filter(|&&n| n == 1).count();
    let mut directed = std::collections::HashSet::with_capacity(faces.len() * 3);
    let edges_used_twice_one_way = faces
        .iter()
        .flat_map(|f| (0..3).map(move |k| (f[k], f[(k + 1) % 3])))
        .filter(|e| !directed.insert(*e))
        .count();
    let non_manifold_edges = edge_faces.values().filter(|&&n| n > 2).count();

    let n = mesh.positions.len();
    let mut components = DisjointSets::new(n);
    for f in &faces {
        components.union(f[0], f[1]);
        components.union(f[1], f[2]);
    }
    let used = mesh.referenced();
    let mut roots: Vec<u32> = (0..n as u32)
        .filter(|&v| used[v as usize])
        .map(|v| components.find(v))
        .collect();
    roots.sort_unstable();
    roots.dedup();

    // Fans: around each vertex, join incident faces that share an edge through it.
    let mut incident: Vec<Vec<u32>> = vec![Vec::new(); n];
    for (i, f) in faces.iter().enumerate() {
        for &v in f {
            incident[v as usize].push(i as u32);
        }
    }
    let mut non_manifold_vertices = 0;
    for (v, around) in incident.iter().enumerate() {
        if around.len() < 2 {
            continue;
        }
        let mut fans = DisjointSets::new(around.len());
        let mut by_other: HashMap<VertexId, u32> = HashMap::new();
        for (slot, &fi) in around.iter().enumerate() {
            for &w in &faces[fi as usize] {
                if w as usize == v {
                    continue;
                }
                match by_other.get(&w) {
                    Some(&first) => fans.union(first, slot as u32),
                    None => {
                        by_other.insert(w, slot as u32);
                    }
                }
            }
        }
        let mut fan_roots: Vec<u32> = (0..around.len() as u32).map(|s| fans.find(s)).collect();
        fan_roots.sort_unstable();
        fan_roots.dedup();
        if fan_roots.len() > 1 {
            non_manifold_vertices += 1;
        }
    }
    TopologyReport {
        edges: edge_faces.len(),
        boundary_edges,
        non_manifold_edges,
        non_manifold_vertices,
        components: roots.len(),
        edges_used_twice_one_way,
    }
}
