//! The index of units (FORMAT.md §2): each unit's length and children count, from which its
//! byte range and parent follow; read whole or entry by entry ([`PartialIndex`]), its counts
//! checked against the bytes that hold them before anything is allocated for what it claims.

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
    /// The unit of each level's appearance, which follows the level, when the header declares
    /// level parts (docs/FORMAT.md §10); empty otherwise.
    pub level_parts: Vec<UnitEntry>,
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
            level_parts: Vec::new(),
        }
    }

    /// True when the units are levels: in order, each depending on the one before (and back to
    /// back, but for the level parts between them).
    pub fn is_layered(&self) -> bool {
        let mut offset = 0;
        self.units.iter().enumerate().all(|(i, unit)| {
            let in_place = unit.offset == offset && unit.parent == i.checked_sub(1);
            offset = unit.end() + self.level_parts.get(i).map_or(0, |p| p.length);
            in_place
        })
    }

    /// One past the last byte, from the payload's start, of level `i` and its level part.
    pub fn level_end(&self, i: usize) -> Option<u64> {
        let unit = self.units.get(i)?;
        Some(self.level_parts.get(i).map_or(unit.end(), UnitEntry::end))
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

    /// Appends the index's bytes to `out`. The units lie back to back in order and form a
    /// tree in breadth-first order (FORMAT.md §2): the writers' own layout, checked here.
    pub fn write(&self, out: &mut Vec<u8>) {
        let units: Vec<UnitEntry> = self.stream_order();
        let mut children = vec![0u64; units.len()];
        let mut offset = 0;
        for unit in &units {
            assert_eq!(
                unit.offset, offset,
                "units are written back to back in order"
            );
            offset += unit.length;
            if let Some(parent) = unit.parent {
                children[parent] += 1;
            }
        }
        let mut entries = Vec::new();
        for (unit, &count) in units.iter().zip(&children) {
            varint::put(&mut entries, unit.length);
            varint::put(&mut entries, count);
        }
        let mut read_back = Tree::default();
        for (i, &count) in children.iter().enumerate() {
            assert_eq!(
                read_back
                    .take(i, count, units.len())
                    .ok()
                    .map(|(parent, _)| parent),
                Some(units[i].parent),
                "units are written in breadth-first order"
            );
        }
        varint::put(out, units.len() as u64);
        varint::put(out, entries.len() as u64);
        varint::put(out, self.payload_bytes);
        out.extend_from_slice(&entries);
    }

    /// The units as the stream lists them: each level followed by its level part (the part's
    /// parent is its level, the next level's the level before), then the appearance unit.
    fn stream_order(&self) -> Vec<UnitEntry> {
        if self.level_parts.is_empty() {
            return self.units.iter().chain(&self.appearance).copied().collect();
        }
        let mut units = Vec::with_capacity(2 * self.units.len());
        for (i, (level, part)) in self.units.iter().zip(&self.level_parts).enumerate() {
            units.push(UnitEntry {
                parent: i.checked_sub(1).map(|p| 2 * p),
                ..*level
            });
            units.push(UnitEntry {
                parent: Some(2 * i),
                ..*part
            });
        }
        units
    }

    /// Takes the level parts out of an index whose units alternate level, level part
    /// (docs/FORMAT.md §10): the levels keep their own numbering; `at` is for errors.
    pub(super) fn split_level_parts(&mut self, at: usize) -> Result<()> {
        let listed = std::mem::take(&mut self.units);
        if !listed.len().is_multiple_of(2) {
            return Err(Error::malformed(
                0,
                at,
                "index: levels and their appearance units do not alternate",
            ));
        }
        for (i, pair) in listed.chunks(2).enumerate() {
            let (level, part) = (pair[0], pair[1]);
            if level.parent != i.checked_sub(1).map(|p| 2 * p) || part.parent != Some(2 * i) {
                return Err(Error::malformed(
                    0,
                    at,
                    format!("index: level {i} or its appearance unit depends on another unit"),
                ));
            }
            self.units.push(UnitEntry {
                parent: i.checked_sub(1),
                ..level
            });
            self.level_parts.push(part);
        }
        Ok(())
    }

    /// Reads and checks an index from `bytes` at `pos`.
    pub(super) fn read(bytes: &[u8], pos: &mut usize) -> Result<Index> {
        let mut partial = PartialIndex::start(bytes, pos)?;
        // Nothing is allocated for the entries before the bytes that must hold them are there.
        if bytes.len() < partial.payload_start {
            return Err(Error::Truncated("the stream ends inside its index".into()));
        }
        partial.read_on(bytes)?;
        *pos = partial.payload_start;
        partial.finish()
    }
}

/// The parents that the children counts read so far give: unit 0 needs no other; the units
/// after it are, in order, the children of unit 0, then those of unit 1, and so on, each
/// unit's after it; a unit no earlier unit counts among its children needs no other.
#[derive(Clone, Debug, Default)]
struct Tree {
    /// The first unit not yet given a parent.
    next: usize,
    /// Units given a parent and not yet read: (first, last + 1, parent), in order.
    waiting: std::collections::VecDeque<(usize, usize, usize)>,
}

impl Tree {
    /// Unit `i`'s parent and its children, now that its entry is read and says it has
    /// `children` (of `units` in all); `Err` with what is wrong when the children run past the
    /// last unit.
    fn take(
        &mut self,
        i: usize,
        children: u64,
        units: usize,
    ) -> std::result::Result<(Option<usize>, std::ops::Range<usize>), String> {
        while self.waiting.front().is_some_and(|&(_, end, _)| end <= i) {
            self.waiting.pop_front();
        }
        let parent = self
            .waiting
            .front()
            .filter(|&&(first, _, _)| first <= i)
            .map(|&(_, _, parent)| parent);
        let first = self.next.max(i + 1);
        if children == 0 {
            return Ok((parent, first..first));
        }
        if children > (units - first) as u64 {
            return Err(format!(
                "unit {i} has {children} children, {} units follow those listed before",
                units - first
            ));
        }
        self.next = first + children as usize;
        self.waiting.push_back((first, self.next, i));
        Ok((parent, first..self.next))
    }
}

/// An index read entry by entry, as far as the bytes fetched so far hold it: a client that
/// fetches units by their byte ranges needs the entries up to the last unit it reads, and the
/// payload's offset is known from the index's first bytes (FORMAT.md §2). Each entry is
/// checked as it is read (inside the payload, its children after it and before the last
/// unit), and the whole index once its last entry is in ([`PartialIndex::finish`]).
#[derive(Clone, Debug)]
pub struct PartialIndex {
    /// Units the index lists.
    pub listed: usize,
    /// The entries read so far (the first [`Index::len`] units) and the payload's bytes.
    pub index: Index,
    /// Per entry read: the units that need it decoded first (its children, consecutive).
    pub children: Vec<std::ops::Range<usize>>,
    /// Offset of the payload in the stream.
    pub payload_start: usize,
    /// Offset in the stream just past the last entry read.
    end: usize,
    tree: Tree,
}

impl PartialIndex {
    /// The index at `pos` of `bytes`, before its entries: its counts, checked against the
    /// limits. `pos` moves past them.
    pub fn start(bytes: &[u8], pos: &mut usize) -> Result<PartialIndex> {
        let units = read_count(bytes, pos, "units", limits::MAX_UNITS)?;
        let entry_bytes = read_count(
            bytes,
            pos,
            "index bytes",
            limits::MAX_UNITS * MAX_ENTRY_BYTES,
        )?;
        let payload_bytes = read_count(bytes, pos, "payload bytes", u64::MAX >> 1)?;
        if units == 0 {
            return Err(Error::malformed(0, *pos, "the index lists no unit"));
        }
        if entry_bytes < units * MIN_ENTRY_BYTES {
            return Err(Error::malformed(
                0,
                *pos,
                format!("index: {units} units in {entry_bytes} bytes"),
            ));
        }
        Ok(PartialIndex {
            listed: units as usize,
            index: Index {
                units: Vec::new(),
                payload_bytes,
                appearance: None,
                level_parts: Vec::new(),
            },
            children: Vec::new(),
            payload_start: *pos + entry_bytes as usize,
            end: *pos,
            tree: Tree::default(),
        })
    }

    /// The units the index lists for the codec of `header`: all but the appearance unit,
    /// where the header declares one (it is the last).
    pub fn codec_units(&self, header: &Header) -> usize {
        if header.has_level_parts() {
            return self.listed / 2;
        }
        self.listed - header.has_appearance_unit() as usize
    }

    /// True once every entry is read.
    pub fn is_complete(&self) -> bool {
        self.index.units.len() == self.listed
    }

    /// Reads on every whole entry that `bytes` (the stream's first bytes, as many as are
    /// fetched) holds past those read.
    pub fn read_on(&mut self, bytes: &[u8]) -> Result<()> {
        let within = &bytes[..bytes.len().min(self.payload_start)];
        while !self.is_complete() {
            let i = self.index.units.len();
            let at = self.end;
            let mut pos = at;
            let entry =
                read_count(within, &mut pos, "unit length", u64::MAX >> 2).and_then(|length| {
                    Ok((
                        length,
                        read_count(within, &mut pos, "children", limits::MAX_UNITS)?,
                    ))
                });
            let (length, children) = match entry {
                Ok(entry) => entry,
                // Cut where the index ends: its byte count lied.
                Err(Error::Truncated(_)) if within.len() == self.payload_start => {
                    return Err(Error::malformed(
                        0,
                        at,
                        format!("index: entry {i} runs past the index's end"),
                    ))
                }
                // Cut where the bytes fetched end: read on once more are.
                Err(Error::Truncated(_)) => return Ok(()),
                Err(e) => return Err(e),
            };
            let offset = self.index.units.last().map_or(0, UnitEntry::end);
            if length > self.index.payload_bytes - offset {
                return Err(Error::malformed(
                    0,
                    at,
                    format!(
                        "index: unit {i} (bytes {offset}..{}) runs past the {} payload bytes",
                        offset + length,
                        self.index.payload_bytes
                    ),
                ));
            }
            let (parent, children) = self
                .tree
                .take(i, children, self.listed)
                .map_err(|e| Error::malformed(0, at, format!("index: {e}")))?;
            self.children.push(children);
            self.index.units.push(UnitEntry {
                offset,
                length,
                parent,
            });
            self.end = pos;
        }
        // Every entry is read: they must end where the index said.
        if self.end != self.payload_start {
            return Err(Error::malformed(
                0,
                self.end,
                format!(
                    "index: its entries end at byte {}, it says at {}",
                    self.end, self.payload_start
                ),
            ));
        }
        Ok(())
    }

    /// The whole index, once every entry is read: refused if its units leave payload bytes
    /// uncovered.
    pub fn finish(self) -> Result<Index> {
        if !self.is_complete() {
            return Err(Error::Truncated("the stream ends inside its index".into()));
        }
        let covered = self.index.units.last().map_or(0, UnitEntry::end);
        if covered != self.index.payload_bytes {
            return Err(Error::malformed(
                0,
                self.end,
                format!(
                    "index: units cover {covered} of the {} payload bytes it declares",
                    self.index.payload_bytes
                ),
            ));
        }
        Ok(self.index)
    }
}
