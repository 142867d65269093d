//! `emc`: Embedded Mesh Coding with context-modelled arithmetic coding.
//!
//! The octree, its splits and the STAY / MOVE / DUPLICATE edge updates are the paper's (see
//! [`super`]); what changes is how each decision is coded. Every decision is one binary question
//! (see [`walk::Question`]) with an adaptive context chosen from what the decoder already knows,
//! coded by constriction's range coder (a leaf's three "which half" questions of a level go
//! through it as one symbol); each level is flushed on its own, so every prefix of
//! whole levels decodes.
//!
//! # Syntax, per level
//! A vertex known to be a single mesh vertex (a *leaf*) never splits again and its edges change
//! only when a neighbour splits; the others are *clusters*. A level is three passes over the
//! vertices that were clusters at its start, then one pass over those that were leaves.
//!
//! Each of the three passes (one per axis), for each cluster present at the start of the pass
//! (and each vertex split off one earlier in the level), in list order:
//! 1. unless it is a leaf by now: does it split now?
//! 2. if not: which half it takes;
//! 3. if it splits: is there a connecting edge; for each neighbour (ascending ids) is the edge
//!    duplicated, and if not, does it move to the upper half; then, for each half, is it a leaf.
//!
//! Then, for each vertex that was a leaf at the level's start, in list order: which half it takes
//! on each of the three axes, coded as one symbol of three bits
//! ([`crate::coding::arith::ArithEncoder::bits3`]) under three "which half" contexts taken from
//! one look at its neighbours. At the finest levels nearly every vertex is a leaf: the passes
//! visit the few clusters left, and each leaf costs one neighbourhood and one range-coder step a
//! level instead of three. A stream cut after one or two passes of a level (`Stop::Passes`)
//! shows the clusters refined by those passes and the leaves as the level before left them.
//!
//! The first level at whose end every vertex is decoded (often several levels before the last:
//! bunny.ply at 12 bits has all its vertices after level 9) ends with the paper coder's three
//! face-correction lists (false triangles, faces in both orientations, orientation
//! exceptions), lengths and gaps in adaptive Exp-Golomb. No split follows, so the edge graph is
//! final, and the levels after it show the mesh's own faces rather than every 3-clique: the
//! paper sends the lists after the last level, where the false triangles of the levels before
//! made bunny's Hausdorff error rise from level 10 to 11. Streams whose corrections byte is 0
//! (as `emc` wrote before this) still decode, with the lists after the last level.
//!
//! An intermediate level shows each vertex where the walker's estimate expects it inside its
//! cell, not at the cell's centre (`placement`; no bits).
//!
//! # `emc-ahead`: positions before vertices
//! An `emc` level shows every cluster of its octree depth inside its cell, so that by level 7 of
//! bunny.ply (4.96 bits a vertex) 30,172 vertices stand in cells 1/128 of the box wide, where `pm`
//! at the same bits shows 2,900 vertices at full precision, 2.5× closer to the surface. King and
//! Rossignac (1999) trade precision against vertex count; `emc-ahead` (docs/FORMAT.md §7.1) does
//! it inside the octree: after each level a **lookahead pass** takes every vertex's cell two
//! levels further. A leaf's bits are its own, coded early. A cluster's cell follows one of its
//! mesh vertices, its **representative**: where its vertices part, the predicted half, so the
//! decoder knows which half that was without being told, and the split waiting at that step is
//! coded later, in its own level's pass, only where the step took the predicted half. Every bit
//! of the octree is coded once; what the lookahead adds are the representative's steps at
//! splits (about a quarter bit each on bunny.ply) and the bits coded before their neighbours are
//! refined (the larger cost: a bit coded a level early sees neighbours a level coarser).
//!
//! On bunny.ply at 12 bits, a lookahead of 1, 2 and 3 levels costs the lossless stream 2.7%,
//! 7.3% and 11.5%, and the worst level's RMS over `pm`'s at the same bits (levels 4–9) falls from
//! `emc`'s 2.52 to 1.87, 1.64 and 1.69 (BENCHMARKS.md, "`emc-ahead`"). The largest error of a
//! level does not fall: it comes from the level's faces cutting across the surface, which more
//! precise corners do not change, so at the same bits `emc-ahead`'s Hausdorff error is above
//! `emc`'s. `emc` stays the smaller lossless stream and the better largest error; `emc-ahead`
//! is for streams read in part whose average error matters.
//!
//! # Slabs: the passes of large meshes on several cores
//! Every question's context reads the vertex's neighbours as the passes left them, so a pass is
//! one chain of decisions. A mesh of 65,536 vertices or more is coded with **slabs**
//! (docs/FORMAT.md §7, "Slabs"): each pass of 2^13 visits or more is cut along the longest axis
//! into four slabs of about equal visits; each slab first codes its visits whose neighbours
//! all lie in it, in a stream of its own and with its own copy of the contexts (merged after
//! the pass), and the visits on the slabs' boundaries (about 3%) follow in the level's stream.
//! A slab never reads or writes another slab's vertices, so the decoder codes them on threads
//! at once (`walk::lanes::Lanes` says why that is sound); on one thread it codes them one after
//! another, to the same mesh. The encoder codes them at once too, each slab planning its splits
//! on its own clusters (`clusters::ClusterLanes`), to the same bytes as on one thread.
//!
//! What they cost and buy, on bunny-closed-35k ×16 at 12 bits (BENCHMARKS.md): 0.86% more bytes
//! (the slabs learn apart within a pass and each stream is flushed; 2 slabs cost 0.52%, 8 cost
//! 1.61%, 16 cost 2.80%), and on this machine's two cores decoding takes 0.60–0.70 of the time
//! on one, encoding about 0.67. Meshes under 65,536 vertices have no slabs: their streams are as before.
//!
//! # Contexts
//! - *Which half*: a smooth surface puts a vertex near its ring's plane and near the ring's
//!   centroid. Where the neighbours span the two other axes and their regression plane (the
//!   coordinate along the split axis as a linear function of the other two) is no steeper than
//!   a squared gradient of 1.5, the prediction is that plane evaluated at the vertex's own place
//!   across the axis (the neighbours' mean clamped into its cell); otherwise the neighbours'
//!   mean. The bit is coded as "agrees with the prediction's side" under a context made of the
//!   prediction's distance from the split plane (10 bins) and its expected error (the
//!   neighbours' residual spread plus what the vertex's own cell leaves open; 8 bins), both in
//!   half-widths of the cell, and a vertex kind (cluster; leaf of valence ≤ 4, 5–6, ≥ 7: few
//!   neighbours, as on a boundary, predict worse).
//! - *Split* (clusters only; leaves never ask): the prediction's distance from the split plane
//!   (a cluster straddles the plane where its surface crosses it), the valence (a bigger
//!   cluster has more neighbours) and the levels left.
//! - *Leaf*: which half — the upper half's question knows the lower half's answer — its
//!   valence after the split and the levels left.
//! - *Duplicate* and *moves*: where the neighbour lies relative to the split — its distance
//!   along the axis (the halves' centres lie at ±½ half-width), the ratio of its distance across
//!   to along — whether it is a leaf, and what the already coded neighbours that share an edge
//!   with it did (some stayed / moved / were duplicated: around a manifold vertex the duplicated
//!   edges are where the stayed arc meets the moved one). *Duplicate* also counts the duplicates
//!   coded so far in this split (a manifold vertex split duplicates two); *moves* is coded as
//!   "goes to the half on its side", its ring seen from that side.
//! - *Connecting*: valence and levels left.
//! - Every context mixes a fast and a slow adaptive estimate and warms up by counting
//!   ([`crate::coding::arith::BitContext`]).
//!
//! # What each context saves
//! Measured on bunny.ply at 12 bits, cubic grid (`cargo run --release --example emc_fields`),
//! each row adding to the one before; total bits per vertex (connectivity / geometry):
//!
//! | step | bunny.ply |
//! |---|---:|
//! | the paper's syntax (`emc-paper`) at 12 bits | 32.65 |
//! | arithmetic coding, half by the neighbours' mean and spread, split by age and valence, duplicate / moves by the neighbour's place, leaf by valence | 17.62 (4.52 / 13.08) |
//! | contexts warm up by counting | 17.44 |
//! | regression-plane prediction (gradient² ≤ 1.5; 0.5: 17.32, 3.0: 17.85 … measured with mean prediction elsewhere) | 17.24 |
//! | duplicate by what the coded ring neighbours did | 16.55 (3.75 conn.) |
//! | moves by the same, seen from the neighbour's side | 16.10 (3.30 conn.) |
//! | the upper half's leaf question knows the lower's answer | 16.05 |
//! | split by the prediction's distance from the plane instead of the cluster's age | 15.86 |
//! | finer distance bins for the half question | 15.82 |
//! | fast + slow estimates mixed (rates 1/16 and 1/128; 1/16 + 1/64: 15.77 but worse geometry, 1/32 + 1/256: 15.92) | 15.78 |
//! | half by vertex kind (cluster, leaf by valence) | 15.60 (3.27 / 12.31) |
//! | leaves take a level's three bits in a pass of their own, after the clusters' passes (the clusters see their leaf neighbours one level coarser, the leaves see every cluster refined) | 15.73 (3.34 / 12.37) |
//! | a leaf's three contexts from one look at its neighbours, before any of its three bits (its own place across each axis as at the level's start), the bits coded as one symbol | **15.74 (3.34 / 12.38)** |
//!
//! The last two rows cost 0.14 bits a vertex and bought decoding speed: a leaf's neighbours are
//! read once a level instead of three times (bunny.ply at 12 bits: 71 → 50 ms with the other
//! changes of the same commit; see BENCHMARKS.md). Its three bits take one range-coder step,
//! which is only a little faster than three: `cargo bench --bench arith` measures 14.7 ns for a
//! three-bit symbol, 5.8 ns for one bit. Reusing a leaf's neighbour moments from an earlier
//! level instead of reading the neighbours every level was measured too and dropped: every
//! other level 16.22, once only 17.20 (the neighbours' last level of precision matters).
//!
//! Tried and not kept: the neighbours' reach (their distance in cell widths) for split and leaf
//! (+0.02), the cluster's age beside the distance for split (+0.00), a single adaptation rate
//! of 1/64 (+0.06). armadillo-43k.obj ends at 15.98 (4.58 / 11.38).
//!
//! The finest levels stay expensive: at 12 bits the last three levels cost 2.2–2.7 bits a
//! vertex each (nearly a bit per step), because the prediction's error (a few grid units on
//! bunny.ply, whose edges are about 36 units long) is larger than the cells there.
mod contexts;
mod decoder;
mod encoder;
mod placement;
pub mod walk;

use super::{EmcParams, Syntax};
use crate::codecs::descriptor::cubic;
use crate::codecs::Descriptor;
use crate::codecs::{names, Capability, Codec, Encoded, LevelDecoder, Stats};
use crate::container::StreamReader;
use crate::error::Result;
use crate::mesh::CanonicalMesh;

/// The `emc` codec, and `emc-ahead` beside it.
pub struct Emc {
    /// Levels each level's lookahead pass takes every vertex's cell ahead of the octree's
    /// splits: 0 for `emc`, [`AHEAD_LEVELS`] for `emc-ahead`.
    pub ahead_levels: u8,
}

/// The levels `emc-ahead` takes cells ahead: on bunny.ply at 12 bits, 1 level costs the
/// lossless stream 2.7% and leaves level 7 at 1.87x `pm`'s RMS at the same bits, 2 levels 7.3%
/// for 1.64x at worst, 3 levels 11.5% for 1.69x (BENCHMARKS.md, "`emc-ahead`").
pub const AHEAD_LEVELS: u8 = 2;

/// What `Emc` is.
const DESCRIPTOR: Descriptor = Descriptor {
    naming: names::EMC,
    summary: "embedded mesh coding with context-modelled arithmetic coding: octree splits whose positions and edges are predicted from decoded neighbours",
    default_options: cubic(12),
    capabilities: &[
        Capability::PassStops,
        Capability::Attributes,
        Capability::AppearanceWithLevels,
    ],
    lossless: true,
};

/// What `Emc` with a lookahead is.
const AHEAD_DESCRIPTOR: Descriptor = Descriptor {
    naming: names::EMC_AHEAD,
    summary: "emc with every vertex's position coded two levels ahead of the octree's splits: better intermediate levels for a larger lossless stream",
    default_options: cubic(12),
    capabilities: &[
        Capability::PassStops,
        Capability::Attributes,
        Capability::AppearanceWithLevels,
    ],
    lossless: true,
};

impl Codec for Emc {
    fn descriptor(&self) -> &'static Descriptor {
        if self.ahead_levels == 0 {
            &DESCRIPTOR
        } else {
            &AHEAD_DESCRIPTOR
        }
    }

    fn measure(&self, _stream: &[u8]) -> Result<Stats> {
        Ok(Stats::default())
    }

    fn encode(&self, mesh: &CanonicalMesh) -> Result<Encoded> {
        let params = EmcParams {
            ahead_levels: self.ahead_levels,
            ..EmcParams::for_mesh(mesh, Syntax::Modelled)
        };
        let header = params.header(Syntax::Modelled, self.descriptor().naming, mesh);
        encoder::encode(mesh, &params, header)
    }

    fn decoder<'a>(&self, stream: StreamReader<'a>) -> Result<Box<dyn LevelDecoder + 'a>> {
        let params = EmcParams::from_stream(&stream, Syntax::Modelled)?;
        if (params.ahead_levels == 0) != (self.ahead_levels == 0) {
            return Err(crate::Error::malformed(
                0,
                7,
                if self.ahead_levels == 0 {
                    "emc stream with a lookahead byte (only emc-ahead streams have one)"
                } else {
                    "emc-ahead stream without its lookahead byte"
                },
            ));
        }
        Ok(Box::new(decoder::EmcDecoder::new(stream, params)))
    }
}

/// `emc`'s stream of `mesh` with its passes of 2^`sliced_visits_log2` visits or more sliced
/// into `slabs` slabs (2..=64; 1: none), whatever the mesh's size: what [`Emc`] writes for
/// large meshes, for smaller ones (tests, measurements of what slabs cost).
pub fn encode_sliced(mesh: &CanonicalMesh, slabs: u8, sliced_visits_log2: u8) -> Result<Encoded> {
    encode_sliced_ahead(mesh, 0, slabs, sliced_visits_log2)
}

/// [`encode_sliced`] for the codec that takes cells `ahead_levels` ahead (0: `emc`, 1 to 8:
/// `emc-ahead`'s syntax with that lookahead).
pub fn encode_sliced_ahead(
    mesh: &CanonicalMesh,
    ahead_levels: u8,
    slabs: u8,
    sliced_visits_log2: u8,
) -> Result<Encoded> {
    if !(1..=64).contains(&slabs) || sliced_visits_log2 >= 32 {
        return Err(crate::Error::Unsupported(format!(
            "emc slices into 1 to 64 slabs passes of under 2^32 visits, not {slabs} slabs of 2^{sliced_visits_log2}"
        )));
    }
    if ahead_levels > super::MAX_AHEAD_LEVELS {
        return Err(crate::Error::Unsupported(format!(
            "emc-ahead takes cells 1 to {} levels ahead, not {ahead_levels}",
            super::MAX_AHEAD_LEVELS
        )));
    }
    let params = EmcParams {
        slabs,
        sliced_visits_log2,
        ahead_levels,
        ..EmcParams::for_mesh(mesh, Syntax::Modelled)
    };
    let naming = if ahead_levels == 0 {
        names::EMC
    } else {
        names::EMC_AHEAD
    };
    let header = params.header(Syntax::Modelled, naming, mesh);
    encoder::encode(mesh, &params, header)
}
