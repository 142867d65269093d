//! Decoding a stream as its bytes arrive (a download, a socket, a browser's `fetch`): each
//! chunk is taken as it comes, and the newest level it completes is handed over. Every codec's
//! decoder takes more bytes ([`LevelDecoder::extend`]) and goes on from the level it stopped at,
//! so the whole stream is decoded once: `raw` and `emc`'s decoders read on, `pm`'s applies the
//! new levels' splits, the CAME codecs' decode the new depth band's units into the tree they
//! hold, and appearance (`emc`'s parts, another codec's unit) follows its levels. A decoder
//! that could not take them (none today) would be opened again on the longer prefix for each
//! level handed over.

use super::{decode_with, level_ends, on_pool, open_owned, LevelDecoder, LevelMesh, Stop};
use crate::container::Header;
use crate::error::{Error, Result};

/// A stream decoded chunk by chunk.
#[derive(Default)]
pub struct Progressive {
    /// The bytes taken, while the decoder cannot take them itself.
    bytes: Vec<u8>,
    received: u64,
    /// Where each level ends, once the header and index are in.
    ends: Option<Vec<u64>>,
    /// The decoder, once the header and index are in.
    decoder: Option<Box<dyn LevelDecoder>>,
    /// Whether the decoder takes the chunks itself.
    extends: bool,
    /// Levels handed over so far.
    handed: usize,
}

impl Progressive {
    /// A decoder with no bytes yet.
    pub fn new() -> Progressive {
        Progressive::default()
    }

    /// Takes the next chunk; returns the newest level it completed (the mesh and its number),
    /// or `None` when it completed none. Levels completed by one chunk are handed over as one,
    /// the newest.
    pub fn push(&mut self, chunk: &[u8]) -> Result<Option<(LevelMesh, usize)>> {
        self.received += chunk.len() as u64;
        match &mut self.decoder {
            Some(decoder) if self.extends => {
                decoder.extend(chunk)?;
            }
            _ => self.bytes.extend_from_slice(chunk),
        }
        if self.ends.is_none() {
            match level_ends(&self.bytes) {
                Ok(ends) => {
                    let mut decoder = open_owned(self.bytes.clone())?;
                    self.extends = decoder.extend(&[])?;
                    if self.extends {
                        self.bytes = Vec::new();
                    }
                    self.decoder = Some(decoder);
                    self.ends = Some(ends);
                }
                Err(Error::Truncated(_)) => return Ok(None),
                Err(e) => return Err(e),
            }
        }
        let ends = self.ends.as_deref().unwrap_or_default();
        let complete = ends.iter().take_while(|&&e| e <= self.received).count();
        if complete <= self.handed {
            return Ok(None);
        }
        if !self.extends {
            // Opened again on everything received: it decodes from the first level.
            self.decoder = Some(open_owned(self.bytes.clone())?);
        }
        let decoder = self.decoder.as_mut().expect("opened with the index");
        let (mesh, level) = on_pool(|| decode_with(decoder.as_mut(), Stop::Levels(complete)))?;
        self.handed = level;
        Ok(Some((mesh, level)))
    }

    /// The stream's header, once it is in.
    pub fn header(&self) -> Option<&Header> {
        self.decoder.as_ref().map(|d| d.header())
    }

    /// Bytes taken so far.
    pub fn received(&self) -> u64 {
        self.received
    }

    /// Levels the stream holds (0 until its header and index are in).
    pub fn levels(&self) -> usize {
        self.ends.as_ref().map_or(0, Vec::len)
    }

    /// Levels handed over so far.
    pub fn level(&self) -> usize {
        self.handed
    }

    /// Whether each level is decoded once (the decoder takes the chunks itself), rather than
    /// from the first level at each hand-over.
    pub fn incremental(&self) -> bool {
        self.extends
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::codecs::decode;
    use crate::codecs::golden;

    /// Streams of every codec with the appearance in one unit after the last level (a textured
    /// cube with seams), where the codec can carry it.
    fn streams_with_an_appearance_unit() -> Vec<(String, Vec<u8>)> {
        use crate::codecs::{by_name, canonical_attributed_for, encode_with_appearance_unit};
        use crate::mesh::attribute_quantization::AttributeBits;
        let cube = crate::mesh::generate::textured_cube(6);
        ["raw", "pm", "pm-reordered", "came", "emc-paper"]
            .into_iter()
            .map(|name| {
                let codec = by_name(name).unwrap();
                let (canonical, appearance) = canonical_attributed_for(
                    &cube,
                    &codec.default_options(),
                    AttributeBits::default(),
                )
                .unwrap();
                let encoded = encode_with_appearance_unit(codec, &canonical, &appearance).unwrap();
                (format!("{name} with an appearance unit"), encoded.bytes)
            })
            .collect()
    }

    /// Every level handed over is the level `decode` makes of the same prefix, bit for bit,
    /// whatever the chunks; the last is the full mesh; every codec's decoder goes on from the
    /// level before (incremental), appearance included.
    #[test]
    fn levels_fed_in_chunks_are_the_levels_of_the_prefix() {
        let mut streams: Vec<(String, Vec<u8>)> = [
            "v8/emc-eight.mc",
            "v8/emc-ahead-eight.mc",
            "v8/emc-paper-beethoven.mc",
            "v8/raw-eight.mc",
            "v8/pm-eight.mc",
            "v8/pm-reordered-eight.mc",
            "v8/pm-reordered-spot-appearance-fit.mc",
            "v8/came-eight.mc",
            "v8/came-paper-eight.mc",
            "v8/emc-spot-appearance.mc",
        ]
        .into_iter()
        .map(|name| (name.to_string(), golden(name)))
        .collect();
        streams.extend(streams_with_an_appearance_unit());
        for (name, bytes) in &streams {
            // `raw` has one level; every other stream has levels to hand over one by one.
            let levels = crate::codecs::StreamInfo::of(bytes).unwrap().levels;
            assert!(
                levels > 2 || name.contains("raw"),
                "{name}: {levels} levels"
            );
            for chunk in [1, 7, 100, 4096] {
                let mut progressive = Progressive::new();
                let mut last = 0;
                for (k, piece) in bytes.chunks(chunk).enumerate() {
                    let received = ((k + 1) * chunk).min(bytes.len());
                    if let Some((mesh, level)) = progressive.push(piece).unwrap() {
                        assert!(level > last, "{name}: level {level} after {last}");
                        last = level;
                        let (expected, _) =
                            decode(&bytes[..received], Stop::Levels(level)).unwrap();
                        assert_eq!(
                            mesh.mesh.positions, expected.mesh.positions,
                            "{name} level {level}"
                        );
                        assert_eq!(mesh.mesh.faces, expected.mesh.faces, "{name} level {level}");
                        assert_eq!(mesh.attributes, expected.attributes, "{name} level {level}");
                    }
                }
                assert_eq!(
                    last,
                    progressive.levels(),
                    "{name}: every level handed over"
                );
                assert!(progressive.incremental(), "{name}");
                assert_eq!(progressive.received(), bytes.len() as u64);
            }
        }
    }

    /// Bytes past the stream's end are an error; a corrupt stream fed in chunks ends as
    /// `decode` ends on it whole: in the same error, or the same mesh.
    #[test]
    fn bytes_past_the_end_are_an_error_and_corrupt_streams_end_as_decode_ends() {
        let bytes = golden("v8/emc-eight.mc");
        let mut progressive = Progressive::new();
        progressive.push(&bytes).unwrap();
        let e = progressive.push(&[0]).unwrap_err().to_string();
        assert!(e.contains("after the last unit"), "{e}");
        for (name, at) in [
            ("v8/emc-eight.mc", 0.9),
            ("v8/emc-beethoven.mc", 0.5),
            ("v8/emc-beethoven.mc", 0.1),
        ] {
            let mut corrupt = golden(name);
            let k = (corrupt.len() as f64 * at) as usize;
            corrupt[k] ^= 0x5a;
            let whole = decode(&corrupt, Stop::All);
            let mut progressive = Progressive::new();
            let mut fed: Result<Option<(LevelMesh, usize)>> = Ok(None);
            for chunk in corrupt.chunks(64) {
                match progressive.push(chunk) {
                    Ok(None) => {}
                    other => fed = other,
                }
                if fed.is_err() {
                    break;
                }
            }
            match (whole, fed) {
                (Ok((mesh, _)), Ok(Some((fed, _)))) => assert_eq!(mesh, fed, "{name} at {at}"),
                (Err(a), Err(b)) => assert_eq!(a.to_string(), b.to_string(), "{name} at {at}"),
                (whole, fed) => panic!("{name} at {at}: decode {whole:?}, fed in chunks {fed:?}"),
            }
        }
    }
}
