//! CAME: Grabner's *Compressed Adaptive Multiresolution Encoding* — a binary vertex hierarchy of
//! any mesh coded compactly enough to be a compression format and completely enough to drive
//! view-dependent refinement (docs/FORMAT.md §8).
//!
//! Based on: M. Grabner, "Compressed Adaptive Multiresolution Encoding", WSCG 2002; the
//! dependencies follow H. Hoppe, "View-dependent refinement of progressive meshes",
//! SIGGRAPH 1997.
//!
//! Glossary (the paper's symbols; the hierarchy's own are in [`crate::hierarchy::came`]):
//! - v_s, v_t, v_u: a split node and its left and right children; d_t = v_t − v_s and
//!   d_u = v_u − v_s its difference vectors.
//! - n1, n2, n3 (n3.up): a triangle's corners as paths relative to the split creating it.
//! - L: levels per meta-node (8); l: depth below the meta-node's root.
//! - d̃ = c·2^(l/2)·d: a normalized difference vector, |d̃| ≤ 1 by the meta-node's constant c;
//!   e1, e2, e3: the eigenvectors of M = (1/N)·Σ dᵢdᵢᵀ, largest eigenvalue first.
//! - q_ij = r_j / r_i: an error-sphere radius ratio, rounded up.
//!
//! The codecs share the hierarchy, the meta-node partition and the decoder:
//! - `came-paper` ([`paper`]): as published — Huffman-coded path lengths before raw path bits,
//!   difference vectors d_t and d_u per split in the meta-node's PCA frame ([`frame`]) at B bits
//!   per component, 2-bit radius ratios; inner nodes at the quadric optimum; lossy.
//! - `came` ([`modelled`]): every element arithmetic-coded with contexts from what the decoder
//!   of the unit already has; inner nodes at a representative vertex, so one integer difference
//!   vector a split and the full decode exactly the canonical mesh.
//!
//! Levels are the depths of the front, coarse to fine: level k shows every node at depth k and
//! every leaf above it, once every meta-node rooted above depth k is decoded.

pub mod decoded;
pub mod frame;
pub mod knowledge;
pub mod modelled;
pub mod paper;
pub mod partition;
pub mod refine;
pub mod selective;

use crate::codecs::{CameField, Stat, Stats};
use crate::container::{Header, LevelCost, StreamWriter};
use crate::error::{Error, Result};
use crate::hierarchy::came::{build, BuildOptions, VertexTree};
use crate::mesh::CanonicalMesh;
use partition::Partition;

/// The bytes each level (front depth) of a CAME stream needs: the front at depth k needs every
/// unit whose splits start above depth k ([`partition::Shape::band`]). Units come in the order
/// their bands deepen (docs/FORMAT.md §8.1), so level k needs the stream up to the end of the
/// last such unit.
pub fn level_ends(stream: &crate::container::StreamReader, params: &Params) -> Result<Vec<u64>> {
    let units = &stream.index().units;
    let shape = params.shape();
    // Per unit: the depth of its root, and of its first splits.
    let mut root_depth: Vec<u8> = Vec::with_capacity(units.len());
    let mut start_depth: Vec<u64> = Vec::with_capacity(units.len());
    for (i, unit) in units.iter().enumerate() {
        let depth = match unit.parent {
            None if i == 0 => 0,
            Some(p) if p < i => shape.band(root_depth[p]).child,
            _ => {
                return Err(Error::malformed(
                    0,
                    stream.payload_start(),
                    format!("unit {i} hangs from no unit before it"),
                ))
            }
        };
        root_depth.push(depth);
        start_depth.push(shape.band(depth).start as u64);
    }
    // The last byte of a unit starting at each depth, then the furthest of those above each
    // level.
    let levels = params.depth as usize;
    let mut last_at_depth = vec![0u64; levels];
    for (unit, &depth) in units.iter().zip(&start_depth) {
        if let Some(last) = last_at_depth.get_mut(depth as usize) {
            *last = (*last).max(unit.end());
        }
    }
    let start = stream.payload_start() as u64;
    let mut furthest = 0;
    Ok(last_at_depth
        .iter()
        .map(|&end| {
            furthest = furthest.max(end);
            start + furthest
        })
        .collect())
}

/// The whole hierarchy of a stream of a codec with selective refinement (either CAME codec),
/// every unit decoded, with its header.
pub fn decode_tree(bytes: &[u8]) -> Result<(Header, decoded::DecodedTree)> {
    let reader = crate::container::StreamReader::open(bytes)?;
    let header = reader.header().clone();
    let tree = refining_codec(&header)?.decode_tree(reader)?;
    Ok((header, tree))
}

/// The codec of the stream of `header`, for view-dependent refinement: an error for a codec
/// whose streams hold no vertex hierarchy.
pub fn refining_codec(header: &Header) -> Result<&'static dyn selective::SelectiveRefinement> {
    let codec = crate::codecs::for_header(header)?;
    codec.selective_refinement().ok_or_else(|| {
        Error::Unsupported(format!(
            "{} streams hold no vertex hierarchy; view-dependent refinement needs a codec with selective refinement (came, came-paper)",
            codec.name()
        ))
    })
}

/// Levels of the hierarchy per meta-node (the paper's L).
pub const META_LEVELS: u8 = 8;

/// A CAME stream's parameters (the header's codec parameters, docs/FORMAT.md §8).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Params {
    /// Levels per meta-node (L).
    pub meta_levels: u8,
    /// Depth of the hierarchy: the number of levels.
    pub depth: u8,
    /// Bits per PCA component (`came-paper`; 0 for `came`).
    pub component_bits: u8,
    /// Bits per radius ratio.
    pub radius_bits: u8,
    /// Bits a coordinate of a normal cone's axis (0: the stream codes no cones).
    pub cone_bits: u8,
    /// Bits of a deviation code (0: the stream codes no deviations, and refinement projects
    /// the spheres).
    pub deviation_bits: u8,
    /// Steps of a triangle normal's octahedral half axis (syntax 4; 0: the stream codes no
    /// triangle normals, `hierarchy::came::face_normals`).
    pub face_normal_steps: u8,
    /// The largest angle between a coded triangle normal and the triangle's, in half-degrees
    /// (`face_normals::bound_code`).
    pub face_normal_bound: u8,
    /// Levels of a unit's region (syntax 5, `partition::Shape::Bands`, whose band is
    /// `meta_levels` deep; 0: meta-nodes of `meta_levels` levels).
    pub region_levels: u8,
}

impl Params {
    /// The header bytes: levels per meta-node, depth, bits per component, bits per radius
    /// ratio; and, with `per_node_bounds` (`came`), the bits of the cones' axes and of the
    /// deviations (0: the stream codes none), then, with triangle normals (syntax 4), their
    /// steps and bound.
    pub fn to_bytes(self, per_node_bounds: bool) -> Vec<u8> {
        let mut bytes = vec![
            self.meta_levels,
            self.depth,
            self.component_bits,
            self.radius_bits,
        ];
        if per_node_bounds {
            bytes.extend([self.cone_bits, self.deviation_bits]);
            if self.face_normal_steps > 0 {
                bytes.extend([self.face_normal_steps, self.face_normal_bound]);
            }
            if self.region_levels > 0 {
                bytes.push(self.region_levels);
            }
        }
        bytes
    }

    /// Parameters from header bytes ([`Self::to_bytes`]); `components`: the range bits per
    /// component may take.
    pub fn from_bytes(
        bytes: &[u8],
        components: std::ops::RangeInclusive<u8>,
        per_node_bounds: bool,
    ) -> Result<Params> {
        let bad = |what: &str| Error::malformed(0, 0, format!("CAME parameters: {what}"));
        let expected: &[usize] = if per_node_bounds { &[6, 8, 9] } else { &[4] };
        if !expected.contains(&bytes.len()) {
            let expected: Vec<String> = expected.iter().map(|n| n.to_string()).collect();
            let expected = expected.join(" or ");
            return Err(bad(&format!("{expected} bytes expected")));
        }
        let (cone_bits, deviation_bits) = match bytes {
            [_, _, _, _, cones, deviations, ..] => (*cones, *deviations),
            _ => (0, 0),
        };
        let (face_normal_steps, face_normal_bound) = match bytes {
            [_, _, _, _, _, _, steps, bound, ..] => (*steps, *bound),
            _ => (0, 0),
        };
        let region_levels = bytes.get(8).copied().unwrap_or(0);
        if region_levels > 16 {
            return Err(bad("region levels outside 0..16"));
        }
        let [meta_levels, depth, component_bits, radius_bits] =
            [bytes[0], bytes[1], bytes[2], bytes[3]];
        if !(1..=16).contains(&meta_levels) {
            return Err(bad("levels per meta-node outside 1..16"));
        }
        if !(1..=crate::hierarchy::came::MAX_DEPTH).contains(&depth) {
            return Err(bad("depth outside 1..52"));
        }
        if !components.contains(&component_bits) {
            return Err(bad("bits per component out of range"));
        }
        if !(1..=8).contains(&radius_bits) {
            return Err(bad("radius bits outside 1..8"));
        }
        Ok(Params {
            meta_levels,
            depth,
            component_bits,
            radius_bits,
            cone_bits,
            deviation_bits,
            face_normal_steps,
            face_normal_bound,
            region_levels,
        })
    }

    /// How the stream's hierarchy is cut into units (what a decoder needs of it).
    pub fn shape(&self) -> partition::Shape {
        if self.region_levels > 0 {
            partition::Shape::Bands {
                region: self.region_levels,
                band: self.meta_levels,
                whole: 0,
            }
        } else {
            partition::Shape::Levels {
                levels: self.meta_levels,
                tails: partition::Tails::Whole,
            }
        }
    }
}

/// A triangle as the split creating it codes it: n1's leaf (under v_t), n2's (under v_u), n3's,
/// and whether the face runs n2, n1, n3 rather than n1, n2, n3.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct BornTriangle {
    /// Leaves of n1, n2, n3.
    pub leaves: [u32; 3],
    /// Orientation: the face is (n2, n1, n3).
    pub flipped: bool,
}

/// The triangles each inner node's split creates, in coding order.
pub fn born_triangles(tree: &VertexTree, mesh: &CanonicalMesh) -> Vec<Vec<BornTriangle>> {
    let mut born = vec![Vec::new(); tree.children.len()];
    for (f, face) in mesh.faces.iter().enumerate() {
        let s = tree.births[f];
        let [t, _] = tree.children_of(s).expect("faces are born at inner nodes");
        let (sid, tid) = (tree.ids[s as usize], tree.ids[t as usize]);
        let under_s = |k: usize| sid.is_ancestor_of(tree.ids[face[k] as usize]);
        let third = (0..3)
            .find(|&k| !under_s(k))
            .expect("one corner lies outside");
        // The face from its third corner on: (third, a, b).
        let (a, b) = (face[(third + 1) % 3], face[(third + 2) % 3]);
        let a_left = tid.is_ancestor_of(tree.ids[a as usize]);
        let (n1, n2) = if a_left { (a, b) } else { (b, a) };
        // (third, n1, n2) is the cyclic order n1, n2, n3 when a is n1.
        born[s as usize - tree.leaves].push(BornTriangle {
            leaves: [n1, n2, face[third]],
            flipped: !a_left,
        });
    }
    for list in &mut born {
        list.sort_unstable();
    }
    born
}

/// Writes the units of `partition` (payloads and costs in unit order) as a stream whose levels
/// are the depths of the front.
fn write_stream(
    header: &Header,
    tree: &VertexTree,
    partition: &Partition,
    units: Vec<(Vec<u8>, LevelCost)>,
) -> (Vec<u8>, Vec<crate::container::LevelRecord>) {
    let depth = tree.depth();
    // Front size and triangles at each depth.
    let mut at_depth = vec![0usize; depth as usize + 2];
    let mut leaves_above = vec![0usize; depth as usize + 2];
    for (i, id) in tree.ids.iter().enumerate() {
        at_depth[id.len() as usize] += 1;
        if tree.is_leaf(i as u32) {
            leaves_above[id.len() as usize + 1] += 1;
        }
    }
    for k in 1..leaves_above.len() {
        leaves_above[k] += leaves_above[k - 1];
    }
    let mut born_above = vec![0usize; depth as usize + 2];
    for &s in &tree.births {
        born_above[tree.ids[s as usize].len() as usize + 1] += 1;
    }
    for k in 1..born_above.len() {
        born_above[k] += born_above[k - 1];
    }
    let mut writer = StreamWriter::new(header);
    let mut next = 0;
    let mut cost = LevelCost::default();
    for k in 1..=depth {
        while next < units.len() && tree.ids[partition.units[next].root as usize].len() < k {
            let (payload, unit_cost) = &units[next];
            writer.push_unit(payload, partition.units[next].parent);
            cost.connectivity_bits += unit_cost.connectivity_bits;
            cost.geometry_bits += unit_cost.geometry_bits;
            next += 1;
        }
        writer.mark_level(LevelCost {
            vertices: at_depth[k as usize] + leaves_above[k as usize],
            triangles: born_above[k as usize],
            ..std::mem::take(&mut cost)
        });
    }
    writer.finish()
}

/// What a CAME coder makes of one unit: its bytes, their bits per syntax class, and per field
/// (named as [`CameField::name`]).
pub type CodedUnit = (
    Vec<u8>,
    crate::coding::BitLedger,
    std::collections::BTreeMap<&'static str, f64>,
);

/// What differs between the CAME codecs' streams: the codec, how meta-nodes end near the
/// leaves, and the bits of components and radius ratios (the header's parameters).
#[derive(Clone, Copy, Debug)]
pub struct Layout {
    /// The codec's id and syntax.
    pub naming: crate::codecs::names::Naming,
    /// Whether the syntax's parameters give the bits of cones and deviations (`came`).
    pub per_node_bounds: bool,
    /// How the hierarchy is built.
    pub build: BuildOptions,
    /// How the hierarchy is cut into units.
    pub shape: partition::Shape,
    /// Bits per PCA component (0: none).
    pub component_bits: u8,
    /// Bits per radius ratio.
    pub radius_bits: u8,
    /// Bits a coordinate of a normal cone's axis (0: no cones).
    pub cone_bits: u8,
    /// Bits of a deviation code (0: no deviations).
    pub deviation_bits: u8,
    /// Steps of a triangle normal's octahedral half axis (0: no triangle normals).
    pub face_normal_steps: u8,
}

/// Encodes `mesh` as a CAME stream: builds the hierarchy, partitions it into meta-nodes, has
/// `code_units` code every unit in stream order (and say the bound of the triangle normals they
/// code, in half-degrees: `hierarchy::came::face_normals`), and writes the stream with its
/// levels and statistics.
pub fn encode_stream(
    mesh: &CanonicalMesh,
    layout: Layout,
    code_units: impl FnOnce(&VertexTree, &Partition) -> (Vec<CodedUnit>, u8),
) -> Result<crate::codecs::Encoded> {
    let started = std::time::Instant::now();
    let tree = hierarchy(mesh, &layout.build)?;
    let seconds = started.elapsed().as_secs_f64();
    let part = partition::partition(&tree, layout.shape);
    let (meta_levels, region_levels) = match layout.shape {
        partition::Shape::Levels { levels, .. } => (levels, 0),
        partition::Shape::Bands { region, band, .. } => (band, region),
    };
    let params = Params {
        meta_levels,
        region_levels,
        depth: tree.depth(),
        component_bits: layout.component_bits,
        radius_bits: layout.radius_bits,
        cone_bits: layout.cone_bits,
        deviation_bits: layout.deviation_bits,
        face_normal_steps: layout.face_normal_steps,
        face_normal_bound: 0,
    };
    let (coded, face_normal_bound) = code_units(&tree, &part);
    let params = Params {
        face_normal_bound,
        ..params
    };
    let mut fields = std::collections::BTreeMap::<&'static str, f64>::new();
    let units: Vec<(Vec<u8>, LevelCost)> = coded
        .into_iter()
        .map(|(bytes, ledger, unit_fields)| {
            for (k, v) in unit_fields {
                *fields.entry(k).or_default() += v;
            }
            let cost = LevelCost {
                connectivity_bits: ledger.connectivity,
                geometry_bits: ledger.geometry,
                ..Default::default()
            };
            (bytes, cost)
        })
        .collect();
    let (bytes, levels) = write_stream(&header(layout, mesh, params), &tree, &part, units);
    let mut stats = Stats::default();
    hierarchy_stats(&tree, &part, seconds, &fields, &mut stats);
    Ok(crate::codecs::Encoded {
        bytes,
        levels,
        stats,
    })
}

/// The error of a unit whose bytes end inside a syntax element (`at`: the unit's offset).
pub fn cut_at(at: usize) -> Error {
    Error::malformed(0, at, "a CAME unit ends inside a syntax element")
}

/// The stream's header for `mesh` and `params`.
fn header(layout: Layout, mesh: &CanonicalMesh, params: Params) -> Header {
    Header {
        codec_id: layout.naming.id,
        syntax: layout.naming.syntax,
        params: params.to_bytes(layout.per_node_bounds),
        grid: mesh.grid,
        vertices: mesh.vertex_count() as u64,
        triangles: mesh.face_count() as u64,
        appearance: None,
    }
}

/// The hierarchy CAME codes, built with `options`, or a refusal for meshes it cannot take.
pub fn hierarchy(mesh: &CanonicalMesh, options: &BuildOptions) -> Result<VertexTree> {
    if mesh.vertex_count() < 3 || mesh.faces.is_empty() {
        return Err(Error::Unsupported(
            "CAME codes meshes of at least one triangle".into(),
        ));
    }
    build(&mesh.cells, &mesh.faces, options)
}

/// Records what every CAME encoder reports.
fn hierarchy_stats(
    tree: &VertexTree,
    partition: &Partition,
    seconds: f64,
    field_bits: &std::collections::BTreeMap<&'static str, f64>,
    stats: &mut Stats,
) {
    stats.set(Stat::HierarchySeconds, seconds);
    for field in CameField::ALL {
        let bits = field_bits.get(field.name()).copied().unwrap_or(0.0);
        stats.set(Stat::CameBits(field), bits);
    }
    stats.set(Stat::HierarchyDepth, tree.depth() as f64);
    stats.set(Stat::MetaNodes, partition.units.len() as f64);
    stats.set(Stat::DependenciesPerNode, tree.dependencies_per_node());
    stats.set(
        Stat::RawDependenciesPerNode,
        tree.raw_dependencies as f64 / tree.children.len().max(1) as f64,
    );
}

#[cfg(test)]
pub(crate) mod tests {
    use crate::codecs::{decode, Stop};
    use crate::mesh::CanonicalMesh;

    /// Prefixes of a stream of `canonical` (a quarter, a half, all but a byte) decode to more
    /// and more levels, never all of them, never more faces than the mesh.
    pub fn check_prefixes(canonical: &CanonicalMesh, bytes: &[u8]) {
        let (_, levels) = decode(bytes, Stop::All).unwrap();
        let mut previous = 0;
        for cut in [bytes.len() / 4, bytes.len() / 2, bytes.len() - 1] {
            let (mesh, got) = decode(&bytes[..cut], Stop::All).unwrap();
            assert!(got >= previous && got < levels, "{got} of {levels}");
            assert!(mesh.mesh.face_count() <= canonical.face_count());
            previous = got;
        }
    }
}
