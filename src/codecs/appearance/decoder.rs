//! A codec's level decoder with the appearance unit decoded after its last level.

use crate::codecs::{LevelDecoder, LevelMesh, PartialLevels, PassStops};
use crate::container::{AppearanceSpec, Header, StreamReader};
use crate::error::Result;
use crate::mesh::attributes::Attributes;

/// Decodes levels with the codec's decoder; once the last is decoded and the appearance unit is
/// present, decodes it against the full mesh, and every mesh after carries it.
pub struct WithAppearance<'a> {
    inner: Box<dyn LevelDecoder + 'a>,
    spec: AppearanceSpec,
    /// The stream beside the codec's decoder (which took its own reader), growing with it as
    /// bytes arrive: the appearance unit is read from it once wholly present.
    stream: StreamReader<'a>,
    decoded: Option<Attributes>,
}

impl<'a> WithAppearance<'a> {
    /// Wraps `inner`, whose stream `stream` declares `spec` and holds the appearance unit.
    pub fn new(
        inner: Box<dyn LevelDecoder + 'a>,
        spec: AppearanceSpec,
        stream: StreamReader<'a>,
    ) -> Self {
        WithAppearance {
            inner,
            spec,
            stream,
            decoded: None,
        }
    }
}

impl LevelDecoder for WithAppearance<'_> {
    fn header(&self) -> &Header {
        self.inner.header()
    }
    fn levels(&self) -> usize {
        self.inner.levels()
    }
    fn levels_decoded(&self) -> usize {
        self.inner.levels_decoded()
    }
    fn advance(&mut self) -> Result<bool> {
        let advanced = self.inner.advance()?;
        if advanced && self.inner.levels_decoded() == self.inner.levels() {
            if let Some((bytes, unit, start)) = self.stream.appearance_unit() {
                let full = self.inner.mesh()?;
                self.decoded = Some(super::decode(bytes, unit, start, &self.spec, &full.mesh)?);
            }
        }
        Ok(advanced)
    }
    fn mesh(&self) -> Result<LevelMesh> {
        let mut mesh = self.inner.mesh()?;
        mesh.attributes = self.decoded.clone();
        Ok(mesh)
    }
    fn pass_stops(&mut self) -> Option<&mut dyn PassStops> {
        self.inner.pass_stops()
    }
    fn partial_levels(&mut self) -> Option<&mut dyn PartialLevels> {
        self.inner.partial_levels()
    }
    /// The codec's decoder takes the bytes, and the stream beside it keeps them for the
    /// appearance unit; the full level (whose end is the unit's: `level_ends`) decodes it.
    fn extend(&mut self, more: &[u8]) -> Result<bool> {
        if !self.inner.extend(more)? {
            return Ok(false);
        }
        self.stream.extend(more)?;
        Ok(true)
    }
}
