//! `came`: the CAME hierarchy with every syntax element arithmetic-coded, losslessly
//! (docs/FORMAT.md §8.2).
//!
//! Inner nodes sit at their representative vertex (left children followed down), so v_t = v_s
//! and a split codes one integer vector d_u = v_u − v_s, with contexts from the parent's sphere.
//! A unit codes its splits' shape, positions and spheres first (pass 1), then their triangles and
//! dependencies (pass 2), so that paths walk a known shape: no length is coded where the decoder
//! knows where leaves are, and each direction is coded as "towards the child nearer the other
//! corner" where both children's positions are known. Contexts start afresh in every unit.

use super::decoded::{CameDecoder, DecodedTree, Triangle, UnitDecoder};
use super::knowledge::Status;
use super::partition::{Partition, Tails};
use super::{born_triangles, cut_at, encode_stream, BornTriangle, Layout, Params};
use crate::codecs::{names, Capability, Codec, EncodeOptions, Encoded, LevelDecoder, Stats};
use crate::coding::arith::{ArithDecoder, ArithEncoder, BitContext, IntContext, UintContext};
use crate::coding::SyntaxClass;
use crate::container::{Header, StreamReader};
use crate::error::{Error, Result};
use crate::hierarchy::came::cones::{self, coded_cones, CodedCone, ANGLE_BITS, NO_CONE};
use crate::hierarchy::came::deviation::{
    decoded_deviation, deviation_code, deviations, round_up, DEVIATION_BITS,
};
use crate::hierarchy::came::spheres::{decoded_radius, exact_radii, ratio_base, ratio_code};
use crate::hierarchy::came::{NodeId, VertexTree};
use crate::mesh::attribute_quantization::octahedral_max;
use crate::mesh::quantize::GridShape;
use crate::mesh::CanonicalMesh;

/// Bits of a radius ratio.
const RADIUS_BITS: u8 = 4;
/// Depth contexts (paths are at most 52 bits).
const DEPTHS: usize = 53;
/// Magnitude classes of the parent's radius, for the difference vector's contexts.
const SCALES: usize = 40;

/// Path kinds, for the direction contexts.
#[derive(Clone, Copy)]
enum Kind {
    N1 = 0,
    N2 = 1,
    N3 = 2,
    Dependency = 3,
}

/// The `came` codec.
pub struct Came;

/// Every adaptive context of one unit.
struct Contexts {
    whole: BitContext,
    leaf_child: Vec<[BitContext; 2]>,
    /// Per class of the parent's radius, made when first used: a unit meets only a few of the
    /// classes, and each is 3 KB of contexts to set up.
    coordinate: Vec<Option<Box<[IntContext; 3]>>>,
    ratio: [Vec<BitContext>; 2],
    /// One tree for both children (two by side, or by the left child's code, cost more:
    /// units are too small to learn them).
    deviation: Vec<BitContext>,
    triangles: [UintContext; 4],
    up: UintContext,
    towards: [BitContext; 4],
    blind: [BitContext; 4],
    leaf_on_path: Vec<BitContext>,
    orientation: [BitContext; 3],
    dependencies: UintContext,
    dependency_on: UintContext,
    dependency_rise: UintContext,
    dependency_up: UintContext,
    stop: [BitContext; 16],
    /// Per class of the parent's cone ([`cone_class`]): the half-angle code's tree; the two
    /// coordinates of an axis of its own (differences from the square's centre).
    cone_angle: Vec<Vec<BitContext>>,
    cone_axis: [IntContext; 2],
}

impl Contexts {
    fn new() -> Contexts {
        Contexts {
            whole: BitContext::default(),
            leaf_child: vec![[BitContext::default(); 2]; DEPTHS],
            coordinate: vec![None; SCALES],
            ratio: [
                vec![BitContext::default(); 1 << RADIUS_BITS],
                vec![BitContext::default(); 1 << RADIUS_BITS],
            ],
            deviation: vec![BitContext::default(); 1 << DEVIATION_BITS],
            triangles: Default::default(),
            up: UintContext::default(),
            towards: [BitContext::default(); 4],
            blind: [BitContext::default(); 4],
            leaf_on_path: vec![BitContext::default(); DEPTHS],
            orientation: [BitContext::default(); 3],
            dependencies: UintContext::default(),
            dependency_on: UintContext::default(),
            dependency_rise: UintContext::default(),
            dependency_up: UintContext::default(),
            stop: [BitContext::default(); 16],
            cone_angle: vec![vec![BitContext::default(); 1 << ANGLE_BITS]; CONE_CLASSES],
            cone_axis: Default::default(),
        }
    }
}

impl Contexts {
    /// The difference vector's contexts for radius class `class`.
    fn coordinates(&mut self, class: usize) -> &mut [IntContext; 3] {
        self.coordinate[class].get_or_insert_with(Default::default)
    }
}

/// The context class of a parent radius: its bit length.
fn scale(radius: f64) -> usize {
    let r = radius.ceil().min(u64::MAX as f64) as u64;
    ((64 - r.leading_zeros()) as usize).min(SCALES - 1)
}

/// Which child (true: v_u) lies nearer `target`; ties go to v_t.
fn nearer(children: [[f64; 3]; 2], target: [f64; 3]) -> bool {
    let d = |p: [f64; 3]| {
        (p[0] - target[0]).powi(2) + (p[1] - target[1]).powi(2) + (p[2] - target[2]).powi(2)
    };
    d(children[1]) < d(children[0])
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// Context classes of a cone: its parent has none, or the parent's half-angle code + 1 (a
/// child's faces are some of its parent's, so its cone is mostly as narrow or narrower).
const CONE_CLASSES: usize = 1 + NO_CONE as usize;

fn cone_class(parent: CodedCone) -> usize {
    if (parent.angle as u32) < NO_CONE {
        1 + parent.angle as usize
    } else {
        0
    }
}

/// Codes a node's cone: its half-angle code, then, unless its parent has a cone (whose axis
/// it takes), its axis.
fn put_cone(enc: &mut ArithEncoder, ctx: &mut Contexts, parent: CodedCone, cone: CodedCone) {
    let class = cone_class(parent);
    let g = SyntaxClass::Geometry;
    put_symbol(
        enc,
        &mut ctx.cone_angle[class],
        cone.angle.into(),
        ANGLE_BITS,
        g,
        "cones",
    );
    if (cone.angle as u32) < NO_CONE && class == 0 {
        let centre = octahedral_max(cones::AXIS_BITS) / 2;
        for k in 0..2 {
            let d = cone.axis[k] as i64 - centre as i64;
            enc.int(&mut ctx.cone_axis[k], d, g, "cones");
        }
    }
}

impl Codec for Came {
    fn name(&self) -> &'static str {
        names::CAME.name
    }

    fn id(&self) -> u8 {
        names::CAME.id
    }

    fn summary(&self) -> &'static str {
        "Grabner's compressed vertex hierarchy of any mesh, context-modelled and lossless"
    }

    fn default_options(&self) -> EncodeOptions {
        EncodeOptions {
            quant_bits: 12,
            grid: GridShape::Cubic,
        }
    }

    fn capabilities(&self) -> &'static [Capability] {
        &[Capability::Attributes]
    }

    fn measure(&self, _stream: &[u8]) -> Result<Stats> {
        Ok(Stats::default())
    }

    fn encode(&self, mesh: &CanonicalMesh) -> Result<Encoded> {
        let layout = Layout {
            id: self.id(),
            tails: Tails::Whole,
            component_bits: 0,
            radius_bits: RADIUS_BITS,
            cone_bits: cones::AXIS_BITS,
            deviation_bits: DEVIATION_BITS,
        };
        encode_stream(mesh, layout, |tree, part| {
            let encoder = Encoder::new(tree, mesh, part);
            (0..part.units.len()).map(|m| encoder.unit(m)).collect()
        })
    }

    fn level_ends(&self, stream: &StreamReader) -> Result<Vec<u64>> {
        super::level_ends(stream, &params(stream.header())?)
    }

    fn decoder<'a>(&self, stream: StreamReader<'a>) -> Result<Box<dyn LevelDecoder + 'a>> {
        let params = params(stream.header())?;
        Ok(Box::new(CameDecoder::new(stream, params, ModelledUnits)?))
    }
}

/// A `came` stream's parameters, checked.
pub fn params(header: &Header) -> Result<Params> {
    let params = Params::from_bytes(&header.params, 0..=0)?;
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

/// What the encoder derives once for all units.
struct Encoder<'a> {
    tree: &'a VertexTree,
    part: &'a Partition,
    grid_bits: u8,
    /// Position of each node: its representative vertex.
    positions: Vec<[f64; 3]>,
    /// The decoder's (rounded-up) sphere radii, and each inner non-root node's ratio code.
    radii: Vec<f64>,
    ratio_codes: Vec<u32>,
    /// The decoder's (rounded-up) deviations, and each inner non-root node's deviation code.
    deviations: Vec<f32>,
    deviation_codes: Vec<u32>,
    /// Each node's normal cone as coded.
    cones: Vec<CodedCone>,
    born: Vec<Vec<BornTriangle>>,
}

impl<'a> Encoder<'a> {
    fn new(tree: &'a VertexTree, mesh: &CanonicalMesh, part: &'a Partition) -> Encoder<'a> {
        let n = tree.leaves;
        let leaf: Vec<[f64; 3]> = mesh.cells.iter().map(|c| c.map(|x| x as f64)).collect();
        let positions: Vec<[f64; 3]> = (0..tree.node_count() as u32)
            .map(|v| leaf[tree.representative(v) as usize])
            .collect();
        let exact = exact_radii(&leaf, &tree.children, &positions);
        let mut radii = vec![0.0; tree.node_count()];
        let mut ratio_codes = vec![0; tree.node_count()];
        radii[tree.root as usize] = exact[tree.root as usize].ceil();
        for s in tree.breadth_first() {
            let [t, u] = tree.children_of(s).expect("inner");
            for c in [t, u] {
                if (c as usize) >= n {
                    let base = ratio_base(
                        radii[s as usize],
                        positions[s as usize],
                        positions[c as usize],
                    );
                    let code = ratio_code(exact[c as usize], base, RADIUS_BITS);
                    radii[c as usize] = decoded_radius(code, base, RADIUS_BITS);
                    ratio_codes[c as usize] = code;
                }
            }
        }
        let measured = deviations(tree, &leaf, &mesh.faces, &positions);
        let mut deviations = vec![0.0f32; tree.node_count()];
        let mut deviation_codes = vec![0; tree.node_count()];
        deviations[tree.root as usize] = round_up(measured[tree.root as usize].ceil());
        for s in tree.breadth_first() {
            let [t, u] = tree.children_of(s).expect("inner");
            for c in [t, u] {
                if (c as usize) >= n {
                    let parent = deviations[s as usize];
                    let code = deviation_code(measured[c as usize], parent);
                    deviations[c as usize] = decoded_deviation(code, parent);
                    deviation_codes[c as usize] = code;
                }
            }
        }
        let cones = coded_cones(tree, &mesh.cells, &mesh.faces, mesh.grid.cell);
        Encoder {
            tree,
            part,
            grid_bits: mesh.grid.bits,
            positions,
            radii,
            ratio_codes,
            deviations,
            deviation_codes,
            cones,
            born: born_triangles(tree, mesh),
        }
    }

    fn status(&self, x: u32, unit: NodeId) -> Status {
        self.part.knowledge.status(x, self.tree.is_leaf(x), unit)
    }

    /// Codes unit `m`: its bytes, ledger and bits per field.
    fn unit(
        &self,
        m: usize,
    ) -> (
        Vec<u8>,
        crate::coding::BitLedger,
        std::collections::BTreeMap<&'static str, f64>,
    ) {
        let tree = self.tree;
        let meta = &self.part.units[m];
        let unit = tree.ids[meta.root as usize];
        let mut enc = ArithEncoder::default();
        let mut ctx = Contexts::new();
        use SyntaxClass::{Connectivity as C, Geometry as G};
        enc.bit(&mut ctx.whole, meta.whole, C, "connectivity");
        if m == 0 {
            let p = self.positions[tree.root as usize];
            for x in p {
                enc.raw(x as u64, self.grid_bits as u32, G, "coordinates");
            }
            let r = self.radii[tree.root as usize] as u64;
            enc.uint(&mut UintContext::default(), r, G, "spheres");
            let e = self.deviations[tree.root as usize] as u64;
            enc.uint(&mut UintContext::default(), e, G, "deviations");
            let cone = self.cones[tree.root as usize];
            put_cone(&mut enc, &mut ctx, CodedCone::NONE, cone);
        }
        // Pass 1: shape, positions, spheres.
        for &s in &meta.nodes {
            let [t, u] = tree.children_of(s).expect("inner");
            let depth = tree.ids[s as usize].len() as usize + 1;
            for (side, c) in [t, u].into_iter().enumerate() {
                let ctx_leaf = &mut ctx.leaf_child[depth.min(DEPTHS - 1)][side];
                enc.bit(ctx_leaf, tree.is_leaf(c), C, "connectivity");
            }
            let class = scale(self.radii[s as usize]);
            let d = sub(self.positions[u as usize], self.positions[s as usize]);
            for (axis, &x) in d.iter().enumerate() {
                enc.int(
                    &mut ctx.coordinates(class)[axis],
                    x as i64,
                    G,
                    "coordinates",
                );
            }
            for (side, c) in [t, u].into_iter().enumerate() {
                if tree.is_leaf(c) {
                    continue;
                }
                let deviation = self.deviation_codes[c as usize];
                put_symbol(
                    &mut enc,
                    &mut ctx.ratio[side],
                    self.ratio_codes[c as usize],
                    RADIUS_BITS,
                    G,
                    "spheres",
                );
                put_symbol(
                    &mut enc,
                    &mut ctx.deviation,
                    deviation,
                    DEVIATION_BITS,
                    G,
                    "deviations",
                );
                let (parent, cone) = (self.cones[s as usize], self.cones[c as usize]);
                put_cone(&mut enc, &mut ctx, parent, cone);
            }
        }
        // Pass 2: triangles and dependencies.
        for &s in &meta.nodes {
            let [t, u] = tree.children_of(s).expect("inner");
            let sid = tree.ids[s as usize];
            let born = &self.born[s as usize - tree.leaves];
            let shape = tree.is_leaf(t) as usize * 2 + tree.is_leaf(u) as usize;
            enc.uint(
                &mut ctx.triangles[shape],
                born.len() as u64,
                C,
                "connectivity",
            );
            let mut previous = 0;
            for tri in born {
                let [l1, l2, l3] = tri.leaves;
                let (pt, pu, ps) = (
                    self.positions[t as usize],
                    self.positions[u as usize],
                    self.positions[s as usize],
                );
                self.put_leaf_path(&mut enc, &mut ctx, t, l1, pu, Kind::N1, unit);
                self.put_leaf_path(&mut enc, &mut ctx, u, l2, pt, Kind::N2, unit);
                let junction = tree.ids[l3 as usize].common_len(sid);
                let up = sid.len() - junction;
                enc.uint(&mut ctx.up, up as u64 - 1, C, "connectivity");
                let start = self.other_child(s, up);
                self.put_leaf_path(&mut enc, &mut ctx, start, l3, ps, Kind::N3, unit);
                enc.bit(
                    &mut ctx.orientation[previous],
                    tri.flipped,
                    C,
                    "connectivity",
                );
                previous = 1 + tri.flipped as usize;
            }
            let deps = &tree.dependencies[s as usize - tree.leaves];
            enc.uint(&mut ctx.dependencies, deps.len() as u64, C, "dependencies");
            for &y in deps {
                // Almost always an ancestor of an n3 corner below its junction: which
                // triangle's, and how far above the corner.
                let yid = tree.ids[y as usize];
                let on = born.iter().position(|t| {
                    let leaf = tree.ids[t.leaves[2] as usize];
                    yid.is_ancestor_of(leaf) && yid.len() > leaf.common_len(sid)
                });
                let which = on.unwrap_or(born.len());
                enc.uint(&mut ctx.dependency_on, which as u64, C, "dependencies");
                if let Some(k) = on {
                    let leaf = tree.ids[born[k].leaves[2] as usize];
                    let rise = leaf.len() - yid.len() - 1;
                    enc.uint(&mut ctx.dependency_rise, rise as u64, C, "dependencies");
                    continue;
                }
                let junction = yid.common_len(sid);
                let up = sid.len() - junction;
                enc.uint(&mut ctx.dependency_up, up as u64 - 1, C, "dependencies");
                let start = self.other_child(s, up);
                self.put_dependency_path(&mut enc, &mut ctx, start, y, unit);
            }
        }
        let fields = std::mem::take(&mut enc.field_bits);
        let (bytes, ledger) = enc.finish();
        (bytes, ledger, fields)
    }

    /// The child of s's ancestor `up` levels above that is not on s's path.
    fn other_child(&self, s: u32, up: u8) -> u32 {
        let mut x = s;
        for _ in 1..up {
            x = self.tree.parent[x as usize];
        }
        let j = self.tree.parent[x as usize];
        let [a, b] = self.tree.children_of(j).expect("a junction is inner");
        if a == x {
            b
        } else {
            a
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn put_leaf_path(
        &self,
        enc: &mut ArithEncoder,
        ctx: &mut Contexts,
        start: u32,
        leaf: u32,
        target: [f64; 3],
        kind: Kind,
        unit: NodeId,
    ) {
        let tree = self.tree;
        let lid = tree.ids[leaf as usize];
        let mut x = start;
        let c = SyntaxClass::Connectivity;
        loop {
            let status = self.status(x, unit);
            let depth = tree.ids[x as usize].len();
            match status {
                Status::Leaf => return,
                Status::Unknown => {
                    let is_leaf = tree.is_leaf(x);
                    enc.bit(
                        &mut ctx.leaf_on_path[(depth as usize).min(DEPTHS - 1)],
                        is_leaf,
                        c,
                        "connectivity",
                    );
                    if is_leaf {
                        return;
                    }
                }
                _ => {}
            }
            let [a, b] = tree.children_of(x).expect("paths pass inner nodes");
            let bit = lid.bit(depth);
            if status == Status::Inner {
                let near = nearer(
                    [self.positions[a as usize], self.positions[b as usize]],
                    target,
                );
                enc.bit(
                    &mut ctx.towards[kind as usize],
                    bit == near,
                    c,
                    "connectivity",
                );
            } else {
                enc.bit(&mut ctx.blind[kind as usize], bit, c, "connectivity");
            }
            x = if bit { b } else { a };
        }
    }

    fn put_dependency_path(
        &self,
        enc: &mut ArithEncoder,
        ctx: &mut Contexts,
        start: u32,
        target: u32,
        unit: NodeId,
    ) {
        let tree = self.tree;
        let tid = tree.ids[target as usize];
        let c = SyntaxClass::Connectivity;
        let mut x = start;
        let mut steps = 0usize;
        loop {
            let status = self.status(x, unit);
            enc.bit(&mut ctx.stop[steps.min(15)], x == target, c, "dependencies");
            if x == target {
                return;
            }
            let [a, b] = tree.children_of(x).expect("paths pass inner nodes");
            let bit = tid.bit(tree.ids[x as usize].len());
            if status == Status::Inner {
                let leaves =
                    [self.status(a, unit), self.status(b, unit)].map(|s| s == Status::Leaf);
                if !leaves[0] && !leaves[1] {
                    let near = nearer(
                        [self.positions[a as usize], self.positions[b as usize]],
                        self.positions[start as usize],
                    );
                    enc.bit(
                        &mut ctx.towards[Kind::Dependency as usize],
                        bit == near,
                        c,
                        "dependencies",
                    );
                }
            } else {
                enc.bit(
                    &mut ctx.blind[Kind::Dependency as usize],
                    bit,
                    c,
                    "dependencies",
                );
            }
            x = if bit { b } else { a };
            steps += 1;
        }
    }
}

/// Codes `value` (< 2^bits) bit by bit down a binary tree of contexts.
fn put_symbol(
    enc: &mut ArithEncoder,
    contexts: &mut [BitContext],
    value: u32,
    bits: u8,
    class: SyntaxClass,
    field: &'static str,
) {
    let mut node = 1usize;
    for i in (0..bits).rev() {
        let bit = value >> i & 1 == 1;
        enc.bit(&mut contexts[node], bit, class, field);
        node = node * 2 + bit as usize;
    }
}

fn get_symbol(dec: &mut ArithDecoder, contexts: &mut [BitContext], bits: u8) -> Option<u32> {
    let mut node = 1usize;
    let mut value = 0;
    for _ in 0..bits {
        let bit = dec.bit(&mut contexts[node])?;
        value = value << 1 | bit as u32;
        node = node * 2 + bit as usize;
    }
    Some(value)
}

/// The unit decoder of `came`.
pub struct ModelledUnits;

struct UnitReader<'t> {
    tree: &'t mut DecodedTree,
    dec: ArithDecoder,
    ctx: Contexts,
    unit: NodeId,
    at: usize,
}

impl UnitReader<'_> {
    fn cut(&self) -> Error {
        cut_at(self.at)
    }

    fn bit(&mut self, pick: impl FnOnce(&mut Contexts) -> &mut BitContext) -> Result<bool> {
        let c = pick(&mut self.ctx);
        self.dec.bit(c).ok_or_else(|| cut_at(self.at))
    }

    /// A node's normal cone ([`put_cone`]).
    fn cone(&mut self, parent: CodedCone) -> Result<CodedCone> {
        let class = cone_class(parent);
        let angle = get_symbol(&mut self.dec, &mut self.ctx.cone_angle[class], ANGLE_BITS)
            .ok_or_else(|| cut_at(self.at))?;
        if angle >= NO_CONE {
            return Ok(CodedCone::NONE);
        }
        let angle = angle as u8;
        if class > 0 {
            return Ok(CodedCone {
                axis: parent.axis,
                angle,
            });
        }
        let centre = octahedral_max(cones::AXIS_BITS) / 2;
        let mut axis = [0; 2];
        for (k, a) in axis.iter_mut().enumerate() {
            let d = self
                .dec
                .int(&mut self.ctx.cone_axis[k])
                .ok_or_else(|| cut_at(self.at))?;
            *a = u8::try_from(centre as i64 + d)
                .ok()
                .filter(|&a| u32::from(a) <= octahedral_max(cones::AXIS_BITS))
                .ok_or_else(|| {
                    Error::malformed(0, self.at, "a normal cone's axis leaves its square")
                })?;
        }
        Ok(CodedCone { axis, angle })
    }

    fn uint(
        &mut self,
        pick: impl FnOnce(&mut Contexts) -> &mut UintContext,
        max: u64,
        what: &str,
    ) -> Result<u64> {
        let c = pick(&mut self.ctx);
        let v = self.dec.uint(c).ok_or_else(|| cut_at(self.at))?;
        if v > max {
            return Err(Error::malformed(
                0,
                self.at,
                format!("{what} {v} exceeds {max}"),
            ));
        }
        Ok(v)
    }

    /// The start of a relative path `up` levels above `s`: the junction's other child.
    /// The other child of split `s`'s ancestor `up` levels above it (1: its sibling), by path
    /// and node: decoded, since its parent is an ancestor of `s`, found by walking up the tree.
    fn other_child(&self, s: u32, up: u64) -> Result<(NodeId, u32)> {
        let sid = self.tree.nodes[s as usize].id;
        if up == 0 || up > sid.len() as u64 {
            return Err(Error::malformed(
                0,
                self.at,
                "a relative path goes above the root",
            ));
        }
        let mut x = s;
        for _ in 1..up {
            x = self.tree.nodes[x as usize].parent;
        }
        let junction = self.tree.nodes[x as usize].parent;
        let [a, b] = self.tree.nodes[junction as usize]
            .children
            .expect("an ancestor is split");
        let other = if a == x { b } else { a };
        Ok((self.tree.nodes[other as usize].id, other))
    }

    fn child(&self, x: NodeId, bit: bool) -> Result<NodeId> {
        x.child(bit)
            .ok_or_else(|| Error::malformed(0, self.at, "a path is longer than 52 bits"))
    }

    fn children_positions(&self, i: u32) -> ([u32; 2], [[f64; 3]; 2]) {
        let [a, b] = self.tree.nodes[i as usize]
            .children
            .expect("inner nodes have children");
        (
            [a, b],
            [
                self.tree.nodes[a as usize].position,
                self.tree.nodes[b as usize].position,
            ],
        )
    }

    /// The status and node of child `bit` of a walk's node: its decoded child below a split
    /// this unit knows (no lookup), nothing known below any other.
    fn descend(&self, status: Status, node: Option<u32>, bit: bool) -> (Status, Option<u32>) {
        if status != Status::Inner {
            return (Status::Unknown, None);
        }
        let (children, _) = self.children_positions(node.expect("an inner node is decoded"));
        let child = children[bit as usize];
        (self.tree.status_of(child, self.unit), Some(child))
    }

    /// A leaf's path from `start` (decoded node `known`).
    fn leaf_path(
        &mut self,
        start: NodeId,
        known: u32,
        target: [f64; 3],
        kind: Kind,
    ) -> Result<NodeId> {
        let mut x = start;
        let (mut status, mut node) = (self.tree.status_of(known, self.unit), Some(known));
        loop {
            let depth = x.len() as usize;
            let ends_here = match status {
                Status::Leaf => true,
                Status::Unknown => self.bit(|c| &mut c.leaf_on_path[depth.min(DEPTHS - 1)])?,
                Status::Inner | Status::Open => false,
            };
            if ends_here {
                return Ok(x);
            }
            let bit = if status == Status::Inner {
                let (_, positions) = self.children_positions(node.expect("decoded"));
                let near = nearer(positions, target);
                let towards = self.bit(|c| &mut c.towards[kind as usize])?;
                towards == near
            } else {
                self.bit(|c| &mut c.blind[kind as usize])?
            };
            (status, node) = self.descend(status, node, bit);
            x = self.child(x, bit)?;
        }
    }

    fn dependency_path(&mut self, start: NodeId, known: u32) -> Result<NodeId> {
        let (mut status, mut node) = (self.tree.status_of(known, self.unit), Some(known));
        let start_position = node.map(|i| self.tree.nodes[i as usize].position);
        let mut x = start;
        let mut steps = 0usize;
        loop {
            if status == Status::Leaf {
                return Err(Error::malformed(
                    0,
                    self.at,
                    "a dependency path enters a leaf",
                ));
            }
            if self.bit(|c| &mut c.stop[steps.min(15)])? {
                return Ok(x);
            }
            let bit = if status == Status::Inner {
                let (children, positions) = self.children_positions(node.expect("decoded"));
                let leaves = children.map(|c| self.tree.nodes[c as usize].leaf);
                match leaves {
                    [true, true] => {
                        return Err(Error::malformed(
                            0,
                            self.at,
                            "a dependency path enters a leaf",
                        ))
                    }
                    [true, false] => true,
                    [false, true] => false,
                    [false, false] => {
                        let near = nearer(
                            positions,
                            start_position.expect("an inner node's child is decoded"),
                        );
                        let towards = self.bit(|c| &mut c.towards[Kind::Dependency as usize])?;
                        towards == near
                    }
                }
            } else {
                self.bit(|c| &mut c.blind[Kind::Dependency as usize])?
            };
            (status, node) = self.descend(status, node, bit);
            x = self.child(x, bit)?;
            steps += 1;
        }
    }
}

impl UnitDecoder for ModelledUnits {
    fn decode_unit(
        &self,
        tree: &mut DecodedTree,
        header: &Header,
        params: &Params,
        root: u32,
        bytes: &[u8],
        at: usize,
    ) -> Result<Vec<u32>> {
        let dec = ArithDecoder::new(bytes)
            .ok_or_else(|| Error::malformed(0, at, "a came unit is not a whole number of words"))?;
        let first = tree.nodes.is_empty();
        let unit = if first {
            NodeId::ROOT
        } else {
            tree.nodes[root as usize].id
        };
        let mut r = UnitReader {
            tree,
            dec,
            ctx: Contexts::new(),
            unit,
            at,
        };
        let whole = r.bit(|c| &mut c.whole)?;
        let with_cones = params.cone_bits > 0;
        let with_deviations = params.deviation_bits > 0;
        if first {
            let mut p = [0.0; 3];
            for x in &mut p {
                *x = r.dec.raw(header.grid.bits as u32).ok_or_else(|| r.cut())? as f64;
            }
            let radius = r
                .dec
                .uint(&mut UintContext::default())
                .filter(|&v| v <= 1 << 40)
                .ok_or_else(|| Error::malformed(0, at, "the root's radius is cut or too large"))?
                as f64;
            // Streams without deviations refine by their spheres.
            let deviation = if with_deviations {
                r.dec
                    .uint(&mut UintContext::default())
                    .filter(|&v| v <= 1 << 40)
                    .ok_or_else(|| {
                        Error::malformed(0, at, "the root's deviation is cut or too large")
                    })? as f32
            } else {
                round_up(radius)
            };
            let cone = if with_cones {
                r.cone(CodedCone::NONE)?
            } else {
                CodedCone::NONE
            };
            r.tree.add_root(p, radius, deviation, cone);
        }
        let top = r.tree.nodes[root as usize].id.len();
        let mut queue = vec![root];
        let mut children_units = Vec::new();
        let mut at_node = 0;
        // Pass 1.
        while at_node < queue.len() {
            let s = queue[at_node];
            at_node += 1;
            let node = &r.tree.nodes[s as usize];
            let (sid, ps, rs, parent_cone) = (node.id, node.position, node.radius, node.cone);
            let parent_deviation = node.deviation;
            let depth = sid.len() as usize + 1;
            let mut leaf = [false; 2];
            for (side, l) in leaf.iter_mut().enumerate() {
                *l = r.bit(|c| &mut c.leaf_child[depth.min(DEPTHS - 1)][side])?;
            }
            let class = scale(rs);
            let mut pu = ps;
            for (axis, p) in pu.iter_mut().enumerate() {
                let d = r
                    .dec
                    .int(&mut r.ctx.coordinates(class)[axis])
                    .ok_or_else(|| r.cut())?;
                if d.unsigned_abs() > 1 << 31 {
                    return Err(Error::malformed(
                        0,
                        at,
                        "a difference vector leaves the grid",
                    ));
                }
                *p += d as f64;
            }
            let positions = [ps, pu];
            let mut radii = [0.0; 2];
            let mut deviations = [0.0f32; 2];
            let mut cones = [CodedCone::NONE; 2];
            for side in 0..2 {
                if leaf[side] {
                    continue;
                }
                let base = ratio_base(rs, ps, positions[side]);
                let code = get_symbol(&mut r.dec, &mut r.ctx.ratio[side], RADIUS_BITS)
                    .ok_or_else(|| r.cut())?;
                radii[side] = decoded_radius(code, base, RADIUS_BITS);
                deviations[side] = if with_deviations {
                    let code = get_symbol(&mut r.dec, &mut r.ctx.deviation, DEVIATION_BITS)
                        .ok_or_else(|| r.cut())?;
                    decoded_deviation(code, parent_deviation)
                } else {
                    round_up(radii[side])
                };
                if with_cones {
                    cones[side] = r.cone(parent_cone)?;
                }
            }
            let spheres = [0, 1].map(|side| (radii[side], deviations[side]));
            let children = r.tree.split(s, leaf, positions, spheres, cones, unit, at)?;
            for side in 0..2 {
                if leaf[side] {
                    continue;
                }
                let c = children[side];
                if whole || (depth as u8) < top + params.meta_levels {
                    queue.push(c);
                } else {
                    children_units.push(c);
                }
            }
        }
        // Pass 2.
        let max_triangles = header.triangles;
        for &s in &queue {
            let node = &r.tree.nodes[s as usize];
            let sid = node.id;
            let (children, positions) = r.children_positions(s);
            let ps = node.position;
            let shape = r.tree.nodes[children[0] as usize].leaf as usize * 2
                + r.tree.nodes[children[1] as usize].leaf as usize;
            let count = r.uint(
                |c| &mut c.triangles[shape],
                max_triangles,
                "triangles at a split",
            )?;
            let mut previous = 0;
            let mut thirds = Vec::with_capacity(count as usize);
            for _ in 0..count {
                let [t, u] = children;
                let n1 = r.leaf_path(r.child(sid, false)?, t, positions[1], Kind::N1)?;
                let n2 = r.leaf_path(r.child(sid, true)?, u, positions[0], Kind::N2)?;
                let up = r.uint(|c| &mut c.up, 52, "n3.up")? + 1;
                let (start, start_node) = r.other_child(s, up)?;
                let n3 = r.leaf_path(start, start_node, ps, Kind::N3)?;
                thirds.push((n3, start.len()));
                let flipped = r.bit(|c| &mut c.orientation[previous])?;
                previous = 1 + flipped as usize;
                let corners = if flipped { [n2, n1, n3] } else { [n1, n2, n3] };
                r.tree.add_triangle(
                    Triangle {
                        corners,
                        birth_depth: sid.len(),
                    },
                    at,
                )?;
            }
            let count = r.uint(|c| &mut c.dependencies, 64, "dependencies of a split")?;
            let first = r.tree.dependency_nodes.len();
            for _ in 0..count {
                let which = r.uint(
                    |c| &mut c.dependency_on,
                    thirds.len() as u64,
                    "a dependency's triangle",
                )?;
                if let Some(&(leaf, below)) = thirds.get(which as usize) {
                    // An inner node of the n3 path, from the junction's child down.
                    let rise = r.uint(|c| &mut c.dependency_rise, 52, "a dependency's rise")?;
                    let len = (leaf.len() as u64)
                        .checked_sub(rise + 1)
                        .filter(|&l| l >= below as u64);
                    let Some(len) = len else {
                        return Err(Error::malformed(0, at, "a dependency above its path"));
                    };
                    r.tree.dependency_nodes.push(leaf.ancestor(len as u8));
                    continue;
                }
                let up = r.uint(|c| &mut c.dependency_up, 52, "a dependency's up")? + 1;
                let (start, start_node) = r.other_child(s, up)?;
                let dependency = r.dependency_path(start, start_node)?;
                r.tree.dependency_nodes.push(dependency);
            }
            r.tree.close_dependencies(sid, first);
        }
        Ok(children_units)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::codecs::{canonical_for, decode, Stop};
    use crate::mesh::generate;

    fn stream(mesh: &crate::mesh::TriMesh) -> (CanonicalMesh, Vec<u8>) {
        let canonical = canonical_for(mesh, &Came.default_options()).unwrap();
        let bytes = Came.encode(&canonical).unwrap().bytes;
        (canonical, bytes)
    }

    fn decoder(bytes: &[u8]) -> CameDecoder<'_, ModelledUnits> {
        let reader = StreamReader::open(bytes).unwrap();
        let params = params(reader.header()).unwrap();
        CameDecoder::new(reader, params, ModelledUnits).unwrap()
    }

    #[test]
    fn every_decoded_cone_holds_the_normal_of_every_face_at_its_subtree() {
        let mut mesh = generate::icosphere(3);
        let far = generate::torus(1.0, 0.3, 30, 12);
        mesh.append(&far, glam::DVec3::new(3.0, 0.5, 0.0), 1.0);
        let (canonical, bytes) = stream(&mesh);
        let mut d = decoder(&bytes);
        while d.advance().unwrap() {}
        let tree = d.tree();
        let leaf_at: std::collections::HashMap<[u32; 3], NodeId> = tree
            .nodes
            .iter()
            .filter(|n| n.leaf)
            .map(|n| (n.position.map(|x| x as u32), n.id))
            .collect();
        let cell = glam::DVec3::from_array(canonical.grid.cell);
        let (mut checked, mut with_cone) = (0, 0);
        for face in &canonical.faces {
            let p = face.map(|v| {
                glam::DVec3::from_array(canonical.cells[v as usize].map(f64::from)) * cell
            });
            let normal = (p[1] - p[0]).cross(p[2] - p[0]).normalize();
            for &v in face {
                let leaf = leaf_at[&canonical.cells[v as usize]];
                for len in 0..leaf.len() {
                    let a = &tree.nodes[tree.get(leaf.ancestor(len)).unwrap() as usize];
                    let cone = a.cone.decoded();
                    checked += 1;
                    if !cone.is_some() {
                        continue;
                    }
                    with_cone += 1;
                    let axis = glam::DVec3::from_array(cone.axis.map(f64::from));
                    let off = normal.cross(axis).length().atan2(normal.dot(axis));
                    assert!(off <= cone.half_angle as f64 + 1e-5, "{:?}", a.id);
                }
            }
        }
        assert!(
            with_cone > checked / 4,
            "{with_cone} of {checked} with a cone"
        );
    }

    #[test]
    fn every_sphere_holds_every_vertex_of_its_subtree() {
        let mut mesh = generate::icosphere(4);
        let far = generate::torus(1.0, 0.3, 30, 12);
        mesh.append(&far, glam::DVec3::new(3.0, 0.5, 0.0), 1.0);
        let (_, bytes) = stream(&mesh);
        let mut d = decoder(&bytes);
        while d.advance().unwrap() {}
        let tree = d.tree();
        let mut checked = 0;
        for leaf in tree.nodes.iter().filter(|n| n.leaf) {
            let p = glam::DVec3::from_array(leaf.position);
            for len in 0..leaf.id.len() {
                let a = &tree.nodes[tree.get(leaf.id.ancestor(len)).unwrap() as usize];
                let distance = p.distance(glam::DVec3::from_array(a.position));
                assert!(
                    distance <= a.radius,
                    "{:?}: {distance} > {}",
                    a.id,
                    a.radius
                );
                checked += 1;
            }
        }
        assert!(checked > 10 * tree.nodes.len() / 2);
    }

    #[test]
    fn a_meta_node_decodes_alone_once_its_ancestors_are() {
        let (_, bytes) = stream(&generate::icosphere(5));
        let mut full = decoder(&bytes);
        while full.advance().unwrap() {}
        let reader = StreamReader::open(&bytes).unwrap();
        let units = reader.index().units.clone();
        assert!(units.len() > 8, "{} units", units.len());
        let last = units.len() - 1;
        let mut chain = vec![last];
        while let Some(p) = units[*chain.last().unwrap()].parent {
            chain.push(p);
        }
        chain.reverse();
        let mut alone = decoder(&bytes);
        let e = alone.decode_unit(last).unwrap_err();
        assert!(e.to_string().contains("parent unit decoded first"), "{e}");
        for &i in &chain {
            assert!(alone.decode_unit(i).unwrap());
        }
        let corners = |d: &CameDecoder<'_, ModelledUnits>| -> Vec<[NodeId; 3]> {
            d.unit_triangles(last)
                .unwrap()
                .iter()
                .map(|t| t.corners)
                .collect()
        };
        assert!(!corners(&alone).is_empty());
        assert_eq!(corners(&alone), corners(&full));
        assert!(alone.decode_unit(last).is_err());
    }

    #[test]
    fn prefixes_decode_the_levels_they_hold_and_the_whole_stream_is_exact() {
        let (canonical, bytes) = stream(&generate::icosphere(4));
        let (whole, _) = decode(&bytes, Stop::All).unwrap();
        canonical.check_lossless(&whole.mesh).unwrap();
        crate::codecs::came::tests::check_prefixes(&canonical, &bytes);
    }
}
