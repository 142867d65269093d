//! The passes of the modelled coder, written once for both sides: a [`Side`] answers each binary
//! question (the encoder from the mesh, the decoder from the stream) and the [`Walker`] applies
//! the answers to the shared state, choosing every question's context from what the decoder
//! already knows.

use super::contexts::{self, Contexts};
use crate::codecs::emc::state::{EdgeCode, EmcState, NO_SPLIT};
use crate::hierarchy::octree::StepOrder;

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
pub trait Side {
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

    /// Called when `v` is about to split at `step`, before its connectivity is coded.
    fn begin_split(&mut self, _state: &EmcState, _v: usize, _step: usize) {}

    /// Called after `v` split into `v` (lower half) and `r` (upper half).
    fn end_split(&mut self, _v: usize, _r: usize) {}
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

/// Count, mean and covariance of a vertex's neighbours (see [`Walker::moments`]).
pub(super) struct Moments {
    k: usize,
    pub(super) mean: [f64; 3],
    pub(super) cov: [[f64; 3]; 3],
}

/// The state both sides keep, with the modelled coder's extra knowledge of each vertex.
pub struct Walker {
    /// Cells, depths and edges (shared with the paper's coder).
    pub state: EmcState,
    /// Known to be a single mesh vertex (no further split).
    pub leaf: Vec<bool>,
    pub contexts: Box<Contexts>,
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
    marks: Vec<u64>,
    /// Serial of the current split.
    split_serial: u64,
}

impl Walker {
    pub fn new(order: StepOrder, vertices: u64) -> Walker {
        let shifts = (0..=order.steps())
            .map(|d| order.bits_per_axis(d).map(|b| order.levels - b))
            .collect();
        let mut walker = Walker {
            state: EmcState::new(order, vertices),
            leaf: vec![vertices <= 1],
            contexts: Box::default(),
            shifts,
            centres: Vec::new(),
            codes: Vec::new(),
            active: Vec::new(),
            resting: Vec::new(),
            marks: Vec::new(),
            split_serial: 0,
        };
        walker.refresh(0);
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

    /// Recomputes the cached centre of `v` from its cell.
    fn refresh(&mut self, v: usize) {
        let shifts = self.shifts[self.state.depth[v] as usize];
        // At most 2^25 (24 levels), so i32 holds it; the neighbours' offsets too.
        let centre = [0, 1, 2].map(|a| (((self.state.cells[v][a] as i32) << 1) | 1) << shifts[a]);
        if v == self.centres.len() {
            self.centres.push(centre);
        } else {
            self.centres[v] = centre;
        }
    }

    /// Twice `v`'s cell centre in units of the full grid, and the shifts of its half-widths:
    /// half the width of its cell along axis `a` is 2^`shifts[a]` in those units.
    pub(super) fn cell_of(&self, v: usize) -> ([i32; 3], [u8; 3]) {
        (self.centres[v], self.shifts[self.state.depth[v] as usize])
    }

    /// Half the width of `v`'s cell along `axis` is 2^this, in the units of the centres.
    #[inline]
    fn half_width_shift(&self, v: usize, axis: usize) -> u8 {
        self.shifts[self.state.depth[v] as usize][axis]
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
            self.pass(side, step, max_vertices, max_triangles)?;
        }
        if passes >= 3 {
            self.leaf_pass(side, first)?;
        }
        Ok(())
    }

    /// One pass (`step`) over the active vertices present at its start.
    fn pass<S: Side>(
        &mut self,
        side: &mut S,
        step: usize,
        max_vertices: u64,
        max_triangles: u64,
    ) -> Result<(), Stop> {
        let order = self.state.order;
        let axis = order.axis(step);
        let remaining = order.levels as usize - order.level(step);
        let present = self.active.len();
        for i in 0..present {
            let v = self.active[i] as usize;
            let valence = self.state.adjacency[v].len();
            let (half, flip) = self.half_context(v, axis);
            let splits = !self.leaf[v] && {
                let c = contexts::split(half.offset, valence, remaining);
                side.code(&mut self.contexts.split[c], Question::Split, false, v, step)?
            };
            if !splits {
                let c = half.index;
                let bit = side.code(&mut self.contexts.half[c], Question::Half, flip, v, step)?;
                self.state.refine(v, step, bit as u32);
                self.refresh(v);
                continue;
            }
            if self.state.len() as u64 >= max_vertices {
                return Err(Stop::Fault(format!(
                    "more splits than the {max_vertices} vertices the header declares"
                )));
            }
            let r = self.split(side, v, step, axis, remaining, max_triangles)?;
            self.active.push(r as u32);
        }
        Ok(())
    }

    /// The three refinement bits of a level (steps `first`..`first + 3`) of every vertex that
    /// was a leaf at the level's start, vertex by vertex: the neighbours' moments are taken once,
    /// and all three contexts come from them and the vertex's cell at the level's start, before
    /// any of the three bits, so that the bits go through the coder as one symbol.
    fn leaf_pass<S: Side>(&mut self, side: &mut S, first: usize) -> Result<(), Stop> {
        let axes = [0, 1, 2].map(|k| self.state.order.axis(first + k));
        for i in 0..self.resting.len() {
            let v = self.resting[i] as usize;
            let (mut index, mut flips) = ([0; 3], [false; 3]);
            match self.moments(v) {
                None => index = [contexts::half_isolated(true).index; 3],
                Some(m) => {
                    let shifts = self.shifts[self.state.depth[v] as usize];
                    let (by_axis, below) = leaf_contexts(&m, shifts);
                    for k in 0..3 {
                        (index[k], flips[k]) = (by_axis[axes[k]], below[axes[k]]);
                    }
                }
            }
            let bits = side.code3(&mut self.contexts.half, index, flips, v, first)?;
            for (k, bit) in bits.into_iter().enumerate() {
                self.state.refine(v, first + k, bit as u32);
            }
            self.refresh(v);
        }
        Ok(())
    }

    /// Reads `v`'s neighbours' lists and centres (a sum for [`std::hint::black_box`] to keep).
    fn touch(&self, v: usize) -> usize {
        self.state.adjacency[v]
            .iter()
            .map(|&n| self.state.adjacency[n as usize].len() + self.centres[n as usize][0] as usize)
            .sum()
    }

    /// Count, mean and covariance of `v`'s neighbours' cell centres, relative to `v`'s centre;
    /// `None` without neighbours.
    pub(super) fn moments(&self, v: usize) -> Option<Moments> {
        let origin = self.centres[v];
        let neighbours = &self.state.adjacency[v];
        if neighbours.is_empty() {
            return None;
        }
        // Sums of the offsets and their products: x, y, z, xx, yy, zz, xy, xz, yz.
        let mut s = [0f64; 9];
        for &n in neighbours {
            let c = self.centres[n as usize];
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

    /// Context and flip of the half `v` takes along `axis`, from its neighbours' moments `m`
    /// (relative to `v`'s centre); see [`estimate`].
    #[inline]
    fn predict(&self, v: usize, axis: usize, m: &Moments) -> (contexts::HalfContext, bool) {
        let shifts = self.shifts[self.state.depth[v] as usize];
        let (prediction, variance) = estimate(m, axis, shifts);
        let scale = per_half_width(shifts[axis]);
        (
            contexts::half(
                self.leaf[v],
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
            None => (contexts::half_isolated(self.leaf[v]), false),
            Some(m) => self.predict(v, axis, &m),
        }
    }

    /// What the already coded neighbours of the splitting vertex that are also neighbours of
    /// `n` did: bit 0 some stayed, bit 1 some moved, bit 2 some were duplicated (read from the
    /// marks of the current split). Around a manifold vertex the duplicated edges are where the
    /// stayed arc meets the moved one.
    fn coded_ring(&self, n: usize) -> usize {
        let mut seen = 0;
        for &m in &self.state.adjacency[n] {
            let mark = self.marks[m as usize];
            seen |= if mark >> 3 == self.split_serial {
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
        max_triangles: u64,
    ) -> Result<usize, Stop> {
        side.begin_split(&self.state, v, step);
        let valence = self.state.adjacency[v].len();
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
        let centre = self.centres[v];
        let scale = per_half_width(self.half_width_shift(v, axis));
        let mut codes = std::mem::take(&mut self.codes);
        codes.clear();
        // Marks left by earlier splits are told apart by their serial.
        self.split_serial += 1;
        if self.marks.len() < self.state.len() {
            self.marks.resize(self.state.len() + 1, 0);
        }
        let mut duplicates = 0;
        for i in 0..valence {
            let n = self.state.adjacency[v][i] as usize;
            let offset = self.centres[n].map(|x| x as i64);
            let along = (offset[axis] - centre[axis] as i64) as f64 * scale;
            let (b, c) = ((axis + 1) % 3, (axis + 2) % 3);
            let across = (offset[b] - centre[b] as i64)
                .abs()
                .max((offset[c] - centre[c] as i64).abs()) as f64
                * scale;
            let place = contexts::edge_place(along.abs(), across, self.leaf[n]);
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
            self.marks[n] = self.split_serial << 3
                | match code {
                    EdgeCode::Stay => 1,
                    EdgeCode::Move => 2,
                    EdgeCode::Duplicate => 4,
                };
        }
        let r = self
            .state
            .split(v, step, connecting, &codes, [NO_SPLIT, NO_SPLIT]);
        self.state.check_edges(max_triangles).map_err(Stop::Fault)?;
        self.refresh(v);
        self.refresh(r);
        self.codes = codes;
        self.leaf.push(false);
        for (half, vertex) in [(0, v), (1, r)] {
            let valence = self.state.adjacency[vertex].len();
            // The upper half's question knows the lower half's answer.
            let kind = if half == 0 {
                0
            } else {
                1 + self.leaf[v] as usize
            };
            let c = contexts::leaf(kind, valence, remaining);
            self.leaf[vertex] = side.code(
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
