//! EMC decoder: the passes of the paper, over the shared [`EmcState`]. A level can be decoded
//! from a cut payload too: every vertex operation is read whole before it is applied, so a cut
//! leaves the state after the last complete operation.

use super::super::state::{EmcState, FaceCorrections, NO_SPLIT};
use super::syntax;
use crate::codecs::{LevelDecoder, LevelMesh, PartialLevels, PassStops};
use crate::coding::BitSource;
use crate::container::{Header, LevelPayload, StreamReader};
use crate::error::{Error, Result};

pub struct EmcDecoder<'a> {
    stream: StreamReader<'a>,
    header: Header,
    state: EmcState,
    levels_done: usize,
    /// The full mesh once the last level's corrections are read.
    final_mesh: Option<LevelMesh>,
}

/// Why a level could not be decoded to its end.
enum Stop {
    /// The bits ran out (a cut payload).
    OutOfBits,
    /// The stream contradicts itself.
    Fault(Error),
}

impl<'a> EmcDecoder<'a> {
    pub fn new(stream: StreamReader<'a>, order: crate::hierarchy::octree::StepOrder) -> Self {
        let header = stream.header().clone();
        EmcDecoder {
            state: EmcState::new(order, header.vertices),
            header,
            stream,
            levels_done: 0,
            final_mesh: None,
        }
    }

    /// Decodes the steps of level `levels_done + 1` from `payload`.
    fn decode_level(&mut self, payload: &LevelPayload) -> Result<(), Stop> {
        self.decode_passes(payload, 3)
    }

    /// Decodes the first `passes` (1..=3) passes of level `levels_done + 1` from `payload`; the
    /// last level's face corrections only after all three.
    fn decode_passes(&mut self, payload: &LevelPayload, passes: usize) -> Result<(), Stop> {
        let order = self.state.order;
        let level = self.levels_done + 1;
        let mut source = BitSource::new(payload.bytes);
        let fault = |what: String| Stop::Fault(Error::malformed(level, payload.start, what));
        for step in 3 * (level - 1)..3 * (level - 1) + passes.min(3) {
            // Vertices that were present before the pass; a cut pass resumes nowhere, so each
            // vertex is checked by its depth.
            let present = self.state.len();
            for v in 0..present {
                if self.state.depth[v] as usize > step {
                    continue;
                }
                if self.state.next_split[v] as usize != step {
                    let bit = source.get(1).ok_or(Stop::OutOfBits)?;
                    self.state.refine(v, step, bit);
                    continue;
                }
                if self.state.len() as u64 >= self.header.vertices {
                    return Err(fault(format!(
                        "more splits than the {} vertices the header declares",
                        self.header.vertices
                    )));
                }
                let connecting = source.get(1).ok_or(Stop::OutOfBits)? == 1;
                let degree = self.state.adjacency[v].len();
                let mut codes = Vec::with_capacity(degree);
                for _ in 0..degree {
                    codes.push(syntax::get_edge(&mut source).ok_or(Stop::OutOfBits)?);
                }
                let mut next = [NO_SPLIT; 2];
                for slot in &mut next {
                    if let Some(d) = syntax::get_distance(&mut source).ok_or(Stop::OutOfBits)? {
                        if step + d >= order.steps() {
                            return Err(fault(format!(
                                "split distance {d} at step {step} passes the last step"
                            )));
                        }
                        *slot = (step + d) as u16;
                    }
                }
                self.state.split(v, step, connecting, &codes, next);
                self.state
                    .check_edges(self.header.triangles)
                    .map_err(fault)?;
            }
        }
        if level == order.levels as usize && passes >= 3 {
            self.read_corrections(&mut source, payload)?;
        }
        Ok(())
    }

    fn read_corrections(
        &mut self,
        source: &mut BitSource,
        payload: &LevelPayload,
    ) -> Result<(), Stop> {
        let level = self.levels_done + 1;
        let fault = |what: String| Stop::Fault(Error::malformed(level, payload.start, what));
        let cliques = self
            .state
            .final_cliques(self.header.vertices, self.header.triangles)
            .map_err(fault)?;
        let false_triangles = syntax::get_list(source, cliques.len()).ok_or(Stop::OutOfBits)?;
        let double_sided = syntax::get_list(source, cliques.len()).ok_or(Stop::OutOfBits)?;
        let orientation_exceptions =
            syntax::get_list(source, cliques.len()).ok_or(Stop::OutOfBits)?;
        let corrections = FaceCorrections {
            false_triangles,
            double_sided,
            orientation_exceptions,
        };
        let mesh = self
            .state
            .corrected_mesh(
                &self.header.grid,
                &cliques,
                &corrections,
                self.header.triangles,
            )
            .map_err(fault)?;
        self.final_mesh = Some(mesh);
        Ok(())
    }
}

impl LevelDecoder for EmcDecoder<'_> {
    fn extend(&mut self, more: &[u8]) -> Result<bool> {
        self.stream.extend(more)?;
        Ok(true)
    }
    fn header(&self) -> &Header {
        &self.header
    }

    fn levels(&self) -> usize {
        self.state.order.levels as usize
    }

    fn levels_decoded(&self) -> usize {
        self.levels_done
    }

    fn advance(&mut self) -> Result<bool> {
        let Some(payload) = self.stream.next_level().map(|p| p.to_owned_level()) else {
            return Ok(false);
        };
        match self.decode_level(&payload.payload()) {
            Ok(()) => {
                self.levels_done += 1;
                Ok(true)
            }
            Err(Stop::Fault(e)) => Err(e),
            Err(Stop::OutOfBits) => Err(Error::malformed(
                self.levels_done + 1,
                payload.start,
                "level payload ends before its last operation",
            )),
        }
    }

    fn mesh(&self) -> Result<LevelMesh> {
        self.state
            .shown_mesh(self.final_mesh.as_ref(), &self.header)
    }

    fn pass_stops(&mut self) -> Option<&mut dyn PassStops> {
        Some(self)
    }

    fn partial_levels(&mut self) -> Option<&mut dyn PartialLevels> {
        Some(self)
    }
}

impl PassStops for EmcDecoder<'_> {
    fn passes_per_level(&self) -> usize {
        3
    }

    fn advance_passes(&mut self, passes: usize) -> Result<bool> {
        let Some(payload) = self.stream.next_level().map(|p| p.to_owned_level()) else {
            return Ok(false);
        };
        match self.decode_passes(&payload.payload(), passes) {
            Ok(()) => Ok(true),
            Err(Stop::Fault(e)) => Err(e),
            Err(Stop::OutOfBits) => Err(Error::malformed(
                self.levels_done + 1,
                payload.start,
                "level payload ends before its last operation",
            )),
        }
    }
}

impl PartialLevels for EmcDecoder<'_> {
    fn advance_partial(&mut self) -> Result<bool> {
        let Some(payload) = self.stream.partial_level().map(|p| p.to_owned_level()) else {
            return Ok(false);
        };
        let before = self.state.depth.iter().map(|&d| d as usize).sum::<usize>();
        match self.decode_level(&payload.payload()) {
            Ok(()) | Err(Stop::OutOfBits) => {}
            Err(Stop::Fault(e)) => return Err(e),
        }
        let after = self.state.depth.iter().map(|&d| d as usize).sum::<usize>();
        Ok(after > before)
    }
}
