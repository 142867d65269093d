//! Writing a stream unit by unit, and what each level cost.

use super::*;

/// What a layered encoder reports about one level as it writes it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LevelCost {
    /// Connectivity bits booked in this level alone.
    pub connectivity_bits: u64,
    /// Geometry bits booked in this level alone.
    pub geometry_bits: u64,
    /// Vertices of the mesh after this level.
    pub vertices: usize,
    /// Triangles of the mesh after this level.
    pub triangles: usize,
}

/// One level as the encoder wrote it, with the cost of the stream up to its end.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LevelRecord {
    /// Offset in the stream where this level ends (so bits so far = 8 × end_byte).
    pub end_byte: usize,
    /// Connectivity bits booked in this level and all before it.
    pub connectivity_bits: u64,
    /// Geometry bits booked in this level and all before it.
    pub geometry_bits: u64,
    /// Vertices of the mesh after this level.
    pub vertices: usize,
    /// Triangles of the mesh after this level.
    pub triangles: usize,
}

/// Builds a stream unit by unit: the header and index are written when it finishes. A layered
/// codec pushes one unit per level ([`StreamWriter::push_level`]); a hierarchical one pushes its
/// units with their parents ([`StreamWriter::push_unit`]) and marks where each level ends
/// ([`StreamWriter::mark_level`]). The appearance unit, which follows the last level and is
/// coded over the full level's mesh as decoded, is handed to a writer [`reopen`](Self::reopen)ed
/// on the codec's stream ([`StreamWriter::set_appearance`]) before it finishes.
pub struct StreamWriter {
    header: Header,
    payload: Vec<u8>,
    units: Vec<(u64, Option<usize>)>,
    /// Per level: payload bytes up to its end, and its cost.
    marks: Vec<(u64, LevelCost)>,
    /// The appearance unit, after every other.
    appearance: Option<Vec<u8>>,
    /// The appearance part of each level, after it (docs/FORMAT.md §10).
    level_parts: Vec<Vec<u8>>,
}

impl StreamWriter {
    /// Starts a stream with `header`.
    pub fn new(header: &Header) -> Self {
        StreamWriter {
            header: header.clone(),
            payload: Vec::new(),
            units: Vec::new(),
            marks: Vec::new(),
            appearance: None,
            level_parts: Vec::new(),
        }
    }

    /// A finished stream without appearance opened again, with the levels its encoder
    /// recorded: its header, units and levels, so that it can take an appearance unit.
    pub fn reopen(mut bytes: Vec<u8>, levels: &[LevelRecord]) -> Result<Self> {
        let (header, index, start) = read_header_and_index(&bytes)?;
        if header.appearance.is_some() || index.appearance.is_some() {
            return Err(Error::Unsupported(
                "the stream already carries appearance".into(),
            ));
        }
        let laid_out = Index::back_to_back(index.units.iter().map(|u| (u.length, u.parent)));
        if laid_out.units != index.units || start + index.payload_bytes as usize != bytes.len() {
            return Err(Error::malformed(
                start,
                bytes.len(),
                "a stream whose units are not laid out back to back cannot be reopened",
            ));
        }
        let mut before = LevelRecord {
            end_byte: start,
            connectivity_bits: 0,
            geometry_bits: 0,
            vertices: 0,
            triangles: 0,
        };
        let mut marks = Vec::with_capacity(levels.len());
        for level in levels {
            if level.end_byte < before.end_byte || level.end_byte > bytes.len() {
                return Err(Error::malformed(
                    start,
                    bytes.len(),
                    "level records outside the stream",
                ));
            }
            let cost = LevelCost {
                connectivity_bits: level.connectivity_bits - before.connectivity_bits,
                geometry_bits: level.geometry_bits - before.geometry_bits,
                vertices: level.vertices,
                triangles: level.triangles,
            };
            marks.push(((level.end_byte - start) as u64, cost));
            before = *level;
        }
        bytes.drain(..start);
        Ok(StreamWriter {
            header,
            payload: bytes,
            units: index.units.iter().map(|u| (u.length, u.parent)).collect(),
            marks,
            appearance: None,
            level_parts: Vec::new(),
        })
    }

    /// The appearance unit, described by `spec` in the header: it follows the last unit, and
    /// the full level, which a reader needs for the mesh and its appearance, ends with it.
    pub fn set_appearance(&mut self, spec: AppearanceSpec, unit: Vec<u8>) {
        self.header.appearance = Some(spec);
        self.appearance = Some(unit);
    }

    /// The appearance part of every level (docs/FORMAT.md §10), described by `spec` in the
    /// header: each follows its level, which a reader decodes with it. A stream of levels
    /// only, one part a level.
    pub fn set_level_parts(&mut self, spec: AppearanceSpec, parts: Vec<Vec<u8>>) -> Result<()> {
        let layered = self
            .units
            .iter()
            .enumerate()
            .all(|(i, u)| u.1 == i.checked_sub(1));
        if !layered || parts.len() != self.units.len() || self.marks.len() != self.units.len() {
            return Err(Error::Unsupported(
                "appearance parts need a stream of levels, one part a level".into(),
            ));
        }
        self.header.appearance = Some(AppearanceSpec {
            level_parts: true,
            ..spec
        });
        self.level_parts = parts;
        Ok(())
    }

    /// Appends one level's payload and what it cost: a unit whose parent is the level before.
    pub fn push_level(&mut self, payload: &[u8], cost: LevelCost) {
        let parent = self.units.len().checked_sub(1);
        self.push_unit(payload, parent);
        self.mark_level(cost);
    }

    /// Appends one unit that depends on unit `parent` (an earlier one), or on none; returns its
    /// number.
    pub fn push_unit(&mut self, payload: &[u8], parent: Option<usize>) -> usize {
        debug_assert!(parent.is_none_or(|p| p < self.units.len()));
        self.payload.extend_from_slice(payload);
        self.units.push((payload.len() as u64, parent));
        self.units.len() - 1
    }

    /// Ends a level after the units pushed so far; `cost` is what this level added.
    pub fn mark_level(&mut self, cost: LevelCost) {
        self.marks.push((self.payload.len() as u64, cost));
    }

    /// The stream and, for each level, where it ends and what the stream cost up to there.
    pub fn finish(self) -> (Vec<u8>, Vec<LevelRecord>) {
        if !self.level_parts.is_empty() {
            return self.finish_with_level_parts();
        }
        let appearance_bytes = self.appearance.as_ref().map_or(0, Vec::len);
        let mut bytes =
            Vec::with_capacity(self.payload.len() + appearance_bytes + 64 + 12 * self.units.len());
        self.header.write(&mut bytes);
        let mut index = Index::back_to_back(self.units.iter().copied());
        if let Some(unit) = &self.appearance {
            index.appearance = Some(UnitEntry {
                offset: index.payload_bytes,
                length: unit.len() as u64,
                parent: index.units.len().checked_sub(1),
            });
            index.payload_bytes += unit.len() as u64;
        }
        index.write(&mut bytes);
        let start = bytes.len();
        bytes.extend_from_slice(&self.payload);
        if let Some(unit) = &self.appearance {
            bytes.extend_from_slice(unit);
        }
        let (mut connectivity, mut geometry) = (0, 0);
        let records = self
            .marks
            .iter()
            .map(|&(end, cost)| {
                connectivity += cost.connectivity_bits;
                geometry += cost.geometry_bits;
                LevelRecord {
                    end_byte: start + end as usize,
                    connectivity_bits: connectivity,
                    geometry_bits: geometry,
                    vertices: cost.vertices,
                    triangles: cost.triangles,
                }
            })
            .collect::<Vec<_>>();
        let mut records = records;
        // The full level is what a reader needs for the mesh and its appearance.
        if let (Some(_), Some(last)) = (&self.appearance, records.last_mut()) {
            last.end_byte = bytes.len();
        }
        (bytes, records)
    }

    /// [`Self::finish`] for a stream of levels each followed by its appearance part.
    fn finish_with_level_parts(self) -> (Vec<u8>, Vec<LevelRecord>) {
        let mut bytes = Vec::new();
        self.header.write(&mut bytes);
        let mut index = Index::back_to_back([]);
        let mut payload = Vec::with_capacity(self.payload.len());
        let mut level_start = 0;
        for ((length, parent), part) in self.units.iter().zip(&self.level_parts) {
            let level = &self.payload[level_start..level_start + *length as usize];
            level_start += level.len();
            for (unit, bytes) in [(&mut index.units, level), (&mut index.level_parts, part)] {
                unit.push(UnitEntry {
                    offset: payload.len() as u64,
                    length: bytes.len() as u64,
                    parent: *parent,
                });
                payload.extend_from_slice(bytes);
            }
        }
        index.payload_bytes = payload.len() as u64;
        index.write(&mut bytes);
        let start = bytes.len();
        bytes.extend_from_slice(&payload);
        let (mut connectivity, mut geometry) = (0, 0);
        let records = self
            .marks
            .iter()
            .zip(&index.level_parts)
            .map(|(&(_, cost), part)| {
                connectivity += cost.connectivity_bits;
                geometry += cost.geometry_bits;
                LevelRecord {
                    end_byte: start + part.end() as usize,
                    connectivity_bits: connectivity,
                    geometry_bits: geometry,
                    vertices: cost.vertices,
                    triangles: cost.triangles,
                }
            })
            .collect();
        (bytes, records)
    }
}
