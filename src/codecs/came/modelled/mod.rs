//! `came`: the CAME hierarchy with every syntax element arithmetic-coded, losslessly
//! (docs/FORMAT.md §8.2).
//!
//! Inner nodes sit at their representative vertex (left children followed down), so v_t = v_s
//! and a split codes one integer vector d_u = v_u − v_s, with contexts from the parent's sphere.
//! A unit codes its splits' shape, positions and spheres first (pass 1), then their triangles and
//! dependencies (pass 2), so that paths walk a known shape: no length is coded where the decoder
//! knows where leaves are, and each direction is coded as "towards the child nearer the other
//! corner" where both children's positions are known. Every unit's contexts start from priors
//! the first unit codes, learnt by the encoder over the whole stream (syntax 2, `priors`);
//! in syntax 1 they started afresh, and such streams still decode.
//!
//! The hierarchy is built by quadric error alone (syntax 7, `BuildOptions::QUADRIC_ORDER`), not
//! balanced as the paper's (b = 1, which `came-paper` keeps): a far view's front is then a
//! simplified mesh rather than a tree level. Syntax 7 is read as syntax 6; its streams differ in
//! the tree they hold.
//!
//! Syntax 8 cuts that tree's bands over regions of four levels instead of six ([`SHAPE`]): the
//! deeper tree's far fronts then read fewer and smaller units, and its streams are smaller too.

mod contexts;
mod decoder;
mod encoder;
mod priors;
#[cfg(test)]
mod tests;

use crate::codecs::descriptor::cubic;
use crate::codecs::{CodecFacts, Descriptor};
use contexts::RADIUS_BITS;
pub use decoder::ModelledUnits;
use encoder::Encoder;

use super::decoded::CameDecoder;
use super::partition::Shape;
use super::{encode_stream, Layout, Params};
use crate::codecs::{names, Capability, Codec, Encoded, LevelDecoder, Stats};
use crate::container::{Header, StreamReader};
use crate::error::{Error, Result};
use crate::hierarchy::came::cones::{self};
use crate::hierarchy::came::deviation::DEVIATION_BITS;
use crate::hierarchy::came::face_normals;
use crate::hierarchy::came::{BuildOptions, NodeId};
use crate::mesh::CanonicalMesh;

/// The `came` codec.
pub struct Came;

/// What `Came` is.
const DESCRIPTOR: Descriptor = Descriptor {
    naming: names::CAME,
    summary: "Grabner's compressed vertex hierarchy of any mesh, context-modelled and lossless",
    default_options: cubic(12),
    capabilities: &[Capability::Attributes, Capability::SelectiveRefinement],
    lossless: true,
};

impl Codec for Came {
    fn descriptor(&self) -> &'static Descriptor {
        &DESCRIPTOR
    }

    fn facts(&self, header: &Header) -> CodecFacts {
        CodecFacts {
            normal_cones: params(header).ok().map(|p| p.cone_bits > 0),
            ..CodecFacts::default()
        }
    }

    fn selective_refinement(&self) -> Option<&dyn super::selective::SelectiveRefinement> {
        Some(self)
    }

    fn measure(&self, _stream: &[u8]) -> Result<Stats> {
        Ok(Stats::default())
    }

    fn encode(&self, mesh: &CanonicalMesh) -> Result<Encoded> {
        Ok(encode_with_unit_fields(mesh)?.0)
    }

    fn level_ends(&self, stream: &StreamReader) -> Result<Vec<u64>> {
        super::level_ends(stream, &params(stream.header())?)
    }

    fn decoder<'a>(&self, stream: StreamReader<'a>) -> Result<Box<dyn LevelDecoder + 'a>> {
        let params = params(stream.header())?;
        Ok(Box::new(CameDecoder::new(
            stream,
            params,
            ModelledUnits::default(),
        )?))
    }
}

/// Each unit of a stream: its root, and its bits a field, named as the stream's statistics
/// name them.
pub type UnitFieldBits = Vec<(NodeId, std::collections::BTreeMap<&'static str, f64>)>;

/// `mesh`'s `came` stream, and the root and the bits by field of each of its units, in stream
/// order (the index's): what a view's units hold, for probes
/// (lab/examples/came_unit_fields.rs).
pub fn encode_with_unit_fields(mesh: &CanonicalMesh) -> Result<(Encoded, UnitFieldBits)> {
    let layout = Layout {
        naming: DESCRIPTOR.naming,
        per_node_bounds: true,
        build: BuildOptions::QUADRIC_ORDER,
        shape: SHAPE,
        component_bits: 0,
        radius_bits: RADIUS_BITS,
        cone_bits: cones::AXIS_BITS,
        deviation_bits: DEVIATION_BITS,
        face_normal_steps: face_normals::STEPS,
    };
    let mut fields = Vec::new();
    let encoded = encode_stream(mesh, layout, |tree, part| {
        let encoder = Encoder::new(tree, mesh, part);
        let units = encoder.units();
        let roots = part.units.iter().map(|u| tree.ids[u.root as usize]);
        fields = roots
            .zip(&units)
            .map(|(root, (_, _, f))| (root, f.clone()))
            .collect();
        (units, encoder.face_normal_bound())
    })?;
    Ok((encoded, fields))
}

/// How `came` cuts its hierarchy into units (syntax 8): bands of two levels over regions of
/// four, a unit holding the rest of its subtree when that is at most 256 splits. On the tree
/// built by quadric error alone (syntax 7), regions of six, five, four, three and two read
/// dragon-50k's far view in 7.3%, 7.1%, 5.8%, 6.1% and 6.3% of its stream, and the streams
/// shrink with the regions down to three (BENCHMARKS.md, "`came` syntax 8: regions of four
/// levels").
pub const SHAPE: Shape = Shape::Bands {
    region: 4,
    band: 2,
    whole: 256,
};

/// The bands of syntaxes 5 to 7: two levels over regions of six (chosen on the balanced tree
/// of syntaxes 5 and 6: BENCHMARKS.md, "`came` syntax 5: units by depth band").
const SHAPE_BEFORE_8: Shape = Shape::Bands {
    region: 6,
    band: 2,
    whole: 256,
};

/// How a stream of `syntax` cuts its bands (syntax 5 on).
fn shape_of(syntax: u8) -> Shape {
    if syntax >= 8 {
        SHAPE
    } else {
        SHAPE_BEFORE_8
    }
}

/// A `came` stream's parameters, checked.
pub fn params(header: &Header) -> Result<Params> {
    let params = Params::from_bytes(&header.params, 0..=0, true)?;
    if params.radius_bits != RADIUS_BITS {
        return Err(Error::malformed(
            0,
            0,
            "came streams use 4-bit radius ratios",
        ));
    }
    if ![0, DEVIATION_BITS].contains(&params.deviation_bits) {
        return Err(Error::malformed(
            0,
            0,
            format!("came streams code deviations on {DEVIATION_BITS} bits"),
        ));
    }
    // Syntax 4 adds the triangle normals' steps and bound, syntax 5 the region's levels.
    let with_face_normals = header.syntax >= 4;
    let expected = match header.syntax {
        ..=3 => 6,
        4 => 8,
        _ => 9,
    };
    if header.params.len() != expected {
        return Err(Error::malformed(
            0,
            0,
            format!(
                "came syntax {} has {expected} parameter bytes",
                header.syntax
            ),
        ));
    }
    if let (5.., Shape::Bands { region, band, .. }) = (header.syntax, shape_of(header.syntax)) {
        if params.region_levels != region || params.meta_levels != band {
            return Err(Error::malformed(
                0,
                0,
                format!("came streams cut bands of {band} levels over regions of {region}"),
            ));
        }
    }
    if with_face_normals
        && (params.face_normal_steps != face_normals::STEPS
            || params.face_normal_bound > face_normals::BOUND_HALF_DEGREES_MAX)
    {
        return Err(Error::malformed(
            0,
            0,
            format!(
                "came streams code triangle normals in {} steps within at most 90°",
                face_normals::STEPS
            ),
        ));
    }
    if ![0, cones::AXIS_BITS].contains(&params.cone_bits) {
        return Err(Error::malformed(
            0,
            0,
            format!(
                "came streams code normal cones on {} bits a coordinate",
                cones::AXIS_BITS
            ),
        ));
    }
    Ok(params)
}
