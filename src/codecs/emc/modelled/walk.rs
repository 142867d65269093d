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

    /// Called when `v` is about to split at `step`, before its connectivity is coded.
    fn begin_split(&mut self, _state: &EmcState, _v: usize, _step: usize) {}

    /// Called after `v` split into `v` (lower half) and `r` (upper half).
    fn end_split(&mut self, _v: usize, _r: usize) {}
}

/// Steepest regression plane used for prediction (squared gradient).
const SLOPE: f64 = 1.5;

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
    centres: Vec<[i64; 3]>,
    codes: Vec<EdgeCode>,
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
        };
        walker.refresh(0);
        walker
    }

    /// Twice the centre of `v`'s cell along `axis`, in units of the full grid.
    #[inline]
    fn centre2(&self, v: usize, axis: usize) -> i64 {
        self.centres[v][axis]
    }

    /// Recomputes the cached centre of `v` from its cell.
    fn refresh(&mut self, v: usize) {
        let shifts = self.shifts[self.state.depth[v] as usize];
        let centre = [0, 1, 2].map(|a| (((self.state.cells[v][a] as i64) << 1) | 1) << shifts[a]);
        if v == self.centres.len() {
            self.centres.push(centre);
        } else {
            self.centres[v] = centre;
        }
    }

    /// Half the width of `v`'s cell along `axis`, in the units of [`Self::centre2`].
    #[inline]
    fn half_width2(&self, v: usize, axis: usize) -> i64 {
        1 << self.shifts[self.state.depth[v] as usize][axis]
    }

    /// Runs one pass (`step`) over the vertices present at its start. `max_vertices` and
    /// `max_triangles` are the header's counts, which no stream may exceed.
    pub fn pass<S: Side>(
        &mut self,
        side: &mut S,
        step: usize,
        max_vertices: u64,
        max_triangles: u64,
    ) -> Result<(), Stop> {
        let order = self.state.order;
        let axis = order.axis(step);
        let remaining = order.levels as usize - order.level(step);
        let present = self.state.len();
        for v in 0..present {
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
            self.split(side, v, step, axis, remaining, max_triangles)?;
        }
        Ok(())
    }

    /// Context and flip of the half `v` takes. The prediction is the neighbours' regression
    /// plane (the coordinate along the axis as a linear function of the other two, evaluated at
    /// the vertex's own cell centre) where the neighbours span the other two axes, else their
    /// mean; the context is its distance from the split plane and the expected error (the
    /// neighbours' residual spread plus what the vertex's own cell leaves open), both in
    /// half-widths of the cell.
    fn half_context(&self, v: usize, axis: usize) -> (contexts::HalfContext, bool) {
        let neighbours = &self.state.adjacency[v];
        if neighbours.is_empty() {
            return (contexts::half_isolated(self.leaf[v]), false);
        }
        let (b, c) = ((axis + 1) % 3, (axis + 2) % 3);
        let own = [
            self.centre2(v, axis),
            self.centre2(v, b),
            self.centre2(v, c),
        ];
        // Sums of the neighbours' offsets from the vertex's centre: a, b, c and their products.
        let mut s = [0f64; 9];
        for &n in neighbours {
            let n = n as usize;
            let da = (self.centre2(n, axis) - own[0]) as f64;
            let db = (self.centre2(n, b) - own[1]) as f64;
            let dc = (self.centre2(n, c) - own[2]) as f64;
            s[0] += da;
            s[1] += db;
            s[2] += dc;
            s[3] += da * da;
            s[4] += db * db;
            s[5] += dc * dc;
            s[6] += db * dc;
            s[7] += da * db;
            s[8] += da * dc;
        }
        let k = neighbours.len() as f64;
        let mean = [s[0] / k, s[1] / k, s[2] / k];
        let var_a = (s[3] / k - mean[0] * mean[0]).max(0.0);
        let (cbb, ccc) = (s[4] / k - mean[1] * mean[1], s[5] / k - mean[2] * mean[2]);
        let cbc = s[6] / k - mean[1] * mean[2];
        let (cab, cac) = (s[7] / k - mean[0] * mean[1], s[8] / k - mean[0] * mean[2]);
        let det = cbb * ccc - cbc * cbc;
        let w = self.half_width2(v, axis) as f64;
        let plane = (neighbours.len() >= 4 && det > 1e-2 * (cbb + ccc) * (cbb + ccc))
            .then(|| ((cab * ccc - cac * cbc) / det, (cac * cbb - cab * cbc) / det));
        let (prediction, variance) = if let Some((beta_b, beta_c)) =
            plane.filter(|&(beta_b, beta_c)| beta_b * beta_b + beta_c * beta_c <= SLOPE)
        {
            let residual = (var_a - beta_b * cab - beta_c * cac).max(0.0);
            // The vertex's own place across the axis: the neighbours' mean, kept inside its cell.
            let (wb, wc) = (self.half_width2(v, b) as f64, self.half_width2(v, c) as f64);
            let (eb, ec) = (mean[1].clamp(-wb, wb), mean[2].clamp(-wc, wc));
            let own_cell = beta_b * beta_b * (wb * wb / 3.0).min(cbb)
                + beta_c * beta_c * (wc * wc / 3.0).min(ccc);
            (
                mean[0] + beta_b * (eb - mean[1]) + beta_c * (ec - mean[2]),
                residual + own_cell,
            )
        } else {
            (mean[0], var_a)
        };
        (
            contexts::half(
                self.leaf[v],
                neighbours.len(),
                prediction.abs() / w,
                variance / (w * w),
            ),
            prediction < 0.0,
        )
    }

    /// What the already coded neighbours of `v` that are also neighbours of `n` (the `i`-th
    /// neighbour) did: bit 0 some stayed, bit 1 some moved, bit 2 some were duplicated. Around a
    /// manifold vertex the duplicated edges are where the stayed arc meets the moved one.
    fn coded_ring(&self, v: usize, i: usize, n: usize, codes: &[EdgeCode]) -> usize {
        let coded = &self.state.adjacency[v][..i];
        let around = &self.state.adjacency[n];
        let (mut x, mut y, mut seen) = (0, 0, 0);
        while x < coded.len() && y < around.len() {
            match coded[x].cmp(&around[y]) {
                std::cmp::Ordering::Less => x += 1,
                std::cmp::Ordering::Greater => y += 1,
                std::cmp::Ordering::Equal => {
                    seen |= match codes[x] {
                        EdgeCode::Stay => 1,
                        EdgeCode::Move => 2,
                        EdgeCode::Duplicate => 4,
                    };
                    x += 1;
                    y += 1;
                }
            }
        }
        seen
    }

    fn split<S: Side>(
        &mut self,
        side: &mut S,
        v: usize,
        step: usize,
        axis: usize,
        remaining: usize,
        max_triangles: u64,
    ) -> Result<(), Stop> {
        side.begin_split(&self.state, v, step);
        let valence = self.state.adjacency[v].len();
        let c = contexts::connecting(valence, remaining);
        let connecting = side.code(
            &mut self.contexts.connecting[c],
            Question::Connecting,
            false,
            v,
            step,
        )?;
        let mid = self.centre2(v, axis);
        let w = self.half_width2(v, axis) as f64;
        let centre = [0, 1, 2].map(|a| self.centre2(v, a));
        let mut codes = std::mem::take(&mut self.codes);
        codes.clear();
        let mut duplicates = 0;
        for i in 0..valence {
            let n = self.state.adjacency[v][i] as usize;
            let along = (self.centre2(n, axis) - mid) as f64 / w;
            let mut across = 0f64;
            for a in (0..3).filter(|&a| a != axis) {
                across = across.max((self.centre2(n, a) - centre[a]).abs() as f64 / w);
            }
            let place = contexts::edge_place(along.abs(), across, self.leaf[n]);
            let ring = self.coded_ring(v, i, n, &codes);
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
        Ok(())
    }
}
