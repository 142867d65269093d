//! Embedded Mesh Coding: the octree of vertex splits in which positions and connectivity refine
//! together, so that any prefix of the stream decodes to a coarser mesh. Two coders share the
//! hierarchy and the decoder's state ([`state::EmcState`]):
//! - [`paper`] (`emc-paper`): the paper's syntax — raw refinement bits, fixed prefix codes for
//!   STAY / MOVE / DUPLICATE, a fixed Huffman table of split distances;
//! - [`modelled`] (`emc`): the same octree splits coded by adaptive binary arithmetic coding with
//!   contexts drawn from what the decoder already knows (neighbour positions, valences, the
//!   split plane);
//! - `emc-ahead`, [`modelled`] with a lookahead: every vertex's cell is coded two levels ahead of
//!   the octree's splits (a cluster's along its representative's path), so that intermediate
//!   levels show fewer vertices more precisely, for a larger lossless stream.
//!
//! Based on: M. Magnor and B. Girod, *Fully Embedded Coding of Triangle Meshes*, Proc. Vision,
//! Modeling and Visualization (VMV) 1999 (../shared/papers/004_d00e3be26dc15ae5.txt).
//!
//! # Glossary
//! | paper | here |
//! |---|---|
//! | bounding box, header of 6 floats | the quantization [`Grid`](crate::mesh::Grid) in the container header |
//! | resolution level l = 1..24 | `level`; L = quantization bits Q (`--quant`, default 24) |
//! | direction (X, Y, Z binary trees) | `axis`; each level refines the longest box side, then the middle, then the shortest |
//! | step (level × direction) | `step` s = 3(l − 1) + k, 0..3L |
//! | RF, Refinement | one bit: which half of its cell a vertex takes at a step |
//! | VM, Vertex Merge (bottom-up) / VS, Vertex Split (top-down) | `EmcState::split`: the old vertex keeps the left half, a new vertex takes the right |
//! | connecting edge | one flag bit per split |
//! | STAY / MOVE / DUPLICATE | [`paper::syntax::EdgeCode`], one per neighbour of the splitting vertex |
//! | distance to the next split, fixed Huffman table | [`paper::syntax::SPLIT_DISTANCE_CODE_LENGTHS`]; symbol 0 = "no further split" |
//! | triangles from edges | `hierarchy::cliques`: every 3-clique of the edge graph |
//! | (not in the paper) a cluster's representative | `emc-ahead`: the mesh vertex whose path a cluster's cell follows ahead of its splits |
//!
//! # The direction order
//! Top-down, level 1 starts with the longest box side and each level takes the three axes from
//! the longest to the shortest; bottom-up the paper's merges start at level L − 1 along the
//! shortest side, which is the same sequence reversed (the merge "at level 23, shortest side"
//! undoes the split "at level 24, shortest side": the paper counts merge levels by the coarser
//! cell). The axis order is measured on the canonical mesh's extent and stored in the stream.
//!
//! # Grids
//! `--grid per-axis` is the paper's box (each axis divided into 2^L cells of its own length);
//! `--grid cubic` (the default) is the cubic grid of docs/CONTRACT.md §1 used to compare codecs. With the
//! cubic grid the shorter axes start inside the box's first half, and their first refinement bits
//! are the same for every vertex.
//!

mod clusters;
pub mod modelled;
pub mod paper;
pub mod state;

use crate::codecs::names::Naming;
use crate::container::{Header, StreamReader};
use crate::error::{Error, Result};
use crate::hierarchy::octree::{axes_by_extent, StepOrder};
use crate::mesh::CanonicalMesh;

/// Parameters stored in the header: the axis order and, for `emc`, where the face corrections
/// are coded and how passes are sliced (docs/FORMAT.md §5, §7).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EmcParams {
    /// Levels and axis order.
    pub order: StepOrder,
    /// The face corrections follow the first level after which every vertex is decoded (the
    /// edge graph is final from then on), so that the levels after it show the mesh's own
    /// faces; else they follow the last level, as the paper codes them. `emc` writes the
    /// former (its fourth parameter byte, 1); `emc-paper` always codes the latter.
    pub faces_when_settled: bool,
    /// Slabs of a sliced pass (docs/FORMAT.md §7): a pass that visits at least
    /// 2^`sliced_visits_log2` vertices codes each slab's interior in a stream of its own, so
    /// that the slabs decode at once. 1: no pass is sliced (and no sixth parameter byte).
    /// `emc` slices meshes of [`SLICED_VERTICES`] vertices or more into [`SLABS`].
    pub slabs: u8,
    /// See [`Self::slabs`].
    pub sliced_visits_log2: u8,
    /// Levels each level's lookahead pass takes every vertex's cell ahead of the octree's
    /// splits (docs/FORMAT.md §7); 0: no lookahead (and no seventh parameter byte).
    pub ahead_levels: u8,
}

/// Slabs of the `emc` streams that have them: up to four cores decode them at once; each slab
/// more costs about 0.2% of the stream (bunny-closed-35k ×16 at 12 bits: 2 slabs +0.52%,
/// 4 +0.86%, 8 +1.61%, 16 +2.80%; BENCHMARKS.md).
pub const SLABS: u8 = 4;

/// The passes `emc` slices: those of 2^this visits or more (2,048 a slab at four slabs). On
/// bunny-closed-35k ×16, 2^13 costs 0.18% more than 2^15 and slices the levels' first
/// passes from level 7 on, whose serial time kept two cores from 1.6× one (BENCHMARKS.md).
pub const SLICED_VISITS_LOG2: u8 = 13;

/// The meshes whose `emc` streams have slabs: those of this many vertices or more.
pub const SLICED_VERTICES: usize = 1 << 16;

/// Most levels a lookahead may take cells ahead (the walker keeps a bit a step ahead in 32).
pub const MAX_AHEAD_LEVELS: u8 = 8;

/// Most slabs a stream may have.
const MAX_SLABS: u8 = 64;

/// Which of the two coders a stream uses (its codec: `emc-paper` or `emc`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Syntax {
    /// The paper's fixed codes (`emc-paper`).
    Paper,
    /// Context-modelled arithmetic coding (`emc`).
    Modelled,
}

impl EmcParams {
    /// The parameters for `mesh` in `syntax`: as many levels as quantization bits, axes by
    /// extent.
    pub fn for_mesh(mesh: &CanonicalMesh, syntax: Syntax) -> EmcParams {
        EmcParams {
            order: StepOrder {
                levels: mesh.grid.bits,
                axes: axes_by_extent(extent_of(mesh)),
            },
            faces_when_settled: syntax == Syntax::Modelled,
            slabs: if syntax == Syntax::Modelled && mesh.vertex_count() >= SLICED_VERTICES {
                SLABS
            } else {
                1
            },
            sliced_visits_log2: SLICED_VISITS_LOG2,
            ahead_levels: 0,
        }
    }

    /// The header that a stream of `mesh` in `syntax` by the codec `naming` starts with: the
    /// axes, and for `emc` the corrections' place and the slabs.
    pub fn header(&self, syntax: Syntax, naming: Naming, mesh: &CanonicalMesh) -> Header {
        let mut params = self.order.axes.to_vec();
        if syntax == Syntax::Modelled {
            params.extend([u8::from(self.faces_when_settled), self.slabs]);
            if self.slabs > 1 || self.ahead_levels > 0 {
                params.push(self.sliced_visits_log2);
            }
            if self.ahead_levels > 0 {
                params.push(self.ahead_levels);
            }
        }
        Header {
            codec_id: naming.id,
            syntax: naming.syntax,
            params,
            grid: mesh.grid,
            vertices: mesh.vertex_count() as u64,
            triangles: mesh.face_count() as u64,
            appearance: None,
        }
    }

    /// Whether the face corrections follow `level` (1-based), at whose end `decoded` of the
    /// header's `vertices` are in the list: the encoder writes them, and the decoder reads them,
    /// after the first level for which this holds.
    pub fn corrections_follow(&self, level: usize, decoded: u64, vertices: u64) -> bool {
        level == self.order.levels as usize || self.faces_when_settled && decoded == vertices
    }

    /// Reads and checks the parameters of a stream in `syntax`.
    pub fn from_stream(stream: &StreamReader, syntax: Syntax) -> Result<EmcParams> {
        stream.require_layered()?;
        let header = stream.header();
        let bad = |what: &str| Error::malformed(0, 7, what);
        let p = &header.params;
        let (axes, faces_when_settled, slabs, sliced_visits_log2, ahead_levels) =
            match (syntax, &p[..]) {
                (Syntax::Paper, &[a, b, c]) => ([a, b, c], 0, 1, SLICED_VISITS_LOG2, 0),
                (Syntax::Modelled, &[a, b, c, settled, 1]) => {
                    ([a, b, c], settled, 1, SLICED_VISITS_LOG2, 0)
                }
                (Syntax::Modelled, &[a, b, c, settled, slabs, log2]) => {
                    if !(2..=MAX_SLABS).contains(&slabs) || log2 >= 32 {
                        return Err(bad(
                            "emc slabs out of range (2 to 64 slabs, passes of under 2^32 visits)",
                        ));
                    }
                    ([a, b, c], settled, slabs, log2, 0)
                }
                (Syntax::Modelled, &[a, b, c, settled, slabs, log2, ahead]) => {
                    if !(1..=MAX_SLABS).contains(&slabs) || log2 >= 32 {
                        return Err(bad(
                            "emc slabs out of range (1 to 64 slabs, passes of under 2^32 visits)",
                        ));
                    }
                    if !(1..=MAX_AHEAD_LEVELS).contains(&ahead) {
                        return Err(bad("emc lookahead out of range (1 to 8 levels)"));
                    }
                    ([a, b, c], settled, slabs, log2, ahead)
                }
                (Syntax::Paper, _) => return Err(bad("emc-paper parameters: 3 bytes expected")),
                (Syntax::Modelled, _) => return Err(bad(
                    "emc parameters: 5 bytes expected, 6 with slabs (2 to 64), 7 with a lookahead",
                )),
            };
        let faces_when_settled = match faces_when_settled {
            0 => false,
            1 => true,
            _ => return Err(bad("emc face corrections byte other than 0 or 1")),
        };
        let mut sorted = axes;
        sorted.sort_unstable();
        if sorted != [0, 1, 2] {
            return Err(bad("emc axis order is not a permutation of x, y, z"));
        }
        if stream.index().len() != header.grid.bits as usize {
            return Err(bad(
                "emc stream with a level count other than its quantization bits",
            ));
        }
        Ok(EmcParams {
            order: StepOrder {
                levels: header.grid.bits,
                axes,
            },
            faces_when_settled,
            slabs,
            sliced_visits_log2,
            ahead_levels,
        })
    }
}

/// Extent of the mesh along each axis, in the grid's units.
fn extent_of(mesh: &CanonicalMesh) -> [f64; 3] {
    let mut lo = [u32::MAX; 3];
    let mut hi = [0u32; 3];
    for c in &mesh.cells {
        for a in 0..3 {
            lo[a] = lo[a].min(c[a]);
            hi[a] = hi[a].max(c[a]);
        }
    }
    [0, 1, 2].map(|a| (hi[a].saturating_sub(lo[a]) as f64 + 1.0) * mesh.grid.cell[a])
}
