//! The modelled coder's decoder: the walker's questions answered from the stream. Each level is
//! its own arithmetic-coded block, so a stream cut inside a level decodes to the level before.

use super::walk::{Question, Side, Stop, Walker};
use crate::codecs::emc::state::FaceCorrections;
use crate::codecs::emc::EmcParams;
use crate::codecs::on_pool;
use crate::codecs::{LevelDecoder, LevelMesh, PassStops};
use crate::coding::arith::{ArithDecoder, BitContext, UintContext};
use crate::coding::varint;
use crate::container::{Header, StreamReader};
use crate::error::{Error, Result};
use crate::mesh::TriMesh;

/// The decoder's side: the level's stream and, in a stream with slabs, the level's slab
/// table and slab streams.
struct DecoderSide<'p> {
    coder: ArithDecoder,
    /// The level's slab table, read from `table_at` on.
    table: &'p [u8],
    table_at: usize,
    /// The slab streams, one after another; the next starts at `streams_at`.
    streams: &'p [u8],
    streams_at: usize,
    /// Byte lengths of the current sliced pass's slab streams.
    lengths: Vec<usize>,
    /// The level's stream while a slab's is read.
    parked: Option<ArithDecoder>,
    /// Whether the slabs of a sliced pass are decoded on threads.
    threads: bool,
}

impl<'p> DecoderSide<'p> {
    /// The side over a level's `payload`: in a stream with slabs (`slabs` > 1) the slab table,
    /// the level's stream and the slab streams (docs/FORMAT.md §7), else the level's stream.
    fn new(payload: &'p [u8], slabs: usize, threads: bool) -> Result<Self, String> {
        let whole = |bytes: &[u8]| {
            ArithDecoder::new(bytes)
                .ok_or_else(|| "level payload is not whole 32-bit words".to_string())
        };
        if slabs < 2 {
            return Ok(DecoderSide::over(whole(payload)?, threads));
        }
        let mut at = 0;
        let mut part = |what: &str| -> Result<&'p [u8], String> {
            let len = varint::get(payload, &mut at)
                .map_err(|_| format!("level's {what} length is cut or too long"))?;
            let bytes = usize::try_from(len)
                .ok()
                .and_then(|len| payload.get(at..at.checked_add(len)?))
                .ok_or_else(|| format!("level's {what} runs past its payload"))?;
            at += bytes.len();
            Ok(bytes)
        };
        let table = part("slab table")?;
        let main = part("stream")?;
        Ok(DecoderSide {
            table,
            streams: &payload[at..],
            ..DecoderSide::over(whole(main)?, threads)
        })
    }

    /// A side reading `coder` alone (no slab table or slab streams yet).
    fn over(coder: ArithDecoder, threads: bool) -> Self {
        DecoderSide {
            coder,
            table: &[],
            table_at: 0,
            streams: &[],
            streams_at: 0,
            lengths: Vec::new(),
            parked: None,
            threads,
        }
    }

    /// An error unless the level's slab table and slab streams were read to their ends.
    fn finish(&self) -> Result<(), Stop> {
        if self.table_at != self.table.len() || self.streams_at != self.streams.len() {
            return Err(Stop::Fault(
                "the level's slab table or slab streams hold more than its passes read".into(),
            ));
        }
        Ok(())
    }

    /// The next slab stream, of `len` bytes.
    fn next_stream(&mut self, len: usize) -> Result<ArithDecoder, Stop> {
        let bytes = &self.streams[self.streams_at..self.streams_at + len];
        self.streams_at += len;
        ArithDecoder::new(bytes)
            .ok_or_else(|| Stop::Fault("a slab stream is not whole 32-bit words".into()))
    }
}

impl Side for DecoderSide<'_> {
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
        _ahead: bool,
    ) -> Result<[bool; 3], Stop> {
        let bits = self.coder.bits3(contexts, index).ok_or(Stop::OutOfBits)?;
        Ok([0, 1, 2].map(|k| bits[k] ^ flips[k]))
    }

    fn begin_sliced_pass(
        &mut self,
        interior: &[Vec<u32>],
        step: Option<usize>,
    ) -> Result<Vec<u32>, Stop> {
        let fault = |what: &str| Stop::Fault(format!("the level's slab table {what}"));
        let mut counts = Vec::with_capacity(interior.len());
        self.lengths.clear();
        let mut left = self.streams.len() - self.streams_at;
        for visits in interior {
            let mut get =
                || varint::get(self.table, &mut self.table_at).map_err(|_| fault("is cut"));
            let (count, len) = (get()?, get()?);
            if count > visits.len() as u64 || step.is_none() && count > 0 {
                return Err(fault("splits more vertices than a slab visits"));
            }
            if len > left as u64 {
                return Err(fault("lists slab streams past the payload's end"));
            }
            left -= len as usize;
            counts.push(count as u32);
            self.lengths.push(len as usize);
        }
        Ok(counts)
    }

    fn slab_sides(&mut self) -> Result<Option<Vec<Self>>, Stop> {
        if !self.threads {
            return Ok(None);
        }
        let lengths = std::mem::take(&mut self.lengths);
        let mut sides = Vec::with_capacity(lengths.len());
        for len in lengths {
            sides.push(DecoderSide::over(self.next_stream(len)?, false));
        }
        Ok(Some(sides))
    }

    fn begin_slab(&mut self, slab: usize) -> Result<(), Stop> {
        let coder = self.next_stream(self.lengths[slab])?;
        self.parked = Some(std::mem::replace(&mut self.coder, coder));
        Ok(())
    }

    fn end_slab(&mut self, _slab: usize) {
        if let Some(coder) = self.parked.take() {
            self.coder = coder;
        }
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
    /// The level whose decoding failed: its passes may have stopped halfway, so neither it
    /// nor any later level is shown.
    failed: Option<usize>,
}

impl<'a> EmcDecoder<'a> {
    pub fn new(stream: StreamReader<'a>, params: EmcParams) -> Self {
        let header = stream.header().clone();
        let mut walker = Walker::new(
            params.order,
            header.vertices,
            params.slabs as usize,
            1 << params.sliced_visits_log2,
        );
        walker.ahead_levels = params.ahead_levels as usize;
        EmcDecoder {
            walker,
            header,
            params,
            stream,
            levels_done: 0,
            settled: None,
            failed: None,
        }
    }

    /// An error once a level failed to decode.
    fn check_failed(&self) -> Result<()> {
        match self.failed {
            Some(level) => Err(Error::malformed(
                level,
                0,
                "an earlier error stopped this level halfway",
            )),
            None => Ok(()),
        }
    }

    /// Decodes the first `passes` (1..=3) passes of the next level, on rayon's pool
    /// ([`on_pool`]: for callers that drive the levels themselves, outside the pool).
    fn decode_passes(&mut self, passes: usize) -> Result<bool> {
        on_pool(|| self.decode_passes_here(passes))
    }

    fn decode_passes_here(&mut self, passes: usize) -> Result<bool> {
        self.check_failed()?;
        // Owned: decoding the level changes the decoder, which may own the stream's bytes.
        let Some(payload) = self.stream.next_level().map(|p| p.to_owned_level()) else {
            return Ok(false);
        };
        let level = self.levels_done + 1;
        let fault = |what: String| Error::malformed(level, payload.start, what);
        let threads = rayon::current_num_threads() > 1;
        let mut side =
            DecoderSide::new(&payload.bytes, self.params.slabs as usize, threads).map_err(fault)?;
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
            side.finish()
        })();
        if outcome.is_err() {
            self.failed = Some(level);
        }
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
    fn extend(&mut self, more: &[u8]) -> Result<bool> {
        self.stream.extend(more)?;
        Ok(true)
    }
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
        on_pool(|| self.mesh_here())
    }

    fn pass_stops(&mut self) -> Option<&mut dyn PassStops> {
        Some(self)
    }

    /// `emc-ahead`'s vertices stand for the representatives their cells went ahead with, which
    /// a split may hand to its new vertex; `emc`'s for the vertex that keeps their id.
    fn representatives(&self) -> Option<Vec<u32>> {
        Some(if self.params.ahead_levels > 0 {
            self.walker.representative.clone()
        } else {
            (0..self.walker.state.len() as u32).collect()
        })
    }
}

impl EmcDecoder<'_> {
    fn mesh_here(&self) -> Result<LevelMesh> {
        self.check_failed()?;
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
}

impl PassStops for EmcDecoder<'_> {
    fn passes_per_level(&self) -> usize {
        3
    }

    fn advance_passes(&mut self, passes: usize) -> Result<bool> {
        self.decode_passes(passes)
    }
}
