//! What the front gives out: the adapted mesh, its present triangles, picking, and the check of
//! every invariant of `front`'s module docs.

use super::super::loader::NONE;
use super::{Pick, State, Suspicion, ViewMesh};
use crate::hierarchy::came::NodeId;
use crate::mesh::TriMesh;
use glam::DVec3;

/// A triangle of the adapted mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PresentTriangle {
    /// Which of the full mesh's triangles it stands for: the node whose split creates it and
    /// its place among that split's triangles, the same in every front of the stream.
    pub birth: (NodeId, u32),
    /// Its corners' paths as far as the loaded meta-nodes give them: the full mesh's vertices'
    /// leaf paths once the meta-nodes below are loaded (`came` from syntax 9 codes a path only
    /// as far as its meta-node knows the hierarchy; the meta-node splitting the node it stops
    /// at carries it on).
    pub paths: [NodeId; 3],
    /// Its corners' positions in the adapted mesh.
    pub at: [DVec3; 3],
}

impl ViewMesh {
    /// Where the vertex with leaf path `leaf` stands in the adapted mesh: the position of the
    /// active node on its path (`None` if the path leaves the hierarchy above the front).
    pub fn position_of(&self, leaf: NodeId) -> Option<DVec3> {
        self.active_on(leaf)
            .map(|v| self.nodes.bounds[v as usize].center)
    }

    /// The front's nodes (the adapted mesh's vertices), by their paths in the hierarchy.
    pub fn active_nodes(&self) -> impl Iterator<Item = NodeId> + '_ {
        self.front
            .active
            .iter()
            .map(|&v| self.nodes.links[v as usize].id)
    }

    /// The present triangles ([`PresentTriangle`]), by their birth nodes in loading order.
    pub fn present_triangles(&self) -> impl Iterator<Item = PresentTriangle> + '_ {
        self.present_by_birth()
            .map(move |(v, ordinal, t)| PresentTriangle {
                birth: (self.nodes.links[v as usize].id, ordinal),
                paths: self.faces.leaf_corners[t as usize],
                at: self.faces.corners[t as usize].map(|c| self.nodes.bounds[c as usize].center),
            })
    }

    /// The present triangles as (birth node, place among its triangles, triangle): those
    /// born at the split nodes.
    pub(super) fn present_by_birth(&self) -> impl Iterator<Item = (u32, u32, u32)> + '_ {
        (0..self.nodes.links.len() as u32)
            .filter(|&v| self.nodes.links[v as usize].state == State::Split)
            .flat_map(move |v| {
                let born = self.nodes.born[v as usize].iter();
                born.enumerate()
                    .map(move |(ordinal, &t)| (v, ordinal as u32, t))
            })
    }

    /// The adapted mesh: the active nodes' positions, the present triangles.
    pub fn mesh(&self) -> TriMesh {
        let mut index = vec![NONE; self.nodes.links.len()];
        let mut positions = Vec::with_capacity(self.front.active.len());
        for &v in &self.front.active {
            index[v as usize] = positions.len() as u32;
            positions.push(self.nodes.bounds[v as usize].center);
        }
        let faces = (0..self.faces.corners.len())
            .filter(|&t| self.faces.present(t))
            .map(|t| self.faces.corners[t].map(|v| index[v as usize]))
            .collect();
        TriMesh { positions, faces }
    }

    /// The nearest present triangle the ray from `origin` along `direction` hits.
    pub fn pick(&self, origin: DVec3, direction: DVec3) -> Option<Pick> {
        let mut best: Option<Pick> = None;
        for t in 0..self.faces.corners.len() {
            if !self.faces.present(t) {
                continue;
            }
            let [a, b, c] = self.faces.corners[t].map(|v| self.nodes.bounds[v as usize].center);
            if let Some(d) = ray_triangle(origin, direction, a, b, c) {
                if best.is_none_or(|p| d < p.distance) {
                    best = Some(Pick {
                        triangle: t as u32,
                        distance: d,
                        point: origin + direction * d,
                    });
                }
            }
        }
        best
    }

    /// Checks every invariant of the module docs; the first broken one, described.
    pub fn check_invariants(&self) -> std::result::Result<(), String> {
        let n = self.nodes.links.len();
        self.nodes.check()?;
        self.front.check(&self.nodes.links)?;
        self.faces.check()?;
        self.guard.check()?;
        if self.nodes.links[0].state == State::Below {
            return Err("the root is below the front".into());
        }
        for v in 0..n {
            let st = self.nodes.links[v].state;
            let inner = self.nodes.links[v].children[0] != NONE;
            for c in self.nodes.links[v]
                .children
                .into_iter()
                .filter(|&c| c != NONE)
            {
                let cs = self.nodes.links[c as usize].state;
                let fine = match st {
                    State::Split => cs != State::Below,
                    _ => cs == State::Below,
                };
                if !fine {
                    return Err(format!("node {v} is {st:?}, its child {c} {cs:?}"));
                }
            }
            if st == State::Split && !inner {
                return Err(format!("leaf {v} is split"));
            }
            let bit = self.front.active_bits[v / 64] >> (v % 64) & 1 == 1;
            if (st == State::Active) != (self.nodes.links[v].active_slot != NONE)
                || (st == State::Active) != bit
            {
                return Err(format!("node {v} is {st:?} but listed otherwise"));
            }
            if st == State::Split {
                if let Some(d) = self.nodes.depends_on[v].iter().find(|d| {
                    d.node == NONE || self.nodes.links[d.node as usize].state != State::Split
                }) {
                    return Err(format!(
                        "split node {v} depends on {:?}, which is not split",
                        d.id
                    ));
                }
            }
        }
        let mut dependants = vec![0u32; n];
        for v in (0..n).filter(|&v| self.nodes.links[v].state == State::Split) {
            for d in &self.nodes.depends_on[v] {
                dependants[d.node as usize] += 1;
            }
        }
        if dependants
            .iter()
            .zip(&self.nodes.links)
            .any(|(&d, l)| d != l.split_dependants)
        {
            return Err("the counts of split dependants are off".into());
        }
        let mut listed = vec![0usize; n];
        let mut faces = 0;
        for v in 0..n {
            for &t in &self.nodes.born[v] {
                let tu = t as usize;
                if self.faces.present(tu) != (self.nodes.links[v].state == State::Split) {
                    return Err(format!(
                        "triangle {t} present {} at a {:?} birth node",
                        self.faces.present(tu),
                        self.nodes.links[v].state
                    ));
                }
                if !self.faces.present(tu) {
                    continue;
                }
                faces += 1;
                let c = self.faces.corners[tu];
                for (k, (&corner, &leaf)) in c.iter().zip(&self.faces.leaf_corners[tu]).enumerate()
                {
                    let cu = corner as usize;
                    if self.nodes.links[cu].state != State::Active
                        || !self.nodes.links[cu].id.is_ancestor_of(leaf)
                    {
                        return Err(format!(
                            "triangle {t}'s corner {k} is not its leaf's active node"
                        ));
                    }
                    listed[cu] += 1;
                }
                if c[0] == c[1] || c[1] == c[2] || c[0] == c[2] {
                    return Err(format!("triangle {t} has a repeated corner"));
                }
            }
        }
        if faces != self.faces.count {
            return Err(format!(
                "{faces} triangles present, {} counted",
                self.faces.count
            ));
        }
        if let Some(t) = (0..self.faces.corners.len()).find(|&t| {
            self.faces.present(t)
                && self.guard.suspected[t] == Suspicion::None
                && !self.orientation_certain(self.faces.corners[t], t as u32)
        }) {
            return Err(format!(
                "triangle {t} is not certain of its orientation and not listed"
            ));
        }
        for &v in &self.front.active {
            let list = &self.nodes.links[v as usize].faces_at;
            if list.len() != listed[v as usize]
                || list
                    .iter()
                    .any(|&t| !self.faces.corners[t as usize].contains(&v))
            {
                return Err(format!("node {v}'s triangle list is off"));
            }
        }
        Ok(())
    }
}

/// Möller–Trumbore: the distance along the ray to triangle (a, b, c), either side facing.
fn ray_triangle(origin: DVec3, direction: DVec3, a: DVec3, b: DVec3, c: DVec3) -> Option<f64> {
    let (e1, e2) = (b - a, c - a);
    let p = direction.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-300 {
        return None;
    }
    let s = origin - a;
    let u = s.dot(p) / det;
    let q = s.cross(e1);
    let v = direction.dot(q) / det;
    let t = e2.dot(q) / det;
    (u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t >= 0.0).then_some(t)
}
