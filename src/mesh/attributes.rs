//! Appearance beyond positions, in Hoppe's model (Hoppe 1998 §3): faces → wedges → vertices.
//!
//! A corner is a (face, vertex) pair; a **wedge** is the set of corners around one vertex that
//! share every scalar attribute (normal, texture coordinate, colour). A seam — a jump in uvs or
//! normals along an edge — is two or more wedges at one vertex: the position stays one, so no
//! crack can open when the mesh coarsens (split vertices, as glTF stores them, would drift
//! apart). Faces also carry a material id, an index into the material names.
//!
//! Glossary: `corners[f][k]` is the wedge of face f's k-th corner (its vertex is
//! `faces[f][k]`); `wedge_vertex[w]` the vertex of wedge w; `normals`, `uvs`, `colours` are per
//! wedge when present. A per-vertex attribute (a PLY vertex colour) is the case of one wedge a
//! vertex.

use super::{TriMesh, VertexId};
use crate::error::{Error, Result};
use glam::{DVec2, DVec3};
use std::collections::HashMap;

/// A wedge index.
pub type WedgeId = u32;

/// The materials of a mesh: each face's id, the names ids stand for, and the library file the
/// names come from (OBJ's `mtllib`), kept to be written back.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Materials {
    /// Material id of each face, an index into `names`.
    pub face: Vec<u32>,
    /// The materials' names.
    pub names: Vec<String>,
    /// The material library the file named, if any.
    pub library: Option<String>,
}

/// Wedges, their attributes and the faces' materials of one mesh.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Attributes {
    /// Wedge of each face corner, face by face.
    pub corners: Vec<[WedgeId; 3]>,
    /// Vertex of each wedge.
    pub wedge_vertex: Vec<VertexId>,
    /// Normal of each wedge (not necessarily of unit length, as files store them).
    pub normals: Option<Vec<DVec3>>,
    /// Texture coordinate of each wedge.
    pub uvs: Option<Vec<DVec2>>,
    /// Colour of each wedge, RGBA in [0, 1].
    pub colours: Option<Vec<[f64; 4]>>,
    /// Materials of the faces.
    pub materials: Option<Materials>,
}

/// A triangle mesh with its appearance.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AttributedMesh {
    /// Positions and faces.
    pub mesh: TriMesh,
    /// Wedges and materials; `Attributes::default()` when the mesh has none.
    pub attributes: Attributes,
}

/// What one corner carries, as a reader meets it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Corner {
    /// Its normal, if the file gives corners normals.
    pub normal: Option<DVec3>,
    /// Its texture coordinate.
    pub uv: Option<DVec2>,
    /// Its colour.
    pub colour: Option<[f64; 4]>,
}

impl Corner {
    /// The bits that decide whether two corners at one vertex are one wedge: equal values.
    fn key(&self) -> [u64; 9] {
        let bits = |x: f64| (x + 0.0).to_bits(); // −0 and +0 are one value
        let n = self.normal.unwrap_or(DVec3::NAN);
        let t = self.uv.unwrap_or(DVec2::NAN);
        let c = self.colour.unwrap_or([f64::NAN; 4]);
        [
            bits(n.x),
            bits(n.y),
            bits(n.z),
            bits(t.x),
            bits(t.y),
            bits(c[0]),
            bits(c[1]),
            bits(c[2]),
            bits(c[3]),
        ]
    }
}

impl Attributes {
    /// The number of wedges.
    pub fn wedge_count(&self) -> usize {
        self.wedge_vertex.len()
    }

    /// Whether the mesh carries no appearance at all.
    pub fn is_empty(&self) -> bool {
        self.normals.is_none()
            && self.uvs.is_none()
            && self.colours.is_none()
            && self.materials.is_none()
    }

    /// Wedges from what every corner of `faces` carries (`corners[f][k]` for corner k of face
    /// f): corners at one vertex with equal values are one wedge. Each attribute is present when
    /// every corner has it, and a mesh where some corners have it and others not is refused.
    pub fn weld(faces: &[[VertexId; 3]], corners: &[[Corner; 3]]) -> Result<Attributes> {
        if faces.len() != corners.len() {
            return Err(Error::mesh(format!(
                "{} faces but attributes for {}",
                faces.len(),
                corners.len()
            )));
        }
        let all = corners.iter().flatten();
        let presence = |has: fn(&Corner) -> bool, what: &str| -> Result<bool> {
            let with = all.clone().filter(|c| has(c)).count();
            match with {
                0 => Ok(false),
                n if n == corners.len() * 3 => Ok(true),
                n => Err(Error::mesh(format!(
                    "{n} of {} corners have {what}; the others none",
                    corners.len() * 3
                ))),
            }
        };
        let has_normals = presence(|c| c.normal.is_some(), "a normal")?;
        let has_uvs = presence(|c| c.uv.is_some(), "a texture coordinate")?;
        let has_colours = presence(|c| c.colour.is_some(), "a colour")?;
        if !(has_normals || has_uvs || has_colours) {
            // No scalar attribute: no wedges either (materials may still come).
            return Ok(Attributes::default());
        }
        let mut attributes = Attributes {
            normals: has_normals.then(Vec::new),
            uvs: has_uvs.then(Vec::new),
            colours: has_colours.then(Vec::new),
            ..Attributes::default()
        };
        let mut by_key: HashMap<(VertexId, [u64; 9]), WedgeId> = HashMap::new();
        for (face, corner) in faces.iter().zip(corners) {
            let mut wedges = [0; 3];
            for k in 0..3 {
                let c = corner[k];
                let next = attributes.wedge_vertex.len() as WedgeId;
                let w = *by_key.entry((face[k], c.key())).or_insert(next);
                if w == next {
                    attributes.wedge_vertex.push(face[k]);
                    if let (Some(v), Some(n)) = (attributes.normals.as_mut(), c.normal) {
                        v.push(n);
                    }
                    if let (Some(v), Some(t)) = (attributes.uvs.as_mut(), c.uv) {
                        v.push(t);
                    }
                    if let (Some(v), Some(x)) = (attributes.colours.as_mut(), c.colour) {
                        v.push(x);
                    }
                }
                wedges[k] = w;
            }
            attributes.corners.push(wedges);
        }
        Ok(attributes)
    }

    /// What corner k of face f carries.
    pub fn corner(&self, face: usize, k: usize) -> Corner {
        let Some(w) = self.corners.get(face).map(|c| c[k] as usize) else {
            return Corner::default();
        };
        Corner {
            normal: self.normals.as_ref().map(|v| v[w]),
            uv: self.uvs.as_ref().map(|v| v[w]),
            colour: self.colours.as_ref().map(|v| v[w]),
        }
    }

    /// Whether every vertex has at most one wedge (the attributes are per vertex, as a PLY
    /// vertex element holds them).
    pub fn per_vertex(&self, vertices: usize) -> bool {
        let mut seen = vec![false; vertices];
        self.wedge_vertex
            .iter()
            .all(|&v| !std::mem::replace(&mut seen[v as usize], true))
    }

    /// Per-vertex values of a per-wedge attribute when every wedge of a vertex has the same
    /// (vertices without a wedge take `T::default()`); `None` when some vertex has two.
    pub fn per_vertex_values<T: Copy + Default + PartialEq>(
        &self,
        values: &[T],
        vertices: usize,
    ) -> Option<Vec<T>> {
        let mut out: Vec<Option<T>> = vec![None; vertices];
        for (w, &v) in self.wedge_vertex.iter().enumerate() {
            match out[v as usize] {
                Some(seen) if seen != values[w] => return None,
                _ => out[v as usize] = Some(values[w]),
            }
        }
        Some(out.into_iter().map(Option::unwrap_or_default).collect())
    }

    /// Checks the wedges against `mesh`: one wedge triple a face, each corner's wedge on the
    /// corner's vertex, one value a wedge for each attribute, finite values, material ids
    /// within the names.
    pub fn validate(&self, mesh: &TriMesh) -> Result<()> {
        let wedges = self.wedge_vertex.len();
        let scalar = self.normals.is_some() || self.uvs.is_some() || self.colours.is_some();
        if scalar && self.corners.len() != mesh.faces.len() {
            return Err(Error::mesh(format!(
                "{} faces but wedges for {}",
                mesh.faces.len(),
                self.corners.len()
            )));
        }
        for (f, (face, corner)) in mesh.faces.iter().zip(&self.corners).enumerate() {
            for k in 0..3 {
                let w = corner[k] as usize;
                if w >= wedges || self.wedge_vertex[w] != face[k] {
                    return Err(Error::mesh(format!(
                        "face {f} corner {k}: wedge {w} is not on vertex {}",
                        face[k]
                    )));
                }
            }
        }
        if let Some(&v) = self
            .wedge_vertex
            .iter()
            .find(|&&v| v as usize >= mesh.positions.len())
        {
            return Err(Error::mesh(format!("a wedge of vertex {v} out of range")));
        }
        let lengths = [
            ("normals", self.normals.as_ref().map(Vec::len)),
            ("texture coordinates", self.uvs.as_ref().map(Vec::len)),
            ("colours", self.colours.as_ref().map(Vec::len)),
        ];
        for (what, len) in lengths {
            if len.is_some_and(|n| n != wedges) {
                return Err(Error::mesh(format!(
                    "{} {what} for {wedges} wedges",
                    len.unwrap_or(0)
                )));
            }
        }
        let finite = self.normals.iter().flatten().all(|n| n.is_finite())
            && self.uvs.iter().flatten().all(|t| t.is_finite())
            && self
                .colours
                .iter()
                .flatten()
                .all(|c| c.iter().all(|x| x.is_finite()));
        if !finite {
            return Err(Error::mesh(
                "a non-finite normal, texture coordinate or colour",
            ));
        }
        if let Some(m) = &self.materials {
            if m.face.len() != mesh.faces.len() {
                return Err(Error::mesh(format!(
                    "{} faces but materials for {}",
                    mesh.faces.len(),
                    m.face.len()
                )));
            }
            if let Some(&id) = m.face.iter().find(|&&id| id as usize >= m.names.len()) {
                return Err(Error::mesh(format!(
                    "material {id} of {} named",
                    m.names.len()
                )));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn uv(u: f64, v: f64) -> Corner {
        Corner {
            uv: Some(DVec2::new(u, v)),
            ..Corner::default()
        }
    }

    #[test]
    fn equal_corners_at_a_vertex_are_one_wedge_and_a_seam_is_two() {
        // Two triangles sharing edge 1-2; vertex 2's uv jumps across it (a seam).
        let faces = [[0, 1, 2], [2, 1, 3]];
        let corners = [
            [uv(0.0, 0.0), uv(1.0, 0.0), uv(0.0, 1.0)],
            [uv(0.5, 1.0), uv(1.0, 0.0), uv(1.0, 1.0)],
        ];
        let a = Attributes::weld(&faces, &corners).unwrap();
        assert_eq!(a.wedge_count(), 5);
        assert_eq!(a.corners[0][1], a.corners[1][1], "vertex 1: one wedge");
        assert_ne!(a.corners[0][2], a.corners[1][0], "vertex 2: a seam");
        assert!(!a.per_vertex(4));
        let mesh = TriMesh::new(vec![DVec3::ZERO; 4], faces.to_vec());
        a.validate(&mesh).unwrap();
        for (f, corner) in corners.iter().enumerate() {
            for (k, c) in corner.iter().enumerate() {
                assert_eq!(a.corner(f, k), *c);
            }
        }
    }

    #[test]
    fn partial_attributes_and_bad_wedges_are_refused() {
        let faces = [[0, 1, 2]];
        let some = [[uv(0.0, 0.0), Corner::default(), uv(1.0, 1.0)]];
        assert!(Attributes::weld(&faces, &some).is_err());
        let mut a =
            Attributes::weld(&faces, &[[uv(0.0, 0.0), uv(1.0, 0.0), uv(0.0, 1.0)]]).unwrap();
        let mesh = TriMesh::new(vec![DVec3::ZERO; 3], faces.to_vec());
        a.validate(&mesh).unwrap();
        a.wedge_vertex[0] = 2;
        assert!(a.validate(&mesh).is_err());
        let nan = [[uv(f64::NAN, 0.0), uv(1.0, 0.0), uv(0.0, 1.0)]];
        assert!(Attributes::weld(&faces, &nan)
            .unwrap()
            .validate(&mesh)
            .is_err());
    }
}
