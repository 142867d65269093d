//! Each triangle's own normal, coded where the triangle is born (`came` syntax 4), so that a
//! view-dependent front can tell whether a coarse face turns the way of the full mesh's triangle
//! it stands for (its *counterpart*) from the meta-nodes it already holds.
//!
//! Without it, nothing a front holds tells a coarse face's counterpart apart from the rest of
//! the surface under its corners (their spheres and normal cones span that surface), and the
//! orientation guard fetched meta-nodes down to the leaves to prove faces: dragon-50k's far view
//! read 98.5% of its stream, against 68.1% unguarded (BENCHMARKS.md).
//!
//! The split creating a triangle names its corners' leaves; the meta-node coding that split and
//! its ancestors place some node on each corner's leaf path, the deepest whose position they
//! hold (the *proxy*: the first node of the path that is not an inner node they split). The
//! three proxies make a triangle whose normal predicts the counterpart's; when all three are
//! leaves, they *are* the counterpart, and nothing is coded. Otherwise the counterpart's normal
//! is coded in a frame about the proxy's normal as an octahedral point of [`STEPS`] steps a half
//! axis (the proxy's normal at the centre, so that the usual small turn is a small code), or as
//! having no area. The stream's header carries the largest angle between a coded normal and the
//! counterpart's over the whole stream, rounded up ([`bound_code`]): a client takes each coded
//! normal as a cone of that half-angle about it.

use crate::mesh::attribute_quantization::{octahedral_code, octahedral_normal};
use glam::DVec3;

/// Steps of the octahedral square's half axis: codes run −STEPS … STEPS on each axis. Eight
/// keep a coded normal within about 7° of the counterpart's for some 6.7 bits a coded triangle
/// on dragon-50k (16: about 3.5°, 8.5 bits).
pub const STEPS: u8 = 8;

/// Half-degrees of the header's bound: the largest it can say is 90°, which proves nothing.
pub const BOUND_HALF_DEGREES_MAX: u8 = 180;

/// The normal of a triangle on corners `p` (grid units) in the mesh's units: the cross product
/// of its edges scaled by the grid's cells (its length twice the area).
pub fn scaled_normal(p: [[f64; 3]; 3], cell: [f64; 3]) -> DVec3 {
    let at = |k: usize| DVec3::new(p[k][0] * cell[0], p[k][1] * cell[1], p[k][2] * cell[2]);
    (at(1) - at(0)).cross(at(2) - at(0))
}

/// An orthonormal frame whose third axis is `proxy`'s direction (Duff et al. 2017's branchless
/// basis; the world's axes where `proxy` has no direction). Computed alike by both sides.
fn frame(proxy: DVec3) -> [DVec3; 3] {
    let length = proxy.length();
    if !(length > 0.0 && length.is_finite()) {
        return [DVec3::X, DVec3::Y, DVec3::Z];
    }
    let n = proxy / length;
    let sign = 1f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    [
        DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        DVec3::new(b, sign + n.y * n.y * a, -n.y),
        n,
    ]
}

fn sign(x: f64) -> f64 {
    if x < 0.0 {
        -1.0
    } else {
        1.0
    }
}

/// The unit normal that `code` stands for about `proxy` (codes within −steps … steps).
pub fn decoded(proxy: DVec3, code: [i32; 2], steps: u8) -> DVec3 {
    let (mut u, mut v) = (code[0] as f64 / steps as f64, code[1] as f64 / steps as f64);
    let z = 1.0 - u.abs() - v.abs();
    if z < 0.0 {
        (u, v) = ((1.0 - v.abs()) * sign(u), (1.0 - u.abs()) * sign(v));
    }
    let [x, y, n] = frame(proxy);
    (x * u + y * v + n * z).normalize()
}

/// The code whose normal is nearest `normal`'s direction about `proxy`, and the angle between
/// them in degrees; `None` for a normal of no area.
pub fn nearest_code(proxy: DVec3, normal: DVec3, steps: u8) -> Option<([i32; 2], f64)> {
    let length = normal.length();
    if !(length > 0.0 && length.is_finite()) {
        return None;
    }
    let n = normal / length;
    let [x, y, z] = frame(proxy);
    let d = DVec3::new(n.dot(x), n.dot(y), n.dot(z));
    let l1 = d.x.abs() + d.y.abs() + d.z.abs();
    let (mut u, mut v) = (d.x / l1, d.y / l1);
    if d.z < 0.0 {
        (u, v) = ((1.0 - v.abs()) * sign(u), (1.0 - u.abs()) * sign(v));
    }
    let m = steps as i32;
    let (i0, j0) = ((u * m as f64).round() as i32, (v * m as f64).round() as i32);
    let mut best: Option<([i32; 2], f64)> = None;
    for i in (i0 - 1).max(-m)..=(i0 + 1).min(m) {
        for j in (j0 - 1).max(-m)..=(j0 + 1).min(m) {
            let cos = decoded(proxy, [i, j], steps).dot(n);
            if best.is_none_or(|(_, c)| cos > c) {
                best = Some(([i, j], cos));
            }
        }
    }
    best.map(|(code, cos)| (code, cos.clamp(-1.0, 1.0).acos().to_degrees()))
}

/// The header's code for a largest angle of `degrees`: half-degrees, rounded up with a margin
/// for the rounding of the angles measured (at most [`BOUND_HALF_DEGREES_MAX`]).
pub fn bound_code(degrees: f64) -> u8 {
    let half = (degrees * 2.0 + 1e-6).ceil().max(1.0);
    half.min(BOUND_HALF_DEGREES_MAX as f64) as u8
}

/// The angle a bound code stands for, in degrees.
pub fn bound_degrees(code: u8) -> f64 {
    code as f64 / 2.0
}

/// Bits a coordinate of the octahedral direction a decoder keeps a triangle's normal in.
const KEPT_BITS: u8 = 16;
/// The most a kept direction is off its decoded normal, in degrees (16-bit octahedral
/// coordinates are off by under 0.004°: `kept_directions_are_within_their_margin`).
const KEPT_MARGIN_DEGREES: f64 = 0.01;
const UNKNOWN: u8 = u8::MAX;
const NO_AREA: u8 = u8::MAX - 1;

/// What a decoder knows of a triangle's normal, in six bytes (a decoded triangle keeps it in
/// the padding of its record): a direction as 16-bit octahedral coordinates and the angle
/// within which the normal lies, in half-degrees rounded up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FaceNormal {
    direction: [u16; 2],
    /// Half-degrees, or [`UNKNOWN`], or [`NO_AREA`].
    bound: u8,
}

impl Default for FaceNormal {
    fn default() -> FaceNormal {
        FaceNormal::UNKNOWN
    }
}

impl FaceNormal {
    /// Nothing known (streams before syntax 4).
    pub const UNKNOWN: FaceNormal = FaceNormal {
        direction: [0; 2],
        bound: UNKNOWN,
    };
    /// The triangle has no area: it turns no way.
    pub const NO_AREA: FaceNormal = FaceNormal {
        direction: [0; 2],
        bound: NO_AREA,
    };

    /// A normal within `degrees` of `direction` (a unit vector in the mesh's units); unknown
    /// when that is 90° or more, which proves nothing.
    pub fn within(direction: DVec3, degrees: f64) -> FaceNormal {
        let half = ((degrees + KEPT_MARGIN_DEGREES) * 2.0).ceil();
        // (A NaN angle is no bound either.)
        if half.is_nan() || half >= BOUND_HALF_DEGREES_MAX as f64 || !direction.is_finite() {
            return FaceNormal::UNKNOWN;
        }
        let code = octahedral_code(direction, KEPT_BITS);
        FaceNormal {
            direction: code.map(|c| c as u16),
            bound: half.max(0.0) as u8,
        }
    }

    /// The normal's direction and the angle within which it lies, in degrees; `None` for a
    /// triangle of no area or an unknown normal ([`Self::is_known`] tells them apart).
    pub fn cone(self) -> Option<(DVec3, f64)> {
        (self.bound < NO_AREA).then(|| {
            (
                octahedral_normal(self.direction.map(u32::from), KEPT_BITS),
                bound_degrees(self.bound),
            )
        })
    }

    /// Whether the stream says anything of the normal.
    pub fn is_known(self) -> bool {
        self.bound != UNKNOWN
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn random_unit(seed: &mut u64) -> DVec3 {
        let mut next = || {
            *seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (*seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        loop {
            let v = DVec3::new(next(), next(), next());
            if v.length() > 0.1 && v.length() <= 1.0 {
                return v.normalize();
            }
        }
    }

    #[test]
    fn a_code_stands_within_a_few_degrees_of_the_normal_whatever_the_proxy() {
        let mut seed = 7;
        let mut worst = 0.0f64;
        for _ in 0..20_000 {
            let proxy = random_unit(&mut seed) * 3.0;
            let normal = random_unit(&mut seed) * 0.5;
            let (code, angle) = nearest_code(proxy, normal, STEPS).expect("a normal");
            assert!(code.iter().all(|c| c.abs() <= STEPS as i32));
            let back = decoded(proxy, code, STEPS);
            let measured = back
                .dot(normal.normalize())
                .clamp(-1.0, 1.0)
                .acos()
                .to_degrees();
            assert!((measured - angle).abs() < 1e-9);
            worst = worst.max(angle);
        }
        assert!(worst < 10.0, "worst {worst}°");
        assert!(worst > 1.0, "worst {worst}°: no rounding at all?");
    }

    #[test]
    fn the_proxys_own_normal_is_the_centre_and_no_area_has_no_code() {
        let proxy = DVec3::new(0.3, -2.0, 0.7);
        let (code, angle) = nearest_code(proxy, proxy * 5.0, STEPS).unwrap();
        assert_eq!(code, [0, 0]);
        assert!(angle < 1e-6);
        assert!(nearest_code(proxy, DVec3::ZERO, STEPS).is_none());
        // A proxy of no area: the world's axes.
        let (code, _) = nearest_code(DVec3::ZERO, DVec3::Z, STEPS).unwrap();
        assert_eq!(code, [0, 0]);
    }

    #[test]
    fn kept_directions_are_within_their_margin() {
        let mut seed = 3;
        for _ in 0..20_000 {
            let n = random_unit(&mut seed);
            let (kept, degrees) = FaceNormal::within(n, 1.0).cone().unwrap();
            let off = kept.dot(n).clamp(-1.0, 1.0).acos().to_degrees();
            assert!(off < 0.4 * KEPT_MARGIN_DEGREES, "{off}°");
            assert!(degrees >= 1.0 + KEPT_MARGIN_DEGREES);
        }
        assert_eq!(FaceNormal::within(DVec3::Z, 89.9), FaceNormal::UNKNOWN);
        assert!(FaceNormal::NO_AREA.cone().is_none() && FaceNormal::NO_AREA.is_known());
        assert!(!FaceNormal::UNKNOWN.is_known());
    }

    #[test]
    fn the_bound_rounds_up() {
        assert_eq!(bound_code(6.2), 13);
        assert!(bound_degrees(bound_code(6.5)) >= 6.5);
        assert_eq!(bound_code(500.0), BOUND_HALF_DEGREES_MAX);
    }
}
