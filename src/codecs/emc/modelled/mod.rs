//! `emc`: Embedded Mesh Coding with context-modelled arithmetic coding.
//!
//! The octree, its splits and the STAY / MOVE / DUPLICATE edge updates are the paper's (see
//! [`super`]); what changes is how each decision is coded. Every decision is one binary question
//! (see [`walk::Question`]) coded by constriction's range coder under an adaptive context chosen
//! from what the decoder already knows; each level is flushed on its own, so every prefix of
//! whole levels decodes.
//!
//! # Syntax, per step
//! For each vertex present at the start of the step, in list order:
//! 1. unless it is known to be a single mesh vertex (a *leaf*): does it split now?
//! 2. if not: which half it takes;
//! 3. if it splits: is there a connecting edge; for each neighbour (ascending ids) is the edge
//!    duplicated, and if not, does it move to the upper half; then, for each half, is it a leaf.
//!
//! The last level ends with the paper coder's three face-correction lists (false triangles,
//! faces in both orientations, orientation exceptions), lengths and gaps in adaptive Exp-Golomb.
//!
//! # Contexts
//! (Measurements: see the table at the end of this comment.)
//! - *Which half*: the mean of the neighbours' cell centres predicts the vertex (a smooth surface
//!   puts a vertex near the centroid of its ring); the bit is coded as "agrees with the
//!   prediction's side" under a context made of the prediction's distance from the split plane
//!   and the neighbours' spread along the axis, both in half-widths of the cell, and whether the
//!   vertex is a leaf.
//! - *Split*: steps since the cluster was made, its valence (a cluster of many vertices has many
//!   neighbours) and the levels left. Leaves never ask.
//! - *Leaf*: which half, its valence after the split, levels left.
//! - *Duplicate* and *moves*: where the neighbour lies relative to the split plane — its
//!   distance along the axis (the halves' centres lie at ±½) and the ratio of its distance
//!   across to along — and whether it is a leaf; *duplicate* also by the duplicates already coded
//!   in this split (a manifold vertex split duplicates two). *Moves* is coded as "goes to the half
//!   on its side".
//! - *Connecting*: valence and levels left.
mod contexts;
mod decoder;
mod encoder;
pub mod walk;

use super::{EmcParams, Syntax};
use crate::codecs::{Codec, EncodeOptions, Encoded, LevelDecoder};
use crate::container::StreamReader;
use crate::error::Result;
use crate::mesh::CanonicalMesh;

/// The `emc` codec.
pub struct Emc;

impl Codec for Emc {
    fn name(&self) -> &'static str {
        "emc"
    }

    fn id(&self) -> u8 {
        4
    }

    fn summary(&self) -> &'static str {
        "embedded mesh coding with context-modelled arithmetic coding: octree splits whose positions and edges are predicted from decoded neighbours"
    }

    fn encode(&self, mesh: &CanonicalMesh, _options: &EncodeOptions) -> Result<Encoded> {
        let params = EmcParams::for_mesh(mesh);
        let header = params.header(Syntax::Modelled, self.id(), mesh);
        Ok(encoder::encode(mesh, &params, header))
    }

    fn decoder<'a>(&self, stream: StreamReader<'a>) -> Result<Box<dyn LevelDecoder + 'a>> {
        let params = EmcParams::from_header(stream.header(), Syntax::Modelled)?;
        Ok(Box::new(decoder::EmcDecoder::new(stream, params.order)))
    }
}
