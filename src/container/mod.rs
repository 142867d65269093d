//! The stream container (docs/FORMAT.md §2): a header, an index of independently decodable
//! units, then the units' payloads.
//!
//! ```text
//! magic "MshC"  format version (u8)  codec id (u8)
//! params: varint length + codec-specific bytes
//! grid: bits (u8), origin 3 × f64 LE, cell 3 × f64 LE
//! vertices (varint)  triangles (varint)                        -- of the full mesh
//! version 4 only: appearance block (flags u8, then each attribute's quantization, names)
//! index: units N (varint), payload bytes P (varint),
//!        N × { offset (varint), length (varint), parent (varint: 0 = none, k = unit i − k) }
//! payload: P bytes, every byte in exactly one unit
//! ```
//! A unit is what a decoder can take on its own once the units it depends on are decoded: a level
//! for the layered codecs (each level's parent is the level before), a meta-node for a hierarchy
//! fetched by parts. A reader holding the header and index can fetch any unit by its byte range;
//! a prefix of the stream decodes to the units wholly inside it. The index is checked whole —
//! counts against [`crate::limits`] and the bytes that hold them, ranges inside the payload,
//! no overlaps, no stray bytes — before anything is allocated for what it claims.

use crate::coding::varint;
use crate::error::{Error, Result};
use std::io::Read as _;

/// First bytes of every stream.
pub const MAGIC: [u8; 4] = *b"MshC";
/// Version of the stream syntax: bumped on every change to the bytes any codec writes
/// (docs/FORMAT.md, "History"). Versions 3 and 4 are version 2 with an appearance block after
/// the header and an appearance unit after the last level (4 predicts uvs and colours better,
/// so version 3's units no longer decode); version 5 is version 4 whose appearance block may
/// say that the values are coded inside the levels (`pm`), with no appearance unit. Each
/// stream is written in the oldest version that holds it — 2 without appearance, 4 with an
/// appearance unit — and this build reads 2, 4 and 5.
pub const FORMAT_VERSION: u8 = 5;
/// The version of streams with an appearance unit.
pub const APPEARANCE_UNIT_VERSION: u8 = 4;
/// The version of streams without appearance, and the oldest this build reads.
pub const GEOMETRY_ONLY_VERSION: u8 = 2;
/// The fewest bytes an index entry takes (three one-byte varints).
const MIN_ENTRY_BYTES: u64 = 3;

mod header;
mod index;
mod reader;
#[cfg(test)]
mod tests;
mod writer;

pub use header::{AppearanceSpec, Header, MaterialNames};
pub use index::{Index, UnitEntry};
pub use reader::{LevelPayload, LevelSource, OwnedLevel, ReadLevels, StreamReader};
pub use writer::{LevelCost, LevelRecord, StreamWriter};

/// A varint count at `pos`, no larger than `limit`.
fn read_count(bytes: &[u8], pos: &mut usize, what: &str, limit: u64) -> Result<u64> {
    let at = *pos;
    let value = varint::get(bytes, pos).map_err(|f| match f {
        varint::VarintFault::Truncated => {
            Error::Truncated("the stream ends inside its header".into())
        }
        varint::VarintFault::Overflow => {
            Error::malformed(0, at, format!("{what} overflows 64 bits"))
        }
    })?;
    if value > limit {
        return Err(Error::Limit(format!(
            "stream declares {value} {what} (at most {limit})"
        )));
    }
    Ok(value)
}

/// Reads the header and index at the start of `bytes`; returns them and the payload's offset.
/// When the header declares an appearance unit, the index's last unit is that unit: it is
/// taken out of the units into [`Index::appearance`], so a codec sees its own units only.
pub fn read_header_and_index(bytes: &[u8]) -> Result<(Header, Index, usize)> {
    let (header, mut pos) = Header::read(bytes)?;
    let mut index = Index::read(bytes, &mut pos)?;
    if header.appearance.as_ref().is_some_and(|a| !a.in_levels) {
        if index.units.len() < 2 {
            return Err(Error::malformed(
                0,
                pos,
                "index: a stream with appearance needs a unit of geometry and the appearance unit",
            ));
        }
        let unit = index.units.pop().expect("two units or more");
        if unit.end() != index.payload_bytes {
            return Err(Error::malformed(
                0,
                pos,
                "index: the appearance unit is not the payload's last bytes",
            ));
        }
        index.appearance = Some(unit);
    }
    Ok((header, index, pos))
}
