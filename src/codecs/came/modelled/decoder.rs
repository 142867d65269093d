//! `came`'s unit decoder: a unit's two passes read back into the decoded tree.

use super::super::decoded::{
    Bounds, DecodedTree, FaceNormal, Triangle, UnitDecoder, WaitingCorner,
};
use super::super::knowledge::Status;
use super::super::{cut_at, Params};
use super::contexts::*;
use super::priors::{get_priors, Priors};
use crate::coding::arith::{ArithDecoder, BitContext, UintContext};
use crate::container::Header;
use crate::error::{Error, Result};
use crate::hierarchy::came::cones::{self, CodedCone, ANGLE_BITS, NO_CONE};
use crate::hierarchy::came::deviation::{
    anchored_deviation, anchored_step, decoded_deviation, round_up, DEVIATION_BITS,
    FINE_DEVIATION_BITS, FINE_DEVIATION_DEPTHS,
};
use crate::hierarchy::came::face_normals::{bound_degrees, decoded, scaled_normal};
use crate::hierarchy::came::spheres::{decoded_radius, ratio_base};
use crate::hierarchy::came::NodeId;
use crate::mesh::attribute_quantization::octahedral_max;

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

/// The unit decoder of `came`: syntax 1 starts every unit's contexts afresh, syntax 2 from the
/// priors its first unit codes (docs/FORMAT.md §8.2), kept here once that unit is decoded.
#[derive(Default)]
pub struct ModelledUnits {
    priors: std::sync::OnceLock<Priors>,
}

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

    /// A leaf's path from `start` (decoded node `known`), and its proxy: the first node on it
    /// that is not an inner node whose split the unit knows (`hierarchy::came::face_normals`).
    /// With `defer` (syntax 9) the path stops at the first node this unit created and does not
    /// split, returned third: the unit that splits that node carries it on.
    fn leaf_path(
        &mut self,
        start: NodeId,
        known: u32,
        target: [f64; 3],
        kind: Kind,
        defer: bool,
    ) -> Result<(NodeId, u32, Option<u32>)> {
        let mut x = start;
        let (mut status, mut node) = (self.tree.status_of(known, self.unit), Some(known));
        let mut proxy = None;
        loop {
            if status != Status::Inner && proxy.is_none() {
                proxy = node;
            }
            if let (true, Status::Open, Some(i)) = (defer, status, node) {
                if self.tree.nodes[i as usize].created_unit == self.unit {
                    return Ok((x, proxy.unwrap_or(known), Some(i)));
                }
            }
            let depth = x.len() as usize;
            let ends_here = match status {
                Status::Leaf => true,
                Status::Unknown => self.bit(|c| &mut c.leaf_on_path[depth.min(DEPTHS - 1)])?,
                Status::Inner | Status::Open => false,
            };
            if ends_here {
                return Ok((x, proxy.unwrap_or(known), None));
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

    /// Syntax 9: carries on the corner paths waiting at `s`, which this unit splits, each as
    /// far as this unit knows ([`UnitReader::leaf_path`]), in the order they began to wait.
    fn carry_on(&mut self, s: u32) -> Result<()> {
        let start = self.tree.nodes[s as usize].id;
        for i in 0..self.tree.take_waiting(s) {
            let waiting = self.tree.taken(i);
            let kind = Kind::of_corner(waiting.kind);
            let target = self.tree.nodes[waiting.target as usize].position;
            let (path, _, stop) = self.leaf_path(start, s, target, kind, true)?;
            self.tree.carry(waiting.triangle, waiting.corner, path);
            if let Some(node) = stop {
                self.tree.wait(node, waiting);
            }
        }
        Ok(())
    }

    /// What the stream says of a triangle's normal (syntax 4), after its orientation bit: on
    /// proxies that are its leaves, the normal they make; else a code about theirs.
    fn face_normal(
        &mut self,
        proxies: [u32; 3],
        params: &Params,
        cell: [f64; 3],
    ) -> Result<FaceNormal> {
        let steps = params.face_normal_steps;
        if steps == 0 {
            return Ok(FaceNormal::UNKNOWN);
        }
        let at = proxies.map(|p| self.tree.nodes[p as usize].position);
        let normal = scaled_normal(at, cell);
        if proxies.iter().all(|&p| self.tree.nodes[p as usize].leaf) {
            let length = normal.length();
            return Ok(if length > 0.0 && length.is_finite() {
                FaceNormal::within(normal / length, 0.0)
            } else {
                FaceNormal::NO_AREA
            });
        }
        if self.bit(|c| &mut c.face_no_area)? {
            return Ok(FaceNormal::NO_AREA);
        }
        let mut code = [0i32; 2];
        for (k, c) in code.iter_mut().enumerate() {
            let v = self
                .dec
                .int(&mut self.ctx.face_normal[k])
                .ok_or_else(|| self.cut())?;
            if v.unsigned_abs() > steps as u64 {
                return Err(Error::malformed(
                    0,
                    self.at,
                    "a triangle normal's code runs past its square",
                ));
            }
            *c = v as i32;
        }
        Ok(FaceNormal::within(
            decoded(normal, code, steps),
            bound_degrees(params.face_normal_bound),
        ))
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
        let mut dec = ArithDecoder::new(bytes)
            .ok_or_else(|| Error::malformed(0, at, "a came unit is not a whole number of words"))?;
        let first = tree.nodes.is_empty();
        if header.syntax < 2 {
            return self.decode_from(tree, header, params, root, dec, at, Contexts::new(false));
        }
        let fine_deviations = header.syntax >= 6;
        if !first {
            let prior = self.priors.get().ok_or_else(|| {
                Error::malformed(0, at, "a came unit decoded before the first one")
            })?;
            return self.decode_from(tree, header, params, root, dec, at, prior.start());
        }
        let cut = || Error::malformed(0, at, "the came unit's priors are cut");
        let prior = if dec.bit(&mut BitContext::default()).ok_or_else(cut)? {
            get_priors(&mut dec, fine_deviations).ok_or_else(cut)?
        } else {
            Priors::even(fine_deviations)
        };
        let children = self.decode_from(tree, header, params, root, dec, at, prior.start())?;
        // A first unit decodes once (a refused one leaves the stream unreadable).
        let _ = self.priors.set(prior);
        Ok(children)
    }
}

impl ModelledUnits {
    /// Decodes the rest of a unit with contexts starting from `ctx`.
    #[allow(clippy::too_many_arguments)]
    fn decode_from(
        &self,
        tree: &mut DecodedTree,
        header: &Header,
        params: &Params,
        root: u32,
        dec: ArithDecoder,
        at: usize,
        ctx: Contexts,
    ) -> Result<Vec<u32>> {
        let first = tree.nodes.is_empty();
        let unit = if first {
            NodeId::ROOT
        } else {
            tree.nodes[root as usize].id
        };
        let mut r = UnitReader {
            tree,
            dec,
            ctx,
            unit,
            at,
        };
        let whole = r.bit(|c| &mut c.whole)?;
        let with_cones = params.cone_bits > 0;
        let with_deviations = params.deviation_bits > 0;
        // Syntax 6 codes deviations on one grid anchored at the root's, in quarter steps above
        // a depth.
        let anchored = with_deviations && header.syntax >= 6;
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
        let band = params.shape().band(top);
        // The band's first splits: breadth first from the root through the nodes its
        // ancestors split (docs/FORMAT.md §8.1).
        let mut queue = Vec::new();
        let mut above = vec![root];
        let mut k = 0;
        while k < above.len() {
            let v = above[k];
            k += 1;
            let node = &r.tree.nodes[v as usize];
            if node.id.len() >= band.start {
                queue.push(v);
                continue;
            }
            let Some(children) = node.children else {
                return Err(Error::malformed(
                    0,
                    at,
                    "a unit's region holds a node no unit above it split",
                ));
            };
            for c in children {
                if !r.tree.nodes[c as usize].leaf {
                    above.push(c);
                }
            }
        }
        let mut children_units: Vec<u32> = Vec::new();
        let mut at_node = 0;
        let root_deviation = r.tree.nodes[0].deviation;
        // Pass 1.
        while at_node < queue.len() {
            let s = queue[at_node];
            at_node += 1;
            let node = &r.tree.nodes[s as usize];
            let (sid, ps, rs, parent_cone) = (node.id, node.position, node.radius, node.cone);
            let (parent_deviation, parent_step) =
                (node.deviation, r.tree.deviation_steps[s as usize]);
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
            // Differences add up down the tree: a corrupt stream's can take a node where the
            // grid's cells multiply out past the largest float.
            if !crate::codecs::came::decoded::to_world(&header.grid, pu).is_finite() {
                return Err(Error::malformed(
                    0,
                    at,
                    "a node lies beyond the grid's reach",
                ));
            }
            let positions = [ps, pu];
            let mut bounds = [Bounds::default(); 2];
            let mut cones = [CodedCone::NONE; 2];
            for side in 0..2 {
                if leaf[side] {
                    continue;
                }
                let base = ratio_base(rs, ps, positions[side]);
                let code = get_symbol(&mut r.dec, &mut r.ctx.ratio[side], RADIUS_BITS)
                    .ok_or_else(|| r.cut())?;
                let b = &mut bounds[side];
                b.radius = decoded_radius(code, base, RADIUS_BITS);
                if anchored {
                    let fine = depth < FINE_DEVIATION_DEPTHS;
                    let code = if fine {
                        get_symbol(&mut r.dec, &mut r.ctx.deviation_fine, FINE_DEVIATION_BITS)
                    } else {
                        get_symbol(&mut r.dec, &mut r.ctx.deviation, DEVIATION_BITS)
                    }
                    .ok_or_else(|| r.cut())?;
                    // Children of a node without deviation have none.
                    let step =
                        anchored_step(code, parent_step, fine).filter(|_| parent_deviation > 0.0);
                    if let Some(step) = step {
                        b.deviation = anchored_deviation(root_deviation, step);
                        b.deviation_step = step;
                    }
                } else if with_deviations {
                    let code = get_symbol(&mut r.dec, &mut r.ctx.deviation, DEVIATION_BITS)
                        .ok_or_else(|| r.cut())?;
                    b.deviation = decoded_deviation(code, parent_deviation);
                } else {
                    b.deviation = round_up(b.radius);
                }
                if with_cones {
                    cones[side] = r.cone(parent_cone)?;
                }
            }
            let children = r.tree.split(s, leaf, positions, bounds, cones, unit, at)?;
            for side in 0..2 {
                if leaf[side] {
                    continue;
                }
                let c = children[side];
                if whole || (depth as u8) < band.end {
                    queue.push(c);
                    continue;
                }
                // Its unit is rooted at its ancestor at the band's child depth.
                let mut root_of = c;
                while r.tree.nodes[root_of as usize].id.len() > band.child {
                    root_of = r.tree.nodes[root_of as usize].parent;
                }
                if !children_units.contains(&root_of) {
                    children_units.push(root_of);
                }
            }
        }
        // Pass 2.
        let max_triangles = header.triangles;
        // Syntax 9 codes corner paths only as far as their unit knows: first the paths that
        // wait at this unit's splits, carried on.
        let defer = header.syntax >= 9;
        if defer {
            for &s in &queue {
                r.carry_on(s)?;
            }
        }
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
                // Where each path's steps point: v_u, v_t, v_s.
                let targets = [u, t, s];
                let n1 = r.leaf_path(r.child(sid, false)?, t, positions[1], Kind::N1, defer)?;
                let n2 = r.leaf_path(r.child(sid, true)?, u, positions[0], Kind::N2, defer)?;
                let up = r.uint(|c| &mut c.up, 52, "n3.up")? + 1;
                let (start, start_node) = r.other_child(s, up)?;
                let n3 = r.leaf_path(start, start_node, ps, Kind::N3, defer)?;
                thirds.push((n3.0, start.len(), n3.2.is_none()));
                let flipped = r.bit(|c| &mut c.orientation[previous])?;
                previous = 1 + flipped as usize;
                // Which corner each path is (n1, n2, n3 in the triangle's order).
                let slots = if flipped { [1, 0, 2] } else { [0, 1, 2] };
                let mut corners = [NodeId::ROOT; 3];
                let mut proxies = [0; 3];
                for (kind, path) in [n1, n2, n3].into_iter().enumerate() {
                    corners[slots[kind]] = path.0;
                    proxies[slots[kind]] = path.1;
                }
                let normal = r.face_normal(proxies, params, header.grid.cell)?;
                let triangle = r.tree.triangles.len() as u32;
                for (kind, path) in [n1, n2, n3].into_iter().enumerate() {
                    if let Some(node) = path.2 {
                        let waiting = WaitingCorner {
                            triangle,
                            corner: slots[kind] as u8,
                            kind: kind as u8,
                            target: targets[kind],
                        };
                        r.tree.wait(node, waiting);
                    }
                }
                r.tree.add_triangle(
                    Triangle {
                        corners,
                        birth_depth: sid.len(),
                        normal,
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
                if let Some(&(path, below, complete)) = thirds.get(which as usize) {
                    // An inner node of the n3 path, from the junction's child down: counted
                    // up from the node above its leaf, or from where the path waits.
                    let rise = r.uint(|c| &mut c.dependency_rise, 52, "a dependency's rise")?;
                    let len = (path.len() as u64 + !complete as u64)
                        .checked_sub(rise + 1)
                        .filter(|&l| l >= below as u64);
                    let Some(len) = len else {
                        return Err(Error::malformed(0, at, "a dependency above its path"));
                    };
                    r.tree.dependency_nodes.push(path.ancestor(len as u8));
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
