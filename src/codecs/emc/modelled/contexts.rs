//! The adaptive contexts of the modelled coder and how each question picks one. Measurements
//! behind the choices are in the module docs of [`super`].

use crate::coding::arith::{BitContext, UintContext};

/// First index of `x` in ascending `thresholds` that `x` is below; `thresholds.len()` if none.
/// (Counted without branches: the comparisons are as good as random to a branch predictor.)
#[inline]
fn bin(x: f64, thresholds: &[f64]) -> usize {
    thresholds.iter().map(|&t| (x >= t) as usize).sum()
}

/// Levels still to come after the current one, capped.
const REMAINING: usize = 8;
/// Valences told apart.
const VALENCES: usize = 16;

/// Distance of the neighbours' mean from the split plane, in half-widths of the cell.
const HALF_OFFSET: [f64; 10] = [
    1.0 / 32.0,
    1.0 / 16.0,
    1.0 / 8.0,
    0.1875,
    0.25,
    0.375,
    0.5,
    0.75,
    1.0,
    2.0,
];
/// Expected squared error of the prediction, in squared half-widths: standard deviations of
/// 1/8, 1/4, 1/2, 1, 2, 4 and 8 half-widths.
const HALF_SPREAD: [f64; 7] = [
    0.125 * 0.125,
    0.25 * 0.25,
    0.5 * 0.5,
    1.0,
    2.0 * 2.0,
    4.0 * 4.0,
    8.0 * 8.0,
];
const HALF_KINDS: usize = 4;
/// Levels ahead of the octree told apart by the lookahead's contexts.
pub const AHEAD_DISTANCES: usize = 4;
pub const HALF_CONTEXTS: usize = HALF_KINDS * (HALF_OFFSET.len() + 1) * (HALF_SPREAD.len() + 1) + 2;

/// Distance of a neighbour from the split plane, in half-widths of the splitting cell (the two
/// halves' centres are at ±0.5).
const EDGE_ALONG: [f64; 8] = [0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0, 5.0];
/// Its largest distance across the axis, over its distance along it.
const EDGE_ACROSS: [f64; 4] = [0.5, 1.0, 2.0, 4.0];
/// Number of neighbour places an edge can be in.
pub const EDGE_PLACES: usize = 2 * (EDGE_ALONG.len() + 1) * (EDGE_ACROSS.len() + 1);

/// Every context of the coder, in their initial state.
#[derive(Clone)]
pub struct Contexts {
    pub split: [BitContext; (OFFSETS + 1) * VALENCES * REMAINING],
    pub half: [BitContext; HALF_CONTEXTS],
    /// A cluster's "which half" coded ahead of its splits (its representative's path).
    pub ahead: [BitContext; HALF_CONTEXTS * AHEAD_DISTANCES],
    /// Does a cluster split at a step its representative's path took ahead, as predicted.
    pub split_ahead: [BitContext; (OFFSETS + 1) * VALENCES * REMAINING],
    pub connecting: [BitContext; VALENCES * REMAINING],
    pub duplicate: [BitContext; EDGE_PLACES * 8 * 3],
    pub moves: [BitContext; EDGE_PLACES * 8],
    pub leaf: [BitContext; 3 * VALENCES * REMAINING],
    /// Lengths and gaps of the three face-correction lists.
    pub corrections: [UintContext; 3],
}

impl Default for Contexts {
    fn default() -> Self {
        Contexts {
            split: [BitContext::default(); (OFFSETS + 1) * VALENCES * REMAINING],
            half: [BitContext::default(); HALF_CONTEXTS],
            ahead: [BitContext::default(); HALF_CONTEXTS * AHEAD_DISTANCES],
            split_ahead: [BitContext::default(); (OFFSETS + 1) * VALENCES * REMAINING],
            connecting: [BitContext::default(); VALENCES * REMAINING],
            duplicate: [BitContext::default(); EDGE_PLACES * 8 * 3],
            moves: [BitContext::default(); EDGE_PLACES * 8],
            leaf: [BitContext::default(); 3 * VALENCES * REMAINING],
            corrections: Default::default(),
        }
    }
}

impl Contexts {
    /// Hands on what the slabs of a sliced pass learnt: each of `self`'s binary contexts becomes
    /// its slab copies merged ([`BitContext::merged`]). The face-correction contexts are not
    /// used by passes.
    pub fn merge(&mut self, slabs: &[Box<Contexts>]) {
        fn each<const N: usize>(
            base: &mut [BitContext; N],
            slabs: &[Box<Contexts>],
            field: impl Fn(&Contexts) -> &[BitContext; N],
        ) {
            for (i, context) in base.iter_mut().enumerate() {
                *context = context.merged(slabs.iter().map(|slab| &field(slab)[i]));
            }
        }
        each(&mut self.split, slabs, |c| &c.split);
        each(&mut self.half, slabs, |c| &c.half);
        each(&mut self.ahead, slabs, |c| &c.ahead);
        each(&mut self.split_ahead, slabs, |c| &c.split_ahead);
        each(&mut self.connecting, slabs, |c| &c.connecting);
        each(&mut self.duplicate, slabs, |c| &c.duplicate);
        each(&mut self.moves, slabs, |c| &c.moves);
        each(&mut self.leaf, slabs, |c| &c.leaf);
    }
}

/// Does a cluster split now: by how close its neighbours' predicted place is to the split plane
/// (a cluster straddles the plane where its surface crosses it), its valence (a bigger cluster
/// has more neighbours) and the levels left.
pub fn split(offset: usize, valence: usize, remaining: usize) -> usize {
    ((offset * VALENCES) + valence.min(VALENCES - 1)) * REMAINING + remaining.min(REMAINING - 1)
}

/// The context of a "which half" question and the bins it is made of.
#[derive(Clone, Copy, Debug)]
pub struct HalfContext {
    /// Index into [`Contexts::half`].
    pub index: usize,
    /// Bin of the prediction's distance from the split plane (`OFFSETS` without neighbours).
    pub offset: usize,
}

/// Offset bins, and one for "no neighbours".
pub const OFFSETS: usize = HALF_OFFSET.len() + 1;

/// Which half, for a vertex with no neighbours.
pub fn half_isolated(leaf: bool) -> HalfContext {
    HalfContext {
        index: HALF_CONTEXTS - 2 + leaf as usize,
        offset: OFFSETS,
    }
}

/// Which half: by the neighbours' mean offset and variance (both relative to the half-width,
/// the variance to its square).
#[inline]
pub fn half(leaf: bool, valence: usize, offset: f64, variance: f64) -> HalfContext {
    half_in(half_kind(leaf, valence), offset, variance)
}

/// The vertex kind of a "which half" question: cluster, or leaf of valence ≤ 4, 5–6, ≥ 7.
#[inline]
pub fn half_kind(leaf: bool, valence: usize) -> usize {
    if leaf {
        1 + (valence >= 5) as usize + (valence >= 7) as usize
    } else {
        0
    }
}

/// [`half`] for a vertex of kind `kind` ([`half_kind`]).
#[inline]
pub fn half_in(kind: usize, offset: f64, variance: f64) -> HalfContext {
    let o = bin(offset, &HALF_OFFSET);
    let s = bin(variance, &HALF_SPREAD);
    HalfContext {
        index: ((kind * OFFSETS) + o) * (HALF_SPREAD.len() + 1) + s,
        offset: o,
    }
}

/// Is there an edge between the two halves.
pub fn connecting(valence: usize, remaining: usize) -> usize {
    valence.min(VALENCES - 1) * REMAINING + remaining.min(REMAINING - 1)
}

/// Where a neighbour lies relative to the split: `along` and `across` the axis in half-widths,
/// and whether it is a single vertex.
pub fn edge_place(along: f64, across: f64, leaf: bool) -> usize {
    let a = bin(along, &EDGE_ALONG);
    // The bin of across / along, without dividing (along 0: the last bin).
    let c: usize = EDGE_ACROSS
        .iter()
        .map(|&t| (across >= t * along) as usize)
        .sum();
    ((a * (EDGE_ACROSS.len() + 1)) + c) * 2 + leaf as usize
}

/// Is the edge duplicated: by the neighbour's place and the duplicates so far in this split.
pub fn duplicate(place: usize, ring: usize, duplicates_so_far: usize) -> usize {
    (place * 8 + ring) * 3 + duplicates_so_far.min(2)
}

/// Does a (not duplicated) edge move to the upper half: by the neighbour's place and what its
/// coded ring neighbours did, seen from the neighbour's side of the plane (`flip`: below it).
pub fn moves(place: usize, ring: usize, flip: bool) -> usize {
    let ring = if flip {
        // Swap "stayed" and "moved" so that both read as "went to my side" / "the other".
        (ring & 4) | ((ring & 1) << 1) | ((ring & 2) >> 1)
    } else {
        ring
    };
    place * 8 + ring
}

/// Is a half a single vertex: by which half (and for the upper, the lower's answer), its valence after the split and the levels left.
pub fn leaf(kind: usize, valence: usize, remaining: usize) -> usize {
    ((kind * VALENCES) + valence.min(VALENCES - 1)) * REMAINING + remaining.min(REMAINING - 1)
}
