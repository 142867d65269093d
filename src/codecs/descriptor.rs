//! What a codec is, in one static value per codec ([`Descriptor`]): its name and stream id (from
//! [`names`](super::names), the one table of them), a one-line summary, the options used when
//! the user gives none, what it does beyond decoding level by level, and whether its full
//! decode is the canonical mesh. [`Codec`](super::Codec) answers its name, id, summary,
//! defaults and capabilities from it, so that nothing outside the names table tells codecs
//! apart by name.

use super::names::Naming;
use super::{Capability, EncodeOptions};
use crate::mesh::quantize::GridShape;

/// One codec's static description.
#[derive(Debug)]
pub struct Descriptor {
    /// Its name on the command line and in results/, and its id in stream headers.
    pub naming: Naming,
    /// One line on what the codec is.
    pub summary: &'static str,
    /// The quantization used when the user gives none.
    pub default_options: EncodeOptions,
    /// What it does beyond decoding level by level.
    pub capabilities: &'static [Capability],
    /// Whether its full decode is the canonical mesh (docs/CONTRACT.md §3); a lossy codec's
    /// full level is reported with its error, never called lossless.
    pub lossless: bool,
}

/// `bits` per axis on a cubic grid: every codec's default shape.
pub(crate) const fn cubic(bits: u8) -> EncodeOptions {
    EncodeOptions {
        quant_bits: bits,
        grid: GridShape::Cubic,
    }
}
