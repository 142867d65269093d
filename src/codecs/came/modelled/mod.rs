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
//!
//! Syntax 9 codes a triangle's corner paths only as far as its unit knows the hierarchy: a path
//! stops at the first node the unit created and does not split, and waits there for the unit
//! that splits that node (always one under this unit), which carries it on as steps through
//! splits it knows. A view that reads only coarse units no longer reads the paths' steps below
//! them, and those steps, coded where the shape is known, need no leaf flags.

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
        shape: shape_for(mesh),
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
/// shrink with the regions down to three (docs/notes/benchmarks-history.md, "`came` syntax 8: regions of four
/// levels").
pub const SHAPE: Shape = Shape::Bands {
    region: 4,
    band: 2,
    whole: 256,
};

/// How `came` cuts the hierarchy of a mesh of [`LARGE_MESH_VERTICES`] or more (syntax 9):
/// bands of one level over regions of three, a unit holding the rest of its subtree when that
/// is at most 64 splits, so that a view of part of a large mesh reads small units. Units cost
/// about 21 bytes each in contexts starting afresh, index entries and flushes, which a small
/// mesh's stream feels (bunny.ply would take 30.51 → 32.81 bits a triangle in syntax 8) and a
/// large mesh's views repay (docs/notes/benchmarks-history.md, "`came` syntax 9").
pub const SHAPE_LARGE: Shape = Shape::Bands {
    region: 3,
    band: 1,
    whole: 64,
};

/// The meshes whose `came` streams are cut by [`SHAPE_LARGE`]: those of this many vertices or
/// more.
pub const LARGE_MESH_VERTICES: usize = 1 << 18;

/// How `came` cuts `mesh`'s hierarchy (syntax 9).
pub fn shape_for(mesh: &CanonicalMesh) -> Shape {
    if mesh.vertex_count() >= LARGE_MESH_VERTICES {
        SHAPE_LARGE
    } else {
        SHAPE
    }
}

/// The bands of syntaxes 5 to 7: two levels over regions of six (chosen on the balanced tree
/// of syntaxes 5 and 6: docs/notes/benchmarks-history.md, "`came` syntax 5: units by depth band").
const SHAPE_BEFORE_8: Shape = Shape::Bands {
    region: 6,
    band: 2,
    whole: 256,
};

/// The ways a stream of `syntax` may cut its bands (syntax 5 on; none before).
fn shapes_of(syntax: u8) -> &'static [Shape] {
    match syntax {
        ..=4 => &[],
        5..=7 => &[SHAPE_BEFORE_8],
        8 => &[SHAPE],
        _ => &[SHAPE, SHAPE_LARGE],
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
    // The bands the syntax cuts (syntax 9: a large mesh's otherwise, `shape_for`).
    let shapes = shapes_of(header.syntax);
    let cuts = |shape: &Shape| match *shape {
        Shape::Bands { region, band, .. } => (region, band),
        Shape::Levels { levels, .. } => (0, levels),
    };
    let cut = (params.region_levels, params.meta_levels);
    if !shapes.is_empty() && !shapes.iter().any(|shape| cuts(shape) == cut) {
        let listed: Vec<String> = shapes
            .iter()
            .map(|shape| {
                let (region, band) = cuts(shape);
                let levels = if band == 1 { "level" } else { "levels" };
                format!("bands of {band} {levels} over regions of {region}")
            })
            .collect();
        return Err(Error::malformed(
            0,
            0,
            format!("came streams cut {}", listed.join(" or ")),
        ));
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
