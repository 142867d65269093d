//! The modelled coder's decoder: the walker's questions answered from the stream. Each level is
//! its own arithmetic-coded block, so a stream cut inside a level decodes to the level before.

use super::walk::{Question, Side, Stop, Walker};
use crate::codecs::emc::state::FaceCorrections;
use crate::codecs::emc::EmcParams;
use crate::codecs::{LevelDecoder, LevelMesh, PassStops};
use crate::coding::arith::{ArithDecoder, BitContext, UintContext};
use crate::container::{Header, StreamReader};
use crate::error::{Error, Result};
use crate::mesh::TriMesh;

struct DecoderSide {
    coder: ArithDecoder,
}

impl Side for DecoderSide {
    fn code(
        &mut self,
        context: &mut BitContext,
        _question: Question,
        flip: bool,
        _v: usize,
        _step: usize,
    ) -> Result<bool, Stop> {
        Ok(self.coder.bit(context).ok_or(Stop::OutOfBits)? ^ flip)
    }

    fn code3(
        &mut self,
        contexts: &mut [BitContext],
        index: [usize; 3],
        flips: [bool; 3],
        _v: usize,
        _first: usize,
    ) -> Result<[bool; 3], Stop> {
        let bits = self.coder.bits3(contexts, index).ok_or(Stop::OutOfBits)?;
        Ok([0, 1, 2].map(|k| bits[k] ^ flips[k]))
    }
}

/// Reads a list written by [`super::encoder::put_list`]; every entry below `bound`.
fn get_list(
    coder: &mut ArithDecoder,
    context: &mut UintContext,
    bound: usize,
) -> Result<Vec<u32>, Stop> {
    let fault = || Stop::Fault("a face-correction list runs past the triangles".into());
    let len = coder.uint(context).ok_or(Stop::OutOfBits)?;
    if len > bound as u64 {
        return Err(fault());
    }
    let mut list = Vec::with_capacity(len as usize);
    let mut next = 0u64;
    for _ in 0..len {
        let x = next
            .checked_add(coder.uint(context).ok_or(Stop::OutOfBits)?)
            .filter(|&x| x < bound as u64)
            .ok_or_else(fault)?;
        list.push(x as u32);
        next = x + 1;
    }
    Ok(list)
}

/// What the face corrections make final: the full mesh's faces and its edges on no face.
struct SettledFaces {
    faces: Vec<[u32; 3]>,
    loose_edges: Vec<[u32; 2]>,
}

pub struct EmcDecoder<'a> {
    stream: StreamReader<'a>,
    header: Header,
    params: EmcParams,
    walker: Walker,
    levels_done: usize,
    /// The mesh's faces and loose edges, once the face corrections are read (every later
    /// level shows them).
    settled: Option<SettledFaces>,
}

impl<'a> EmcDecoder<'a> {
    pub fn new(stream: StreamReader<'a>, params: EmcParams) -> Self {
        let header = stream.header().clone();
        EmcDecoder {
            walker: Walker::new(params.order, header.vertices),
            header,
            params,
            stream,
            levels_done: 0,
            settled: None,
        }
    }

    /// Decodes the first `passes` (1..=3) passes of the next level.
    fn decode_passes(&mut self, passes: usize) -> Result<bool> {
        let Some(payload) = self.stream.next_level() else {
            return Ok(false);
        };
        let level = self.levels_done + 1;
        let fault = |what: String| Error::malformed(level, payload.start, what);
        let coder = ArithDecoder::new(payload.bytes)
            .ok_or_else(|| fault("level payload is not whole 32-bit words".into()))?;
        let mut side = DecoderSide { coder };
        let outcome = (|| {
            self.walker.level(
                &mut side,
                level,
                passes,
                self.header.vertices,
                self.header.triangles,
            )?;
            let decoded = self.walker.state.len() as u64;
            if passes >= 3
                && self.settled.is_none()
                && self
                    .params
                    .corrections_follow(level, decoded, self.header.vertices)
            {
                self.read_corrections(&mut side.coder)?;
            }
            Ok(())
        })();
        match outcome {
            Ok(()) => Ok(true),
            Err(Stop::Fault(what)) => Err(fault(what)),
            Err(Stop::OutOfBits) => {
                Err(fault("level payload ends before its last question".into()))
            }
        }
    }

    fn read_corrections(&mut self, coder: &mut ArithDecoder) -> Result<(), Stop> {
        let state = &self.walker.state;
        let cliques = state
            .final_cliques(self.header.vertices, self.header.triangles)
            .map_err(Stop::Fault)?;
        let [c0, c1, c2] = &mut self.walker.contexts.corrections;
        let corrections = FaceCorrections {
            false_triangles: get_list(coder, c0, cliques.len())?,
            double_sided: get_list(coder, c1, cliques.len())?,
            orientation_exceptions: get_list(coder, c2, cliques.len())?,
        };
        let mesh = self
            .walker
            .state
            .corrected_mesh(
                &self.header.grid,
                &cliques,
                &corrections,
                self.header.triangles,
            )
            .map_err(Stop::Fault)?;
        self.settled = Some(SettledFaces {
            faces: mesh.mesh.faces,
            loose_edges: mesh.loose_edges,
        });
        Ok(())
    }
}

impl LevelDecoder for EmcDecoder<'_> {
    fn header(&self) -> &Header {
        &self.header
    }

    fn levels(&self) -> usize {
        self.walker.state.order.levels as usize
    }

    fn levels_decoded(&self) -> usize {
        self.levels_done
    }

    fn advance(&mut self) -> Result<bool> {
        let advanced = self.decode_passes(3)?;
        self.levels_done += advanced as usize;
        Ok(advanced)
    }

    fn mesh(&self) -> Result<LevelMesh> {
        let grid = &self.header.grid;
        // The full level is exact: its cells' centres.
        let positions = if self.levels_done == self.levels() {
            self.walker.state.positions(grid)
        } else {
            self.walker.shown_positions(grid)
        };
        match &self.settled {
            Some(settled) => Ok(LevelMesh {
                mesh: TriMesh::new(positions, settled.faces.clone()),
                loose_edges: settled.loose_edges.clone(),
                attributes: None,
            }),
            None => self
                .walker
                .state
                .level_mesh_at(positions, self.header.triangles)
                .map_err(Error::Limit),
        }
    }

    fn pass_stops(&mut self) -> Option<&mut dyn PassStops> {
        Some(self)
    }
}

impl PassStops for EmcDecoder<'_> {
    fn passes_per_level(&self) -> usize {
        3
    }

    fn advance_passes(&mut self, passes: usize) -> Result<bool> {
        self.decode_passes(passes)
    }
}
