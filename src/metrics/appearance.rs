//! Appearance error of a decoded level against the original (docs/CONTRACT.md §5.1).
//!
//! Positions say nothing about a level's seams, so the error is measured where a viewer sees it:
//! at random points on the original surface. Each point carries the original's attributes,
//! interpolated inside its face from the face's wedges; the same point is projected onto the
//! level, and the level's attributes are interpolated at the projection inside the face it lands
//! on. A seam pulled apart or a chart folded over shows as a large difference there. Texture
//! coordinates are compared in texels of a 1024² texture, normals by angle, colours in 8-bit
//! steps, materials by the share of points that land on a face of another material.

use crate::mesh::attributes::{AttributedMesh, Attributes};
use crate::mesh::TriMesh;
use crate::metrics::{sample_faces, SurfaceIndex};
use glam::{DVec2, DVec3};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Texture side the uv error is expressed in: one texel is 1/1024 of the uv unit square.
pub const TEXTURE_SIZE: f64 = 1024.0;

/// What a level's appearance costs the viewer, averaged over the sample points. A field is
/// `None` when the original has no such attribute or the level carries none.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct AppearanceError {
    /// Mean distance between the original's and the level's texture coordinates, in texels of
    /// a 1024² texture.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub uv_texels: Option<f64>,
    /// Root mean square of the same distances (texels of a 1024² texture): weighs a point
    /// carried across a seam more than many slightly off.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub uv_rms_texels: Option<f64>,
    /// Mean angle between the original's and the level's normals, degrees.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal_degrees: Option<f64>,
    /// Mean absolute difference of a colour channel (RGBA), in steps of 1/255.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub colour_steps: Option<f64>,
    /// Share of the sample points that land on a face of another material.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wrong_material: Option<f64>,
}

/// The attributes at one point, interpolated from a face's wedges.
#[derive(Clone, Copy, Debug, Default)]
struct Values {
    uv: Option<DVec2>,
    normal: Option<DVec3>,
    colour: Option<[f64; 4]>,
    material: Option<u32>,
}

/// The original's appearance at its sample points, prepared once for many levels.
pub struct AppearanceReference {
    points: Vec<DVec3>,
    values: Vec<Values>,
}

impl AppearanceReference {
    /// `count` area-weighted points of `original` and its attributes there; `None` when the
    /// original has no appearance.
    pub fn new(original: &AttributedMesh, count: usize, seed: u64) -> Option<AppearanceReference> {
        let a = &original.attributes;
        if a.is_empty() {
            return None;
        }
        let samples = sample_faces(&original.mesh, count, seed);
        let points = samples.iter().map(|s| s.position(&original.mesh)).collect();
        let values = samples
            .iter()
            .map(|s| interpolate(a, s.face, s.weights()))
            .collect();
        Some(AppearanceReference { points, values })
    }

    /// The error of a level's appearance; every field `None` when the level has none.
    pub fn compare(&self, level: &TriMesh, attributes: Option<&Attributes>) -> AppearanceError {
        let Some(attributes) = attributes else {
            return AppearanceError::default();
        };
        let index = SurfaceIndex::of_mesh(level, &[]);
        // Fixed chunks summed in order: the same floating-point sum however rayon schedules
        // them (a fold's splits vary from run to run, and so did the last bits).
        const CHUNK: usize = 1024;
        let chunks: Vec<Sums> = self
            .points
            .par_chunks(CHUNK)
            .zip(self.values.par_chunks(CHUNK))
            .map(|(points, values)| {
                let mut sums = Sums::default();
                for (&p, original) in points.iter().zip(values) {
                    if let Some((face, w)) = index.nearest_face(p) {
                        sums.add(original, &interpolate(attributes, face, w));
                    }
                }
                sums
            })
            .collect();
        chunks
            .into_iter()
            .fold(Sums::default(), Sums::merge)
            .error()
    }
}

/// The attributes of face `face` at corner weights `w`.
fn interpolate(a: &Attributes, face: u32, w: [f64; 3]) -> Values {
    let Some(wedges) = a.corners.get(face as usize) else {
        return Values {
            material: material_of(a, face),
            ..Values::default()
        };
    };
    let mix2 = |values: &[DVec2]| {
        (0..3).fold(DVec2::ZERO, |sum, k| {
            sum + values[wedges[k] as usize] * w[k]
        })
    };
    let mix3 = |values: &[DVec3]| {
        (0..3).fold(DVec3::ZERO, |sum, k| {
            sum + values[wedges[k] as usize].normalize_or_zero() * w[k]
        })
    };
    Values {
        uv: a.uvs.as_deref().map(mix2),
        normal: a.normals.as_deref().map(|n| mix3(n).normalize_or_zero()),
        colour: a.colours.as_deref().map(|c| {
            let mut out = [0.0; 4];
            for (k, weight) in w.iter().enumerate() {
                for (o, x) in out.iter_mut().zip(c[wedges[k] as usize]) {
                    *o += x * weight;
                }
            }
            out
        }),
        material: material_of(a, face),
    }
}

fn material_of(a: &Attributes, face: u32) -> Option<u32> {
    a.materials
        .as_ref()
        .and_then(|m| m.face.get(face as usize).copied())
}

/// Running sums of the per-point differences.
#[derive(Clone, Copy, Debug, Default)]
struct Sums {
    uv: (f64, usize),
    uv_squared: f64,
    normal: (f64, usize),
    colour: (f64, usize),
    material: (f64, usize),
}

impl Sums {
    fn add(&mut self, original: &Values, level: &Values) {
        if let (Some(a), Some(b)) = (original.uv, level.uv) {
            let d = (a - b).length() * TEXTURE_SIZE;
            self.uv.0 += d;
            self.uv_squared += d * d;
            self.uv.1 += 1;
        }
        if let (Some(a), Some(b)) = (original.normal, level.normal) {
            if a != DVec3::ZERO && b != DVec3::ZERO {
                self.normal.0 += a.dot(b).clamp(-1.0, 1.0).acos().to_degrees();
                self.normal.1 += 1;
            }
        }
        if let (Some(a), Some(b)) = (original.colour, level.colour) {
            let steps: f64 = a.iter().zip(b).map(|(x, y)| (x - y).abs() * 255.0).sum();
            self.colour.0 += steps / 4.0;
            self.colour.1 += 1;
        }
        if let (Some(a), Some(b)) = (original.material, level.material) {
            self.material.0 += f64::from(u8::from(a != b));
            self.material.1 += 1;
        }
    }

    fn merge(a: Sums, b: Sums) -> Sums {
        let add = |x: (f64, usize), y: (f64, usize)| (x.0 + y.0, x.1 + y.1);
        Sums {
            uv: add(a.uv, b.uv),
            uv_squared: a.uv_squared + b.uv_squared,
            normal: add(a.normal, b.normal),
            colour: add(a.colour, b.colour),
            material: add(a.material, b.material),
        }
    }

    fn error(&self) -> AppearanceError {
        let mean = |(sum, n): (f64, usize)| (n > 0).then(|| sum / n as f64);
        AppearanceError {
            uv_texels: mean(self.uv),
            uv_rms_texels: mean((self.uv_squared, self.uv.1)).map(f64::sqrt),
            normal_degrees: mean(self.normal),
            colour_steps: mean(self.colour),
            wrong_material: mean(self.material),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::attributes::Materials;
    use crate::mesh::generate;

    /// A grid mesh with uvs equal to x, y (one wedge a vertex), normals +z, one material.
    fn planar_grid() -> AttributedMesh {
        let mesh = generate::terrain(12, 0);
        let flat = TriMesh::new(
            mesh.positions
                .iter()
                .map(|p| DVec3::new(p.x, p.y, 0.0))
                .collect(),
            mesh.faces.clone(),
        );
        let n = flat.positions.len();
        let attributes = Attributes {
            corners: flat.faces.clone(),
            wedge_vertex: (0..n as u32).collect(),
            normals: Some(vec![DVec3::Z; n]),
            uvs: Some(
                flat.positions
                    .iter()
                    .map(|p| DVec2::new(p.x, p.y))
                    .collect(),
            ),
            colours: None,
            materials: Some(Materials {
                face: vec![0; flat.faces.len()],
                names: vec!["m".into()],
                library: None,
            }),
        };
        AttributedMesh {
            mesh: flat,
            attributes,
        }
    }

    #[test]
    fn the_original_against_itself_has_no_error() {
        let m = planar_grid();
        let reference = AppearanceReference::new(&m, 2000, 3).unwrap();
        let e = reference.compare(&m.mesh, Some(&m.attributes));
        assert!(e.uv_texels.unwrap() < 1e-3, "{e:?}");
        assert!(e.normal_degrees.unwrap() < 1e-3, "{e:?}");
        assert_eq!(e.wrong_material, Some(0.0));
        assert_eq!(e.colour_steps, None);
        assert_eq!(reference.compare(&m.mesh, None), AppearanceError::default());
    }

    #[test]
    fn shifted_uvs_and_tilted_normals_are_measured() {
        let m = planar_grid();
        let reference = AppearanceReference::new(&m, 2000, 3).unwrap();
        let mut moved = m.attributes.clone();
        for t in moved.uvs.as_mut().unwrap() {
            *t += DVec2::new(3.0 / TEXTURE_SIZE, 4.0 / TEXTURE_SIZE);
        }
        let tilt = 10f64.to_radians();
        moved.normals = Some(vec![
            DVec3::new(tilt.sin(), 0.0, tilt.cos());
            m.mesh.positions.len()
        ]);
        moved.materials.as_mut().unwrap().face[0] = 1;
        moved.materials.as_mut().unwrap().names.push("n".into());
        let e = reference.compare(&m.mesh, Some(&moved));
        assert!((e.uv_texels.unwrap() - 5.0).abs() < 1e-6, "{e:?}");
        assert!((e.uv_rms_texels.unwrap() - 5.0).abs() < 1e-6, "{e:?}");
        assert!((e.normal_degrees.unwrap() - 10.0).abs() < 1e-6, "{e:?}");
        let share = e.wrong_material.unwrap();
        assert!(share > 0.0 && share < 0.05, "{e:?}");
    }
}
