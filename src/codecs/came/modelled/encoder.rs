//! `came`'s encoder: what it derives once for all units (positions, spheres, deviations,
//! cones, the triangles born at each split), then each unit's two passes.

use super::super::knowledge::Status;
use super::super::partition::Partition;
use super::super::{born_triangles, BornTriangle};
use super::contexts::*;
use super::priors::{put_priors, Learning, Priors};
use crate::coding::arith::{ArithEncoder, BitContext, UintContext};
use crate::coding::SyntaxClass;
use crate::hierarchy::came::cones::{self, coded_cones, CodedCone, ANGLE_BITS, NO_CONE};
use crate::hierarchy::came::deviation::{
    anchored_code, anchored_deviation, deviations, round_up, DEVIATION_BITS, FINE_DEVIATION_BITS,
    FINE_DEVIATION_DEPTHS,
};
use crate::hierarchy::came::face_normals::{self, nearest_code, scaled_normal};
use crate::hierarchy::came::spheres::{decoded_radius, exact_radii, ratio_base, ratio_code};
use crate::hierarchy::came::{NodeId, VertexTree};
use crate::mesh::attribute_quantization::octahedral_max;
use crate::mesh::CanonicalMesh;

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

/// What the encoder derives once for all units.
pub(super) struct Encoder<'a> {
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
    /// Per triangle born at each split (`born`'s order): its normal's code
    /// (`hierarchy::came::face_normals`) — nothing where its proxies are its leaves, `None`
    /// for a triangle of no area.
    face_normal_codes: Vec<Vec<Option<Option<[i32; 2]>>>>,
    /// The largest angle between a coded normal and its triangle's, in degrees.
    face_normal_error: f64,
    /// Per unit, in stream order: the corner paths it carries on (syntax 9), by the unit's
    /// split they wait at, in the order they began to wait.
    carried: Vec<Vec<(u32, Vec<Waiting>)>>,
}

/// A corner path waiting at a node for the unit that splits it (syntax 9).
#[derive(Clone, Copy)]
struct Waiting {
    leaf: u32,
    target: [f64; 3],
    kind: Kind,
}

impl<'a> Encoder<'a> {
    pub(super) fn new(
        tree: &'a VertexTree,
        mesh: &CanonicalMesh,
        part: &'a Partition,
    ) -> Encoder<'a> {
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
        // Steps on the grid anchored at the root's deviation (docs/FORMAT.md §8.2).
        let mut steps = vec![0u16; tree.node_count()];
        let root_deviation = round_up(measured[tree.root as usize].ceil());
        deviations[tree.root as usize] = root_deviation;
        for s in tree.breadth_first() {
            let [t, u] = tree.children_of(s).expect("inner");
            let fine = usize::from(tree.ids[s as usize].len()) + 1 < FINE_DEVIATION_DEPTHS;
            for c in [t, u] {
                if (c as usize) >= n && deviations[s as usize] > 0.0 {
                    let (code, step) = anchored_code(
                        measured[c as usize],
                        root_deviation,
                        steps[s as usize],
                        fine,
                    );
                    if code > 0 {
                        deviations[c as usize] = anchored_deviation(root_deviation, step);
                    }
                    steps[c as usize] = step;
                    deviation_codes[c as usize] = code;
                }
            }
        }
        let cones = coded_cones(tree, &mesh.cells, &mesh.faces, mesh.grid.cell);
        let mut encoder = Encoder {
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
            face_normal_codes: Vec::new(),
            face_normal_error: 0.0,
            carried: Vec::new(),
        };
        encoder.code_face_normals(mesh.grid.cell);
        encoder.carried = encoder.waiting_paths();
        encoder
    }

    /// Codes every triangle's normal about its proxies (the first node of each corner's leaf
    /// path whose split its unit does not know), noting the largest angle a code is off by.
    fn code_face_normals(&mut self, cell: [f64; 3]) {
        let tree = self.tree;
        let mut codes = vec![Vec::new(); self.born.len()];
        let mut worst = 0.0f64;
        for meta in &self.part.units {
            let unit = tree.ids[meta.root as usize];
            for &s in &meta.nodes {
                let [t, u] = tree.children_of(s).expect("inner");
                let sid = tree.ids[s as usize];
                let born = &self.born[s as usize - tree.leaves];
                codes[s as usize - tree.leaves] = born
                    .iter()
                    .map(|tri| {
                        let [l1, l2, l3] = tri.leaves;
                        let up = sid.len() - tree.ids[l3 as usize].common_len(sid);
                        let third = self.other_child(s, up);
                        let proxies = [(t, l1), (u, l2), (third, l3)]
                            .map(|(start, leaf)| self.proxy(start, leaf, unit));
                        if proxies.iter().all(|&p| tree.is_leaf(p)) {
                            return None;
                        }
                        let oriented = |p: [u32; 3]| {
                            let p = if tri.flipped { [p[1], p[0], p[2]] } else { p };
                            scaled_normal(p.map(|v| self.positions[v as usize]), cell)
                        };
                        let proxy = oriented(proxies);
                        let normal = oriented(tri.leaves);
                        let code = nearest_code(proxy, normal, face_normals::STEPS);
                        if let Some((_, angle)) = code {
                            worst = worst.max(angle);
                        }
                        Some(code.map(|(code, _)| code))
                    })
                    .collect();
            }
        }
        self.face_normal_codes = codes;
        self.face_normal_error = worst;
    }

    /// The header's bound on the coded normals' error (`face_normals::bound_code`).
    pub(super) fn face_normal_bound(&self) -> u8 {
        face_normals::bound_code(self.face_normal_error)
    }

    /// The first node on the path from `start` to `leaf` that is not an inner node whose
    /// split `unit` knows: the deepest whose position the unit and its ancestors give.
    fn proxy(&self, start: u32, leaf: u32, unit: NodeId) -> u32 {
        let lid = self.tree.ids[leaf as usize];
        let mut x = start;
        while self.status(x, unit) == Status::Inner {
            let [a, b] = self.tree.children_of(x).expect("inner");
            x = if lid.bit(self.tree.ids[x as usize].len()) {
                b
            } else {
                a
            };
        }
        x
    }

    fn status(&self, x: u32, unit: NodeId) -> Status {
        self.part.knowledge.status(x, self.tree.is_leaf(x), unit)
    }

    /// Whether a corner path coded by `unit` stops at `x` to wait (syntax 9): a node the unit
    /// created and whose split another unit codes.
    fn waits_at(&self, x: u32, unit: NodeId) -> bool {
        self.status(x, unit) == Status::Open && self.part.knowledge.created_unit[x as usize] == unit
    }

    /// Where the path from `start` to `leaf` that `unit` codes ends: the leaf, or the node it
    /// waits at (`true`).
    fn path_end(&self, start: u32, leaf: u32, unit: NodeId) -> (u32, bool) {
        let lid = self.tree.ids[leaf as usize];
        let mut x = start;
        while x != leaf {
            if self.waits_at(x, unit) {
                return (x, true);
            }
            let [a, b] = self.tree.children_of(x).expect("paths pass inner nodes");
            x = if lid.bit(self.tree.ids[x as usize].len()) {
                b
            } else {
                a
            };
        }
        (leaf, false)
    }

    /// The three corner paths of a triangle born at `s`: start, leaf, target, kind.
    fn corner_paths(&self, s: u32, tri: &BornTriangle) -> [(u32, u32, [f64; 3], Kind); 3] {
        let tree = self.tree;
        let [t, u] = tree.children_of(s).expect("inner");
        let [l1, l2, l3] = tri.leaves;
        let sid = tree.ids[s as usize];
        let up = sid.len() - tree.ids[l3 as usize].common_len(sid);
        let p = |v: u32| self.positions[v as usize];
        [
            (t, l1, p(u), Kind::N1),
            (u, l2, p(t), Kind::N2),
            (self.other_child(s, up), l3, p(s), Kind::N3),
        ]
    }

    /// Which corner paths each unit carries on (syntax 9): the units in stream order, as a
    /// decoder meets them, each first carrying on the paths waiting at its splits, then coding
    /// its own triangles' paths, every path as far as the unit knows.
    fn waiting_paths(&self) -> Vec<Vec<(u32, Vec<Waiting>)>> {
        let mut waiting: std::collections::HashMap<u32, Vec<Waiting>> = Default::default();
        let mut carried = Vec::with_capacity(self.part.units.len());
        for meta in &self.part.units {
            let unit = self.tree.ids[meta.root as usize];
            let mut here = Vec::new();
            for &s in &meta.nodes {
                if let Some(list) = waiting.remove(&s) {
                    for w in &list {
                        if let (end, true) = self.path_end(s, w.leaf, unit) {
                            waiting.entry(end).or_default().push(*w);
                        }
                    }
                    here.push((s, list));
                }
            }
            for &s in &meta.nodes {
                for tri in &self.born[s as usize - self.tree.leaves] {
                    for (start, leaf, target, kind) in self.corner_paths(s, tri) {
                        if let (end, true) = self.path_end(start, leaf, unit) {
                            let w = Waiting { leaf, target, kind };
                            waiting.entry(end).or_default().push(w);
                        }
                    }
                }
            }
            carried.push(here);
        }
        debug_assert!(waiting.is_empty(), "every waiting path is carried on");
        carried
    }

    /// Codes every unit: its bytes, ledger and bits per field. A first pass over all units with
    /// one set of contexts learns the priors (docs/FORMAT.md §8.2), which the first unit codes
    /// before anything else and every unit starts from — unless the stream is smaller without
    /// them (a mesh of a few meta-nodes), which the first unit's first bit says.
    pub(super) fn units(&self) -> Vec<super::super::CodedUnit> {
        let mut learning = Learning::new(true);
        let mut scratch = ArithEncoder::default();
        for m in 0..self.part.units.len() {
            self.unit(m, &mut scratch, &mut learning.contexts);
            learning.unit_done();
        }
        let with = self.all_units(Some(&learning));
        let without = self.all_units(None);
        let size = |units: &[super::super::CodedUnit]| -> usize {
            units.iter().map(|(bytes, _, _)| bytes.len()).sum()
        };
        if size(&with) <= size(&without) {
            with
        } else {
            without
        }
    }

    /// Codes every unit, every one's contexts starting from the priors of `learning` (coded at
    /// the head of the first unit), or afresh.
    fn all_units(&self, learning: Option<&Learning>) -> Vec<super::super::CodedUnit> {
        let mut priors: Option<Priors> = None;
        (0..self.part.units.len())
            .map(|m| {
                let mut enc = ArithEncoder::default();
                let mut ctx = priors
                    .get_or_insert_with(|| {
                        let g = SyntaxClass::Geometry;
                        let mut flag = BitContext::NEW;
                        enc.bit(&mut flag, learning.is_some(), g, "priors");
                        match learning {
                            Some(learning) => put_priors(&mut enc, learning),
                            None => Priors::even(true),
                        }
                    })
                    .start();
                self.unit(m, &mut enc, &mut ctx);
                let fields = std::mem::take(&mut enc.field_bits);
                let (bytes, ledger) = enc.finish();
                (bytes, ledger, fields)
            })
            .collect()
    }

    /// Codes unit `m` into `enc` with contexts `ctx`.
    fn unit(&self, m: usize, enc: &mut ArithEncoder, ctx: &mut Contexts) {
        let tree = self.tree;
        let meta = &self.part.units[m];
        let unit = tree.ids[meta.root as usize];
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
            put_cone(enc, ctx, CodedCone::NONE, cone);
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
                    enc,
                    &mut ctx.ratio[side],
                    self.ratio_codes[c as usize],
                    RADIUS_BITS,
                    G,
                    "spheres",
                );
                let (contexts, bits) = if depth < FINE_DEVIATION_DEPTHS {
                    (&mut ctx.deviation_fine, FINE_DEVIATION_BITS)
                } else {
                    (&mut ctx.deviation, DEVIATION_BITS)
                };
                put_symbol(enc, contexts, deviation, bits, G, "deviations");
                let (parent, cone) = (self.cones[s as usize], self.cones[c as usize]);
                put_cone(enc, ctx, parent, cone);
            }
        }
        // Pass 2: the corner paths waiting at the unit's splits, carried on; then triangles
        // and dependencies.
        for (s, list) in &self.carried[m] {
            for w in list {
                self.put_leaf_path(enc, ctx, *s, w.leaf, w.target, w.kind, unit);
            }
        }
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
            let normals = &self.face_normal_codes[s as usize - tree.leaves];
            // Per triangle, its n3 path as the unit codes it (to its leaf, or to the node it
            // waits at: then that node may be a dependency), and its junction's depth.
            let mut thirds = Vec::with_capacity(born.len());
            for (tri, normal) in born.iter().zip(normals) {
                let [n1, n2, n3] = self.corner_paths(s, tri);
                for (start, leaf, target, kind) in [n1, n2] {
                    self.put_leaf_path(enc, ctx, start, leaf, target, kind, unit);
                }
                let junction = tree.ids[tri.leaves[2] as usize].common_len(sid);
                enc.uint(
                    &mut ctx.up,
                    (sid.len() - junction) as u64 - 1,
                    C,
                    "connectivity",
                );
                let (start, leaf, target, kind) = n3;
                let (end, waits) = self.put_leaf_path(enc, ctx, start, leaf, target, kind, unit);
                thirds.push((tree.ids[end as usize], junction, waits));
                enc.bit(
                    &mut ctx.orientation[previous],
                    tri.flipped,
                    C,
                    "connectivity",
                );
                previous = 1 + tri.flipped as usize;
                if let Some(code) = normal {
                    let name = "triangle normals";
                    enc.bit(&mut ctx.face_no_area, code.is_none(), G, name);
                    for (k, &c) in code.iter().flatten().enumerate() {
                        enc.int(&mut ctx.face_normal[k], c as i64, G, name);
                    }
                }
            }
            let deps = &tree.dependencies[s as usize - tree.leaves];
            enc.uint(&mut ctx.dependencies, deps.len() as u64, C, "dependencies");
            for &y in deps {
                // Almost always a node of a triangle's n3 path below its junction: which
                // triangle's, and how far above the path's leaf (or the node it waits at).
                let yid = tree.ids[y as usize];
                let on = thirds
                    .iter()
                    .enumerate()
                    .find_map(|(k, &(end, junction, waits))| {
                        (yid.len() > junction && yid.is_ancestor_of(end) && (waits || yid != end))
                            .then(|| (k, end.len() - yid.len() - !waits as u8))
                    });
                let which = on.map_or(born.len(), |(k, _)| k);
                enc.uint(&mut ctx.dependency_on, which as u64, C, "dependencies");
                if let Some((_, rise)) = on {
                    enc.uint(&mut ctx.dependency_rise, rise as u64, C, "dependencies");
                    continue;
                }
                let junction = yid.common_len(sid);
                let up = sid.len() - junction;
                enc.uint(&mut ctx.dependency_up, up as u64 - 1, C, "dependencies");
                let start = self.other_child(s, up);
                self.put_dependency_path(enc, ctx, start, y, unit);
            }
        }
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

    /// Codes the corner path from `start` to `leaf` as far as `unit` knows the hierarchy, and
    /// returns where it ends: the leaf, or the node it waits at (`true`), as [`Self::path_end`]
    /// finds without coding it.
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
    ) -> (u32, bool) {
        let tree = self.tree;
        let lid = tree.ids[leaf as usize];
        let mut x = start;
        let c = SyntaxClass::Connectivity;
        loop {
            let status = self.status(x, unit);
            let depth = tree.ids[x as usize].len();
            if self.waits_at(x, unit) {
                // The unit that splits x carries the path on (syntax 9).
                return (x, true);
            }
            match status {
                Status::Leaf => return (x, false),
                Status::Unknown => {
                    let is_leaf = tree.is_leaf(x);
                    enc.bit(
                        &mut ctx.leaf_on_path[(depth as usize).min(DEPTHS - 1)],
                        is_leaf,
                        c,
                        "connectivity",
                    );
                    if is_leaf {
                        return (x, false);
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
