//! `emc-paper`: Embedded Mesh Coding with the paper's syntax and fixed codes (the coder of the
//! Table 1 reproduction). See [`super`] for the paper and its glossary.
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

mod decoder;
mod encoder;
pub mod syntax;

use super::{EmcParams, Syntax};
use crate::codecs::descriptor::cubic;
use crate::codecs::Descriptor;
use crate::codecs::{names, Capability, Codec, Encoded, LevelDecoder, Stats};
use crate::container::StreamReader;
use crate::error::Result;
use crate::mesh::CanonicalMesh;

/// The `emc-paper` codec.
pub struct EmcPaper;

/// What `EmcPaper` is.
const DESCRIPTOR: Descriptor = Descriptor {
    naming: names::EMC_PAPER,
    summary: "Magnor & Girod's embedded mesh coding as published: octree splits with STAY/MOVE/DUPLICATE edges, fixed Huffman split distances, exact face corrections",
    default_options: cubic(24),
    capabilities: &[
        Capability::PassStops,
        Capability::PartialLevels,
        Capability::Attributes,
    ],
    lossless: true,
};

impl Codec for EmcPaper {
    fn descriptor(&self) -> &'static Descriptor {
        &DESCRIPTOR
    }

    fn measure(&self, _stream: &[u8]) -> Result<Stats> {
        Ok(Stats::default())
    }

    fn encode(&self, mesh: &CanonicalMesh) -> Result<Encoded> {
        let params = EmcParams::for_mesh(mesh, Syntax::Paper);
        let header = params.header(Syntax::Paper, self.descriptor().naming, mesh);
        encoder::encode(mesh, &params, header)
    }

    fn decoder<'a>(&self, stream: StreamReader<'a>) -> Result<Box<dyn LevelDecoder + 'a>> {
        let params = EmcParams::from_stream(&stream, Syntax::Paper)?;
        Ok(Box::new(decoder::EmcDecoder::new(stream, params.order)))
    }
}
