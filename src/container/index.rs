//! The index of units (FORMAT.md §2): each unit's byte range and parent, checked whole before
//! anything is allocated for what it claims.

use super::*;
use crate::coding::varint;
use crate::error::{Error, Result};
use crate::limits;

/// Where one unit's payload lies, and what it needs decoded first.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UnitEntry {
    /// Offset of the unit's first byte from the payload's start.
    pub offset: u64,
    /// Bytes of the unit.
    pub length: u64,
    /// The unit that must be decoded before this one (always an earlier unit).
    pub parent: Option<usize>,
}

impl UnitEntry {
    /// One past the unit's last byte, from the payload's start.
    pub fn end(&self) -> u64 {
        self.offset + self.length
    }
}

/// The index of a stream's units.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Index {
    /// Units in decoding order.
    pub units: Vec<UnitEntry>,
    /// Bytes of the payload (the sum of the units' lengths, the appearance unit's included).
    pub payload_bytes: u64,
    /// The appearance unit, last in the stream, when the header declares appearance.
    pub appearance: Option<UnitEntry>,
}

impl Index {
    /// The index of units laid out back to back in order, each depending on the one before —
    /// the levels of a layered codec.
    pub fn layered(lengths: &[u64]) -> Index {
        Index::back_to_back(
            lengths
                .iter()
                .enumerate()
                .map(|(i, &length)| (length, i.checked_sub(1))),
        )
    }

    /// The index of units of these lengths and parents, laid out back to back in order.
    pub fn back_to_back(units: impl IntoIterator<Item = (u64, Option<usize>)>) -> Index {
        let mut offset = 0;
        let units = units
            .into_iter()
            .map(|(length, parent)| {
                let unit = UnitEntry {
                    offset,
                    length,
                    parent,
                };
                offset += length;
                unit
            })
            .collect();
        Index {
            units,
            payload_bytes: offset,
            appearance: None,
        }
    }

    /// True when the units are levels: back to back in order, each depending on the one before.
    pub fn is_layered(&self) -> bool {
        let mut offset = 0;
        self.units.iter().enumerate().all(|(i, unit)| {
            let in_place = unit.offset == offset && unit.parent == i.checked_sub(1);
            offset += unit.length;
            in_place
        })
    }

    /// Refuses an index whose units are not levels (`at`: the payload's offset, for the error).
    pub fn require_layered(&self, at: usize) -> Result<()> {
        if !self.is_layered() {
            return Err(Error::malformed(
                0,
                at,
                "index: this codec's units are levels, laid out in order, each after the one before",
            ));
        }
        Ok(())
    }

    /// Number of units.
    pub fn len(&self) -> usize {
        self.units.len()
    }

    /// True when the index lists no unit (no stream has such an index).
    pub fn is_empty(&self) -> bool {
        self.units.is_empty()
    }

    /// Appends the index's bytes to `out`.
    pub fn write(&self, out: &mut Vec<u8>) {
        varint::put(
            out,
            (self.units.len() + self.appearance.is_some() as usize) as u64,
        );
        varint::put(out, self.payload_bytes);
        for (i, unit) in self.units.iter().chain(&self.appearance).enumerate() {
            varint::put(out, unit.offset);
            varint::put(out, unit.length);
            varint::put(out, unit.parent.map_or(0, |p| (i - p) as u64));
        }
    }

    /// Reads and checks an index from `bytes` at `pos`.
    pub(super) fn read(bytes: &[u8], pos: &mut usize) -> Result<Index> {
        let units = read_count(bytes, pos, "units", limits::MAX_UNITS)?;
        let payload_bytes = read_count(bytes, pos, "payload bytes", u64::MAX >> 1)?;
        if units == 0 {
            return Err(Error::malformed(0, *pos, "the index lists no unit"));
        }
        // Nothing is allocated for the entries before the bytes that must hold them are there.
        if ((bytes.len() - *pos) as u64) < units * MIN_ENTRY_BYTES {
            return Err(Error::Truncated("the stream ends inside its index".into()));
        }
        let mut entries = Vec::with_capacity(units as usize);
        for i in 0..units as usize {
            let at = *pos;
            // Bounded so that their sum cannot overflow; checked against the payload below.
            let offset = read_count(bytes, pos, "unit offset", u64::MAX >> 2)?;
            let length = read_count(bytes, pos, "unit length", u64::MAX >> 2)?;
            let back = read_count(bytes, pos, "parent distance", i as u64)?;
            if offset + length > payload_bytes {
                return Err(Error::malformed(
                    0,
                    at,
                    format!(
                        "index: unit {i} (bytes {offset}..{}) runs past the {payload_bytes} payload bytes",
                        offset + length
                    ),
                ));
            }
            entries.push(UnitEntry {
                offset,
                length,
                parent: (back > 0).then(|| i - back as usize),
            });
        }
        let mut by_offset: Vec<usize> = (0..entries.len()).collect();
        by_offset.sort_by_key(|&i| (entries[i].offset, entries[i].length));
        for pair in by_offset.windows(2) {
            let (a, b) = (entries[pair[0]], entries[pair[1]]);
            if b.offset < a.end() {
                return Err(Error::malformed(
                    0,
                    *pos,
                    format!(
                        "index: units {} (bytes {}..{}) and {} (bytes {}..{}) overlap",
                        pair[0],
                        a.offset,
                        a.end(),
                        pair[1],
                        b.offset,
                        b.end()
                    ),
                ));
            }
        }
        let covered: u64 = entries.iter().map(|u| u.length).sum();
        if covered != payload_bytes {
            return Err(Error::malformed(
                0,
                *pos,
                format!(
                    "index: units cover {covered} of the {payload_bytes} payload bytes it declares"
                ),
            ));
        }
        Ok(Index {
            units: entries,
            payload_bytes,
            appearance: None,
        })
    }
}
