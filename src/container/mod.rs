//! The stream container (docs/FORMAT.md §2): a header, an index of independently decodable
//! units, then the units' payloads.
//!
//! ```text
//! magic "MshC"  format version (u8)  codec id (u8)  codec syntax (u8)
//! params: varint length + the syntax's bytes
//! grid: bits (u8), origin 3 × f64 LE, cell 3 × f64 LE
//! vertices (varint)  triangles (varint)                        -- of the full mesh
//! appearance flags (u8; 0: none), then each attribute's quantization, names
//! index: units N (varint), entry bytes E (varint), payload bytes P (varint),
//!        N × { length (varint), children (varint) }             -- E bytes
//! payload: P bytes, the units back to back in index order
//! ```
//! A unit is what a decoder can take on its own once the units it depends on are decoded: a level
//! for the layered codecs (each level's parent is the level before), a meta-node for a hierarchy
//! fetched by parts. The children counts give each unit's parent: the units after the first are
//! the children of unit 0, then those of unit 1, and so on (breadth first). A reader holding the
//! header and index can fetch any unit by its byte range, and one holding the index's first
//! entries ([`PartialIndex`]) any unit among them; a prefix of the stream decodes to the units
//! wholly inside it. Counts are checked against [`crate::limits`] and the bytes that hold them
//! before anything is allocated for what they claim; each entry as it is read (inside the
//! payload, its children after it); the whole index once read (no stray bytes).

use crate::coding::varint;
use crate::error::{Error, Result};
use std::io::Read as _;

/// First bytes of every stream.
pub const MAGIC: [u8; 4] = *b"MshC";
/// Version of the stream format: bumped on every change to the bytes any codec writes
/// (docs/FORMAT.md, "History"). Every stream of this build is written in it, with or without
/// appearance (the appearance flags say which), and it is the only version this build reads:
/// version 7 gives each unit's length and children count where version 6 gave its offset,
/// length and parent (a version 6 stream re-encodes to the same payload).
pub const FORMAT_VERSION: u8 = 8;
/// The fewest bytes an index entry takes (two one-byte varints).
const MIN_ENTRY_BYTES: u64 = 2;
/// The most bytes an index entry takes: a length below 2^62 (nine varint bytes) and a
/// children count within [`crate::limits::MAX_UNITS`] (three).
const MAX_ENTRY_BYTES: u64 = 12;

mod header;
mod index;
mod reader;
#[cfg(test)]
mod tests;
mod writer;

pub use header::{AppearanceSpec, Header, MaterialNames};
pub use index::{Index, PartialIndex, UnitEntry};
pub use reader::{
    check_stream_length, LevelPayload, LevelSource, OwnedLevel, ReadLevels, StreamReader,
};
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
    if header.has_appearance_unit() {
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
    if header.has_level_parts() {
        index.split_level_parts(pos)?;
    }
    Ok((header, index, pos))
}
