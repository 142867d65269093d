//! Normal cones (Hoppe 1997 §4.2's n̂_v and α_v): per node, a cone of directions holding the
//! normal of every face with a corner in the node's subtree, so that a view can tell a node all
//! of whose faces turn away from the eye and leave it unrefined (back-face culling).
//!
//! A cone is coded as an octahedral axis of [`AXIS_BITS`] bits a coordinate and a half-angle
//! rounded up to a multiple of [`ANGLE_STEP`], taken about the *coded* axis, so that a decoded
//! cone holds every normal it stands for. A half-angle of 90° or more can cull nothing; such a
//! node is coded as having no cone.
//!
//! Cones are found bottom-up: a leaf's holds its faces' normals, an inner node's is the least
//! cone holding its children's (their union). Faces of no area have no normal and count for
//! nothing: seen from anywhere, they draw nothing.

use super::VertexTree;
use crate::mesh::attribute_quantization::{octahedral_code, octahedral_normal};
use glam::DVec3;
use std::f64::consts::FRAC_PI_2;

/// Bits a coordinate of a cone's octahedral axis.
pub const AXIS_BITS: u8 = 6;
/// Half-angle codes 0 … NO_CONE − 1 stand for (code + 1) · [`ANGLE_STEP`]; `NO_CONE` for none.
pub const NO_CONE: u32 = 31;
const _: () = assert!(AXIS_BITS <= 8);
/// Bits of a half-angle code.
pub const ANGLE_BITS: u8 = 5;
/// The half-angle's step: 90° / 32.
pub const ANGLE_STEP: f64 = FRAC_PI_2 / 32.0;

/// A cone as a stream codes it: its octahedral axis and its half-angle code (three bytes, so
/// that the decoder's node records hardly grow).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CodedCone {
    pub axis: [u8; 2],
    /// Half-angle code; [`NO_CONE`]: no cone (the axis is then not coded).
    pub angle: u8,
}

impl CodedCone {
    pub const NONE: CodedCone = CodedCone {
        axis: [0, 0],
        angle: NO_CONE as u8,
    };

    /// The cone it stands for.
    pub fn decoded(self) -> NormalCone {
        if self.angle as u32 >= NO_CONE {
            return NormalCone::NONE;
        }
        let a = octahedral_normal(self.axis.map(u32::from), AXIS_BITS);
        NormalCone::new(
            [a.x as f32, a.y as f32, a.z as f32],
            (self.angle as f64 + 1.0) * ANGLE_STEP,
        )
    }
}

/// A decoded cone: every normal it stands for lies within `half_angle` of `axis`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NormalCone {
    pub axis: [f32; 3],
    /// Radians; [`NormalCone::NONE`]'s is π (any direction).
    pub half_angle: f32,
    /// Sine and cosine of the half-angle widened by [`CONE_MARGIN`], for tests without
    /// inverse trigonometry.
    pub sin: f32,
    pub cos: f32,
}

/// Radians a cone is widened by in [`NormalCone::sin`] and `cos`: more than its 32-bit axis
/// and angle can be off.
pub const CONE_MARGIN: f64 = 1e-4;

impl NormalCone {
    /// No cone: any direction.
    pub const NONE: NormalCone = NormalCone {
        axis: [0.0, 0.0, 1.0],
        half_angle: std::f32::consts::PI,
        sin: 0.0,
        cos: -1.0,
    };

    /// The cone of half-angle `half_angle` (radians) about the unit vector `axis`.
    pub fn new(axis: [f32; 3], half_angle: f64) -> NormalCone {
        let widened = (half_angle + CONE_MARGIN).min(std::f64::consts::PI);
        NormalCone {
            axis,
            half_angle: half_angle as f32,
            sin: widened.sin() as f32,
            cos: widened.cos() as f32,
        }
    }

    /// Whether it can cull anything (its half-angle is below 90°).
    pub fn is_some(&self) -> bool {
        (self.half_angle as f64) < FRAC_PI_2
    }
}

/// A cone of exact directions while the tree is built (half-angle π: none).
#[derive(Clone, Copy, Debug)]
struct Cone {
    axis: DVec3,
    half_angle: f64,
}

impl Cone {
    const EMPTY: Cone = Cone {
        axis: DVec3::ZERO,
        half_angle: -1.0,
    };

    fn is_empty(&self) -> bool {
        self.half_angle < 0.0
    }

    /// The least cone holding `self` and `other`.
    fn union(self, other: Cone) -> Cone {
        if self.is_empty() {
            return other;
        }
        if other.is_empty() {
            return self;
        }
        let theta = angle(self.axis, other.axis);
        if theta + other.half_angle <= self.half_angle {
            return self;
        }
        if theta + self.half_angle <= other.half_angle {
            return other;
        }
        let half_angle = (theta + self.half_angle + other.half_angle) / 2.0;
        if half_angle >= FRAC_PI_2 || theta.sin() < 1e-9 {
            return Cone {
                axis: self.axis,
                half_angle: std::f64::consts::PI,
            };
        }
        // Turn self's axis towards other's by the difference of the half-angles.
        let t = half_angle - self.half_angle;
        let axis = ((theta - t).sin() * self.axis + t.sin() * other.axis) / theta.sin();
        Cone {
            axis: axis.normalize(),
            half_angle,
        }
    }
}

/// The angle between two unit vectors, robust near 0 and π.
fn angle(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b))
}

/// Every node's coded cone, for the faces `faces` on the cells `cells` of cell size `cell`.
///
/// A child of a node with a cone takes its parent's axis (its half-angle is taken about that
/// axis): only a node whose parent has no cone codes an axis of its own. On
/// bunny-closed-35k ×16, cones about axes of their own (the nearest octahedral code to the
/// axis of the least cone) culled 0.6% more faces over the fly-through for 1.9× the bits.
pub fn coded_cones(
    tree: &VertexTree,
    cells: &[[u32; 3]],
    faces: &[[u32; 3]],
    cell: [f64; 3],
) -> Vec<CodedCone> {
    let n = tree.leaves;
    let scale = DVec3::from_array(cell);
    let world = |v: u32| DVec3::from_array(cells[v as usize].map(|x| x as f64)) * scale;
    let mut exact = vec![Cone::EMPTY; tree.node_count()];
    for face in faces {
        let [a, b, c] = face.map(world);
        let normal = (b - a).cross(c - a);
        let length = normal.length();
        if !(length > 0.0 && length.is_finite()) {
            continue;
        }
        let cone = Cone {
            axis: normal / length,
            half_angle: 0.0,
        };
        for &v in face {
            exact[v as usize] = exact[v as usize].union(cone);
        }
    }
    // Inner nodes come after their children.
    for (i, &[t, u]) in tree.children.iter().enumerate() {
        exact[n + i] = exact[t as usize].union(exact[u as usize]);
    }
    let mut coded = vec![CodedCone::NONE; tree.node_count()];
    // The cone about `axis` holding `cone`, rounded up.
    let code = |cone: &Cone, axis: [u8; 2]| -> CodedCone {
        if cone.is_empty() {
            // No face with an area: anything culls it; the narrowest cone says so.
            return CodedCone { axis, angle: 0 };
        }
        let about = octahedral_normal(axis.map(u32::from), AXIS_BITS);
        let needed = angle(cone.axis, about) + cone.half_angle;
        // (code + 1) steps hold `needed`; rounding may leave the bound a hair short: one
        // step more then.
        let steps = (needed / ANGLE_STEP)
            .ceil()
            .clamp(1.0, NO_CONE as f64 + 1.0);
        let mut angle = steps as u32 - 1;
        if (angle + 1) as f64 * ANGLE_STEP < needed {
            angle += 1;
        }
        if angle >= NO_CONE {
            return CodedCone::NONE;
        }
        CodedCone {
            axis,
            angle: angle as u8,
        }
    };
    let own = |cone: &Cone| {
        let axis = if cone.is_empty() { DVec3::Z } else { cone.axis };
        // Codes of 6 bits fit a byte.
        code(cone, octahedral_code(axis, AXIS_BITS).map(|c| c as u8))
    };
    if tree.node_count() == 0 {
        return coded;
    }
    coded[tree.root as usize] = own(&exact[tree.root as usize]);
    for s in tree.breadth_first() {
        let parent = coded[s as usize];
        for c in tree.children_of(s).expect("inner") {
            if tree.is_leaf(c) {
                continue;
            }
            let cone = &exact[c as usize];
            coded[c as usize] = if (parent.angle as u32) < NO_CONE {
                code(cone, parent.axis)
            } else {
                own(cone)
            };
        }
    }
    coded
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hierarchy::came::{build, BuildOptions};
    use crate::mesh::generate;

    #[test]
    fn the_union_of_two_cones_holds_both() {
        let a = Cone {
            axis: DVec3::X,
            half_angle: 0.1,
        };
        let b = Cone {
            axis: DVec3::Y,
            half_angle: 0.2,
        };
        let u = a.union(b);
        assert!(angle(u.axis, a.axis) + a.half_angle <= u.half_angle + 1e-12);
        assert!(angle(u.axis, b.axis) + b.half_angle <= u.half_angle + 1e-12);
        assert!((u.half_angle - (FRAC_PI_2 + 0.3) / 2.0).abs() < 1e-12);
        // Opposite directions hold everything.
        let back = Cone {
            axis: -DVec3::X,
            half_angle: 0.0,
        };
        assert!(!a.union(back).half_angle.is_nan());
        assert!(a.union(back).half_angle >= FRAC_PI_2);
    }

    #[test]
    fn every_decoded_cone_holds_the_normals_of_its_subtrees_faces() {
        let mesh = generate::torus(1.0, 0.35, 24, 12);
        let canonical = crate::codecs::canonical_for(
            &mesh,
            &crate::codecs::EncodeOptions {
                quant_bits: 12,
                grid: crate::mesh::quantize::GridShape::Cubic,
            },
        )
        .unwrap();
        let tree = build(&canonical.cells, &canonical.faces, &BuildOptions::default()).unwrap();
        let cones = coded_cones(
            &tree,
            &canonical.cells,
            &canonical.faces,
            canonical.grid.cell,
        );
        let scale = DVec3::from_array(canonical.grid.cell);
        let mut some = 0;
        for (x, coded) in cones.iter().enumerate() {
            let cone = coded.decoded();
            if tree.is_leaf(x as u32) || !cone.is_some() {
                continue;
            }
            some += 1;
            let axis = DVec3::from_array(cone.axis.map(|a| a as f64));
            let id = tree.ids[x];
            for face in &canonical.faces {
                if !face
                    .iter()
                    .any(|&v| id.is_ancestor_of(tree.ids[v as usize]))
                {
                    continue;
                }
                let p = face
                    .map(|v| DVec3::from_array(canonical.cells[v as usize].map(f64::from)) * scale);
                let n = (p[1] - p[0]).cross(p[2] - p[0]);
                if n.length() == 0.0 {
                    continue;
                }
                let off = angle(n.normalize(), axis);
                assert!(
                    off <= cone.half_angle as f64 + 1e-6,
                    "node {x}: a normal {off} off the axis, cone {}",
                    cone.half_angle
                );
            }
        }
        assert!(some > 50, "{some} nodes with a cone");
    }
}
