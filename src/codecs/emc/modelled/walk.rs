//! The passes of the modelled coder, written once for both sides: a [`Side`] answers each binary
//! question (the encoder from the mesh, the decoder from the stream) and the [`Walker`] applies
//! the answers to the shared state, choosing every question's context from what the decoder
//! already knows.

use super::contexts::{self, Contexts};
use crate::codecs::emc::state::{
    check_edge_count, split_edges, EdgeCode, EmcState, NeighbourLists, Neighbours, NO_SPLIT,
};
use crate::hierarchy::octree::StepOrder;
use crate::prefetch::prefetch;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};

/// A question the walker asks about vertex `v` at the current step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Question {
    /// Does the (multi-vertex) cluster split now?
    Split,
    /// Which half does it take: 1 = upper.
    Half,
    /// Do the two halves share an edge?
    Connecting,
    /// Is the edge to the i-th neighbour duplicated?
    Duplicate(usize),
    /// Does the edge to the i-th neighbour move to the upper half (MOVE) or stay (STAY)?
    Moves(usize),
    /// Is the lower (0) or upper (1) half a single vertex?
    Leaf(usize),
}

impl Question {
    /// Name in the bit statistics.
    pub fn field(self) -> &'static str {
        match self {
            Question::Split => "split",
            Question::Half => "half",
            Question::Connecting => "connecting",
            Question::Duplicate(_) => "edge_duplicate",
            Question::Moves(_) => "edge_moves",
            Question::Leaf(_) => "leaf",
        }
    }

    /// Positions (which cells are occupied, and where) or connectivity.
    pub fn class(self) -> crate::coding::SyntaxClass {
        use crate::coding::SyntaxClass::{Connectivity, Geometry};
        match self {
            Question::Split | Question::Half | Question::Leaf(_) => Geometry,
            Question::Connecting | Question::Duplicate(_) | Question::Moves(_) => Connectivity,
        }
    }
}

/// Why a pass stopped early.
#[derive(Debug)]
pub enum Stop {
    /// The level's bits ran out.
    OutOfBits,
    /// The stream contradicts itself or the header.
    Fault(String),
}

/// One side of the coder.
pub trait Side: Send {
    /// Codes (encoder) or reads (decoder) the answer to `question` about `v`, under `context`.
    /// The bit coded is the answer XOR `flip`, so that 1 always means "as predicted".
    fn code(
        &mut self,
        context: &mut crate::coding::arith::BitContext,
        question: Question,
        flip: bool,
        v: usize,
        step: usize,
    ) -> Result<bool, Stop>;

    /// Codes (encoder) or reads (decoder) which half `v` takes at each of the three steps from
    /// `first`, under `contexts[index[k]]` for the k-th, at once; each bit is the answer XOR
    /// `flips[k]`.
    fn code3(
        &mut self,
        contexts: &mut [crate::coding::arith::BitContext],
        index: [usize; 3],
        flips: [bool; 3],
        v: usize,
        first: usize,
    ) -> Result<[bool; 3], Stop>;

    /// Called when `v`, whose neighbours are `neighbours`, is about to split at `step` into
    /// `v` and the new vertex `r`, before its connectivity is coded; `vertices` is more than
    /// every vertex id.
    fn begin_split(
        &mut self,
        _neighbours: &[u32],
        _v: usize,
        _r: usize,
        _step: usize,
        _vertices: usize,
    ) {
    }

    /// Called after `v` split into `v` (lower half) and `r` (upper half).
    fn end_split(&mut self, _v: usize, _r: usize) {}

    /// A sliced pass begins (`step`: the pass's step; `None` for the leaves' pass), in which
    /// slab `s` visits `interior[s]`: returns how many of them split in each slab (the
    /// encoder works it out, the decoder reads it from the level's slab table).
    fn begin_sliced_pass(
        &mut self,
        interior: &[Vec<u32>],
        step: Option<usize>,
    ) -> Result<Vec<u32>, Stop>;

    /// Independent sides for the slabs of the current sliced pass, each reading its own slab
    /// stream, to be run on threads; `None` to code the slabs one after another between
    /// [`Self::begin_slab`] and [`Self::end_slab`].
    fn slab_sides(&mut self) -> Result<Option<Vec<Self>>, Stop>
    where
        Self: Sized;

    /// Slab `slab` of the current sliced pass is coded next, in a stream of its own.
    fn begin_slab(&mut self, slab: usize) -> Result<(), Stop>;

    /// Slab `slab` is coded; the level's own stream follows again.
    fn end_slab(&mut self, slab: usize);

    /// The slabs of the current sliced pass are coded (the encoder writes their table entry).
    fn end_sliced_pass(&mut self) {}

    /// The sides [`Self::slab_sides`] gave, once their slabs are coded, in slab order (the
    /// encoder takes their streams as if each slab had been coded between
    /// [`Self::begin_slab`] and [`Self::end_slab`]).
    fn join_slab_sides(&mut self, _sides: Vec<Self>)
    where
        Self: Sized,
    {
    }
}

/// Steepest regression plane used for prediction (squared gradient).
const SLOPE: f64 = 1.5;

/// 1 / 2^`shift`, exactly: the factor from the centres' units to half-widths of a cell whose
/// half-width is 2^`shift` (multiplying is cheaper than dividing).
fn per_half_width(shift: u8) -> f64 {
    f64::from_bits((1023 - shift as u64) << 52)
}

/// 2^`shift`, exactly.
#[inline]
fn power_of_two(shift: u8) -> f64 {
    f64::from_bits((1023 + shift as u64) << 52)
}

/// `if choose { a } else { b }` without a branch: which one is as good as random to a branch
/// predictor.
#[inline]
fn select(choose: bool, a: f64, b: f64) -> f64 {
    let mask = (choose as u64).wrapping_neg();
    f64::from_bits((a.to_bits() & mask) | (b.to_bits() & !mask))
}

/// Where a vertex is expected along `axis`, relative to its centre, and the expected squared
/// error, both in the units of the centres, from its neighbours' moments `m` (relative to its
/// centre) and the shifts of its cell's half-widths. The prediction is the neighbours'
/// regression plane (the coordinate along the axis as a linear function of the other two,
/// evaluated at the vertex's own place across the axis) where the neighbours span the other two
/// axes, else their mean; the error is the neighbours' residual spread plus what the vertex's
/// own cell leaves open.
#[inline(always)]
pub(super) fn estimate(m: &Moments, axis: usize, shifts: [u8; 3]) -> (f64, f64) {
    let (b, c) = ((axis + 1) % 3, (axis + 2) % 3);
    let var_a = m.cov[axis][axis].max(0.0);
    let (cbb, ccc, cbc) = (m.cov[b][b], m.cov[c][c], m.cov[b][c]);
    let (cab, cac) = (m.cov[axis][b], m.cov[axis][c]);
    // The plane's gradient is (nb, nc) / det; it is used where the neighbours span the
    // other two axes and it is no steeper than SLOPE.
    let det = cbb * ccc - cbc * cbc;
    let (nb, nc) = (cab * ccc - cac * cbc, cac * cbb - cab * cbc);
    let spread = cbb + ccc;
    let plane =
        (m.k >= 4) & (det > 1e-2 * spread * spread) & (nb * nb + nc * nc <= SLOPE * det * det);
    // Both estimates are computed and one is kept (the plane's may be meaningless where it is
    // not used).
    let inverse = 1.0 / det;
    let (beta_b, beta_c) = (nb * inverse, nc * inverse);
    let residual = (var_a - beta_b * cab - beta_c * cac).max(0.0);
    // The vertex's own place across the axis: the neighbours' mean, kept inside its cell.
    let (wb, wc) = (power_of_two(shifts[b]), power_of_two(shifts[c]));
    let (mb, mc) = (m.mean[b], m.mean[c]);
    let (eb, ec) = (mb.max(-wb).min(wb), mc.max(-wc).min(wc));
    let own_cell =
        beta_b * beta_b * (wb * wb / 3.0).min(cbb) + beta_c * beta_c * (wc * wc / 3.0).min(ccc);
    let on_plane = m.mean[axis] + beta_b * (eb - mb) + beta_c * (ec - mc);
    (
        select(plane, on_plane, m.mean[axis]),
        select(plane, residual + own_cell, var_a),
    )
}

/// [`estimate`] and the "which half" context of a leaf on all three axes at once (lane `a`:
/// axis `a`; a fourth lane repeats the first so that the lanes fill vector registers): the same
/// operations in the same order, so the same values, in a form the compiler vectorizes.
/// Returns each axis's context index and whether the prediction is below the split plane.
#[inline(always)]
fn leaf_contexts(m: &Moments, shifts: [u8; 3]) -> ([usize; 3], [bool; 3]) {
    type Lanes = [f64; 4];
    fn each(f: impl Fn(usize) -> f64) -> Lanes {
        [f(0), f(1), f(2), f(3)]
    }
    let cov = &m.cov;
    // Lane a reads axis a, b = a + 1 and c = a + 2 (mod 3).
    let at = |lane: usize, shift: usize| (lane + shift) % 3;
    let var_a = each(|l| cov[at(l, 0)][at(l, 0)].max(0.0));
    let cbb = each(|l| cov[at(l, 1)][at(l, 1)]);
    let ccc = each(|l| cov[at(l, 2)][at(l, 2)]);
    let cbc = each(|l| cov[at(l, 1)][at(l, 2)]);
    let cab = each(|l| cov[at(l, 0)][at(l, 1)]);
    let cac = each(|l| cov[at(l, 0)][at(l, 2)]);
    let mean_a = each(|l| m.mean[at(l, 0)]);
    let mb = each(|l| m.mean[at(l, 1)]);
    let mc = each(|l| m.mean[at(l, 2)]);
    let wb = each(|l| power_of_two(shifts[at(l, 1)]));
    let wc = each(|l| power_of_two(shifts[at(l, 2)]));
    let scale = each(|l| per_half_width(shifts[at(l, 0)]));
    let det = each(|l| cbb[l] * ccc[l] - cbc[l] * cbc[l]);
    let nb = each(|l| cab[l] * ccc[l] - cac[l] * cbc[l]);
    let nc = each(|l| cac[l] * cbb[l] - cab[l] * cbc[l]);
    let spread = each(|l| cbb[l] + ccc[l]);
    let inverse = each(|l| 1.0 / det[l]);
    let beta_b = each(|l| nb[l] * inverse[l]);
    let beta_c = each(|l| nc[l] * inverse[l]);
    let residual = each(|l| (var_a[l] - beta_b[l] * cab[l] - beta_c[l] * cac[l]).max(0.0));
    let eb = each(|l| mb[l].max(-wb[l]).min(wb[l]));
    let ec = each(|l| mc[l].max(-wc[l]).min(wc[l]));
    let own_cell = each(|l| {
        beta_b[l] * beta_b[l] * (wb[l] * wb[l] / 3.0).min(cbb[l])
            + beta_c[l] * beta_c[l] * (wc[l] * wc[l] / 3.0).min(ccc[l])
    });
    let on_plane = each(|l| mean_a[l] + beta_b[l] * (eb[l] - mb[l]) + beta_c[l] * (ec[l] - mc[l]));
    let mut index = [0; 3];
    let mut below = [false; 3];
    let kind = contexts::half_kind(true, m.k);
    for l in 0..3 {
        let plane = (m.k >= 4)
            & (det[l] > 1e-2 * spread[l] * spread[l])
            & (nb[l] * nb[l] + nc[l] * nc[l] <= SLOPE * det[l] * det[l]);
        let prediction = select(plane, on_plane[l], mean_a[l]);
        let variance = select(plane, residual[l] + own_cell[l], var_a[l]);
        index[l] = contexts::half_in(
            kind,
            prediction.abs() * scale[l],
            variance * scale[l] * scale[l],
        )
        .index;
        below[l] = prediction < 0.0;
    }
    (index, below)
}

/// Count, mean and covariance of a vertex's neighbours (see [`neighbour_moments`]).
pub(super) struct Moments {
    k: usize,
    pub(super) mean: [f64; 3],
    pub(super) cov: [[f64; 3]; 3],
}

/// Count, mean and covariance of the cell centres of `neighbours` (`centre` gives each), relative
/// to `origin`; `None` without neighbours.
#[inline(always)]
fn neighbour_moments(
    origin: [i32; 3],
    neighbours: &[u32],
    centre: impl Fn(usize) -> [i32; 3],
) -> Option<Moments> {
    if neighbours.is_empty() {
        return None;
    }
    // Sums of the offsets and their products: x, y, z, xx, yy, zz, xy, xz, yz.
    let mut s = [0f64; 9];
    for &n in neighbours {
        let c = centre(n as usize);
        let d = [0, 1, 2].map(|a| (c[a] - origin[a]) as f64);
        s[0] += d[0];
        s[1] += d[1];
        s[2] += d[2];
        s[3] += d[0] * d[0];
        s[4] += d[1] * d[1];
        s[5] += d[2] * d[2];
        s[6] += d[0] * d[1];
        s[7] += d[0] * d[2];
        s[8] += d[1] * d[2];
    }
    let k = neighbours.len();
    let inv = 1.0 / k as f64;
    let mean = [s[0] * inv, s[1] * inv, s[2] * inv];
    let (xy, xz, yz) = (
        s[6] * inv - mean[0] * mean[1],
        s[7] * inv - mean[0] * mean[2],
        s[8] * inv - mean[1] * mean[2],
    );
    let cov = [
        [s[3] * inv - mean[0] * mean[0], xy, xz],
        [xy, s[4] * inv - mean[1] * mean[1], yz],
        [xz, yz, s[5] * inv - mean[2] * mean[2]],
    ];
    Some(Moments { k, mean, cov })
}

/// The state both sides keep, with the modelled coder's extra knowledge of each vertex.
pub struct Walker {
    /// Cells, depths and edges (shared with the paper's coder).
    pub state: EmcState,
    /// Known to be a single mesh vertex (no further split).
    pub leaf: Vec<bool>,
    pub contexts: Box<Contexts>,
    /// Slabs of a sliced pass (1: no pass is sliced), and the fewest visits a sliced pass has.
    slabs: usize,
    sliced_visits: usize,
    /// Where the slabs lie in the current level.
    slab_cuts: Slabs,
    /// For each depth, the shift from the cell prefix to the full grid per axis.
    shifts: Vec<[u8; 3]>,
    /// Twice each vertex's cell centre, in units of the full grid (kept with the cells: the
    /// contexts read the neighbours' centres over and over).
    centres: Vec<[i32; 3]>,
    codes: Vec<EdgeCode>,
    /// Vertices that were clusters at the start of the level (and those split off them since),
    /// in list order: the passes visit only these.
    active: Vec<u32>,
    /// Vertices that were leaves at the start of the level, in list order.
    resting: Vec<u32>,
    /// Per vertex: the serial of the last split that coded its edge to the splitting vertex
    /// (bits 3 and up) and the code (bit 0 stay, 1 move, 2 duplicate).
    /// Atomic (relaxed loads and stores, plain moves on common processors) because a slab
    /// walking a neighbour's list reads the marks of vertices another slab may be marking:
    /// those never carry its own serial, so what it reads of them does not matter.
    marks: Vec<AtomicU64>,
    /// Serial of the last split (the serials of a sliced pass's slabs interleave).
    split_serial: u64,
}

/// What a pass does to the vertices it visits.
#[derive(Clone, Copy)]
enum Work {
    /// The clusters' pass of a step: split, or take a half.
    Split(usize),
    /// The leaves' three bits of the level whose first step is this.
    Leaves(usize),
}

/// How a sliced pass divides its visits: those of each slab whose neighbours all lie in the
/// same slab, and the others.
struct SlabPlan {
    interior: Vec<Vec<u32>>,
    boundary: Vec<u32>,
}

/// Bins of the centres along the longest axis from which the slabs are cut.
const SLAB_BINS: usize = 1024;

/// Where the slabs lie during a level: the slab of each bin of the centres along the longest
/// axis (cut at the level's first sliced pass so that the slabs hold about equal shares of its
/// visits), and the slab of every vertex (by its centre when a pass first needed it: a vertex
/// keeps its slab for the rest of the level).
struct Slabs {
    level: usize,
    of_bin: Vec<u8>,
    of_vertex: Vec<u8>,
}

impl Walker {
    /// The walker of a stream of `vertices` vertices whose passes of `sliced_visits` visits or
    /// more are sliced into `slabs` slabs (1: none).
    pub fn new(order: StepOrder, vertices: u64, slabs: usize, sliced_visits: usize) -> Walker {
        let shifts = (0..=order.steps())
            .map(|d| order.bits_per_axis(d).map(|b| order.levels - b))
            .collect();
        let mut walker = Walker {
            state: EmcState::new(order, vertices),
            leaf: vec![vertices <= 1],
            contexts: Box::default(),
            slabs: slabs.max(1),
            sliced_visits,
            slab_cuts: Slabs {
                level: 0,
                of_bin: Vec::new(),
                of_vertex: Vec::new(),
            },
            shifts,
            centres: Vec::new(),
            codes: Vec::new(),
            active: Vec::new(),
            resting: Vec::new(),
            marks: vec![AtomicU64::new(0)],
            split_serial: 0,
        };
        walker.centres.push(cell_centre([0; 3], walker.shifts[0]));
        walker
    }

    /// Frees the caches only the levels' passes read (centres, marks, visit lists), once the
    /// last level is coded: the face corrections that follow are the encoder's peak of memory.
    pub fn release_caches(&mut self) {
        self.centres = Vec::new();
        self.marks = Vec::new();
        self.active = Vec::new();
        self.resting = Vec::new();
        self.codes = Vec::new();
    }

    /// Twice `v`'s cell centre in units of the full grid, and the shifts of its half-widths:
    /// half the width of its cell along axis `a` is 2^`shifts[a]` in those units.
    pub(super) fn cell_of(&self, v: usize) -> ([i32; 3], [u8; 3]) {
        (self.centres[v], self.shifts[self.state.depth[v] as usize])
    }

    /// Count, mean and covariance of `v`'s neighbours' cell centres, relative to `v`'s centre;
    /// `None` without neighbours.
    pub(super) fn moments(&self, v: usize) -> Option<Moments> {
        neighbour_moments(self.centres[v], &self.state.adjacency[v], |n| {
            self.centres[n]
        })
    }

    /// Codes the first `passes` (1..=3) passes of `level` (1-based) and, when all three are
    /// coded, the level's refinement of the vertices that were leaves at its start. The passes
    /// visit only the vertices that were clusters at the level's start (and those split off
    /// them): at the finest levels these are few, and the leaves, whose edges no longer change,
    /// take their three bits together from one look at their neighbours. `max_vertices` and
    /// `max_triangles` are the header's counts, which no stream may exceed.
    pub fn level<S: Side>(
        &mut self,
        side: &mut S,
        level: usize,
        passes: usize,
        max_vertices: u64,
        max_triangles: u64,
    ) -> Result<(), Stop> {
        self.active.clear();
        self.resting.clear();
        for v in 0..self.state.len() {
            if self.leaf[v] {
                self.resting.push(v as u32);
            } else {
                self.active.push(v as u32);
            }
        }
        let first = 3 * (level - 1);
        for step in first..first + passes.min(3) {
            // One pass over the active vertices present at its start; those it splits off are
            // visited from the next pass on.
            let mut active = std::mem::take(&mut self.active);
            let created = self.pass(
                side,
                &active,
                Work::Split(step),
                max_vertices,
                max_triangles,
            );
            active.extend(created?);
            self.active = active;
        }
        if passes >= 3 {
            // The three refinement bits of a level of every vertex that was a leaf at the
            // level's start, vertex by vertex: the neighbours' moments are taken once, and all
            // three contexts come from them and the vertex's cell at the level's start, before
            // any of the three bits, so that the bits go through the coder as one symbol.
            let resting = std::mem::take(&mut self.resting);
            let done = self.pass(
                side,
                &resting,
                Work::Leaves(first),
                max_vertices,
                max_triangles,
            );
            self.resting = resting;
            done?;
        }
        Ok(())
    }

    /// One pass over `visits` (in list order); returns the vertices it created. In a stream
    /// with slabs, a pass of at least `sliced_visits` visits is sliced: each slab first
    /// codes its visits whose neighbours all lie in the slab, in a stream of its own and with
    /// its own copy of the contexts (so the slabs can be coded at once: none reads or writes
    /// another's vertices), then the contexts are merged and the remaining visits are coded in
    /// the level's stream, in list order.
    fn pass<S: Side>(
        &mut self,
        side: &mut S,
        visits: &[u32],
        work: Work,
        max_vertices: u64,
        max_triangles: u64,
    ) -> Result<Vec<u32>, Stop> {
        if self.slabs < 2 || visits.len() < self.sliced_visits {
            return self.run_in_order(side, visits, work, max_vertices, max_triangles);
        }
        let (step, level) = match work {
            Work::Split(step) => (Some(step), self.state.order.level(step)),
            Work::Leaves(first) => (None, self.state.order.level(first)),
        };
        let plan = self.slab_plan(visits, level);
        let counts = side.begin_sliced_pass(&plan.interior, step)?;
        let mut created =
            self.run_slabs(side, &plan, &counts, work, max_vertices, max_triangles)?;
        side.end_sliced_pass();
        created.extend(self.run_in_order(
            side,
            &plan.boundary,
            work,
            max_vertices,
            max_triangles,
        )?);
        Ok(created)
    }

    /// Divides `visits`, a pass of `level`, into slabs (see [`SlabPlan`], [`Slabs`]).
    fn slab_plan(&mut self, visits: &[u32], level: usize) -> SlabPlan {
        let axis = self.state.order.axes[0] as usize;
        // Centres lie below 2^(levels + 1).
        let shift = (self.state.order.levels as u32 + 1).saturating_sub(SLAB_BINS.ilog2());
        let centres = &self.centres;
        let bin = |v: usize| ((centres[v][axis] >> shift) as usize).min(SLAB_BINS - 1);
        if self.slab_cuts.level != level {
            let mut histogram = [0usize; SLAB_BINS];
            for &v in visits {
                histogram[bin(v as usize)] += 1;
            }
            let mut seen = 0;
            self.slab_cuts.of_bin = histogram
                .iter()
                .map(|&count| {
                    let slab = (seen * self.slabs / visits.len()).min(self.slabs - 1) as u8;
                    seen += count;
                    slab
                })
                .collect();
            self.slab_cuts.of_vertex.clear();
            self.slab_cuts.level = level;
        }
        let Slabs {
            of_bin, of_vertex, ..
        } = &mut self.slab_cuts;
        let known = of_vertex.len();
        of_vertex.par_extend(
            (known..self.state.len())
                .into_par_iter()
                .map(|v| of_bin[bin(v)]),
        );
        let slab_of = &*of_vertex;
        let adjacency = &self.state.adjacency;
        let kind: Vec<u8> = visits
            .par_iter()
            .map(|&v| {
                let slab = slab_of[v as usize];
                let inside = adjacency[v as usize]
                    .iter()
                    .all(|&n| slab_of[n as usize] == slab);
                if inside {
                    slab
                } else {
                    u8::MAX
                }
            })
            .collect();
        // Each slab's interior, then the boundary, in list order: a scan per list, the
        // lists on threads.
        let mut interior: Vec<Vec<u32>> = (0..=self.slabs)
            .into_par_iter()
            .map(|list| {
                let kind_listed = if list < self.slabs {
                    list as u8
                } else {
                    u8::MAX
                };
                let listed = visits.iter().zip(&kind).filter(|&(_, &k)| k == kind_listed);
                listed.map(|(&v, _)| v).collect()
            })
            .collect();
        let boundary = interior.pop().unwrap_or_default();
        SlabPlan { interior, boundary }
    }

    /// Makes room for `more` vertices after the list's end (each array gets a blank entry).
    fn grow(&mut self, more: usize) {
        let n = self.state.len() + more;
        self.state.cells.resize(n, [0; 3]);
        self.state.depth.resize(n, 0);
        self.state.next_split.resize(n, NO_SPLIT);
        self.state.adjacency.resize_with(n, Neighbours::new);
        self.leaf.resize(n, false);
        self.centres.resize(n, [0; 3]);
        self.marks.resize_with(n, AtomicU64::default);
    }

    /// Drops the entries from `n` on (room [`Self::grow`] made that no split took).
    fn shrink(&mut self, n: usize) {
        self.state.cells.truncate(n);
        self.state.depth.truncate(n);
        self.state.next_split.truncate(n);
        self.state.adjacency.truncate(n);
        self.leaf.truncate(n);
        self.centres.truncate(n);
        self.marks.truncate(n);
    }

    /// The arrays a pass reads and writes, for [`Run`]s. Nothing else may touch them while
    /// the view is in use.
    fn lanes(&mut self) -> Lanes {
        Lanes {
            cells: self.state.cells.as_mut_ptr(),
            depth: self.state.depth.as_mut_ptr(),
            next_split: self.state.next_split.as_mut_ptr(),
            adjacency: self.state.adjacency.as_mut_ptr(),
            leaf: self.leaf.as_mut_ptr(),
            centres: self.centres.as_mut_ptr(),
            marks: self.marks.as_ptr(),
            len: self.state.len(),
        }
    }

    /// Codes `visits` one after another in the level's stream (a pass that is not sliced, or
    /// the boundary of one that is).
    fn run_in_order<S: Side>(
        &mut self,
        side: &mut S,
        visits: &[u32],
        work: Work,
        max_vertices: u64,
        max_triangles: u64,
    ) -> Result<Vec<u32>, Stop> {
        let start = self.state.len();
        let room = match work {
            Work::Split(_) => visits
                .len()
                .min(max_vertices.saturating_sub(start as u64) as usize),
            Work::Leaves(_) => 0,
        };
        self.grow(room);
        let lanes = self.lanes();
        let mut run = Run {
            lanes: &lanes,
            shifts: &self.shifts,
            order: self.state.order,
            contexts: &mut self.contexts,
            slab: None,
            codes: std::mem::take(&mut self.codes),
            serial: self.split_serial,
            serial_step: 1,
            first_id: start,
            next_id: start,
            end_id: start + room,
            edges: self.state.edge_count(),
            max_vertices,
            max_triangles,
            created: Vec::new(),
        };
        let done = run.work(side, visits, work);
        let Run {
            codes,
            serial,
            next_id,
            edges,
            created,
            ..
        } = run;
        self.codes = codes;
        self.split_serial = serial;
        self.state.add_edges(edges - self.state.edge_count());
        // A split takes its id before any list names it: the lists name no dropped entry.
        self.shrink(next_id);
        done.map(|()| created)
    }

    /// Codes each slab's interior visits (see [`Self::pass`]), on threads where the side
    /// offers a side per slab; `counts[s]` is how many of slab `s`'s visits split. Returns the
    /// vertices created, slab after slab.
    fn run_slabs<S: Side>(
        &mut self,
        side: &mut S,
        plan: &SlabPlan,
        counts: &[u32],
        work: Work,
        max_vertices: u64,
        max_triangles: u64,
    ) -> Result<Vec<u32>, Stop> {
        let start = self.state.len();
        let mut firsts = Vec::with_capacity(self.slabs + 1);
        firsts.push(start);
        for (slab, &count) in counts.iter().enumerate() {
            if count as usize > plan.interior[slab].len() {
                return Err(Stop::Fault(format!(
                    "slab {slab} splits {count} of its {} vertices",
                    plan.interior[slab].len()
                )));
            }
            firsts.push(firsts[slab] + count as usize);
        }
        let end = firsts[self.slabs];
        if end as u64 > max_vertices {
            return Err(Stop::Fault(format!(
                "more splits than the {max_vertices} vertices the header declares"
            )));
        }
        self.grow(end - start);
        let mut contexts: Vec<Box<Contexts>> =
            (0..self.slabs).map(|_| self.contexts.clone()).collect();
        let lanes = self.lanes();
        let slab_of = std::mem::take(&mut self.slab_cuts.of_vertex);
        let stride = self.slabs as u64;
        // The slabs' serials interleave above the last one used: slab s's k-th split takes
        // serial + 1 + s + k · stride.
        let (shifts, order, serial, edges) = (
            &self.shifts,
            self.state.order,
            self.split_serial + stride,
            self.state.edge_count(),
        );
        let run = |slab: usize, contexts: &mut Contexts, side: &mut S| {
            let mut run = Run {
                lanes: &lanes,
                shifts,
                order,
                contexts,
                slab: Some((&slab_of, slab as u8)),
                codes: Vec::new(),
                serial: serial + slab as u64 + 1 - stride,
                serial_step: stride,
                first_id: firsts[slab],
                next_id: firsts[slab],
                end_id: firsts[slab + 1],
                edges,
                max_vertices,
                max_triangles,
                created: Vec::new(),
            };
            run.work(side, &plan.interior[slab], work)?;
            if run.next_id != run.end_id {
                return Err(Stop::Fault(format!(
                    "slab {slab} splits {} vertices, its table entry says {}",
                    run.next_id - run.first_id,
                    run.end_id - run.first_id
                )));
            }
            Ok((run.serial, run.edges - edges, run.created))
        };
        let ends: Vec<Result<_, Stop>> = match side.slab_sides()? {
            Some(mut sides) => {
                let ends = sides
                    .par_iter_mut()
                    .zip(contexts.par_iter_mut())
                    .enumerate()
                    .map(|(slab, (side, contexts))| run(slab, contexts, side))
                    .collect();
                side.join_slab_sides(sides);
                ends
            }
            None => {
                let mut ends = Vec::with_capacity(self.slabs);
                for (slab, contexts) in contexts.iter_mut().enumerate() {
                    side.begin_slab(slab)?;
                    ends.push(run(slab, contexts, side));
                    side.end_slab(slab);
                }
                ends
            }
        };
        let mut created = Vec::with_capacity(end - start);
        for end in ends {
            let (serial, added, slab_created) = end?;
            self.split_serial = self.split_serial.max(serial);
            self.state.add_edges(added);
            created.extend(slab_created);
        }
        self.state.check_edges(max_triangles).map_err(Stop::Fault)?;
        self.contexts.merge(&contexts);
        self.slab_cuts.of_vertex = slab_of;
        Ok(created)
    }
}

/// How many visits ahead [`Run::prefetch_ring`] asks for a vertex's neighbours.
const PREFETCH_AHEAD: usize = 5;

/// Twice the centre of a cell of prefix `cell`, whose half-widths have shifts `shifts`.
fn cell_centre(cell: [u32; 3], shifts: [u8; 3]) -> [i32; 3] {
    // At most 2^25 (24 levels), so i32 holds it; the neighbours' offsets too.
    [0, 1, 2].map(|a| (((cell[a] as i32) << 1) | 1) << shifts[a])
}

/// Raw views of the per-vertex arrays of a [`Walker`], shared by the [`Run`]s of a pass.
///
/// The slabs of a sliced pass run at once over these arrays. That is sound because each reads
/// and writes only its own vertices: a slab visits only vertices whose neighbours all lie in
/// the slab; a visit reads and writes the visited vertex, its neighbours and the vertex its
/// split creates (which takes the slab's own ids); a split gives its vertex's neighbours only
/// the created vertex, so no slab vertex ever gains a neighbour from elsewhere, whatever the
/// stream says. Only the marks are read across slabs (the coded ring walks a neighbour's list,
/// which may name another slab's vertices): they are atomic, and no slab's serial is
/// another's, so what one slab reads of another's marks never counts.
struct Lanes {
    cells: *mut [u32; 3],
    depth: *mut u16,
    next_split: *mut u16,
    adjacency: *mut Neighbours,
    leaf: *mut bool,
    centres: *mut [i32; 3],
    marks: *const AtomicU64,
    len: usize,
}

// SAFETY: see the type's docs: the runs sharing a view touch disjoint vertices.
#[allow(unsafe_code)]
unsafe impl Sync for Lanes {}
// SAFETY: as for `Sync`: a run moved to another thread still touches only its own vertices.
#[allow(unsafe_code)]
unsafe impl Send for Lanes {}

/// One vertex's entry in an array of [`Lanes`], bounds-checked, to read.
macro_rules! lane {
    ($lanes:expr, $field:ident, $v:expr) => {{
        let v: usize = $v;
        assert!(v < $lanes.len, "vertex {v} outside the lanes");
        // SAFETY: in bounds; the run owns vertex v (see `Lanes`).
        unsafe { &*$lanes.$field.add(v) }
    }};
}

/// One vertex's entry in an array of [`Lanes`], bounds-checked, to write.
macro_rules! lane_mut {
    ($lanes:expr, $field:ident, $v:expr) => {{
        let v: usize = $v;
        assert!(v < $lanes.len, "vertex {v} outside the lanes");
        // SAFETY: in bounds; the run owns vertex v (see `Lanes`), and no other reference to
        // the entry is alive.
        unsafe { &mut *$lanes.$field.add(v) }
    }};
}

/// One run of a pass over some of its visits: the whole pass, or one slab of a sliced pass, or
/// the boundary that follows the slabs.
struct Run<'a> {
    lanes: &'a Lanes,
    shifts: &'a [[u8; 3]],
    order: StepOrder,
    contexts: &'a mut Contexts,
    /// In a slab: the slab of every vertex at the pass's start, and this slab.
    slab: Option<(&'a [u8], u8)>,
    codes: Vec<EdgeCode>,
    serial: u64,
    serial_step: u64,
    /// The ids this run's splits take: from `first_id`, the next one, and the end.
    first_id: usize,
    next_id: usize,
    end_id: usize,
    /// Edges of the graph as this run knows them.
    edges: u64,
    max_vertices: u64,
    max_triangles: u64,
    /// Vertices created, in order.
    created: Vec<u32>,
}

// The lanes are read and written here only (`lane!`, `lane_mut!`).
#[allow(unsafe_code)]
impl Run<'_> {
    fn adjacency(&self, v: usize) -> &Neighbours {
        debug_assert!(self.owns(v), "vertex {v} read outside its slab");
        lane!(self.lanes, adjacency, v)
    }

    fn centre(&self, v: usize) -> [i32; 3] {
        debug_assert!(self.owns(v), "vertex {v} read outside its slab");
        *lane!(self.lanes, centres, v)
    }

    fn leaf(&self, v: usize) -> bool {
        debug_assert!(self.owns(v), "vertex {v} read outside its slab");
        *lane!(self.lanes, leaf, v)
    }

    fn depth(&self, v: usize) -> usize {
        debug_assert!(self.owns(v), "vertex {v} read outside its slab");
        *lane!(self.lanes, depth, v) as usize
    }

    /// Whether `v` is this run's to read: every vertex outside a slab; in a slab, its own
    /// vertices and those its splits created.
    fn owns(&self, v: usize) -> bool {
        match self.slab {
            None => true,
            Some((slab_of, slab)) => match slab_of.get(v) {
                Some(&s) => s == slab,
                None => (self.first_id..self.next_id).contains(&v),
            },
        }
    }

    /// Recomputes the cached centre of `v` from its cell.
    fn refresh(&mut self, v: usize) {
        let shifts = self.shifts[self.depth(v)];
        let cell = *lane!(self.lanes, cells, v);
        *lane_mut!(self.lanes, centres, v) = cell_centre(cell, shifts);
    }

    /// RF: `v` takes `bit` at `step`.
    fn refine(&mut self, v: usize, step: usize, bit: u32) {
        let axis = self.order.axis(step);
        let cell = lane_mut!(self.lanes, cells, v);
        cell[axis] = (cell[axis] << 1) | bit;
        *lane_mut!(self.lanes, depth, v) += 1;
    }

    fn work<S: Side>(&mut self, side: &mut S, visits: &[u32], work: Work) -> Result<(), Stop> {
        match work {
            Work::Split(step) => self.pass(side, visits, step),
            Work::Leaves(first) => self.leaf_pass(side, visits, first),
        }
    }

    /// The clusters' pass of `step` over `visits`.
    fn pass<S: Side>(&mut self, side: &mut S, visits: &[u32], step: usize) -> Result<(), Stop> {
        let order = self.order;
        let axis = order.axis(step);
        let remaining = order.levels as usize - order.level(step);
        for (i, &v) in visits.iter().enumerate() {
            if let Some(&ahead) = visits.get(i + PREFETCH_AHEAD) {
                self.prefetch_ring(ahead as usize, true);
            }
            let v = v as usize;
            let valence = self.adjacency(v).len();
            let (half, flip) = self.half_context(v, axis);
            let splits = !self.leaf(v) && {
                let c = contexts::split(half.offset, valence, remaining);
                side.code(&mut self.contexts.split[c], Question::Split, false, v, step)?
            };
            if !splits {
                let c = half.index;
                let bit = side.code(&mut self.contexts.half[c], Question::Half, flip, v, step)?;
                self.refine(v, step, bit as u32);
                self.refresh(v);
                continue;
            }
            if self.next_id == self.end_id {
                return Err(Stop::Fault(match self.slab {
                    None => format!(
                        "more splits than the {} vertices the header declares",
                        self.max_vertices
                    ),
                    Some((_, slab)) => {
                        format!("slab {slab} splits more vertices than its table entry says")
                    }
                }));
            }
            let r = self.split(side, v, step, axis, remaining)?;
            self.created.push(r as u32);
        }
        Ok(())
    }

    /// The leaves' three bits of the level whose first step is `first`, for `visits`.
    fn leaf_pass<S: Side>(
        &mut self,
        side: &mut S,
        visits: &[u32],
        first: usize,
    ) -> Result<(), Stop> {
        let axes = [0, 1, 2].map(|k| self.order.axis(first + k));
        for (i, &v) in visits.iter().enumerate() {
            if let Some(&ahead) = visits.get(i + PREFETCH_AHEAD) {
                self.prefetch_ring(ahead as usize, false);
            }
            let v = v as usize;
            let (mut index, mut flips) = ([0; 3], [false; 3]);
            match self.moments(v) {
                None => index = [contexts::half_isolated(true).index; 3],
                Some(m) => {
                    let shifts = self.shifts[self.depth(v)];
                    let (by_axis, below) = leaf_contexts(&m, shifts);
                    for k in 0..3 {
                        (index[k], flips[k]) = (by_axis[axes[k]], below[axes[k]]);
                    }
                }
            }
            let bits = side.code3(&mut self.contexts.half, index, flips, v, first)?;
            for (k, bit) in bits.into_iter().enumerate() {
                self.refine(v, first + k, bit as u32);
            }
            self.refresh(v);
        }
        Ok(())
    }

    /// Asks the processor to load the centres of `v`'s neighbours (and their lists, with
    /// `lists`), which the visit of `v`, one of this run's, reads a few visits from now: on a
    /// large mesh they lie far apart in memory, and loading them while the visits before are
    /// coded hides the wait (bunny-closed-35k ×16: a decode on one thread 8–10% faster).
    fn prefetch_ring(&self, v: usize, lists: bool) {
        for &n in self.adjacency(v) {
            prefetch(self.lanes.centres.wrapping_add(n as usize));
            if lists {
                prefetch(self.lanes.adjacency.wrapping_add(n as usize));
            }
        }
    }

    /// Reads `v`'s neighbours' lists and centres (a sum for [`std::hint::black_box`] to keep).
    fn touch(&self, v: usize) -> usize {
        self.adjacency(v)
            .iter()
            .map(|&n| self.adjacency(n as usize).len() + self.centre(n as usize)[0] as usize)
            .sum()
    }

    fn moments(&self, v: usize) -> Option<Moments> {
        neighbour_moments(self.centre(v), self.adjacency(v), |n| self.centre(n))
    }

    /// Context and flip of the half `v` takes along `axis`, from its neighbours' moments `m`
    /// (relative to `v`'s centre); see [`estimate`].
    #[inline]
    fn predict(&self, v: usize, axis: usize, m: &Moments) -> (contexts::HalfContext, bool) {
        let shifts = self.shifts[self.depth(v)];
        let (prediction, variance) = estimate(m, axis, shifts);
        let scale = per_half_width(shifts[axis]);
        (
            contexts::half(
                self.leaf(v),
                m.k,
                prediction.abs() * scale,
                variance * scale * scale,
            ),
            prediction < 0.0,
        )
    }

    /// Context and flip of the half a vertex in the passes takes ([`Self::predict`] from its
    /// neighbours as they are now).
    fn half_context(&self, v: usize, axis: usize) -> (contexts::HalfContext, bool) {
        match self.moments(v) {
            None => (contexts::half_isolated(self.leaf(v)), false),
            Some(m) => self.predict(v, axis, &m),
        }
    }

    /// What the already coded neighbours of the splitting vertex that are also neighbours of
    /// `n` did: bit 0 some stayed, bit 1 some moved, bit 2 some were duplicated (read from the
    /// marks of the current split). Around a manifold vertex the duplicated edges are where the
    /// stayed arc meets the moved one.
    fn coded_ring(&self, n: usize) -> usize {
        let mut seen = 0;
        for &m in self.adjacency(n) {
            let mark = lane!(self.lanes, marks, m as usize).load(Ordering::Relaxed);
            seen |= if mark >> 3 == self.serial {
                mark & 7
            } else {
                0
            };
        }
        seen as usize
    }

    fn split<S: Side>(
        &mut self,
        side: &mut S,
        v: usize,
        step: usize,
        axis: usize,
        remaining: usize,
    ) -> Result<usize, Stop> {
        let r = self.next_id;
        side.begin_split(self.adjacency(v), v, r, step, self.lanes.len);
        let valence = self.adjacency(v).len();
        // The neighbours' lists and centres are about to be read (and most lists edited): load
        // them now, side by side, rather than one after another between the questions (which
        // leaves the processor waiting on each in turn).
        std::hint::black_box(self.touch(v));
        let c = contexts::connecting(valence, remaining);
        let connecting = side.code(
            &mut self.contexts.connecting[c],
            Question::Connecting,
            false,
            v,
            step,
        )?;
        let centre = self.centre(v);
        let scale = per_half_width(self.shifts[self.depth(v)][axis]);
        let mut codes = std::mem::take(&mut self.codes);
        codes.clear();
        // Marks left by earlier splits are told apart by their serial.
        self.serial += self.serial_step;
        let mut duplicates = 0;
        for i in 0..valence {
            let n = self.adjacency(v)[i] as usize;
            let offset = self.centre(n).map(|x| x as i64);
            let along = (offset[axis] - centre[axis] as i64) as f64 * scale;
            let (b, c) = ((axis + 1) % 3, (axis + 2) % 3);
            let across = (offset[b] - centre[b] as i64)
                .abs()
                .max((offset[c] - centre[c] as i64).abs()) as f64
                * scale;
            let place = contexts::edge_place(along.abs(), across, self.leaf(n));
            let ring = self.coded_ring(n);
            let c = contexts::duplicate(place, ring, duplicates);
            let code = if side.code(
                &mut self.contexts.duplicate[c],
                Question::Duplicate(i),
                false,
                v,
                step,
            )? {
                duplicates += 1;
                EdgeCode::Duplicate
            } else if side.code(
                &mut self.contexts.moves[contexts::moves(place, ring, along < 0.0)],
                Question::Moves(i),
                along < 0.0,
                v,
                step,
            )? {
                EdgeCode::Move
            } else {
                EdgeCode::Stay
            };
            codes.push(code);
            let mark = self.serial << 3
                | match code {
                    EdgeCode::Stay => 1,
                    EdgeCode::Move => 2,
                    EdgeCode::Duplicate => 4,
                };
            lane!(self.lanes, marks, n).store(mark, Ordering::Relaxed);
        }
        // VS: `v` keeps the lower half, `r` takes the upper.
        self.next_id += 1;
        let mut cell = *lane!(self.lanes, cells, v);
        lane_mut!(self.lanes, cells, v)[axis] = cell[axis] << 1;
        cell[axis] = (cell[axis] << 1) | 1;
        *lane_mut!(self.lanes, cells, r) = cell;
        let depth = lane_mut!(self.lanes, depth, v);
        *depth += 1;
        let depth = *depth;
        *lane_mut!(self.lanes, depth, r) = depth;
        *lane_mut!(self.lanes, next_split, v) = NO_SPLIT;
        *lane_mut!(self.lanes, next_split, r) = NO_SPLIT;
        *lane_mut!(self.lanes, adjacency, r) = Neighbours::new();
        self.edges += split_edges(&mut LaneLists(self.lanes), v, r, connecting, &codes);
        check_edge_count(self.edges, self.max_triangles).map_err(Stop::Fault)?;
        self.refresh(v);
        self.refresh(r);
        self.codes = codes;
        *lane_mut!(self.lanes, leaf, r) = false;
        for (half, vertex) in [(0, v), (1, r)] {
            let valence = self.adjacency(vertex).len();
            // The upper half's question knows the lower half's answer.
            let kind = if half == 0 {
                0
            } else {
                1 + self.leaf(v) as usize
            };
            let c = contexts::leaf(kind, valence, remaining);
            *lane_mut!(self.lanes, leaf, vertex) = side.code(
                &mut self.contexts.leaf[c],
                Question::Leaf(half),
                false,
                vertex,
                step,
            )?;
        }
        side.end_split(v, r);
        Ok(r)
    }
}

/// The neighbour lists of [`Lanes`], for [`split_edges`].
struct LaneLists<'a>(&'a Lanes);

// A lane's list, through `lane_mut!`.
#[allow(unsafe_code)]
impl NeighbourLists for LaneLists<'_> {
    fn list(&mut self, v: usize) -> &mut Neighbours {
        lane_mut!(self.0, adjacency, v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// The lane-wise contexts of a leaf are exactly those of [`estimate`] axis by axis, for
    /// neighbourhoods flat and not, with few neighbours and many, at fine and coarse cells.
    #[test]
    fn leaf_contexts_match_the_estimate_of_each_axis() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        for _ in 0..20_000 {
            let k = rng.gen_range(1..12);
            let shifts = [0; 3].map(|_| rng.gen_range(0..13u8));
            let flat = rng.gen_range(0..3usize);
            let reach = 1i64 << rng.gen_range(0..14);
            let offsets: Vec<[f64; 3]> = (0..k)
                .map(|_| {
                    let mut d = [0; 3].map(|_| rng.gen_range(-reach..=reach) as f64);
                    if rng.gen_bool(0.5) {
                        d[flat] = (d[(flat + 1) % 3] * 0.3).round();
                    }
                    d
                })
                .collect();
            let inv = 1.0 / k as f64;
            let mean: [f64; 3] =
                std::array::from_fn(|a| offsets.iter().map(|d| d[a]).sum::<f64>() * inv);
            let cov: [[f64; 3]; 3] = std::array::from_fn(|a| {
                std::array::from_fn(|b| {
                    offsets.iter().map(|d| d[a] * d[b]).sum::<f64>() * inv - mean[a] * mean[b]
                })
            });
            let m = Moments { k, mean, cov };
            let (index, below) = leaf_contexts(&m, shifts);
            for axis in 0..3 {
                let (prediction, variance) = estimate(&m, axis, shifts);
                let scale = per_half_width(shifts[axis]);
                let half =
                    contexts::half(true, k, prediction.abs() * scale, variance * scale * scale);
                assert_eq!((index[axis], below[axis]), (half.index, prediction < 0.0));
            }
        }
    }
}
