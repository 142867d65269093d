//! One way from a mesh with its appearance to a stream ([`EncodeRequest`]): the command line's
//! `encode`, the lab's harness and the Python package's `encode` all make this request, so that
//! quantizing the mesh and its appearance, refusing what a codec cannot carry and coding the
//! appearance are written once.

use super::{
    canonical_attributed_for, canonical_for, encode_attributed_with, AttributeFit, Codec,
    EncodeOptions, Encoded,
};
use crate::error::{Error, Result};
use crate::mesh::attribute_quantization::AttributeBits;
use crate::mesh::attributes::AttributedMesh;
use crate::mesh::canonical_attributes::CanonicalAttributes;
use crate::mesh::CanonicalMesh;

/// What to encode a mesh as.
#[derive(Clone, Copy)]
pub struct EncodeRequest<'c> {
    /// The codec.
    pub codec: &'c dyn Codec,
    /// The quantization grid of the positions.
    pub options: EncodeOptions,
    /// How to quantize the appearance, when it is coded; `None`: the mesh has none to code (a
    /// mesh with appearance is refused rather than encoded without it).
    pub appearance: Option<AttributeBits>,
    /// Appearance inside the levels by this rule, for codecs with
    /// [`Capability::AppearanceInLevels`](super::Capability::AppearanceInLevels); `None`: in an
    /// appearance unit after the last level.
    pub in_levels: Option<AttributeFit>,
    /// The appearance in an appearance unit after the last level (docs/FORMAT.md §9) even for
    /// a codec whose own way is another (`emc`, `emc-ahead`: a part after each level): to
    /// measure what that way costs.
    pub appearance_unit: bool,
}

/// What a stream was made of: the canonical mesh, the canonical appearance it carries, the
/// stream.
pub struct EncodedMesh {
    /// The canonical mesh (docs/CONTRACT.md §2): what a lossless codec's full decode is.
    pub canonical: CanonicalMesh,
    /// The canonical appearance the stream carries, if any (CONTRACT §2.1).
    pub appearance: Option<CanonicalAttributes>,
    /// The stream.
    pub encoded: Encoded,
}

impl EncodeRequest<'_> {
    /// `codec` with its default options, geometry alone.
    pub fn geometry(codec: &dyn Codec) -> EncodeRequest<'_> {
        EncodeRequest {
            codec,
            options: codec.default_options(),
            appearance: None,
            in_levels: None,
            appearance_unit: false,
        }
    }

    /// The canonical mesh and appearance the codec is handed for `mesh`.
    pub fn canonical(
        &self,
        mesh: &AttributedMesh,
    ) -> Result<(CanonicalMesh, Option<CanonicalAttributes>)> {
        if mesh.attributes.is_empty() {
            return Ok((canonical_for(&mesh.mesh, &self.options)?, None));
        }
        let Some(bits) = self.appearance else {
            return Err(Error::Unsupported(
                "the mesh has appearance (normals, uvs, colours or materials) that this encode does not code"
                    .into(),
            ));
        };
        bits.check()?;
        let (canonical, appearance) = canonical_attributed_for(mesh, &self.options, bits)?;
        Ok((canonical, Some(appearance).filter(|a| !a.is_empty())))
    }

    /// Encodes what [`canonical`](Self::canonical) made: the codec refuses appearance it
    /// cannot carry.
    pub fn encode_canonical(
        &self,
        canonical: &CanonicalMesh,
        appearance: Option<&CanonicalAttributes>,
    ) -> Result<Encoded> {
        match appearance.filter(|a| !a.is_empty()) {
            Some(appearance) if self.appearance_unit && self.in_levels.is_none() => {
                super::encode_with_appearance_unit(self.codec, canonical, appearance)
            }
            _ => encode_attributed_with(self.codec, canonical, appearance, self.in_levels),
        }
    }

    /// Quantizes `mesh` and its appearance and encodes them; `mesh` is taken so that a large
    /// mesh as read is freed once quantized (a tenth of the peak).
    pub fn encode(&self, mesh: AttributedMesh) -> Result<EncodedMesh> {
        let (canonical, appearance) = self.canonical(&mesh)?;
        drop(mesh);
        let encoded = self.encode_canonical(&canonical, appearance.as_ref())?;
        Ok(EncodedMesh {
            canonical,
            appearance,
            encoded,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::codecs::{by_name, decode, Stop};
    use crate::mesh::generate;

    /// A mesh with appearance: refused without appearance bits, coded with them by a codec
    /// that carries it, refused by one that cannot; without appearance, geometry alone.
    #[test]
    fn appearance_is_coded_or_refused_never_dropped() {
        let torus = generate::torus(1.0, 0.4, 12, 8);
        let mut attributed = AttributedMesh {
            mesh: torus.clone(),
            attributes: Default::default(),
        };
        let faces = torus.faces.len() as u32;
        attributed.attributes.corners = (0..faces).map(|f| [3 * f, 3 * f + 1, 3 * f + 2]).collect();
        attributed.attributes.wedge_vertex = torus.faces.iter().flatten().copied().collect();
        attributed.attributes.colours = Some(vec![[1.0, 0.5, 0.25, 1.0]; 3 * faces as usize]);
        attributed.attributes.validate(&torus).unwrap();

        let emc = by_name("emc").unwrap();
        let geometry = EncodeRequest::geometry(emc);
        let refused = geometry.encode(attributed.clone()).err().unwrap();
        assert!(refused.to_string().contains("does not code"), "{refused}");

        let with = EncodeRequest {
            appearance: Some(AttributeBits::default()),
            ..geometry
        };
        let made = with.encode(attributed.clone()).unwrap();
        assert!(made.appearance.is_some());
        let (full, _) = decode(&made.encoded.bytes, Stop::All).unwrap();
        assert!(full.attributes.is_some());
        assert_eq!(made.canonical.check_lossless(&full.mesh), Ok(()));

        let lossy = EncodeRequest {
            codec: by_name("came-paper").unwrap(),
            ..with
        };
        assert!(lossy.encode(attributed).is_err());

        let plain = AttributedMesh {
            mesh: torus,
            attributes: Default::default(),
        };
        let made = geometry.encode(plain).unwrap();
        assert!(made.appearance.is_none());
    }
}
