//! The hierarchy by pair contraction (Garland & Heckbert 1997): valid pairs are the mesh's edges
//! and vertex pairs closer than a threshold, contracted cheapest first by the cost
//! E(i) = 2^(b·d(i)) · E_q(i) until one node is left (b = 1 balances the tree as the paper
//! does; b = 0 contracts by quadric error alone, [`BuildOptions::QUADRIC_ORDER`]). When the
//! pairs run out with several nodes left (components farther apart than the threshold), each
//! remaining node is paired with its nearest remaining neighbour and contraction goes on; every
//! such round at least halves the nodes left.
//!
//! Faces carry their current corners; a face whose corners meet in a contraction vanishes there,
//! and the split that undoes that contraction creates it. Faces never need neighbours, so
//! nothing here cares whether the mesh is a manifold.

use super::grid::CellGrid;
use super::{NodeId, VertexTree, MAX_DEPTH};
use crate::error::{Error, Result};
use crate::hierarchy::simplify::engine::topology;
use crate::hierarchy::simplify::quadric::{initial_quadrics, Quadric};
use glam::DVec3;
use orx_priority_queue::{DaryHeapOfIndices, PriorityQueue, PriorityQueueDecKey};
use rayon::prelude::*;
use smallvec::SmallVec;

/// How the hierarchy is built.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BuildOptions {
    /// Balancing factor b of E(i) = 2^(b·d(i))·E_q(i) (the paper's Table 3: b = 1).
    pub balance: f64,
    /// Vertex pairs closer than this fraction of the mean edge length are valid pairs besides
    /// the edges.
    pub pair_distance: f64,
}

impl BuildOptions {
    /// The paper's (its Table 3: b = 1), which `came-paper` builds: a shallow tree, its coarse
    /// levels made of pairs of about one size whatever the surface's curvature.
    pub const PAPER: BuildOptions = BuildOptions {
        balance: 1.0,
        pair_distance: 0.5,
    };

    /// By quadric error alone (b = 0), which `came` builds from syntax 7: the pairs contract in a
    /// simplifier's order, so the front a far view keeps is a simplified mesh, flat regions
    /// merged and curved ones kept, and holds fewer faces for the same error (dragon-50k from
    /// 20 diagonals: 972 → 700 faces, from 11.8% → 7.3% of its stream; docs/notes/benchmarks-history.md, "`came`
    /// syntax 7"). The tree is 2–10 levels deeper and the streams within ±2.5% of the paper's.
    pub const QUADRIC_ORDER: BuildOptions = BuildOptions {
        balance: 0.0,
        ..BuildOptions::PAPER
    };
}

impl Default for BuildOptions {
    fn default() -> Self {
        BuildOptions::PAPER
    }
}

/// Close pairs kept per vertex (the nearest ones), so that dense clusters stay linear.
const CLOSE_PAIRS_PER_VERTEX: usize = 4;

/// Quadric errors that tie (flat regions, where E_q = 0) are broken by the pair's length: this
/// fraction of |a − b|⁴, small against any curvature the grid can show.
const LENGTH_TIE_BREAK: f64 = 1e-6;

/// Builds the hierarchy of the mesh (`cells`, `faces`); faces may be anything that repeats no
/// vertex. Errors if the hierarchy would be deeper than [`MAX_DEPTH`].
///
/// One greedy loop over the whole mesh. (Large meshes were once contracted first in regions
/// of 32k vertices in parallel, their seams pinned: each region's interior collapsed to a root
/// beside seams at full resolution, and a far view had to split every root down to the seams'
/// level: igea.ply from 20 diagonals kept 3,928 faces, not 676, and bunny-closed-35k ×16
/// 11,664, not 708; the streams were 0.4–6% larger.)
pub fn build(cells: &[[u32; 3]], faces: &[[u32; 3]], options: &BuildOptions) -> Result<VertexTree> {
    let n = cells.len();
    if n == 0 {
        return Err(Error::mesh("no vertices to build a hierarchy of"));
    }
    // Work in a spatial order (vertices by Morton code, faces by their first corner), so that
    // what one contraction touches lies close in memory.
    let vertex_of_slot = morton_order(cells);
    let mut slot_of_vertex = vec![0u32; n];
    for (slot, &v) in vertex_of_slot.iter().enumerate() {
        slot_of_vertex[v as usize] = slot as u32;
    }
    let slot_cells: Vec<[u32; 3]> = vertex_of_slot.iter().map(|&v| cells[v as usize]).collect();
    let slot_faces: Vec<[u32; 3]> = faces
        .iter()
        .map(|f| f.map(|v| slot_of_vertex[v as usize]))
        .collect();
    let mut face_order: Vec<u32> = (0..faces.len() as u32).collect();
    face_order.par_sort_unstable_by_key(|&f| (slot_faces[f as usize].iter().min().copied(), f));
    let ordered_faces: Vec<[u32; 3]> = face_order.iter().map(|&f| slot_faces[f as usize]).collect();
    let start = Start::new(&slot_cells, ordered_faces, &vertex_of_slot, options);
    let mut c = Contraction::new(start, options.balance);
    c.run(1, true);
    c.finish(cells, &face_order)
}

/// Vertices sorted by the Morton code of their cells (ties by index).
fn morton_order(cells: &[[u32; 3]]) -> Vec<u32> {
    fn spread(x: u32) -> u64 {
        // 21 bits of x, two zero bits after each.
        let mut v = (x as u64) & 0x1f_ffff;
        v = (v | v << 32) & 0x1f_0000_0000_ffff;
        v = (v | v << 16) & 0x1f_0000_ff00_00ff;
        v = (v | v << 8) & 0x100f_00f0_0f00_f00f;
        v = (v | v << 4) & 0x10c3_0c30_c30c_30c3;
        v = (v | v << 2) & 0x1249_2492_4924_9249;
        v
    }
    // Grids finer than 21 bits an axis are ordered by their top 21 bits.
    let shift = cells
        .iter()
        .flat_map(|c| c.iter())
        .max()
        .map_or(0, |&m| (32 - m.leading_zeros()).saturating_sub(21));
    let mut keyed: Vec<(u64, u32)> = cells
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let [x, y, z] = c.map(|a| spread(a >> shift));
            (x | y << 1 | z << 2, i as u32)
        })
        .collect();
    keyed.par_sort_unstable();
    keyed.into_iter().map(|(_, i)| i).collect()
}

/// A state of the contraction: the slots (every live node sits in the slot of one of its
/// leaves, which it keeps when it absorbs another node, so that its faces and pairs stay where
/// they were and only the vanishing node's move), the faces' current corners, the pairs, and the
/// tree made so far.
struct Start {
    /// The id of the first inner node (the mesh's vertex count); inner node `base + i` is
    /// `children[i]`.
    pub base: u32,
    /// Per slot: the node in it, its position, quadric, subtree height, the position of its
    /// representative leaf, and whether it is live.
    pub node: Vec<u32>,
    pub position: Vec<DVec3>,
    pub quadric: Vec<Quadric>,
    pub height: Vec<u8>,
    pub rep_position: Vec<DVec3>,
    pub alive: Vec<bool>,
    /// Per face: its corners' slots, whether it vanished, and the node whose split creates it.
    pub corners: Vec<[u32; 3]>,
    pub face_dead: Vec<bool>,
    pub births: Vec<u32>,
    /// Pairs of slots, each once.
    pub pairs: Vec<[u32; 2]>,
    /// Per inner node: its children, its position, and the faces (fn0..fn3) its split needs,
    /// `dependency_faces[dependency_start[i]..dependency_start[i + 1]]`.
    pub children: Vec<[u32; 2]>,
    pub inner_positions: Vec<DVec3>,
    pub dependency_faces: Vec<u32>,
    pub dependency_start: Vec<u32>,
}

impl Start {
    /// The mesh before any contraction: one slot per vertex (`cells` and `faces` in slot order,
    /// `vertex_of_slot` the vertex in each slot).
    fn new(
        cells: &[[u32; 3]],
        faces: Vec<[u32; 3]>,
        vertex_of_slot: &[u32],
        options: &BuildOptions,
    ) -> Start {
        let n = cells.len();
        let signed: Vec<[i32; 3]> = cells.iter().map(|c| c.map(|x| x as i32)).collect();
        let t = topology(n, &faces, &vec![true; faces.len()]);
        let quadric = initial_quadrics(&signed, &faces, &t);
        let position: Vec<DVec3> = cells.iter().map(|&c| to_f(c)).collect();
        let pairs = initial_pairs(cells, &faces, &t.edges, options.pair_distance);
        Start {
            base: n as u32,
            node: vertex_of_slot.to_vec(),
            rep_position: position.clone(),
            position,
            quadric,
            height: vec![0; n],
            alive: vec![true; n],
            face_dead: vec![false; faces.len()],
            births: vec![u32::MAX; faces.len()],
            corners: faces,
            pairs,
            children: Vec::with_capacity(n.saturating_sub(1)),
            inner_positions: Vec::with_capacity(n.saturating_sub(1)),
            dependency_faces: Vec::with_capacity(2 * n),
            dependency_start: vec![0],
        }
    }
}

/// The greedy contraction over a [`Start`], with each slot's faces and pairs at hand and the
/// allowed pairs in a heap by cost.
struct Contraction {
    balance: f64,
    s: Start,
    /// Free live slots.
    left: usize,
    /// Faces and pairs around each live slot (dead ones dropped lazily).
    slot_faces: Vec<Around>,
    slot_pairs: Vec<Around>,
    /// A tag per slot, for "already seen in this contraction".
    mark: Vec<u32>,
    pair_dead: Vec<bool>,
    /// Allowed live pairs by cost (f32 bits, then pair id): keys updated in place, so the heap
    /// never holds more than the live pairs.
    heap: DaryHeapOfIndices<usize, u64, 8>,
    /// Third corners of the faces vanishing in one contraction.
    vanishing: Vec<u32>,
}

/// A slot's faces or pairs: most slots have few, kept inline.
type Around = SmallVec<[u32; 8]>;

fn to_f(c: [u32; 3]) -> DVec3 {
    DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64)
}

/// A heap key: the cost as f32 bits above the pair's id, so ties go to the lower id.
fn heap_key(cost: f64, pair: u32) -> u64 {
    ((cost as f32).to_bits() as u64) << 32 | pair as u64
}

impl Contraction {
    fn new(s: Start, balance: f64) -> Contraction {
        let n = s.node.len();
        let mut slot_faces = vec![Around::new(); n];
        for (f, face) in s.corners.iter().enumerate() {
            if !s.face_dead[f] {
                for &v in face {
                    slot_faces[v as usize].push(f as u32);
                }
            }
        }
        let mut slot_pairs = vec![Around::new(); n];
        for (p, &[a, b]) in s.pairs.iter().enumerate() {
            slot_pairs[a as usize].push(p as u32);
            slot_pairs[b as usize].push(p as u32);
        }
        let left = (0..n).filter(|&v| s.alive[v]).count();
        let mut c = Contraction {
            balance,
            left,
            slot_faces,
            slot_pairs,
            mark: vec![u32::MAX; n],
            pair_dead: vec![false; s.pairs.len()],
            heap: DaryHeapOfIndices::with_index_bound(0),
            vanishing: Vec::new(),
            s,
        };
        let keys: Vec<(usize, u64)> = (0..c.s.pairs.len() as u32)
            .into_par_iter()
            .map(|p| (p as usize, heap_key(c.cost(p), p)))
            .collect();
        c.heap = DaryHeapOfIndices::from_iter_with_index_bound(c.s.pairs.len(), keys);
        c
    }

    /// The merged quadric's optimum for a pair of slots, or the best of its ends and midpoint.
    fn place(&self, a: u32, b: u32) -> (DVec3, Quadric) {
        let q = Quadric::sum(&self.s.quadric[a as usize], &self.s.quadric[b as usize]);
        let (pa, pb) = (self.s.position[a as usize], self.s.position[b as usize]);
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
        let [a, b] = self.s.pairs[p as usize];
        let (pos, q) = self.place(a, b);
        let length2 = self.s.position[a as usize].distance_squared(self.s.position[b as usize]);
        let eq = q.error(pos).max(0.0) + LENGTH_TIE_BREAK * length2 * length2;
        let d = self.s.height[a as usize].max(self.s.height[b as usize]) as f64 + 1.0;
        eq * (self.balance * d).exp2()
    }

    /// Contracts the cheapest allowed pairs until `stop_at` free live slots are left or no pair is;
    /// with `nearest`, pairs the nearest live slots whenever the pairs run out.
    fn run(&mut self, stop_at: usize, nearest: bool) {
        while self.left > stop_at {
            match self.heap.pop() {
                Some((p, _)) => self.contract(p as u32),
                None if nearest && self.left > 1 => self.pair_nearest(),
                None => break,
            }
        }
    }

    /// Contracts pair `p` of slots (a, b) into a new node k in slot a.
    fn contract(&mut self, p: u32) {
        let [a, b] = self.s.pairs[p as usize];
        self.pair_dead[p as usize] = true;
        self.left -= 1;
        let k = self.s.base + self.s.children.len() as u32;
        let (pos, q) = self.place(a, b);
        let (au, bu) = (a as usize, b as usize);
        let s = &mut self.s;
        let ea = q.error(s.rep_position[au]);
        let eb = q.error(s.rep_position[bu]);
        let (na, nb) = (s.node[au], s.node[bu]);
        let (children, representative) = if eb < ea {
            ([nb, na], s.rep_position[bu])
        } else {
            ([na, nb], s.rep_position[au])
        };
        s.children.push(children);
        s.inner_positions.push(pos);
        s.node[au] = k;
        s.position[au] = pos;
        s.quadric[au] = q;
        s.height[au] = s.height[au].max(s.height[bu]) + 1;
        s.rep_position[au] = representative;
        s.alive[bu] = false;

        // Faces: b's move to a; those holding both vanish here.
        let moving = std::mem::take(&mut self.slot_faces[bu]);
        let mut vanishing = std::mem::take(&mut self.vanishing);
        vanishing.clear();
        let list_a = &mut self.slot_faces[au];
        for f in moving {
            let fu = f as usize;
            if s.face_dead[fu] {
                continue;
            }
            let c = &mut s.corners[fu];
            if c.contains(&a) {
                s.face_dead[fu] = true;
                s.births[fu] = k;
                let w = *c
                    .iter()
                    .find(|&&x| x != a && x != b)
                    .expect("a face has three corners");
                vanishing.push(w);
                continue;
            }
            for x in c.iter_mut() {
                if *x == b {
                    *x = a;
                }
            }
            list_a.push(f);
        }
        // Hoppe 1997's fn0..fn3: the faces across the vanishing faces' other edges (k, w).
        let first = s.dependency_faces.len();
        for &w in &vanishing {
            let list = &mut self.slot_faces[w as usize];
            list.retain(|g| !s.face_dead[*g as usize]);
            for &g in list.iter() {
                if s.corners[g as usize].contains(&a) && !s.dependency_faces[first..].contains(&g) {
                    s.dependency_faces.push(g);
                }
            }
        }
        s.dependency_start.push(s.dependency_faces.len() as u32);
        let vanished = !vanishing.is_empty();
        self.vanishing = vanishing;
        if vanished {
            let (dead, list) = (&s.face_dead, &mut self.slot_faces[au]);
            list.retain(|g| !dead[*g as usize]);
        }

        // Pairs: a's stay, b's move to a; one pair per other end.
        let mut pairs = std::mem::take(&mut self.slot_pairs[au]);
        let moving = std::mem::take(&mut self.slot_pairs[bu]);
        pairs.retain(|pid| !self.pair_dead[*pid as usize]);
        for &pid in &pairs {
            let [x, y] = s.pairs[pid as usize];
            let other = if x == a { y } else { x };
            self.mark[other as usize] = k;
        }
        for pid in moving {
            let pu = pid as usize;
            if self.pair_dead[pu] {
                continue;
            }
            let [x, y] = s.pairs[pu];
            let other = if x == b { y } else { x };
            if other == a || self.mark[other as usize] == k {
                self.pair_dead[pu] = true;
                if self.heap.contains(&pu) {
                    self.heap.remove(&pu);
                }
                continue;
            }
            self.mark[other as usize] = k;
            s.pairs[pu] = [a, other];
            pairs.push(pid);
        }
        for &pid in &pairs {
            let pu = pid as usize;
            let key = heap_key(self.cost(pid), pid);
            self.heap.update_key_or_push(&pu, key);
        }
        self.slot_pairs[au] = pairs;
    }

    /// Pairs every live slot with its nearest live neighbour.
    fn pair_nearest(&mut self) {
        let live: Vec<u32> = (0..self.s.alive.len() as u32)
            .filter(|&v| self.s.alive[v as usize])
            .collect();
        let points: Vec<DVec3> = live.iter().map(|&v| self.s.position[v as usize]).collect();
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
        let mut keys = Vec::with_capacity(found.len());
        for pair in found {
            let pid = self.s.pairs.len() as u32;
            self.s.pairs.push(pair);
            self.pair_dead.push(false);
            self.slot_pairs[pair[0] as usize].push(pid);
            self.slot_pairs[pair[1] as usize].push(pid);
            keys.push((pid as usize, heap_key(self.cost(pid), pid)));
        }
        // The heap is empty here: a new one covers the new pairs.
        self.heap = DaryHeapOfIndices::from_iter_with_index_bound(self.s.pairs.len(), keys);
    }

    /// The tree of the whole mesh (`cells` by vertex), faces back in the caller's order
    /// (`face_order[i]`: the caller's index of internal face i).
    fn finish(self, cells: &[[u32; 3]], face_order: &[u32]) -> Result<VertexTree> {
        let s = self.s;
        let leaves = s.base as usize;
        let total = leaves + s.children.len();
        let root = (total - 1) as u32;
        let mut parent = vec![u32::MAX; total];
        for (i, pair) in s.children.iter().enumerate() {
            for &c in pair {
                parent[c as usize] = (leaves + i) as u32;
            }
        }
        let mut ids = vec![NodeId::ROOT; total];
        // Children are created after their parents' ids are needed: walk down from the root.
        for i in (0..s.children.len()).rev() {
            let k = leaves + i;
            for (bit, &c) in s.children[i].iter().enumerate() {
                ids[c as usize] = ids[k].child(bit == 1).ok_or_else(|| {
                    Error::Unsupported(format!(
                        "the vertex hierarchy is deeper than {MAX_DEPTH} levels"
                    ))
                })?;
            }
        }
        let raw = s.dependency_faces.len();
        let dependencies = (0..s.children.len())
            .into_par_iter()
            .map(|i| {
                let range = s.dependency_start[i] as usize..s.dependency_start[i + 1] as usize;
                let faces = &s.dependency_faces[range];
                let own = ids[leaves + i];
                let mut nodes: Vec<u32> = Vec::with_capacity(faces.len());
                for &f in faces {
                    let d = s.births[f as usize];
                    if !ids[d as usize].is_ancestor_of(own) && !nodes.contains(&d) {
                        nodes.push(d);
                    }
                }
                nodes
            })
            .collect();
        let mut births = vec![0u32; s.births.len()];
        for (internal, &f) in face_order.iter().enumerate() {
            births[f as usize] = s.births[internal];
        }
        let positions = cells
            .iter()
            .map(|&c| to_f(c))
            .chain(s.inner_positions.iter().copied())
            .map(|p| p.to_array())
            .collect();
        Ok(VertexTree {
            leaves,
            children: s.children,
            parent,
            root,
            positions,
            ids,
            births,
            dependencies,
            raw_dependencies: raw,
        })
    }
}

/// The mesh's edges and, per vertex, up to [`CLOSE_PAIRS_PER_VERTEX`] nearest vertices closer
/// than `fraction` of the mean edge length; each pair once, ends in ascending order.
/// `edges` are the mesh's edges, sorted, each once.
fn initial_pairs(
    cells: &[[u32; 3]],
    faces: &[[u32; 3]],
    edges: &[[u32; 2]],
    fraction: f64,
) -> Vec<[u32; 2]> {
    // The mean over the faces' edges, shared edges counted once a face.
    let mut length_sum = 0.0;
    for f in faces {
        for k in 0..3 {
            let (x, y) = (f[k], f[(k + 1) % 3]);
            length_sum += to_f(cells[x as usize]).distance(to_f(cells[y as usize]));
        }
    }
    let mut close: Vec<[u32; 2]> = Vec::new();
    let threshold = fraction * length_sum / (3 * faces.len()).max(1) as f64;
    if threshold > 0.0 {
        let points: Vec<DVec3> = cells.iter().map(|&c| to_f(c)).collect();
        // Cells of twice the threshold: a point's ball of that radius meets at most the two
        // cells nearest it along each axis, so eight cells hold every point it can pair with.
        let size = 2.0 * threshold;
        let grid = CellGrid::new(&points, DVec3::ZERO, size);
        close = points
            .par_iter()
            .enumerate()
            .flat_map_iter(|(v, &p)| {
                let cell = grid.key(p);
                let side = |axis: usize| {
                    let inside = p[axis] / size - cell[axis] as f64;
                    if inside < 0.5 {
                        -1
                    } else {
                        1
                    }
                };
                let step = [side(0), side(1), side(2)];
                let mut near: Vec<(f64, u32)> = Vec::new();
                for corner in 0..8 {
                    let mut key = cell;
                    for (axis, k) in key.iter_mut().enumerate() {
                        if corner >> axis & 1 == 1 {
                            *k += step[axis];
                        }
                    }
                    for &w in grid.cell(key) {
                        let d = p.distance(points[w as usize]);
                        if w != v as u32 && d < threshold {
                            near.push((d, w));
                        }
                    }
                }
                near.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
                let v = v as u32;
                near.truncate(CLOSE_PAIRS_PER_VERTEX);
                near.into_iter().map(move |(_, w)| [v.min(w), v.max(w)])
            })
            .collect();
        close.par_sort_unstable();
        close.dedup();
    }
    // Both lists sorted: merge them, each pair once.
    let mut pairs = Vec::with_capacity(edges.len() + close.len());
    let (mut i, mut j) = (0, 0);
    while i < edges.len() || j < close.len() {
        let next = match (edges.get(i), close.get(j)) {
            (Some(e), Some(c)) if c < e => {
                j += 1;
                *c
            }
            (Some(e), Some(c)) => {
                i += 1;
                j += usize::from(c == e);
                *e
            }
            (Some(e), None) => {
                i += 1;
                *e
            }
            (None, Some(c)) => {
                j += 1;
                *c
            }
            (None, None) => unreachable!("one list has more"),
        };
        pairs.push(next);
    }
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
    let grid = CellGrid::new(points, lo, cell);
    let reach = ((extent / cell).ceil().max_element() as i64) + 1;
    // Cells past the points' box are empty: shells are walked inside it only, so that points
    // spread along one axis cost shells of a line, not of a cube (a fuzzed mesh of 4 points
    // took half a second here).
    let top = grid.key(hi);
    points
        .iter()
        .enumerate()
        .map(|(i, &p)| {
            let [x, y, z] = grid.key(p);
            let mut best = (f64::MAX, u32::MAX);
            for r in 0..=reach {
                // Every point within r − 1 cells is seen; stop once none closer can remain.
                if best.1 != u32::MAX && (r - 1) as f64 * cell >= best.0 {
                    break;
                }
                let span = |c: i64, top: i64| (-r).max(-c)..=r.min(top - c);
                for dx in span(x, top[0]) {
                    for dy in span(y, top[1]) {
                        for dz in span(z, top[2]) {
                            if dx.abs().max(dy.abs()).max(dz.abs()) != r {
                                continue;
                            }
                            for &j in grid.cell([x + dx, y + dy, z + dz]) {
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
    fn by_quadric_error_alone_the_tree_is_whole_and_deeper_than_balanced() {
        // A terrain: flat stretches merge early under QEM alone, and the balance no longer
        // holds the tree near log2 of its vertices.
        let c = canonical(&generate::terrain(2_000, 7));
        let balanced = build(&c.cells, &c.faces, &BuildOptions::PAPER).unwrap();
        let by_error = build(&c.cells, &c.faces, &BuildOptions::QUADRIC_ORDER).unwrap();
        check_tree(&by_error, &c.faces);
        assert!(
            by_error.depth() > balanced.depth(),
            "{} against {}",
            by_error.depth(),
            balanced.depth()
        );
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
