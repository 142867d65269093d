//! Progressive meshes without bits: Hoppe's face-adjacency mesh, the vertex split record and the
//! two transformations, vsplit and its inverse ecol, applied in place.
//!
//! Conventions (ours, in Hoppe's vocabulary). Faces are counter-clockwise; `nei[k]` is the face
//! across edge `(v[k], v[k+1])`. A vsplit of vertex vs creates vt and the faces
//! fl = (vs, vl, vt) and, unless vr is nil, fr = (vs, vt, vr). Around vs, counter-clockwise from vl
//! to vr, lie the faces that move to vt; `flclw` is the first of them (the face (vs, vl, ·)),
//! `vs_index` is vs's corner in it, and `vlr_rot` counts the further faces to reach vr. When no
//! face moves, `flclw` is the face on the other side of edge (vs, vl). A vertex fan that is open
//! (vs on a boundary) is walked across its gap, so moved faces may sit on both sides of it.
//! Positions are integer cells; the split places vs and vt relative to vs's position by `ii`,
//! `vad_l` = vt − vs after the split, and a small correction `vad_s` (Hoppe §3.2).

/// No face / no vertex.
pub const NIL: u32 = u32::MAX;

/// A triangle with its three neighbours.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Face {
    /// Corners, counter-clockwise.
    pub v: [u32; 3],
    /// `nei[k]`: the face across edge `(v[k], v[(k+1) % 3])`, or [`NIL`] on a boundary.
    pub nei: [u32; 3],
}

/// How vr is reached from vl around vs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rotation {
    /// `flclw` and this many further faces move to vt; the last one's third corner is vr.
    Faces(u32),
    /// Faces from `flclw` to the fan's boundary move; vr is nil (vs–vt is a boundary edge).
    ToBoundary,
    /// No face moves; vr is nil. `flclw` is the face across (vs, vl).
    Empty,
    /// No face moves; vr is the neighbour at the other side of vs's boundary gap.
    EmptyAcrossGap,
}

impl Rotation {
    /// Whether the split creates fr.
    pub fn has_fr(self) -> bool {
        matches!(self, Rotation::Faces(_) | Rotation::EmptyAcrossGap)
    }
}

/// One vertex split (Hoppe's Vsplit, with the fields for positions; wedge corners and material
/// ids would join as further fields coded after `ii`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Vsplit {
    /// A face in the neighbourhood of the split (see the module docs).
    pub flclw: u32,
    /// Corner of vs in `flclw` (0..3).
    pub vs_index: u8,
    /// Where vr is.
    pub vlr_rot: Rotation,
    /// Position prediction: 2 = vs stays at the collapsed position, 0 = vt does, 1 = their
    /// midpoint does (Hoppe Fig. 10).
    pub ii: u8,
    /// vt − vs after the split.
    pub vad_l: [i32; 3],
    /// Correction of the predicted anchor (zero when collapses keep an endpoint or midpoint).
    pub vad_s: [i32; 3],
}

fn add(a: [i32; 3], b: [i32; 3]) -> [i32; 3] {
    [
        a[0].wrapping_add(b[0]),
        a[1].wrapping_add(b[1]),
        a[2].wrapping_add(b[2]),
    ]
}

fn sub(a: [i32; 3], b: [i32; 3]) -> [i32; 3] {
    [
        a[0].wrapping_sub(b[0]),
        a[1].wrapping_sub(b[1]),
        a[2].wrapping_sub(b[2]),
    ]
}

fn half(d: [i32; 3]) -> [i32; 3] {
    d.map(|x| x.div_euclid(2))
}

/// The anchor a split places at the collapsed position p: vs (ii = 2), vt (ii = 0) or their
/// floor-midpoint vs + ⌊(vt − vs)/2⌋ (ii = 1).
pub fn anchor(ii: u8, vs: [i32; 3], vt: [i32; 3]) -> [i32; 3] {
    match ii {
        0 => vt,
        1 => add(vs, half(sub(vt, vs))),
        _ => vs,
    }
}

/// Positions after a split of a vertex at `p`: (vs, vt).
pub fn split_positions(
    p: [i32; 3],
    ii: u8,
    vad_l: [i32; 3],
    vad_s: [i32; 3],
) -> ([i32; 3], [i32; 3]) {
    let a = add(p, vad_s);
    let vs = match ii {
        0 => sub(a, vad_l),
        1 => sub(a, half(vad_l)),
        _ => a,
    };
    (vs, add(vs, vad_l))
}

/// Why a split cannot apply (a corrupt record or a mismatched mesh).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SplitFault(pub &'static str);

/// A mesh with face adjacency, as PMeshIter holds it.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PmMesh {
    /// Vertex positions (integer cells).
    pub positions: Vec<[i32; 3]>,
    /// Faces with neighbours.
    pub faces: Vec<Face>,
}

impl PmMesh {
    /// A mesh from oriented manifold triangles; neighbours are found by matching each directed
    /// edge with its reverse. `None` if an edge is used twice in one direction or by more than two
    /// faces (not an oriented manifold).
    pub fn from_triangles(positions: Vec<[i32; 3]>, triangles: &[[u32; 3]]) -> Option<PmMesh> {
        let mut directed: std::collections::HashMap<(u32, u32), (u32, u8)> =
            std::collections::HashMap::with_capacity(triangles.len() * 3);
        let mut faces: Vec<Face> = triangles
            .iter()
            .map(|&v| Face { v, nei: [NIL; 3] })
            .collect();
        for (f, t) in triangles.iter().enumerate() {
            for k in 0..3 {
                let e = (t[k], t[(k + 1) % 3]);
                if directed.insert(e, (f as u32, k as u8)).is_some() {
                    return None;
                }
            }
        }
        for (f, t) in triangles.iter().enumerate() {
            for k in 0..3 {
                if let Some(&(g, _)) = directed.get(&(t[(k + 1) % 3], t[k])) {
                    faces[f].nei[k] = g;
                }
            }
        }
        Some(PmMesh { positions, faces })
    }

    /// Corner of `v` in face `f`.
    pub fn corner(&self, f: u32, v: u32) -> Option<usize> {
        self.faces[f as usize].v.iter().position(|&x| x == v)
    }

    /// The next face counter-clockwise around `v` from `f` (across edge (v, third corner)).
    pub fn ccw(&self, f: u32, v: u32) -> u32 {
        let i = self.corner(f, v).expect("v is a corner of f");
        self.faces[f as usize].nei[(i + 2) % 3]
    }

    /// The next face clockwise around `v` from `f` (across edge (v, next corner)).
    pub fn cw(&self, f: u32, v: u32) -> u32 {
        let i = self.corner(f, v).expect("v is a corner of f");
        self.faces[f as usize].nei[i]
    }

    /// All faces around `v`, starting at `f` (a face of `v`).
    pub fn fan(&self, f: u32, v: u32) -> Vec<u32> {
        let mut out = vec![f];
        let mut g = self.ccw(f, v);
        while g != NIL && g != f {
            out.push(g);
            g = self.ccw(g, v);
            if out.len() > self.faces.len() {
                return out;
            }
        }
        if g == NIL {
            let mut g = self.cw(f, v);
            while g != NIL {
                out.push(g);
                g = self.cw(g, v);
                if out.len() > self.faces.len() {
                    break;
                }
            }
        }
        out
    }

    /// Sets the neighbour of `f` across its edge (previous corner, `v`).
    fn set_nei_before(&mut self, f: u32, v: u32, to: u32) {
        if f != NIL {
            let c = self.corner(f, v).expect("v is a corner of f");
            self.faces[f as usize].nei[(c + 2) % 3] = to;
        }
    }

    /// Sets the neighbour of `f` across its edge (`v`, next corner).
    fn set_nei_after(&mut self, f: u32, v: u32, to: u32) {
        if f != NIL {
            let c = self.corner(f, v).expect("v is a corner of f");
            self.faces[f as usize].nei[c] = to;
        }
    }

    /// The faces that move to vt, vl and vr, for a split record; checks everything a corrupt
    /// record could get wrong.
    fn locate(&self, s: &Vsplit) -> Result<(u32, u32, u32, Vec<u32>), SplitFault> {
        let f0 = s.flclw;
        if f0 as usize >= self.faces.len() || s.vs_index > 2 {
            return Err(SplitFault("flclw or vs_index out of range"));
        }
        let face = self.faces[f0 as usize];
        let i = s.vs_index as usize;
        let vs = face.v[i];
        match s.vlr_rot {
            Rotation::Empty | Rotation::EmptyAcrossGap => {
                let vl = face.v[(i + 2) % 3];
                if face.nei[(i + 2) % 3] != NIL {
                    return Err(SplitFault("edge (vs, vl) is not on the boundary"));
                }
                let vr = if s.vlr_rot == Rotation::Empty {
                    NIL
                } else {
                    let mut g = f0;
                    let mut steps = 0;
                    while self.cw(g, vs) != NIL {
                        g = self.cw(g, vs);
                        steps += 1;
                        if steps > self.faces.len() {
                            return Err(SplitFault("vs has a closed fan"));
                        }
                    }
                    let c = self.corner(g, vs).expect("corner");
                    self.faces[g as usize].v[(c + 1) % 3]
                };
                if vr == vl {
                    return Err(SplitFault("vl and vr coincide"));
                }
                Ok((vs, vl, vr, Vec::new()))
            }
            Rotation::Faces(n) => {
                let vl = face.v[(i + 1) % 3];
                let mut moved = vec![f0];
                let mut g = f0;
                let mut wrapped = false;
                for _ in 0..n {
                    let mut next = self.ccw(g, vs);
                    if next == NIL {
                        if wrapped {
                            return Err(SplitFault("rotation passes the boundary twice"));
                        }
                        wrapped = true;
                        // Across the gap: the fan's other end, clockwise of flclw.
                        next = f0;
                        let mut steps = 0;
                        while self.cw(next, vs) != NIL {
                            next = self.cw(next, vs);
                            steps += 1;
                            if steps > self.faces.len() {
                                return Err(SplitFault("rotation loops"));
                            }
                        }
                    }
                    if next == f0 || moved.len() > self.faces.len() {
                        return Err(SplitFault("rotation wraps onto flclw"));
                    }
                    moved.push(next);
                    g = next;
                }
                let c = self.corner(g, vs).expect("corner");
                let vr = self.faces[g as usize].v[(c + 2) % 3];
                if vr == vl {
                    return Err(SplitFault("vl and vr coincide"));
                }
                Ok((vs, vl, vr, moved))
            }
            Rotation::ToBoundary => {
                let vl = face.v[(i + 1) % 3];
                let mut moved = vec![f0];
                let mut g = self.ccw(f0, vs);
                while g != NIL {
                    if g == f0 || moved.len() > self.faces.len() {
                        return Err(SplitFault("vs has a closed fan"));
                    }
                    moved.push(g);
                    g = self.ccw(g, vs);
                }
                Ok((vs, vl, NIL, moved))
            }
        }
    }

    /// The neighbours vt will have (vl, the corners of the moved faces, vr) and those vs keeps
    /// apart from vl and vr, for a split about to apply; `None` if the record does not locate.
    pub fn split_rings(&self, s: &Vsplit) -> Option<(u32, Vec<u32>, Vec<u32>)> {
        let (vs, vl, vr, moved) = self.locate(s).ok()?;
        let mut ring_t = vec![vl];
        for &f in &moved {
            let t = self.faces[f as usize].v;
            ring_t.extend(t.iter().filter(|&&x| x != vs));
        }
        if vr != NIL {
            ring_t.push(vr);
        }
        ring_t.sort_unstable();
        ring_t.dedup();
        let mut ring_s: Vec<u32> = self
            .fan(s.flclw, vs)
            .into_iter()
            .filter(|f| !moved.contains(f))
            .flat_map(|f| self.faces[f as usize].v)
            .filter(|&x| x != vs)
            .collect();
        ring_s.sort_unstable();
        ring_s.dedup();
        Some((vs, ring_t, ring_s))
    }

    /// Applies a vertex split; returns vt.
    pub fn vsplit(&mut self, s: &Vsplit) -> Result<u32, SplitFault> {
        if s.ii > 2 {
            return Err(SplitFault("ii out of range"));
        }
        let (vs, vl, vr, moved) = self.locate(s)?;
        let vt = self.positions.len() as u32;
        let fl = self.faces.len() as u32;
        let fr = if vr != NIL { fl + 1 } else { NIL };
        // Neighbours outside the moved arc, across (vs, vl) and (vs, vr).
        let (first, last) = (moved.first().copied(), moved.last().copied());
        let x = match first {
            Some(f0) => self.cw(f0, vs),
            None => s.flclw,
        };
        let y = match last {
            Some(fk) => self.ccw(fk, vs),
            None if vr != NIL => {
                let mut g = s.flclw;
                while self.cw(g, vs) != NIL {
                    g = self.cw(g, vs);
                }
                g
            }
            None => NIL,
        };
        for &f in &moved {
            let c = self.corner(f, vs).expect("moved faces hold vs");
            self.faces[f as usize].v[c] = vt;
        }
        // x's edge (vl, vs) and the first moved face's edge (vt, vl) now border fl; y's edge
        // (vs, vr) and the last moved face's edge (vr, vt) border fr.
        self.set_nei_before(x, vs, fl);
        if let Some(f0) = first {
            self.set_nei_after(f0, vt, fl);
        }
        self.faces.push(Face {
            v: [vs, vl, vt],
            nei: [x, first.unwrap_or(NIL), fr],
        });
        if vr != NIL {
            self.set_nei_after(y, vs, fr);
            if let Some(fk) = last {
                self.set_nei_before(fk, vt, fr);
            }
            self.faces.push(Face {
                v: [vs, vt, vr],
                nei: [fl, last.unwrap_or(NIL), y],
            });
        }
        let p = self.positions[vs as usize];
        let (ps, pt) = split_positions(p, s.ii, s.vad_l, s.vad_s);
        self.positions[vs as usize] = ps;
        self.positions.push(pt);
        Ok(vt)
    }

    /// Undoes the last vertex split, which was `s`.
    pub fn ecol(&mut self, s: &Vsplit) {
        let vt = self.positions.len() as u32 - 1;
        let has_fr = s.vlr_rot.has_fr();
        let fl = self.faces.len() as u32 - if has_fr { 2 } else { 1 };
        let fr = if has_fr { fl + 1 } else { NIL };
        let flf = self.faces[fl as usize];
        let vs = flf.v[0];
        let (x, f0) = (flf.nei[0], flf.nei[1]);
        let moved: Vec<u32> = self
            .fan(fl, vt)
            .into_iter()
            .filter(|&f| f != fl && f != fr)
            .collect();
        for &f in &moved {
            let c = self.corner(f, vt).expect("moved faces hold vt");
            self.faces[f as usize].v[c] = vs;
        }
        self.set_nei_before(x, vs, f0);
        if f0 != NIL {
            self.set_nei_after(f0, vs, x);
        }
        if has_fr {
            let frf = self.faces[fr as usize];
            let (fk, y) = (frf.nei[1], frf.nei[2]);
            self.set_nei_after(y, vs, fk);
            if fk != NIL {
                self.set_nei_before(fk, vs, y);
            }
            self.faces.pop();
        }
        self.faces.pop();
        let ps = self.positions[vs as usize];
        self.positions[vs as usize] = sub(anchor_from_vs(s.ii, ps, s.vad_l), s.vad_s);
        self.positions.pop();
    }

    /// Checks adjacency symmetry, orientation and manifold fans; returns the first fault.
    pub fn check_invariants(&self) -> Result<(), String> {
        let n = self.positions.len() as u32;
        let mut edges = std::collections::HashSet::new();
        for (f, face) in self.faces.iter().enumerate() {
            let [a, b, c] = face.v;
            if a == b || b == c || a == c || face.v.iter().any(|&v| v >= n) {
                return Err(format!(
                    "face {f} {:?} is degenerate or out of range",
                    face.v
                ));
            }
            for k in 0..3 {
                let (u, v) = (face.v[k], face.v[(k + 1) % 3]);
                if !edges.insert((u, v)) {
                    return Err(format!("directed edge ({u}, {v}) used twice"));
                }
                let g = face.nei[k];
                if g != NIL {
                    let other = self.faces.get(g as usize).ok_or("neighbour out of range")?;
                    let back = (0..3).find(|&j| other.v[j] == v && other.v[(j + 1) % 3] == u);
                    match back {
                        Some(j) if other.nei[j] == f as u32 => {}
                        _ => return Err(format!("faces {f} and {g} disagree on edge ({u}, {v})")),
                    }
                }
            }
        }
        for (f, face) in self.faces.iter().enumerate() {
            for k in 0..3 {
                let (u, v) = (face.v[k], face.v[(k + 1) % 3]);
                if face.nei[k] == NIL && edges.contains(&(v, u)) {
                    return Err(format!(
                        "face {f}: edge ({u}, {v}) has a twin but no neighbour"
                    ));
                }
            }
        }
        // Manifold vertices: one fan holds every face of the vertex.
        let mut count = vec![0usize; n as usize];
        let mut some_face = vec![NIL; n as usize];
        for (f, face) in self.faces.iter().enumerate() {
            for &v in &face.v {
                count[v as usize] += 1;
                some_face[v as usize] = f as u32;
            }
        }
        for v in 0..n {
            if some_face[v as usize] != NIL {
                let fan = self.fan(some_face[v as usize], v).len();
                if fan != count[v as usize] {
                    return Err(format!(
                        "vertex {v}: fan of {fan} faces, {} incident",
                        count[v as usize]
                    ));
                }
            }
        }
        Ok(())
    }

    /// The mesh's triangles.
    pub fn triangles(&self) -> Vec<[u32; 3]> {
        self.faces.iter().map(|f| f.v).collect()
    }
}

/// The anchor of a split recomputed from vs's position after it and vad_l (= vt − vs).
fn anchor_from_vs(ii: u8, vs: [i32; 3], vad_l: [i32; 3]) -> [i32; 3] {
    anchor(ii, vs, add(vs, vad_l))
}
