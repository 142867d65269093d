//! One pass's run over the walker's per-vertex arrays: [`Lanes`], the raw views the slabs of a
//! sliced pass share (and why that is sound), and [`Run`], which visits a slab's vertices.

use super::super::contexts::{self, Contexts, AHEAD_DISTANCES};
use super::*;
use crate::codecs::emc::state::{
    check_edge_count, split_edges, EdgeCode, NeighbourLists, Neighbours, NO_SPLIT,
};
use crate::hierarchy::octree::StepOrder;
use crate::prefetch::prefetch;
use std::sync::atomic::{AtomicU64, Ordering};

/// How many visits ahead [`Run::prefetch_ring`] asks for a vertex's neighbours.
pub(super) const PREFETCH_AHEAD: usize = 5;

/// Twice the centre of a cell of prefix `cell`, whose half-widths have shifts `shifts`.
pub(super) fn cell_centre(cell: [u32; 3], shifts: [u8; 3]) -> [i32; 3] {
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
pub(super) struct Lanes {
    pub(super) cells: *mut [u32; 3],
    pub(super) depth: *mut u16,
    pub(super) next_split: *mut u16,
    pub(super) adjacency: *mut Neighbours,
    pub(super) leaf: *mut bool,
    pub(super) centres: *mut [i32; 3],
    pub(super) marks: *const AtomicU64,
    pub(super) agree: *mut u32,
    pub(super) representative: *mut u32,
    pub(super) len: usize,
}

// SAFETY: see the type's docs: the runs sharing a view touch disjoint vertices.
#[allow(unsafe_code)]
unsafe impl Sync for Lanes {}
// SAFETY: as for `Sync`: a run moved to another thread still touches only its own vertices.
#[allow(unsafe_code)]
unsafe impl Send for Lanes {}

/// One vertex's entry in an array of [`Lanes`], to read, through a `$run` that checks the
/// vertex is in bounds and (debug builds, tests) its own: see [`check`].
macro_rules! lane {
    ($run:expr, $field:ident, $v:expr) => {{
        let v: usize = $v;
        $run.check(v);
        // SAFETY: in bounds, and the run owns vertex v (checked above; see `Lanes`).
        unsafe { &*$run.lanes.$field.add(v) }
    }};
}

/// One vertex's entry in an array of [`Lanes`], to write, checked as [`lane!`] checks it.
macro_rules! lane_mut {
    ($run:expr, $field:ident, $v:expr) => {{
        let v: usize = $v;
        $run.check(v);
        // SAFETY: in bounds, the run owns vertex v (checked above; see `Lanes`), and no other
        // reference to the entry is alive.
        unsafe { &mut *$run.lanes.$field.add(v) }
    }};
}

/// One vertex's mark, which any slab may read or write (atomic; see `Lanes`), bounds-checked.
macro_rules! mark {
    ($run:expr, $v:expr) => {{
        let v: usize = $v;
        assert!(v < $run.lanes.len, "vertex {v} outside the lanes");
        // SAFETY: in bounds; the marks are atomics, shared by the slabs.
        unsafe { &*$run.lanes.marks.add(v) }
    }};
}

/// Whether a run may touch vertex `v`: outside a slab, every vertex; in a slab, its own
/// vertices (`slab_of`, taken at the pass's start) and those its splits created
/// (`first_id..next_id`).
fn owns(slab: Option<(&[u8], u8)>, first_id: usize, next_id: usize, v: usize) -> bool {
    match slab {
        None => true,
        Some((slab_of, slab)) => match slab_of.get(v) {
            Some(&s) => s == slab,
            None => (first_id..next_id).contains(&v),
        },
    }
}

/// Panics unless `v` is in the lanes and, in debug builds and the crate's tests, unless `owns`
/// it: the check before every raw access. The ownership check costs `emc`'s decoder about 5%
/// (docs/notes/benchmarks-history.md, "Slab ownership"), so a release build leaves it to the argument in
/// [`Lanes`]'s docs, which the tests that feed hostile slab streams exercise with it on.
#[inline(always)]
pub(super) fn check(lanes: &Lanes, v: usize, owns: impl FnOnce() -> bool) {
    if v >= lanes.len {
        outside(lanes, v);
    }
    #[cfg(any(debug_assertions, test))]
    if !owns() {
        panic!("vertex {v} touched outside its slab");
    }
    #[cfg(not(any(debug_assertions, test)))]
    let _ = owns;
}

/// The panic of an access out of bounds, out of the hot path.
#[cold]
#[inline(never)]
fn outside(lanes: &Lanes, v: usize) -> ! {
    panic!("vertex {v} outside the lanes ({})", lanes.len);
}

/// One run of a pass over some of its visits: the whole pass, or one slab of a sliced pass, or
/// the boundary that follows the slabs.
pub(super) struct Run<'a> {
    pub(super) lanes: &'a Lanes,
    pub(super) shifts: &'a [[u8; 3]],
    pub(super) order: StepOrder,
    pub(super) contexts: &'a mut Contexts,
    /// In a slab: the slab of every vertex at the pass's start, and this slab.
    pub(super) slab: Option<(&'a [u8], u8)>,
    pub(super) codes: Vec<EdgeCode>,
    pub(super) serial: u64,
    pub(super) serial_step: u64,
    /// The ids this run's splits take: from `first_id`, the next one, and the end.
    pub(super) first_id: usize,
    pub(super) next_id: usize,
    pub(super) end_id: usize,
    /// Edges of the graph as this run knows them.
    pub(super) edges: u64,
    pub(super) max_vertices: u64,
    pub(super) max_triangles: u64,
    /// Vertices created, in order.
    pub(super) created: Vec<u32>,
}

// The lanes are read and written here only (`lane!`, `lane_mut!`).

#[allow(unsafe_code)]
impl Run<'_> {
    pub(super) fn adjacency(&self, v: usize) -> &Neighbours {
        lane!(self, adjacency, v)
    }

    pub(super) fn centre(&self, v: usize) -> [i32; 3] {
        *lane!(self, centres, v)
    }

    pub(super) fn leaf(&self, v: usize) -> bool {
        *lane!(self, leaf, v)
    }

    pub(super) fn depth(&self, v: usize) -> usize {
        *lane!(self, depth, v) as usize
    }

    fn check(&self, v: usize) {
        check(self.lanes, v, || {
            owns(self.slab, self.first_id, self.next_id, v)
        });
    }

    /// Recomputes the cached centre of `v` from its cell.
    pub(super) fn refresh(&mut self, v: usize) {
        let shifts = self.shifts[self.depth(v)];
        let cell = *lane!(self, cells, v);
        *lane_mut!(self, centres, v) = cell_centre(cell, shifts);
    }

    /// RF: `v` takes `bit` at `step`.
    pub(super) fn refine(&mut self, v: usize, step: usize, bit: u32) {
        let axis = self.order.axis(step);
        let cell = lane_mut!(self, cells, v);
        cell[axis] = (cell[axis] << 1) | bit;
        *lane_mut!(self, depth, v) += 1;
    }

    pub(super) fn work<S: Side>(
        &mut self,
        side: &mut S,
        visits: &[u32],
        work: Work,
    ) -> Result<(), Stop> {
        match work {
            Work::Split(step) => self.pass(side, visits, step),
            Work::Leaves(first) => self.leaf_pass(side, visits, first),
            Work::Ahead { target, level } => self.ahead_pass(side, visits, target, level),
        }
    }

    /// The clusters' pass of `step` over `visits`.
    pub(super) fn pass<S: Side>(
        &mut self,
        side: &mut S,
        visits: &[u32],
        step: usize,
    ) -> Result<(), Stop> {
        let order = self.order;
        let axis = order.axis(step);
        let remaining = order.levels as usize - order.level(step);
        for (i, &v) in visits.iter().enumerate() {
            if let Some(&ahead) = visits.get(i + PREFETCH_AHEAD) {
                self.prefetch_ring(ahead as usize, true);
            }
            let v = v as usize;
            let valence = self.adjacency(v).len();
            if self.depth(v) > step {
                // The cell took this step ahead: no half to code, and a split only where the
                // step took the predicted half.
                let depth = self.depth(v);
                let agreed = (*lane!(self, agree, v) >> (depth - 1 - step)) & 1 == 1;
                if self.leaf(v) || !agreed {
                    continue;
                }
                let at = self.cell_at(v, step);
                let (half, _) = self.half_context_at(v, axis, at.centre, at.shifts);
                let c = contexts::split(half.offset, valence, remaining);
                let splits = side.code(
                    &mut self.contexts.split_ahead[c],
                    Question::Split,
                    false,
                    v,
                    step,
                )?;
                if splits {
                    self.check_room()?;
                    let r = self.split(side, v, step, axis, remaining, Some(at))?;
                    self.created.push(r as u32);
                }
                continue;
            }
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
            self.check_room()?;
            let r = self.split(side, v, step, axis, remaining, None)?;
            self.created.push(r as u32);
        }
        Ok(())
    }

    /// An error if the run has no id left for a split.
    fn check_room(&self) -> Result<(), Stop> {
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
        Ok(())
    }

    /// The cell `v`'s cell lies in after `steps` steps (fewer than its depth): its prefix.
    pub(super) fn cell_at(&self, v: usize, steps: usize) -> CellAt {
        let depth = self.depth(v);
        let (deep, shallow) = (
            self.order.bits_per_axis(depth),
            self.order.bits_per_axis(steps),
        );
        let cell = *lane!(self, cells, v);
        let prefix = [0, 1, 2].map(|a| cell[a] >> (deep[a] - shallow[a]));
        let shifts = self.shifts[steps];
        CellAt {
            cell: prefix,
            centre: cell_centre(prefix, shifts),
            shifts,
            steps,
        }
    }

    /// Every vertex of `visits` takes its cell ahead to `target` steps, a level at a time over
    /// all of them (so that each level's bits see their neighbours at the level before), a
    /// step at a time within it (a leaf's three steps of a level as in [`Self::leaf_pass`]).
    /// A cluster's cell follows its representative: the half its vertices keep to, or the
    /// predicted half where they part, so that the split waiting there costs about what it
    /// would have cost in its own pass. `level` is the octree's level: contexts tell apart how
    /// far ahead of it a bit is.
    pub(super) fn ahead_pass<S: Side>(
        &mut self,
        side: &mut S,
        visits: &[u32],
        target: usize,
        level: usize,
    ) -> Result<(), Stop> {
        for stop in (level + 1..=target / 3).map(|l| 3 * l) {
            // Bits coded further ahead see coarser neighbours: contexts of their own.
            let distance = (stop / 3 - level - 1).min(AHEAD_DISTANCES - 1);
            let base = distance * contexts::HALF_CONTEXTS;
            for (i, &v) in visits.iter().enumerate() {
                if let Some(&ahead) = visits.get(i + PREFETCH_AHEAD) {
                    self.prefetch_ring(ahead as usize, false);
                }
                self.take_ahead(side, v as usize, stop, base)?;
            }
        }
        Ok(())
    }

    /// `v`'s cell taken ahead to `stop` steps (a level's end), its bits under the contexts
    /// from `base` of [`Contexts::ahead`].
    fn take_ahead<S: Side>(
        &mut self,
        side: &mut S,
        v: usize,
        stop: usize,
        base: usize,
    ) -> Result<(), Stop> {
        while self.depth(v) < stop {
            let step = self.depth(v);
            if self.leaf(v) && step + 3 == stop {
                self.leaf_bits(side, v, step, Some(base))?;
                *lane_mut!(self, agree, v) <<= 3;
                continue;
            }
            let axis = self.order.axis(step);
            let (half, flip) = self.half_context(v, axis);
            let question = if self.leaf(v) {
                Question::Half
            } else {
                Question::Ahead
            };
            let context = &mut self.contexts.ahead[base + half.index];
            let bit = side.code(context, question, flip, v, step)?;
            self.refine(v, step, bit as u32);
            self.refresh(v);
            let agree = lane_mut!(self, agree, v);
            *agree = *agree << 1 | (bit != flip) as u32;
        }
        Ok(())
    }

    /// The leaves' three bits of the level whose first step is `first`, for `visits`.
    pub(super) fn leaf_pass<S: Side>(
        &mut self,
        side: &mut S,
        visits: &[u32],
        first: usize,
    ) -> Result<(), Stop> {
        for (i, &v) in visits.iter().enumerate() {
            if let Some(&ahead) = visits.get(i + PREFETCH_AHEAD) {
                self.prefetch_ring(ahead as usize, false);
            }
            let v = v as usize;
            if self.depth(v) > first {
                // Taken ahead already.
                continue;
            }
            self.leaf_bits(side, v, first, None)?;
        }
        Ok(())
    }

    /// A leaf's three bits from step `first` (a level's first), from one look at its
    /// neighbours, as one symbol.
    fn leaf_bits<S: Side>(
        &mut self,
        side: &mut S,
        v: usize,
        first: usize,
        ahead: Option<usize>,
    ) -> Result<(), Stop> {
        let axes = [0, 1, 2].map(|k| self.order.axis(first + k));
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
        let contexts = match ahead {
            None => &mut self.contexts.half[..],
            Some(base) => &mut self.contexts.ahead[base..base + contexts::HALF_CONTEXTS],
        };
        let bits = side.code3(contexts, index, flips, v, first, ahead.is_some())?;
        for (k, bit) in bits.into_iter().enumerate() {
            self.refine(v, first + k, bit as u32);
        }
        self.refresh(v);
        Ok(())
    }

    /// Asks the processor to load the centres of `v`'s neighbours (and their lists, with
    /// `lists`), which the visit of `v`, one of this run's, reads a few visits from now: on a
    /// large mesh they lie far apart in memory, and loading them while the visits before are
    /// coded hides the wait (bunny-closed-35k ×16: a decode on one thread 8–10% faster).
    pub(super) fn prefetch_ring(&self, v: usize, lists: bool) {
        for &n in self.adjacency(v) {
            prefetch(self.lanes.centres.wrapping_add(n as usize));
            if lists {
                prefetch(self.lanes.adjacency.wrapping_add(n as usize));
            }
        }
    }

    /// Reads `v`'s neighbours' lists and centres (a sum for [`std::hint::black_box`] to keep).
    pub(super) fn touch(&self, v: usize) -> usize {
        self.adjacency(v)
            .iter()
            .map(|&n| self.adjacency(n as usize).len() + self.centre(n as usize)[0] as usize)
            .sum()
    }

    pub(super) fn moments(&self, v: usize) -> Option<Moments> {
        neighbour_moments(self.centre(v), self.adjacency(v), |n| self.centre(n))
    }

    /// Context and flip of the half `v` takes along `axis`, from its neighbours' moments `m`
    /// (relative to `v`'s centre); see [`estimate`].
    #[inline]
    pub(super) fn predict(
        &self,
        v: usize,
        axis: usize,
        m: &Moments,
    ) -> (contexts::HalfContext, bool) {
        self.predict_in(v, axis, m, self.shifts[self.depth(v)])
    }

    /// [`Self::predict`] in a cell of half-width shifts `shifts` (`m` relative to its centre).
    #[inline]
    fn predict_in(
        &self,
        v: usize,
        axis: usize,
        m: &Moments,
        shifts: [u8; 3],
    ) -> (contexts::HalfContext, bool) {
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

    /// [`Self::half_context`] for `v` as if its cell were the one of centre `centre` and
    /// half-width shifts `shifts` (a cell its own lies in).
    pub(super) fn half_context_at(
        &self,
        v: usize,
        axis: usize,
        centre: [i32; 3],
        shifts: [u8; 3],
    ) -> (contexts::HalfContext, bool) {
        match neighbour_moments(centre, self.adjacency(v), |n| self.centre(n)) {
            None => (contexts::half_isolated(self.leaf(v)), false),
            Some(m) => self.predict_in(v, axis, &m, shifts),
        }
    }

    /// Context and flip of the half a vertex in the passes takes ([`Self::predict`] from its
    /// neighbours as they are now).
    pub(super) fn half_context(&self, v: usize, axis: usize) -> (contexts::HalfContext, bool) {
        match self.moments(v) {
            None => (contexts::half_isolated(self.leaf(v)), false),
            Some(m) => self.predict(v, axis, &m),
        }
    }

    /// What the already coded neighbours of the splitting vertex that are also neighbours of
    /// `n` did: bit 0 some stayed, bit 1 some moved, bit 2 some were duplicated (read from the
    /// marks of the current split). Around a manifold vertex the duplicated edges are where the
    /// stayed arc meets the moved one.
    pub(super) fn coded_ring(&self, n: usize) -> usize {
        let mut seen = 0;
        for &m in self.adjacency(n) {
            let mark = mark!(self, m as usize).load(Ordering::Relaxed);
            seen |= if mark >> 3 == self.serial {
                mark & 7
            } else {
                0
            };
        }
        seen as usize
    }

    pub(super) fn split<S: Side>(
        &mut self,
        side: &mut S,
        v: usize,
        step: usize,
        axis: usize,
        remaining: usize,
        ahead: Option<CellAt>,
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
        let (centre, scale) = match &ahead {
            None => (
                self.centre(v),
                per_half_width(self.shifts[self.depth(v)][axis]),
            ),
            Some(at) => (at.centre, per_half_width(at.shifts[axis])),
        };
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
            mark!(self, n).store(mark, Ordering::Relaxed);
        }
        // VS: `v` keeps the lower half, `r` takes the upper.
        self.next_id += 1;
        match ahead {
            None => {
                let mut cell = *lane!(self, cells, v);
                lane_mut!(self, cells, v)[axis] = cell[axis] << 1;
                cell[axis] = (cell[axis] << 1) | 1;
                *lane_mut!(self, cells, r) = cell;
                let depth = lane_mut!(self, depth, v);
                *depth += 1;
                let depth = *depth;
                *lane_mut!(self, depth, r) = depth;
                *lane_mut!(self, agree, r) = 0;
                *lane_mut!(self, representative, r) = r as u32;
            }
            Some(at) => {
                // The half the cell went ahead into keeps it; the other starts at the split.
                let (deep, deep_depth) = (*lane!(self, cells, v), self.depth(v));
                let below = self.order.bits_per_axis(deep_depth)[axis]
                    - self.order.bits_per_axis(step + 1)[axis];
                let went_upper = (deep[axis] >> below) & 1 == 1;
                let (keeps, starts) = if went_upper { (r, v) } else { (v, r) };
                let mut fresh = at.cell;
                fresh[axis] = (fresh[axis] << 1) | (!went_upper) as u32;
                let agree = *lane!(self, agree, v);
                *lane_mut!(self, cells, keeps) = deep;
                *lane_mut!(self, depth, keeps) = deep_depth as u16;
                *lane_mut!(self, agree, keeps) = agree;
                *lane_mut!(self, cells, starts) = fresh;
                *lane_mut!(self, depth, starts) = at.steps as u16 + 1;
                *lane_mut!(self, agree, starts) = 0;
                // The representative went with the cell; the half that starts afresh stands
                // for a new one, named by the new vertex.
                let kept = *lane!(self, representative, v);
                *lane_mut!(self, representative, keeps) = kept;
                *lane_mut!(self, representative, starts) = r as u32;
            }
        }
        *lane_mut!(self, next_split, v) = NO_SPLIT;
        *lane_mut!(self, next_split, r) = NO_SPLIT;
        *lane_mut!(self, adjacency, r) = Neighbours::new();
        self.edges += split_edges(
            &mut LaneLists {
                lanes: self.lanes,
                slab: self.slab,
                first_id: self.first_id,
                next_id: self.next_id,
            },
            v,
            r,
            connecting,
            &codes,
        );
        check_edge_count(self.edges, self.max_triangles).map_err(Stop::Fault)?;
        self.refresh(v);
        self.refresh(r);
        self.codes = codes;
        *lane_mut!(self, leaf, r) = false;
        for (half, vertex) in [(0, v), (1, r)] {
            let valence = self.adjacency(vertex).len();
            // The upper half's question knows the lower half's answer.
            let kind = if half == 0 {
                0
            } else {
                1 + self.leaf(v) as usize
            };
            let c = contexts::leaf(kind, valence, remaining);
            *lane_mut!(self, leaf, vertex) = side.code(
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

/// A cell that a vertex's deeper cell lies in: its prefix after `steps` steps, twice its
/// centre and its half-widths' shifts.
#[derive(Clone, Copy, Debug)]
pub(super) struct CellAt {
    pub(super) cell: [u32; 3],
    pub(super) centre: [i32; 3],
    pub(super) shifts: [u8; 3],
    pub(super) steps: usize,
}

/// The neighbour lists of [`Lanes`], for [`split_edges`], checked as the [`Run`] that makes
/// them would check them.
pub(super) struct LaneLists<'a> {
    lanes: &'a Lanes,
    slab: Option<(&'a [u8], u8)>,
    first_id: usize,
    next_id: usize,
}

impl LaneLists<'_> {
    fn check(&self, v: usize) {
        check(self.lanes, v, || {
            owns(self.slab, self.first_id, self.next_id, v)
        });
    }
}

// A lane's list, through `lane_mut!`.

#[allow(unsafe_code)]
impl NeighbourLists for LaneLists<'_> {
    fn list(&mut self, v: usize) -> &mut Neighbours {
        lane_mut!(self, adjacency, v)
    }
}
