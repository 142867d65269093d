//! The hierarchy by pair contraction (Garland & Heckbert 1997): valid pairs are the mesh's edges
//! and vertex pairs closer than a threshold, contracted cheapest first by the balanced cost
//! E(i) = 2^(b·d(i)) · E_q(i) until one node is left. When the pairs run out with several nodes
//! left (components farther apart than the threshold), each remaining node is paired with its
//! nearest remaining neighbour and contraction goes on; every such round at least halves the
//! nodes left.
//!
//! Faces carry their current corners; a face whose corners meet in a contraction vanishes there,
//! and the split that undoes that contraction creates it. Faces never need neighbours, so
//! nothing here cares whether the mesh is a manifold.

use super::{NodeId, VertexTree, MAX_DEPTH};
use crate::error::{Error, Result};
use crate::hierarchy::simplify::engine::topology;
use crate::hierarchy::simplify::quadric::{initial_quadrics, Quadric};
use glam::DVec3;
use std::cmp::Reverse;
use std::collections::{BinaryHeap, HashMap};

/// How the hierarchy is built.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BuildOptions {
    /// Balancing factor b of E(i) = 2^(b·d(i))·E_q(i) (the paper's Table 3: b = 1).
    pub balance: f64,
    /// Vertex pairs closer than this fraction of the mean edge length are valid pairs besides
    /// the edges.
    pub pair_distance: f64,
}

impl Default for BuildOptions {
    fn default() -> Self {
        BuildOptions {
            balance: 1.0,
            pair_distance: 0.5,
        }
    }
}

/// Close pairs kept per vertex (the nearest ones), so that dense clusters stay linear.
const CLOSE_PAIRS_PER_VERTEX: usize = 4;

/// Quadric errors that tie (flat regions, where E_q = 0) are broken by the pair's length: this
/// fraction of |a − b|⁴, small against any curvature the grid can show.
const LENGTH_TIE_BREAK: f64 = 1e-6;

/// Builds the hierarchy of the mesh (`cells`, `faces`); faces may be anything that repeats no
/// vertex. Errors if the hierarchy would be deeper than [`MAX_DEPTH`].
pub fn build(cells: &[[u32; 3]], faces: &[[u32; 3]], options: &BuildOptions) -> Result<VertexTree> {
    let n = cells.len();
    if n == 0 {
        return Err(Error::mesh("no vertices to build a hierarchy of"));
    }
    let mut c = Contraction::new(cells, faces, options);
    c.run();
    c.finish()
}

struct Contraction {
    balance: f64,
    leaves: usize,
    positions: Vec<DVec3>,
    quadrics: Vec<Quadric>,
    height: Vec<u8>,
    rep_leaf: Vec<u32>,
    alive: Vec<bool>,
    children: Vec<[u32; 2]>,
    parent: Vec<u32>,
    /// Current corners of each face.
    corners: Vec<[u32; 3]>,
    face_dead: Vec<bool>,
    births: Vec<u32>,
    /// Faces around each live node (dead ones dropped lazily).
    node_faces: Vec<Vec<u32>>,
    pairs: Vec<[u32; 2]>,
    pair_version: Vec<u32>,
    pair_dead: Vec<bool>,
    node_pairs: Vec<Vec<u32>>,
    heap: BinaryHeap<Reverse<(u64, u32, u32)>>,
    dependency_faces: Vec<Vec<u32>>,
    mark: Vec<u32>,
}

fn to_f(c: [u32; 3]) -> DVec3 {
    DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64)
}

impl Contraction {
    fn new(cells: &[[u32; 3]], faces: &[[u32; 3]], options: &BuildOptions) -> Contraction {
        let n = cells.len();
        let total = 2 * n - 1;
        let signed: Vec<[i32; 3]> = cells.iter().map(|c| c.map(|x| x as i32)).collect();
        let t = topology(n, faces, &vec![true; faces.len()]);
        let mut quadrics = initial_quadrics(&signed, faces, &t);
        quadrics.resize(total, Quadric::default());
        let mut positions: Vec<DVec3> = cells.iter().map(|&c| to_f(c)).collect();
        positions.resize(total, DVec3::ZERO);
        let mut node_faces = vec![Vec::new(); total];
        for (f, face) in faces.iter().enumerate() {
            for &v in face {
                node_faces[v as usize].push(f as u32);
            }
        }
        let pairs = initial_pairs(cells, faces, options.pair_distance);
        let mut node_pairs = vec![Vec::new(); total];
        for (p, &[a, b]) in pairs.iter().enumerate() {
            node_pairs[a as usize].push(p as u32);
            node_pairs[b as usize].push(p as u32);
        }
        let mut c = Contraction {
            balance: options.balance,
            leaves: n,
            positions,
            quadrics,
            height: vec![0; total],
            rep_leaf: (0..total as u32).collect(),
            alive: (0..total).map(|i| i < n).collect(),
            children: Vec::with_capacity(n.saturating_sub(1)),
            parent: vec![u32::MAX; total],
            corners: faces.to_vec(),
            face_dead: vec![false; faces.len()],
            births: vec![u32::MAX; faces.len()],
            node_faces,
            pair_version: vec![0; pairs.len()],
            pair_dead: vec![false; pairs.len()],
            pairs,
            node_pairs,
            heap: BinaryHeap::new(),
            dependency_faces: Vec::with_capacity(n.saturating_sub(1)),
            mark: vec![u32::MAX; total],
        };
        let keys: Vec<_> = (0..c.pairs.len() as u32)
            .map(|p| Reverse((c.cost(p).to_bits(), p, 0)))
            .collect();
        c.heap = BinaryHeap::from(keys);
        c
    }

    /// The merged quadric's optimum for a pair, or the best of its ends and midpoint.
    fn place(&self, a: u32, b: u32) -> (DVec3, Quadric) {
        let q = Quadric::sum(&self.quadrics[a as usize], &self.quadrics[b as usize]);
        let (pa, pb) = (self.positions[a as usize], self.positions[b as usize]);
        let fallback = || {
            [pa, pb, (pa + pb) * 0.5]
                .into_iter()
                .min_by(|x, y| q.error(*x).total_cmp(&q.error(*y)))
                .expect("three candidates")
        };
        let p = match q.minimizer() {
            // An optimum far outside the pair (nearly singular quadrics) is no placement.
            Some(p) if p.distance(pa.midpoint(pb)) <= 2.0 * pa.distance(pb) + 1.0 => p,
            _ => fallback(),
        };
        (p, q)
    }

    /// E(i) = 2^(b·d(i)) · E_q(i) of contracting pair `p`, E_q tie-broken by length.
    fn cost(&self, p: u32) -> f64 {
        let [a, b] = self.pairs[p as usize];
        let (pos, q) = self.place(a, b);
        let length2 = self.positions[a as usize].distance_squared(self.positions[b as usize]);
        let eq = q.error(pos).max(0.0) + LENGTH_TIE_BREAK * length2 * length2;
        let d = self.height[a as usize].max(self.height[b as usize]) as f64 + 1.0;
        eq * (self.balance * d).exp2()
    }

    fn run(&mut self) {
        let mut left = self.leaves;
        while left > 1 {
            while let Some(Reverse((_, p, version))) = self.heap.pop() {
                if self.pair_dead[p as usize] || self.pair_version[p as usize] != version {
                    continue;
                }
                self.contract(p);
                left -= 1;
            }
            if left > 1 {
                self.pair_nearest();
            }
        }
    }

    fn contract(&mut self, p: u32) {
        let [a, b] = self.pairs[p as usize];
        self.pair_dead[p as usize] = true;
        let k = (self.leaves + self.children.len()) as u32;
        let (pos, q) = self.place(a, b);
        let (ra, rb) = (self.rep_leaf[a as usize], self.rep_leaf[b as usize]);
        let ea = q.error(self.positions[ra as usize]);
        let eb = q.error(self.positions[rb as usize]);
        let [t, u] = if eb < ea { [b, a] } else { [a, b] };
        let ku = k as usize;
        self.children.push([t, u]);
        self.parent[a as usize] = k;
        self.parent[b as usize] = k;
        self.positions[ku] = pos;
        self.quadrics[ku] = q;
        self.height[ku] = self.height[a as usize].max(self.height[b as usize]) + 1;
        self.rep_leaf[ku] = self.rep_leaf[t as usize];
        self.alive[a as usize] = false;
        self.alive[b as usize] = false;
        self.alive[ku] = true;

        // Faces: move both lists to k; faces holding both ends vanish here.
        let mut faces = std::mem::take(&mut self.node_faces[a as usize]);
        faces.append(&mut std::mem::take(&mut self.node_faces[b as usize]));
        let mut vanishing: Vec<(u32, u32)> = Vec::new();
        faces.retain(|&f| {
            let fu = f as usize;
            if self.face_dead[fu] {
                return false;
            }
            let c = &mut self.corners[fu];
            let mut hits = 0;
            for x in c.iter_mut() {
                if *x == a || *x == b {
                    *x = k;
                    hits += 1;
                }
            }
            if hits >= 2 {
                // Both lists hold it: vanish once.
                if !self.face_dead[fu] {
                    self.face_dead[fu] = true;
                    self.births[fu] = k;
                    let w = *c
                        .iter()
                        .find(|&&x| x != k)
                        .expect("a face has three corners");
                    vanishing.push((f, w));
                }
                return false;
            }
            true
        });
        // Hoppe 1997's fn0..fn3: the faces across the vanishing faces' other edges (k, w).
        let mut depends = Vec::new();
        for &(_, w) in &vanishing {
            let list = &mut self.node_faces[w as usize];
            let (dead, corners) = (&self.face_dead, &self.corners);
            list.retain(|&g| !dead[g as usize]);
            for &g in list.iter() {
                if corners[g as usize].contains(&k) && !depends.contains(&g) {
                    depends.push(g);
                }
            }
        }
        self.dependency_faces.push(depends);
        self.node_faces[ku] = faces;

        // Pairs: move both lists to k, one pair per other end.
        let mut pairs = std::mem::take(&mut self.node_pairs[a as usize]);
        pairs.append(&mut std::mem::take(&mut self.node_pairs[b as usize]));
        let mut kept = Vec::with_capacity(pairs.len());
        for pid in pairs {
            let pu = pid as usize;
            if self.pair_dead[pu] {
                continue;
            }
            let [x, y] = self.pairs[pu];
            let other = if x == a || x == b { y } else { x };
            if self.mark[other as usize] == k {
                self.pair_dead[pu] = true;
                continue;
            }
            self.mark[other as usize] = k;
            self.pairs[pu] = [k, other];
            kept.push(pid);
        }
        for &pid in &kept {
            let pu = pid as usize;
            self.pair_version[pu] += 1;
            let key = self.cost(pid).to_bits();
            self.heap.push(Reverse((key, pid, self.pair_version[pu])));
        }
        self.node_pairs[ku] = kept;
    }

    /// Pairs every live node with its nearest live neighbour.
    fn pair_nearest(&mut self) {
        let live: Vec<u32> = (0..self.alive.len() as u32)
            .filter(|&v| self.alive[v as usize])
            .collect();
        let points: Vec<DVec3> = live.iter().map(|&v| self.positions[v as usize]).collect();
        let mut found: Vec<[u32; 2]> = nearest_neighbours(&points)
            .into_iter()
            .enumerate()
            .map(|(i, j)| {
                let (x, y) = (live[i], live[j as usize]);
                [x.min(y), x.max(y)]
            })
            .collect();
        found.sort_unstable();
        found.dedup();
        for pair in found {
            let pid = self.pairs.len() as u32;
            self.pairs.push(pair);
            self.pair_version.push(0);
            self.pair_dead.push(false);
            self.node_pairs[pair[0] as usize].push(pid);
            self.node_pairs[pair[1] as usize].push(pid);
            let key = self.cost(pid).to_bits();
            self.heap.push(Reverse((key, pid, 0)));
        }
    }

    fn finish(self) -> Result<VertexTree> {
        let total = self.parent.len();
        let root = (total - 1) as u32;
        let leaves = self.leaves;
        let mut ids = vec![NodeId::ROOT; total];
        // Children are created after their parents' ids are needed: walk down from the root.
        for i in (0..self.children.len()).rev() {
            let k = leaves + i;
            for (bit, &c) in self.children[i].iter().enumerate() {
                ids[c as usize] = ids[k].child(bit == 1).ok_or_else(|| {
                    Error::Unsupported(format!(
                        "the vertex hierarchy is deeper than {MAX_DEPTH} levels"
                    ))
                })?;
            }
        }
        let births = self.births;
        let mut raw = 0;
        let dependencies = self
            .dependency_faces
            .iter()
            .enumerate()
            .map(|(i, faces)| {
                raw += faces.len();
                let own = ids[leaves + i];
                let mut nodes: Vec<u32> = Vec::with_capacity(faces.len());
                for &f in faces {
                    let d = births[f as usize];
                    if !ids[d as usize].is_ancestor_of(own) && !nodes.contains(&d) {
                        nodes.push(d);
                    }
                }
                nodes
            })
            .collect();
        Ok(VertexTree {
            leaves,
            children: self.children,
            parent: self.parent,
            root,
            positions: self.positions.iter().map(|p| p.to_array()).collect(),
            ids,
            births,
            dependencies,
            raw_dependencies: raw,
        })
    }
}

/// The mesh's edges and, per vertex, up to [`CLOSE_PAIRS_PER_VERTEX`] nearest vertices closer
/// than `fraction` of the mean edge length; each pair once, ends in ascending order.
fn initial_pairs(cells: &[[u32; 3]], faces: &[[u32; 3]], fraction: f64) -> Vec<[u32; 2]> {
    let mut pairs: Vec<[u32; 2]> = Vec::with_capacity(faces.len() * 3 / 2 + cells.len());
    let mut length_sum = 0.0;
    for f in faces {
        for k in 0..3 {
            let (x, y) = (f[k], f[(k + 1) % 3]);
            pairs.push([x.min(y), x.max(y)]);
            length_sum += to_f(cells[x as usize]).distance(to_f(cells[y as usize]));
        }
    }
    let threshold = fraction * length_sum / (3 * faces.len()).max(1) as f64;
    if threshold > 0.0 {
        let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
        let key = |p: DVec3| (p / threshold).floor().to_array().map(|x| x as i64);
        for (v, &c) in cells.iter().enumerate() {
            grid.entry(key(to_f(c))).or_default().push(v as u32);
        }
        let mut near: Vec<(f64, u32)> = Vec::new();
        for (v, &c) in cells.iter().enumerate() {
            let p = to_f(c);
            let [x, y, z] = key(p);
            near.clear();
            for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        let Some(list) = grid.get(&[x + dx, y + dy, z + dz]) else {
                            continue;
                        };
                        for &w in list {
                            let d = p.distance(to_f(cells[w as usize]));
                            if w != v as u32 && d < threshold {
                                near.push((d, w));
                            }
                        }
                    }
                }
            }
            near.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            for &(_, w) in near.iter().take(CLOSE_PAIRS_PER_VERTEX) {
                let v = v as u32;
                pairs.push([v.min(w), v.max(w)]);
            }
        }
    }
    pairs.sort_unstable();
    pairs.dedup();
    pairs
}

/// Index of the nearest other point of each point (ties to the lower index), by a uniform grid
/// of about two points a cell searched in growing shells. Needs at least two points.
fn nearest_neighbours(points: &[DVec3]) -> Vec<u32> {
    let lo = points.iter().fold(DVec3::splat(f64::MAX), |m, p| m.min(*p));
    let hi = points.iter().fold(DVec3::splat(f64::MIN), |m, p| m.max(*p));
    let extent = (hi - lo).max(DVec3::splat(1.0));
    let cell = (extent.x * extent.y * extent.z * 2.0 / points.len() as f64)
        .cbrt()
        .max(extent.max_element() / 1024.0);
    let key = |p: DVec3| ((p - lo) / cell).floor().to_array().map(|x| x as i64);
    let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
    for (i, &p) in points.iter().enumerate() {
        grid.entry(key(p)).or_default().push(i as u32);
    }
    let reach = ((extent / cell).ceil().max_element() as i64) + 1;
    points
        .iter()
        .enumerate()
        .map(|(i, &p)| {
            let [x, y, z] = key(p);
            let mut best = (f64::MAX, u32::MAX);
            for r in 0..=reach {
                // Every point within r − 1 cells is seen; stop once none closer can remain.
                if best.1 != u32::MAX && (r - 1) as f64 * cell >= best.0 {
                    break;
                }
                for dx in -r..=r {
                    for dy in -r..=r {
                        for dz in -r..=r {
                            if dx.abs().max(dy.abs()).max(dz.abs()) != r {
                                continue;
                            }
                            let Some(list) = grid.get(&[x + dx, y + dy, z + dz]) else {
                                continue;
                            };
                            for &j in list {
                                if j as usize == i {
                                    continue;
                                }
                                let d = p.distance(points[j as usize]);
                                if (d, j) < best {
                                    best = (d, j);
                                }
                            }
                        }
                    }
                }
            }
            best.1
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate;
    use crate::mesh::quantize::GridShape;
    use crate::mesh::{CanonicalMesh, Grid};

    fn canonical(mesh: &crate::mesh::TriMesh) -> CanonicalMesh {
        let grid = Grid::fit(mesh, 10, GridShape::Cubic).unwrap();
        CanonicalMesh::new(mesh, grid).unwrap()
    }

    fn check_tree(tree: &VertexTree, faces: &[[u32; 3]]) {
        let n = tree.leaves;
        assert_eq!(tree.children.len(), n - 1);
        assert_eq!(tree.parent[tree.root as usize], u32::MAX);
        // Every node but the root has one parent, and ids follow the child bits.
        for (i, &[t, u]) in tree.children.iter().enumerate() {
            let k = (n + i) as u32;
            assert_eq!(tree.parent[t as usize], k);
            assert_eq!(tree.parent[u as usize], k);
            assert_eq!(
                tree.ids[t as usize],
                tree.ids[k as usize].child(false).unwrap()
            );
            assert_eq!(
                tree.ids[u as usize],
                tree.ids[k as usize].child(true).unwrap()
            );
        }
        // A face is born at the lowest common ancestor of its corners that splits two of them.
        for (f, face) in faces.iter().enumerate() {
            let birth = tree.ids[tree.births[f] as usize];
            let leaf = face.map(|v| tree.ids[v as usize]);
            let under: Vec<bool> = leaf.iter().map(|l| birth.is_ancestor_of(*l)).collect();
            assert_eq!(under.iter().filter(|&&x| x).count(), 2, "face {f}");
            let inside: Vec<_> = (0..3).filter(|&k| under[k]).map(|k| leaf[k]).collect();
            assert_eq!(inside[0].common_len(inside[1]), birth.len());
        }
        // Dependencies: never an ancestor, never repeated, never the node itself.
        for (i, deps) in tree.dependencies.iter().enumerate() {
            let own = tree.ids[n + i];
            for (j, &d) in deps.iter().enumerate() {
                assert!(!tree.ids[d as usize].is_ancestor_of(own));
                assert!(!deps[..j].contains(&d));
            }
        }
    }

    #[test]
    fn a_closed_mesh_contracts_to_one_root_with_faces_born_at_their_splits() {
        let c = canonical(&generate::icosphere(3));
        let tree = build(&c.cells, &c.faces, &BuildOptions::default()).unwrap();
        check_tree(&tree, &c.faces);
        // Balanced: 642 vertices need at least 10 levels; b = 1 keeps it near that.
        assert!((10..=16).contains(&tree.depth()), "depth {}", tree.depth());
        let per_node = tree.dependencies_per_node();
        assert!((0.5..=4.0).contains(&per_node), "{per_node}");
    }

    #[test]
    fn disjoint_components_and_soup_merge_into_one_hierarchy() {
        let mut mesh = generate::icosphere(1);
        mesh.append(&generate::icosphere(1), DVec3::new(9.0, 0.0, 0.0), 1.0);
        // A loose triangle of its own vertices, and one sharing an edge non-manifoldly.
        let base = mesh.positions.len() as u32;
        mesh.positions.extend([
            glam::DVec3::new(0.0, 5.0, 0.0),
            glam::DVec3::new(1.0, 5.0, 0.0),
            glam::DVec3::new(0.0, 6.0, 0.0),
        ]);
        mesh.faces.push([base, base + 1, base + 2]);
        let [a, b, _] = mesh.faces[0];
        mesh.faces.push([a, b, base]);
        let c = canonical(&mesh);
        let tree = build(&c.cells, &c.faces, &BuildOptions::default()).unwrap();
        check_tree(&tree, &c.faces);
    }

    #[test]
    fn one_vertex_is_its_own_root() {
        let tree = build(&[[1, 2, 3]], &[], &BuildOptions::default()).unwrap();
        assert_eq!((tree.root, tree.depth(), tree.children.len()), (0, 0, 0));
    }

    #[test]
    fn nearest_neighbours_match_brute_force() {
        let points: Vec<DVec3> = (0..300)
            .map(|i| {
                let f = i as f64;
                DVec3::new((f * 7.3) % 13.0, (f * 3.1) % 5.0, (f * f * 0.01) % 40.0)
            })
            .collect();
        let fast = nearest_neighbours(&points);
        for (i, p) in points.iter().enumerate() {
            let best = (0..points.len())
                .filter(|&j| j != i)
                .map(|j| (p.distance(points[j]), j as u32))
                .min_by(|a, b| a.partial_cmp(b).unwrap())
                .unwrap();
            assert_eq!(fast[i], best.1, "point {i}");
        }
    }
}
