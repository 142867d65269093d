//! What the CAME codecs offer view-dependent refinement ([`Capability::SelectiveRefinement`],
//! reached through [`Codec::selective_refinement`]): a decoder of any unit once its ancestors
//! are, given each unit's bytes wherever they were read, and the whole hierarchy at once. The
//! refinement runtime (`refine`) and the tools ask the codec for these, never its name.
//!
//! [`Capability::SelectiveRefinement`]: crate::codecs::Capability::SelectiveRefinement
//! [`Codec::selective_refinement`]: crate::codecs::Codec::selective_refinement

use super::decoded::{CameDecoder, DecodedTree, DecodedUnit, UnitDecoder};
use super::{modelled, paper};
use crate::container::{Header, Index, PartialIndex, StreamReader};
use crate::error::Result;

/// A codec whose units are meta-nodes of a vertex hierarchy.
pub trait SelectiveRefinement: Sync {
    /// A decoder of the stream of `header` and `index` (its payload at `payload_start`) that is
    /// given each unit's bytes rather than holding the stream.
    fn detached(
        &self,
        header: &Header,
        index: &Index,
        payload_start: usize,
    ) -> Result<Box<dyn DetachedUnits>>;

    /// Every unit of the stream `reader` reads, decoded: the whole hierarchy.
    fn decode_tree(&self, reader: StreamReader<'_>) -> Result<DecodedTree>;
}

/// Either CAME codec's decoder detached from its stream ([`CameDecoder::detached`]).
pub trait DetachedUnits: Send {
    /// Decodes unit `i` from `bytes` (its whole payload), its ancestors decoded, then runs
    /// `check` on what it added; an error from either leaves the tree as it was.
    fn decode_unit_then(
        &mut self,
        i: usize,
        bytes: &[u8],
        check: &mut dyn FnMut(&DecodedUnit) -> Result<()>,
    ) -> Result<()>;

    /// Takes the entries of `index` read since the last call (see
    /// [`CameDecoder::extend_index`]).
    fn extend_index(&mut self, index: &PartialIndex) -> Result<()>;
}

impl<U: UnitDecoder + Send> DetachedUnits for CameDecoder<'static, U> {
    fn decode_unit_then(
        &mut self,
        i: usize,
        bytes: &[u8],
        check: &mut dyn FnMut(&DecodedUnit) -> Result<()>,
    ) -> Result<()> {
        self.decode_unit_checked(i, bytes, check)
    }

    fn extend_index(&mut self, index: &PartialIndex) -> Result<()> {
        CameDecoder::extend_index(self, index)
    }
}

/// A decoder of `units`' syntax detached from the stream of `header` and `index`.
fn detached_with<U: UnitDecoder + Send + 'static>(
    header: &Header,
    index: &Index,
    payload_start: usize,
    params: super::Params,
    units: U,
) -> Result<Box<dyn DetachedUnits>> {
    let decoder =
        CameDecoder::detached(header.clone(), index.clone(), payload_start, params, units);
    Ok(Box::new(decoder?))
}

/// Decodes every unit of `reader` with `units`.
fn whole<U: UnitDecoder>(
    reader: StreamReader<'_>,
    params: super::Params,
    units: U,
) -> Result<DecodedTree> {
    let mut decoder = CameDecoder::new(reader, params, units)?;
    decoder.decode_everything()?;
    Ok(decoder.into_tree())
}

impl SelectiveRefinement for modelled::Came {
    fn detached(
        &self,
        header: &Header,
        index: &Index,
        payload_start: usize,
    ) -> Result<Box<dyn DetachedUnits>> {
        let params = modelled::params(header)?;
        detached_with(
            header,
            index,
            payload_start,
            params,
            modelled::ModelledUnits::default(),
        )
    }

    fn decode_tree(&self, reader: StreamReader<'_>) -> Result<DecodedTree> {
        let params = modelled::params(reader.header())?;
        whole(reader, params, modelled::ModelledUnits::default())
    }
}

impl SelectiveRefinement for paper::CamePaper {
    fn detached(
        &self,
        header: &Header,
        index: &Index,
        payload_start: usize,
    ) -> Result<Box<dyn DetachedUnits>> {
        let params = paper::params(header)?;
        detached_with(
            header,
            index,
            payload_start,
            params,
            paper::PaperUnits::default(),
        )
    }

    fn decode_tree(&self, reader: StreamReader<'_>) -> Result<DecodedTree> {
        let params = paper::params(reader.header())?;
        whole(reader, params, paper::PaperUnits::default())
    }
}
