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
/// ([`StreamWriter::mark_level`]).
pub struct StreamWriter {
    header: Header,
    payload: Vec<u8>,
    units: Vec<(u64, Option<usize>)>,
    /// Per level: payload bytes up to its end, and its cost.
    marks: Vec<(u64, LevelCost)>,
}

impl StreamWriter {
    /// Starts a stream with `header`.
    pub fn new(header: &Header) -> Self {
        StreamWriter {
            header: header.clone(),
            payload: Vec::new(),
            units: Vec::new(),
            marks: Vec::new(),
        }
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
        let mut bytes = Vec::with_capacity(self.payload.len() + 64 + 12 * self.units.len());
        self.header.write(&mut bytes);
        Index::back_to_back(self.units.iter().copied()).write(&mut bytes);
        let start = bytes.len();
        bytes.extend_from_slice(&self.payload);
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
            .collect();
        (bytes, records)
    }
}
