//! `emc`: Embedded Mesh Coding, as the paper describes it.
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
//! | STAY / MOVE / DUPLICATE | [`syntax::EdgeCode`], one per neighbour of the splitting vertex |
//! | distance to the next split, fixed Huffman table | [`syntax::SPLIT_DISTANCE_CODE_LENGTHS`]; symbol 0 = "no further split" |
//! | triangles from edges | `hierarchy::cliques`: every 3-clique of the edge graph |
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
//! `--grid cubic` (the default) is the cubic grid of DESIGN.md A2 used to compare codecs. With the
//! cubic grid the shorter axes start inside the box's first half, and their first refinement bits
//! are the same for every vertex.
//!
//! # Syntax, per level
//! For each of the level's three steps, a pass over the vertex list in list order (new vertices
//! are appended and first take part in the next step): a vertex whose next split is not due
//! writes its RF bit; a vertex that splits writes the connecting-edge flag, one edge code per
//! neighbour (ascending list ids), and two split distances (old vertex, new vertex). The first
//! vertex needs no distance: it always splits at step 0, since the longest axis spans the whole
//! grid. Each level is flushed to a byte boundary and carries its length (the container), so any
//! prefix decodes; inside a cut level, every complete operation is applied, and decoding can also
//! stop after any pass (`Stop::Passes`, `meshcodec decode --passes`).
//!
//! # Encoder
//! The paper builds the merge list bottom-up and writes it reversed. The splits it produces are
//! those of a binary trie over the vertices' *keys* (their bits in step order): each cluster is a
//! contiguous range of key-sorted vertices, splitting where its first and last keys differ, and
//! the merge survivor (left half) is the range's first vertex. The encoder therefore runs the
//! decoder's top-down passes directly, reading every decision off the trie and the mesh's edges.
//!
//! # Codes
//! Edge codes: STAY and MOVE are about equally frequent and DUPLICATE rarer (measured at 24
//! bits, cubic grid: bunny.ply 93,067 STAY / 92,844 MOVE / 69,781 DUPLICATE; beethoven.ply
//! 6,955 / 7,098 / 5,175). A three-symbol prefix code gives one symbol 1 bit; STAY takes it
//! (`0`), MOVE is `10`, DUPLICATE `11`: 1.64 bits per edge on bunny.ply, against 1.73 with
//! DUPLICATE as the 1-bit code.
//!
//! Split distances: a single canonical Huffman table for all meshes, from the distance histogram
//! pooled over meshes that are not in the paper's Table 1 (`cargo run --release --example
//! emc_split_distance_table` regenerates it). Symbol 0 is "no further split".
//!
//! # Exactly lossless: what the paper's triangles-from-edges leaves out
//! Rebuilding triangles as the 3-cliques of the edge graph (as the paper's decoder does) loses
//! three things, which the last level codes as three lists of positions (length and gaps in
//! Elias-gamma codes), all booked as connectivity:
//! 1. *False triangles*: 3-cliques that are not faces (the paper instead adds vertices, which
//!    changes the mesh). Positions in the clique list.
//! 2. *Faces present in both orientations* (abc and acb — "faces whose edges all exist twice").
//!    Positions in the clique list; both orientations are output.
//! 3. *Orientation*: the decoder orients the cliques by propagation — each patch starts at its
//!    lowest clique with a guess (normal away from the centroid) and spreads breadth-first across
//!    edges shared by exactly two triangles, predicting agreement. The encoder lists the visits
//!    where the prediction is wrong: one per wrongly guessed patch start, none elsewhere on an
//!    orientable, consistently oriented surface.
//!
//! Intermediate levels show all cliques with the propagated orientation (no bits). The measured
//! cost of the three lists is in the Table 1 reproduction (paper-tables/emc-table1.md).

mod context;
mod decoder;
mod encoder;
pub mod syntax;

use super::{Codec, EncodeOptions, Encoded, LevelDecoder};
use crate::container::{Header, StreamReader};
use crate::error::{Error, Result};
use crate::hierarchy::octree::{axes_by_extent, StepOrder};
use crate::mesh::quantize::GridShape;
use crate::mesh::CanonicalMesh;

/// Parameters stored in the header.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EmcParams {
    /// Levels and axis order.
    pub order: StepOrder,
}

impl EmcParams {
    const SYNTAX_PAPER: u8 = 0;

    fn to_bytes(self) -> Vec<u8> {
        let [a, b, c] = self.order.axes;
        vec![Self::SYNTAX_PAPER, a, b, c]
    }

    fn from_header(header: &Header) -> Result<EmcParams> {
        let bad = |what: &str| Error::malformed(0, 6, what);
        let p = &header.params;
        if p.len() != 4 || p[0] != Self::SYNTAX_PAPER {
            return Err(bad("emc parameters of unknown syntax"));
        }
        let axes = [p[1], p[2], p[3]];
        let mut sorted = axes;
        sorted.sort_unstable();
        if sorted != [0, 1, 2] {
            return Err(bad("emc axis order is not a permutation of x, y, z"));
        }
        Ok(EmcParams {
            order: StepOrder {
                levels: header.grid.bits,
                axes,
            },
        })
    }
}

/// The `emc` codec.
pub struct Emc;

impl Codec for Emc {
    fn name(&self) -> &'static str {
        "emc"
    }

    fn id(&self) -> u8 {
        1
    }

    fn summary(&self) -> &'static str {
        "Magnor & Girod's embedded mesh coding: octree splits with STAY/MOVE/DUPLICATE edges, fixed Huffman split distances, exact face corrections"
    }

    fn default_options(&self) -> EncodeOptions {
        EncodeOptions {
            quant_bits: 24,
            grid: GridShape::Cubic,
        }
    }

    fn encode(&self, mesh: &CanonicalMesh, _options: &EncodeOptions) -> Result<Encoded> {
        let bits = mesh.grid.bits;
        let extent = extent_of(mesh);
        let params = EmcParams {
            order: StepOrder {
                levels: bits,
                axes: axes_by_extent(extent),
            },
        };
        let header = Header {
            codec_id: self.id(),
            params: params.to_bytes(),
            grid: mesh.grid,
            vertices: mesh.vertex_count() as u64,
            triangles: mesh.face_count() as u64,
            levels: bits as u64,
        };
        Ok(encoder::encode(mesh, &params, header))
    }

    fn decoder<'a>(&self, stream: StreamReader<'a>) -> Result<Box<dyn LevelDecoder + 'a>> {
        let params = EmcParams::from_header(stream.header())?;
        if stream.header().levels != params.order.levels as u64 {
            return Err(Error::malformed(
                0,
                6,
                "emc stream with a level count other than its quantization bits",
            ));
        }
        Ok(Box::new(decoder::EmcDecoder::new(stream, params.order)))
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
