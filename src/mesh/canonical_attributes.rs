//! The canonical mesh's appearance (docs/CONTRACT.md §2.1) and the test that a decode carries
//! it losslessly (§3).
//!
//! Each canonical face takes the corners of the input face it comes from; every corner's
//! attributes are quantized ([`super::attribute_quantization`]); at each canonical vertex the
//! corners whose quantized attributes are all equal are one wedge. Wedges are numbered in the
//! order their first corner appears, face by face. Materials follow their faces.

use super::attribute_quantization::{
    colour_code, colour_value, octahedral_code, octahedral_normal, AttributeBits, UvGrid,
};
use super::attributes::{Attributes, Materials, WedgeId};
use super::{CanonicalMesh, TriMesh, VertexId};
use crate::error::Result;
use std::collections::HashMap;

/// Quantized appearance of a canonical mesh: wedges over its faces and vertices.
#[derive(Clone, Debug, PartialEq)]
pub struct CanonicalAttributes {
    /// The bits uvs and normals were quantized to.
    pub bits: AttributeBits,
    /// The uv grid, when the mesh has uvs.
    pub uv_grid: Option<UvGrid>,
    /// Wedge of each corner of each canonical face.
    pub corners: Vec<[WedgeId; 3]>,
    /// Canonical vertex of each wedge.
    pub wedge_vertex: Vec<VertexId>,
    /// Octahedral code of each wedge's normal.
    pub normals: Option<Vec<[u32; 2]>>,
    /// uv cell of each wedge.
    pub uvs: Option<Vec<[u32; 2]>>,
    /// 8-bit RGBA of each wedge.
    pub colours: Option<Vec<[u8; 4]>>,
    /// Each canonical face's material and the names.
    pub materials: Option<Materials>,
}

/// What one corner carries, quantized: the values two corners must share to be one wedge.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct CornerCode {
    /// Octahedral normal code.
    pub normal: Option<[u32; 2]>,
    /// uv cell.
    pub uv: Option<[u32; 2]>,
    /// RGBA.
    pub colour: Option<[u8; 4]>,
}

impl CanonicalAttributes {
    /// The appearance of `canonical`, whose faces come from the input faces `origins` of a mesh
    /// with `attributes` (validated against it).
    pub fn new(
        canonical: &CanonicalMesh,
        origins: &[u32],
        attributes: &Attributes,
        bits: AttributeBits,
    ) -> Result<CanonicalAttributes> {
        bits.check()?;
        let uv_grid = match &attributes.uvs {
            Some(uvs) => UvGrid::fit(
                origins
                    .iter()
                    .flat_map(|&f| attributes.corners[f as usize])
                    .map(|w| uvs[w as usize]),
                bits.uv,
            )?,
            None => None,
        };
        let mut corner_codes: Vec<[CornerCode; 3]> = origins
            .iter()
            .map(|&origin| {
                // A mesh with materials alone has no wedges: one a vertex, with no values.
                let input = attributes.corners.get(origin as usize);
                std::array::from_fn(|k| {
                    input.map_or(CornerCode::default(), |c| {
                        quantize_wedge(attributes, c[k], bits, uv_grid.as_ref())
                    })
                })
            })
            .collect();
        if bits.derive_normals && attributes.normals.is_some() {
            derive_corner_normals(canonical, &mut corner_codes, bits.normal);
        }
        let mut wedge_of: HashMap<(VertexId, CornerCode), WedgeId> = HashMap::new();
        let mut codes = Vec::new();
        let mut wedge_vertex = Vec::new();
        let corners = canonical
            .faces
            .iter()
            .zip(&corner_codes)
            .map(|(face, values)| {
                std::array::from_fn(|k| {
                    *wedge_of.entry((face[k], values[k])).or_insert_with(|| {
                        codes.push(values[k]);
                        wedge_vertex.push(face[k]);
                        (codes.len() - 1) as WedgeId
                    })
                })
            })
            .collect();
        let materials = attributes.materials.as_ref().map(|m| Materials {
            face: origins.iter().map(|&f| m.face[f as usize]).collect(),
            names: m.names.clone(),
            library: m.library.clone(),
        });
        Ok(CanonicalAttributes {
            bits,
            uv_grid,
            corners,
            wedge_vertex,
            normals: attributes
                .normals
                .as_ref()
                .map(|_| codes.iter().map(|c| c.normal.unwrap_or_default()).collect()),
            uvs: uv_grid.map(|_| codes.iter().map(|c| c.uv.unwrap_or_default()).collect()),
            colours: attributes
                .colours
                .as_ref()
                .map(|_| codes.iter().map(|c| c.colour.unwrap_or_default()).collect()),
            materials,
        })
    }

    /// Whether there is no appearance to carry.
    pub fn is_empty(&self) -> bool {
        self.normals.is_none()
            && self.uvs.is_none()
            && self.colours.is_none()
            && self.materials.is_none()
    }

    /// The quantized values of wedge `w`.
    pub fn code(&self, w: WedgeId) -> CornerCode {
        let w = w as usize;
        CornerCode {
            normal: self.normals.as_ref().map(|n| n[w]),
            uv: self.uvs.as_ref().map(|t| t[w]),
            colour: self.colours.as_ref().map(|c| c[w]),
        }
    }

    /// The appearance with values at their quantized points (uv cell centres, unit normals of
    /// the codes, colours of the 8-bit values): what a lossless decode gives.
    pub fn to_attributes(&self) -> Attributes {
        Attributes {
            corners: self.corners.clone(),
            wedge_vertex: self.wedge_vertex.clone(),
            normals: self.normals.as_ref().map(|n| {
                n.iter()
                    .map(|&c| octahedral_normal(c, self.bits.normal))
                    .collect()
            }),
            uvs: match (&self.uvs, &self.uv_grid) {
                (Some(t), Some(grid)) => Some(t.iter().map(|&q| grid.dequantize(q)).collect()),
                _ => None,
            },
            colours: self
                .colours
                .as_ref()
                .map(|c| c.iter().map(|&c| colour_value(c)).collect()),
            materials: self.materials.clone(),
        }
    }

    /// Checks that `decoded` with `appearance` is `canonical` with this appearance: the geometry
    /// exactly (CanonicalMesh::check_lossless), then every face's corners' quantized attributes
    /// and its material name. Returns what differs.
    pub fn check_lossless(
        &self,
        canonical: &CanonicalMesh,
        decoded: &TriMesh,
        appearance: &Attributes,
    ) -> Result<(), String> {
        canonical.check_lossless(decoded)?;
        appearance
            .validate(decoded)
            .map_err(|e| format!("decoded appearance: {e}"))?;
        let presence = |ours: bool, theirs: bool, what: &str| match (ours, theirs) {
            (true, false) => Err(format!("decoded mesh has no {what}")),
            (false, true) => Err(format!("decoded mesh has {what} the input has not")),
            _ => Ok(()),
        };
        presence(
            self.normals.is_some(),
            appearance.normals.is_some(),
            "normals",
        )?;
        presence(self.uvs.is_some(), appearance.uvs.is_some(), "uvs")?;
        presence(
            self.colours.is_some(),
            appearance.colours.is_some(),
            "colours",
        )?;
        presence(
            self.materials.is_some(),
            appearance.materials.is_some(),
            "materials",
        )?;
        let theirs = |w| quantize_wedge(appearance, w, self.bits, self.uv_grid.as_ref());
        let name = |m: &Option<Materials>, f: usize| {
            m.as_ref()
                .and_then(|m| m.names.get(m.face[f] as usize).cloned())
        };
        // Each canonical face by its cells, rotated so the smallest cell leads.
        let mut expected: HashMap<[[u32; 3]; 3], FaceAppearance> =
            HashMap::with_capacity(canonical.faces.len());
        for (f, face) in canonical.faces.iter().enumerate() {
            let cells = face.map(|v| canonical.cells[v as usize]);
            let codes = self.corners[f].map(|w| self.code(w));
            let r = smallest(&cells);
            expected.insert(
                rotate(cells, r),
                (rotate(codes, r), name(&self.materials, f)),
            );
        }
        let grid = canonical.grid;
        for (f, face) in decoded.faces.iter().enumerate() {
            let cells = face.map(|v| grid.quantize(decoded.positions[v as usize]));
            let codes = appearance
                .corners
                .get(f)
                .map_or([CornerCode::default(); 3], |c| c.map(theirs));
            let r = smallest(&cells);
            let Some((want, material)) = expected.get(&rotate(cells, r)) else {
                return Err(format!("decoded face {f} is not a canonical face"));
            };
            if *want != rotate(codes, r) {
                return Err(format!("decoded face {f}: corner attributes differ"));
            }
            if *material != name(&appearance.materials, f) {
                return Err(format!("decoded face {f}: material differs"));
            }
        }
        Ok(())
    }
}

/// The quantized values of wedge `w` of `attributes`.
fn quantize_wedge(
    attributes: &Attributes,
    w: WedgeId,
    bits: AttributeBits,
    uv_grid: Option<&UvGrid>,
) -> CornerCode {
    let w = w as usize;
    CornerCode {
        normal: attributes
            .normals
            .as_ref()
            .map(|n| octahedral_code(n[w], bits.normal)),
        uv: match (&attributes.uvs, uv_grid) {
            (Some(t), Some(grid)) => Some(grid.quantize(t[w])),
            _ => None,
        },
        colour: attributes.colours.as_ref().map(|c| colour_code(c[w])),
    }
}

/// Replaces each corner's normal code by the one derived from the positions over its normal
/// group ([`super::derived_normals`]): the corners of its vertex whose codes are equal. Groups of
/// one vertex whose derived codes come out equal merge and are derived again, until none do, so
/// that a decoder deriving over the groups the wedges show finds the same codes.
fn derive_corner_normals(canonical: &CanonicalMesh, codes: &mut [[CornerCode; 3]], bits: u8) {
    let cell = |v: u32| canonical.cells[v as usize].map(|x| x as i32);
    let mut key: Vec<[[u32; 2]; 3]> = codes
        .iter()
        .map(|c| c.map(|c| c.normal.unwrap_or_default()))
        .collect();
    let groups_of = |key: &[[[u32; 2]; 3]]| {
        super::derived_normals::groups_by_key(&canonical.faces, key.iter().copied())
    };
    let (mut group, mut groups) = groups_of(&key);
    loop {
        let derived = super::derived_normals::group_normal_codes(
            &canonical.faces,
            &group,
            groups,
            cell,
            canonical.grid.cell,
            bits,
        );
        key = group
            .iter()
            .map(|g| g.map(|g| derived[g as usize]))
            .collect();
        // Groups of one vertex whose codes came out equal are one group now.
        let merged = groups_of(&key);
        if merged.1 == groups {
            break;
        }
        (group, groups) = merged;
    }
    for (codes, key) in codes.iter_mut().zip(key) {
        for (c, n) in codes.iter_mut().zip(key) {
            c.normal = Some(n);
        }
    }
}

/// A face's corners' quantized values and its material's name.
type FaceAppearance = ([CornerCode; 3], Option<String>);

fn smallest(cells: &[[u32; 3]; 3]) -> usize {
    (0..3).min_by_key(|&k| cells[k]).expect("three corners")
}

fn rotate<T: Copy>(x: [T; 3], r: usize) -> [T; 3] {
    [x[r], x[(r + 1) % 3], x[(r + 2) % 3]]
}

/// The canonical mesh and appearance of `mesh` with `attributes` on `grid`.
pub fn canonical_with_attributes(
    mesh: &TriMesh,
    attributes: &Attributes,
    grid: super::Grid,
    bits: AttributeBits,
) -> Result<(CanonicalMesh, CanonicalAttributes)> {
    attributes.validate(mesh)?;
    let (canonical, origins) = CanonicalMesh::with_origins(mesh, grid)?;
    let appearance = CanonicalAttributes::new(&canonical, &origins, attributes, bits)?;
    Ok((canonical, appearance))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::attributes::Corner;
    use crate::mesh::quantize::GridShape;
    use glam::{DVec2, DVec3};

    /// Two triangles sharing an edge, with a uv seam along it, one welded duplicate vertex and
    /// a repeated face.
    fn seamed() -> (TriMesh, Attributes) {
        let mesh = TriMesh::new(
            vec![
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(0.0, 1.0, 0.0),
                DVec3::new(1.0, 1.0, 0.0),
                DVec3::new(1.0, 1.0, 1e-9), // welds onto vertex 3
            ],
            vec![[0, 1, 2], [1, 3, 2], [1, 4, 2], [0, 1, 2]],
        );
        let c = |u: f64, v: f64| Corner {
            uv: Some(DVec2::new(u, v)),
            normal: Some(DVec3::new(0.0, 0.0, 2.0)),
            ..Corner::default()
        };
        let corners = vec![
            [c(0.0, 0.0), c(0.5, 0.0), c(0.0, 0.5)],
            [c(0.6, 0.0), c(1.0, 0.5), c(0.6, 0.5)],
            [c(0.6, 0.0), c(1.0, 0.5), c(0.6, 0.5)],
            [c(0.9, 0.9), c(0.9, 0.9), c(0.9, 0.9)],
        ];
        (
            mesh.clone(),
            Attributes::weld(&mesh.faces, &corners).unwrap(),
        )
    }

    #[test]
    fn seams_stay_two_wedges_and_equal_corners_one() {
        let (mesh, attributes) = seamed();
        let grid = crate::mesh::Grid::fit(&mesh, 8, GridShape::Cubic).unwrap();
        let (canonical, appearance) =
            canonical_with_attributes(&mesh, &attributes, grid, AttributeBits::default()).unwrap();
        // Face [1,4,2] welds onto [1,3,2] and repeats it; the last face repeats the first.
        assert_eq!(canonical.faces.len(), 2);
        // Vertices 1 and 2 each have two wedges (the seam), 0 and 3 one: 6 wedges.
        assert_eq!(appearance.wedge_vertex.len(), 6);
        let decoded = canonical.to_mesh();
        let back = appearance.to_attributes();
        assert_eq!(
            appearance.check_lossless(&canonical, &decoded, &back),
            Ok(())
        );
        // A uv moved by one cell is found.
        let mut moved = back.clone();
        moved.uvs.as_mut().unwrap()[3].x += appearance.uv_grid.unwrap().cell;
        assert!(appearance
            .check_lossless(&canonical, &decoded, &moved)
            .is_err());
        // Dropping normals is found.
        let mut dropped = back.clone();
        dropped.normals = None;
        assert!(appearance
            .check_lossless(&canonical, &decoded, &dropped)
            .is_err());
    }
}
