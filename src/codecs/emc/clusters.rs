//! The encoders' view of the hierarchy: which mesh vertices each vertex of the decoder's list
//! stands for (a range of the key trie), and what a split does to its edges. Both EMC encoders
//! read every decision off this; only how they code it differs.

use super::state::EdgeCode;
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
///
/// The mesh's vertices are kept by their trie position (key order): a cluster is a range of
/// positions, its vertices' edges one contiguous run of [`Self::edges`], and their neighbours lie
/// mostly nearby (keys interleave the axes' bits, so near cells have near keys). Indexed by
/// mesh vertex id instead, a split's reads scatter over the whole mesh: on bunny-closed-35k ×16
/// the split plans took 29% of the encode time that way.
pub struct Clusters {
    /// The key trie of the mesh's cells.
    pub trie: KeyTrie,
    /// Trie range of each list vertex.
    pub ranges: Vec<Range<usize>>,
    /// Trie range of the cell each list vertex's cell went ahead to (its representative's
    /// path): its range while it has not gone ahead.
    paths: Vec<Range<usize>>,
    /// Where each trie position's edges start in [`Self::edges`] (one more entry at the end).
    edge_starts: Vec<u32>,
    /// The mesh's edges: for each trie position in order, the trie positions of its neighbours.
    edges: Vec<u32>,
    /// List vertex each trie position belongs to now.
    cluster_of: Vec<u32>,
    stamp_lower: Vec<u32>,
    stamp_upper: Vec<u32>,
    stamp: u32,
}

impl Clusters {
    /// One cluster holding every vertex of `mesh`.
    pub fn new(mesh: &CanonicalMesh, trie: KeyTrie) -> Clusters {
        let n = mesh.vertex_count();
        let (edge_starts, edges) = edges_by_position(&trie, &mesh.faces);
        Clusters {
            trie,
            ranges: std::iter::once(0..n).collect(),
            paths: std::iter::once(0..n).collect(),
            edge_starts,
            edges,
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

    /// The half `v`'s cell takes ahead at `step` (see [`ahead`]).
    pub fn ahead(&mut self, v: usize, step: usize, predicted: bool) -> bool {
        ahead(&self.trie, &mut self.paths[v], step, predicted)
    }

    /// Works out the split of `v` (whose neighbours are `neighbours`) at `step` (which must be
    /// its next split) into `plan`, and assigns the upper half's mesh vertices to `r`, the list
    /// vertex the split will create; `vertices` is more than every list id.
    pub fn plan(
        &mut self,
        neighbours: &[u32],
        v: usize,
        r: usize,
        step: usize,
        vertices: usize,
        plan: &mut SplitPlan,
    ) {
        let size = vertices.max(r + 1);
        if self.stamp_lower.len() < size {
            self.stamp_lower.resize(size, 0);
            self.stamp_upper.resize(size, 0);
        }
        let mut lanes = self.lanes(self.stamp, 1);
        lanes.plan(neighbours, v, r, step, plan);
        self.stamp = lanes.stamp;
    }

    /// Frees what only splits need (the mesh's edges, the cluster of each vertex), once every
    /// cluster is a single vertex: the face corrections that follow are the encoder's peak of
    /// memory, and these are a third of it on a large mesh.
    pub fn release_edges(&mut self) {
        self.edge_starts = Vec::new();
        self.edges = Vec::new();
        self.cluster_of = Vec::new();
        self.stamp_lower = Vec::new();
        self.stamp_upper = Vec::new();
    }

    /// Records the split of `v` by `plan`: `v` keeps the lower half, the new vertex `r` the
    /// upper (the next list vertex, or one [`Self::make_room`] made).
    pub fn commit(&mut self, v: usize, r: usize, plan: &SplitPlan) {
        if r == self.ranges.len() {
            self.ranges.push(0..0);
            self.paths.push(0..0);
        }
        (self.paths[v], self.paths[r]) = split_paths(self.paths[v].clone(), plan);
        self.ranges[v] = plan.lower.clone();
        self.ranges[r] = plan.upper.clone();
    }

    /// Makes room for `more` list vertices after the last: the splits of a sliced pass's slabs,
    /// whose ids are known before any slab is coded.
    pub fn make_room(&mut self, more: usize) {
        let n = self.ranges.len() + more;
        self.ranges.resize(n, 0..0);
        self.paths.resize(n, 0..0);
        if self.stamp_lower.len() < n {
            self.stamp_lower.resize(n, 0);
            self.stamp_upper.resize(n, 0);
        }
    }

    /// Views for the slabs of a sliced pass, which plan and commit their splits at once: slab s
    /// of `slabs` stamps its splits with serials that no other slab's and no earlier split's
    /// take, for `visits` visits at most. `None` if the serials would run out (the slabs are
    /// then coded one after another, to the same stream).
    pub fn slab_lanes(&mut self, slabs: usize, visits: usize) -> Option<Vec<ClusterLanes>> {
        let stride = slabs as u64;
        let needed = stride * (visits as u64 + 2);
        if self.stamp as u64 + needed > u32::MAX as u64 {
            // Start the serials again: no stamp left from earlier splits may match.
            self.stamp_lower.fill(0);
            self.stamp_upper.fill(0);
            self.stamp = 0;
        }
        if needed > u32::MAX as u64 {
            return None;
        }
        let base = self.stamp + stride as u32;
        Some(
            (0..slabs)
                .map(|slab| self.lanes(base + slab as u32 + 1 - stride as u32, stride as u32))
                .collect(),
        )
    }

    /// After the slabs: the serials go on above every one they used.
    pub fn join_slab_lanes(&mut self, lanes: &[ClusterLanes]) {
        for lanes in lanes {
            self.stamp = self.stamp.max(lanes.stamp);
        }
    }

    /// Raw views of the arrays splits read and write, stamping from `stamp` + `stamp_step` on.
    fn lanes(&mut self, stamp: u32, stamp_step: u32) -> ClusterLanes {
        ClusterLanes {
            trie: &self.trie,
            edge_starts: self.edge_starts.as_ptr(),
            starts: self.edge_starts.len(),
            edges: self.edges.as_ptr(),
            edge_count: self.edges.len(),
            ranges: self.ranges.as_mut_ptr(),
            paths: self.paths.as_mut_ptr(),
            vertices: self.ranges.len(),
            cluster_of: self.cluster_of.as_mut_ptr(),
            positions: self.cluster_of.len(),
            stamp_lower: self.stamp_lower.as_mut_ptr(),
            stamp_upper: self.stamp_upper.as_mut_ptr(),
            stamps: self.stamp_lower.len(),
            stamp,
            stamp_step,
        }
    }
}

/// Raw views of what the splits of [`Clusters`] read and write, shared by the slabs of a sliced
/// pass that the encoder codes at once. Sound for the reason `modelled::walk`'s `Lanes` is: a
/// slab splits only its own list vertices, whose neighbours are its own, so it writes only its
/// own vertices' ranges, the trie positions of its own clusters (their `cluster_of`), and the
/// stamps of its own vertices (the clusters its clusters' mesh edges reach are its splitting
/// vertex's neighbours, or the two halves); it reads nothing another slab writes. Valid while
/// the [`Clusters`] it views is neither moved, resized nor otherwise touched.
pub struct ClusterLanes {
    trie: *const KeyTrie,
    edge_starts: *const u32,
    starts: usize,
    edges: *const u32,
    edge_count: usize,
    ranges: *mut Range<usize>,
    paths: *mut Range<usize>,
    vertices: usize,
    cluster_of: *mut u32,
    positions: usize,
    stamp_lower: *mut u32,
    stamp_upper: *mut u32,
    stamps: usize,
    /// The last stamp used, and how far each split moves it.
    stamp: u32,
    stamp_step: u32,
}

// SAFETY: see the type's docs: the slabs sharing the arrays touch disjoint entries.
#[allow(unsafe_code)]
unsafe impl Send for ClusterLanes {}

/// Entry `i` of one of [`ClusterLanes`]' arrays of `len` entries, bounds-checked, as a place.
macro_rules! entry {
    ($pointer:expr, $len:expr, $i:expr) => {{
        let i: usize = $i;
        assert!(i < $len, "entry {i} outside the clusters' arrays");
        // SAFETY: in bounds; the slab owns the entry (see `ClusterLanes`).
        unsafe { &mut *$pointer.add(i) }
    }};
}

/// Entry `i` of a read-only array of [`ClusterLanes`] of `len` entries, bounds-checked.
macro_rules! read {
    ($pointer:expr, $len:expr, $i:expr) => {{
        let i: usize = $i;
        assert!(i < $len, "entry {i} outside the clusters' arrays");
        // SAFETY: in bounds; nothing writes these arrays while views exist.
        unsafe { *$pointer.add(i) }
    }};
}

// The raw views are read and written here only (`entry!`, `read!`).
#[allow(unsafe_code)]
impl ClusterLanes {
    fn trie(&self) -> &KeyTrie {
        // SAFETY: the trie is only read, and outlives the view (see the type's docs).
        unsafe { &*self.trie }
    }

    fn range(&self, v: usize) -> Range<usize> {
        entry!(self.ranges, self.vertices, v).clone()
    }

    /// The step at which list vertex `v` splits next, if it does.
    pub fn next_split(&self, v: usize) -> Option<usize> {
        self.trie().next_split(self.range(v))
    }

    /// The bit list vertex `v` takes at `step` when it does not split.
    pub fn bit(&self, v: usize, step: usize) -> u32 {
        let trie = self.trie();
        trie.order.bit(trie.keys[self.range(v).start], step)
    }

    /// [`Clusters::ahead`].
    pub fn ahead(&mut self, v: usize, step: usize, predicted: bool) -> bool {
        let trie = self.trie;
        // SAFETY: the trie is only read, and outlives the view (see the type's docs).
        ahead(
            unsafe { &*trie },
            entry!(self.paths, self.vertices, v),
            step,
            predicted,
        )
    }

    /// [`Clusters::plan`], for a split whose new vertex `r` has room.
    pub fn plan(
        &mut self,
        neighbours: &[u32],
        v: usize,
        r: usize,
        step: usize,
        plan: &mut SplitPlan,
    ) {
        let range = self.range(v);
        let mid = self.trie().partition(range.clone(), step);
        plan.lower = range.start..mid;
        plan.upper = mid..range.end;
        let r = r as u32;
        for position in plan.upper.clone() {
            *entry!(self.cluster_of, self.positions, position) = r;
        }
        // Which clusters each half touches.
        self.stamp += self.stamp_step;
        plan.connecting = false;
        for (half, stamps) in [
            (plan.lower.clone(), self.stamp_lower),
            (plan.upper.clone(), self.stamp_upper),
        ] {
            let is_lower = half.start == range.start;
            let start = read!(self.edge_starts, self.starts, half.start);
            let end = read!(self.edge_starts, self.starts, half.end);
            for e in start as usize..end as usize {
                let w = read!(self.edges, self.edge_count, e);
                let c = *entry!(self.cluster_of, self.positions, w as usize);
                *entry!(stamps, self.stamps, c as usize) = self.stamp;
                plan.connecting |= is_lower && c == r;
            }
        }
        plan.codes.clear();
        for &nb in neighbours {
            let lower = *entry!(self.stamp_lower, self.stamps, nb as usize) == self.stamp;
            let upper = *entry!(self.stamp_upper, self.stamps, nb as usize) == self.stamp;
            debug_assert!(lower || upper, "neighbour {nb} lost by both halves");
            plan.codes.push(match (lower, upper) {
                (true, true) => EdgeCode::Duplicate,
                (false, true) => EdgeCode::Move,
                _ => EdgeCode::Stay,
            });
        }
    }

    /// [`Clusters::commit`], for a split whose new vertex `r` has room.
    pub fn commit(&mut self, v: usize, r: usize, plan: &SplitPlan) {
        let path = entry!(self.paths, self.vertices, v).clone();
        let (lower, upper) = split_paths(path, plan);
        *entry!(self.paths, self.vertices, v) = lower;
        *entry!(self.paths, self.vertices, r) = upper;
        *entry!(self.ranges, self.vertices, v) = plan.lower.clone();
        *entry!(self.ranges, self.vertices, r) = plan.upper.clone();
    }
}

/// The half a cell with trie range `path` takes at `step`, going ahead of its cluster's
/// splits: the half its vertices keep to, or where they part the `predicted` one (1 = upper);
/// `path` becomes that half's range.
fn ahead(trie: &KeyTrie, path: &mut Range<usize>, step: usize, predicted: bool) -> bool {
    if trie.next_split(path.clone()) == Some(step) {
        let mid = trie.partition(path.clone(), step);
        *path = if predicted {
            mid..path.end
        } else {
            path.start..mid
        };
        predicted
    } else {
        trie.order.bit(trie.keys[path.start], step) == 1
    }
}

/// The paths of a split's two halves (lower, upper), from the splitting vertex's `path`: a
/// path that went ahead stays with the half it lies in, and the other half starts from its
/// range.
fn split_paths(path: Range<usize>, plan: &SplitPlan) -> (Range<usize>, Range<usize>) {
    if path.start == plan.lower.start && path.end == plan.upper.end {
        (plan.lower.clone(), plan.upper.clone())
    } else if path.end <= plan.upper.start {
        (path, plan.upper.clone())
    } else {
        (plan.lower.clone(), path)
    }
}

/// The mesh's edges in trie positions, both ways, each position's neighbours ascending and
/// once: the start of each position's run, and the runs one after another.
fn edges_by_position(trie: &KeyTrie, faces: &[[u32; 3]]) -> (Vec<u32>, Vec<u32>) {
    let n = trie.vertices.len();
    let mut position = vec![0u32; n];
    for (i, &u) in trie.vertices.iter().enumerate() {
        position[u as usize] = i as u32;
    }
    // Every face's three edges both ways (repeats included), counted, then placed: at most
    // 6 · 2^29 entries (limits::MAX_TRIANGLES), within u32.
    let mut starts = vec![0u32; n + 1];
    for f in faces {
        for &u in f {
            starts[position[u as usize] as usize + 1] += 2;
        }
    }
    for i in 0..n {
        starts[i + 1] += starts[i];
    }
    let mut next = starts.clone();
    let mut edges = vec![0u32; starts[n] as usize];
    for f in faces {
        let p = f.map(|u| position[u as usize]);
        for k in 0..3 {
            let (a, b) = (p[k], p[(k + 1) % 3]);
            for (from, to) in [(a, b), (b, a)] {
                edges[next[from as usize] as usize] = to;
                next[from as usize] += 1;
            }
        }
    }
    drop(next);
    // Each run sorted and its repeats dropped, the runs moved down over the gaps.
    let mut end = 0usize;
    let mut start = 0usize;
    for i in 0..n {
        let run_end = starts[i + 1] as usize;
        edges[start..run_end].sort_unstable();
        let new_start = end;
        let mut last = None;
        for j in start..run_end {
            let w = edges[j];
            if last != Some(w) {
                edges[end] = w;
                end += 1;
                last = Some(w);
            }
        }
        starts[i] = new_start as u32;
        start = run_end;
    }
    starts[n] = end as u32;
    edges.truncate(end);
    edges.shrink_to_fit();
    (starts, edges)
}
