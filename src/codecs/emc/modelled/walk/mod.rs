//! The passes of the modelled coder, written once for both sides: a [`Side`] answers each binary
//! question (the encoder from the mesh, the decoder from the stream) and the [`Walker`] applies
//! the answers to the shared state, choosing every question's context from what the decoder
//! already knows.

mod estimates;
#[cfg(test)]
mod hostile_slabs;
mod lanes;

use super::contexts::Contexts;
use crate::codecs::emc::state::{EdgeCode, EmcState, Neighbours, NO_SPLIT};
use crate::hierarchy::octree::StepOrder;
use estimates::*;
pub(super) use estimates::{estimate, Moments};
use lanes::*;
use rayon::prelude::*;
use std::sync::atomic::AtomicU64;

/// A question the walker asks about vertex `v` at the current step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Question {
    /// Does the (multi-vertex) cluster split now?
    Split,
    /// Which half does it take: 1 = upper.
    Half,
    /// Which half does the cluster's representative take at a step ahead of the cluster's
    /// splits: the half the cluster's vertices take if they keep to one, else the predicted one.
    Ahead,
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
            Question::Ahead => "ahead",
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
            Question::Split | Question::Half | Question::Ahead | Question::Leaf(_) => Geometry,
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
        ahead: bool,
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
    /// Per vertex, for the steps its cell took ahead of its splits: bit j is set if the step
    /// `depth - 1 - j` took the predicted half (a split may wait there).
    agree: Vec<u32>,
    /// Per vertex, the representative it stands for (docs/FORMAT.md §10), named by the vertex
    /// a split created when it gave the representative a vertex of its own: a split's new
    /// vertex, unless the representative went ahead into the new vertex's half
    /// (`emc-ahead`), which then takes the old one's and leaves it the new name.
    pub(super) representative: Vec<u32>,
    /// Levels each level's lookahead pass takes every vertex's cell ahead of the octree
    /// (0: none).
    pub ahead_levels: usize,
}

/// What a pass does to the vertices it visits.
#[derive(Clone, Copy)]
enum Work {
    /// The clusters' pass of a step: split, or take a half.
    Split(usize),
    /// The leaves' three bits of the level whose first step is this.
    Leaves(usize),
    /// Every vertex's cell taken ahead to this many steps, in `level`.
    Ahead { target: usize, level: usize },
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
            agree: vec![0],
            representative: vec![0],
            ahead_levels: 0,
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
            let target = (level + self.ahead_levels).min(self.state.order.levels as usize) * 3;
            if target > first + 3 {
                let all: Vec<u32> = (0..self.state.len() as u32).collect();
                self.pass(
                    side,
                    &all,
                    Work::Ahead { target, level },
                    max_vertices,
                    max_triangles,
                )?;
            }
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
            Work::Ahead { level, .. } => (None, level),
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
        self.agree.resize(n, 0);
        self.representative.resize(n, 0);
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
        self.agree.truncate(n);
        self.representative.truncate(n);
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
            agree: self.agree.as_mut_ptr(),
            representative: self.representative.as_mut_ptr(),
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
            Work::Leaves(_) | Work::Ahead { .. } => 0,
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

#[cfg(test)]
mod tests {
    use super::super::contexts;
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
