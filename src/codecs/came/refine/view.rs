//! The view a front is adapted to: the eye, the frustum's side and near planes, and κ.

use crate::error::{Error, Result};
use crate::hierarchy::came::cones::NormalCone;
use glam::DVec3;

/// A pinhole camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub eye: DVec3,
    pub target: DVec3,
    pub up: DVec3,
    /// Vertical field of view φ in degrees.
    pub fov_degrees: f64,
    /// Viewport in pixels.
    pub width: u32,
    pub height: u32,
}

/// What refinement tests nodes against.
#[derive(Clone, Debug, PartialEq)]
pub struct View {
    eye: DVec3,
    /// The viewing direction (zero for the views of no camera).
    forward: DVec3,
    /// Inward unit normals of planes through the eye (sides, and the near plane at the eye).
    planes: Vec<DVec3>,
    /// κ = 2·τ·tan(φ/2) / H: a sphere of radius r at distance d spans about τ·r / (κ·d) pixels.
    kappa: f64,
    /// Whether nodes all of whose faces turn away from the eye are left unrefined (the
    /// surface is drawn one-sided).
    cull_back_faces: bool,
    /// Whether the front keeps every face in view turned as its full-mesh counterpart (the
    /// orientation guard of `ViewMesh`).
    keep_orientation: bool,
}

impl View {
    /// The view of `camera` with a tolerance of `tolerance` pixels.
    pub fn new(camera: &Camera, tolerance: f64) -> Result<View> {
        let bad = |what: &str| Err(Error::Unsupported(format!("camera: {what}")));
        if !(camera.fov_degrees > 0.0 && camera.fov_degrees < 180.0) {
            return bad("the field of view must lie strictly between 0 and 180 degrees");
        }
        if camera.width == 0 || camera.height == 0 {
            return bad("the viewport needs a width and a height");
        }
        if !(tolerance.is_finite() && tolerance >= 0.0) {
            return bad("the tolerance must be a number of pixels, 0 or more");
        }
        let forward = (camera.target - camera.eye).normalize_or_zero();
        let right = forward.cross(camera.up).normalize_or_zero();
        if forward == DVec3::ZERO || right == DVec3::ZERO || !camera.eye.is_finite() {
            return bad("eye, target and up must be finite, the target away from the eye and up not along the view");
        }
        let up = right.cross(forward);
        let tan_y = (camera.fov_degrees.to_radians() / 2.0).tan();
        let tan_x = tan_y * camera.width as f64 / camera.height as f64;
        let planes = vec![
            (forward * tan_x - right).normalize(),
            (forward * tan_x + right).normalize(),
            (forward * tan_y - up).normalize(),
            (forward * tan_y + up).normalize(),
            forward,
        ];
        Ok(View {
            eye: camera.eye,
            forward,
            planes,
            kappa: 2.0 * tolerance * tan_y / camera.height as f64,
            cull_back_faces: true,
            keep_orientation: true,
        })
    }

    /// The same view with back faces refined like front faces (`true`: for a surface drawn
    /// two-sided, or seen from inside) or not (`false`, the default).
    pub fn two_sided(self, two_sided: bool) -> View {
        View {
            cull_back_faces: !two_sided,
            ..self
        }
    }

    /// The same view with the orientation guard on (`true`, the default: no face in view
    /// folds over) or off (`false`: faster, fewer faces, and fold-overs where the hierarchy
    /// makes them).
    pub fn keep_orientation(self, keep: bool) -> View {
        View {
            keep_orientation: keep,
            ..self
        }
    }

    /// Whether the orientation guard is on.
    pub fn keeps_orientation(&self) -> bool {
        self.keep_orientation
    }

    /// Whether every face a node with this sphere and normal cone stands for turns away from
    /// the eye (Hoppe 1997 §4.2, made to hold over the whole sphere): with w the direction
    /// from the eye to the centre, θ its angle to the cone's axis, α the cone's half-angle and
    /// β = asin(r / |w|) the sphere's angular radius, every point p of the sphere and normal n
    /// of the cone have ∠(p − e, n) ≤ β + θ + α, so the node faces away when that is under 90°.
    /// A sphere holding the eye never does.
    pub fn faces_away(&self, center: DVec3, radius: f64, cone: &NormalCone) -> bool {
        if !self.cull_back_faces || !cone.is_some() {
            return false;
        }
        // In cosines: θ < 90° − (α + β) ⇔ cos θ > sin(α + β) while α + β < 90°; with
        // d = |w|, d·sin β = r and d·cos β = √(d² − r²) (α widened by the cone's margin).
        let w = center - self.eye;
        let tangent_sq = w.length_squared() - radius * radius;
        // Not positive, or NaN: the sphere holds the eye.
        if tangent_sq.is_nan() || tangent_sq <= 0.0 {
            return false;
        }
        let tangent = tangent_sq.sqrt();
        let (sin, cos) = (cone.sin as f64, cone.cos as f64);
        if cos * tangent <= sin * radius {
            return false;
        }
        let axis = DVec3::new(
            cone.axis[0] as f64,
            cone.axis[1] as f64,
            cone.axis[2] as f64,
        );
        w.dot(axis) > sin * tangent + cos * radius
    }

    /// A view that wants every node refined (no frustum, no tolerance): the full mesh.
    pub fn everything() -> View {
        View {
            eye: DVec3::ZERO,
            forward: DVec3::ZERO,
            planes: Vec::new(),
            kappa: 0.0,
            cull_back_faces: false,
            keep_orientation: true,
        }
    }

    /// A view that wants no node refined: the root alone.
    pub fn nothing() -> View {
        View {
            eye: DVec3::ZERO,
            forward: DVec3::ZERO,
            planes: Vec::new(),
            kappa: f64::INFINITY,
            cull_back_faces: false,
            keep_orientation: true,
        }
    }

    /// The eye.
    pub fn eye(&self) -> DVec3 {
        self.eye
    }

    /// κ.
    pub fn kappa(&self) -> f64 {
        self.kappa
    }

    /// Whether back faces are refined like front faces ([`View::two_sided`]).
    pub fn is_two_sided(&self) -> bool {
        !self.cull_back_faces
    }

    /// Whether a sphere at `center` of `radius` meets the frustum ([`View::nothing`] sees
    /// nothing).
    pub fn sees(&self, center: DVec3, radius: f64) -> bool {
        if self.planes.is_empty() && self.kappa == f64::INFINITY {
            return false;
        }
        let d = center - self.eye;
        self.planes.iter().all(|n| d.dot(*n) >= -radius)
    }

    /// Whether triangle `p` meets the frustum (its bounding sphere about its centroid does,
    /// widened a hair for rounding).
    pub fn sees_triangle(&self, p: [DVec3; 3]) -> bool {
        let centre = (p[0] + p[1] + p[2]) / 3.0;
        let radius = p.iter().map(|&q| q.distance(centre)).fold(0.0, f64::max);
        self.sees(centre, radius * (1.0 + 1e-9))
    }

    /// Whether triangle `p` meets the frustum and spans the tolerance on the screen (its
    /// bounding sphere's diameter, projected as [`View::wants_split`] projects a deviation): a
    /// face smaller than that shows within the tolerance whichever way it turns.
    pub fn shows_triangle(&self, p: [DVec3; 3]) -> bool {
        let centre = (p[0] + p[1] + p[2]) / 3.0;
        let radius = p.iter().map(|&q| q.distance(centre)).fold(0.0, f64::max) * (1.0 + 1e-9);
        self.sees(centre, radius) && self.deviates(centre, radius, 2.0 * radius, 1.0)
    }

    /// Whether a node with this error sphere, deviation and normal cone is to be refined, κ
    /// scaled by `scale` (the face budget's regulation): in the frustum, not facing away
    /// ([`View::faces_away`]) and deviating by the tolerance or more on the screen.
    ///
    /// The projected deviation is bounded from above wherever in the sphere the error lies:
    /// over the sphere, the projection (x/z, y/z) stretches lengths by at most √(1 + t²) / z,
    /// with z the least depth and t the largest tangent off the axis, so the node is refined
    /// while e·√(1 + t²) ≥ κ·z_min (z_min = depth of the centre − r; t = (lateral distance +
    /// r) / z_min). A sphere reaching the eye's plane is always refined (unless its deviation
    /// is 0: its surface is exact). With e = r, this is the paper's test on the spheres.
    pub fn wants_split(
        &self,
        center: DVec3,
        radius: f64,
        deviation: f64,
        cone: &NormalCone,
        scale: f64,
    ) -> bool {
        self.deviates(center, radius, deviation, scale) && !self.faces_away(center, radius, cone)
    }

    /// How far a node's deviation could reach on the screen, in tolerances: the ratio of the
    /// two sides of [`View::wants_split`]'s test, e·√(1 + t²) / (κ·z_min) (infinite for a sphere
    /// reaching the eye's plane, 0 for one out of the frustum or of no deviation). What the
    /// meta-nodes a view waits for are fetched by, largest first.
    pub fn screen_error(&self, center: DVec3, radius: f64, deviation: f64, scale: f64) -> f64 {
        match self.split_test(center, radius, deviation, scale) {
            SplitTest::Exact => 0.0,
            SplitTest::AtEye => f64::INFINITY,
            SplitTest::Sides(reach, bound) => reach / bound,
        }
    }

    fn deviates(&self, center: DVec3, radius: f64, deviation: f64, scale: f64) -> bool {
        match self.split_test(center, radius, deviation, scale) {
            SplitTest::Exact => false,
            SplitTest::AtEye => true,
            SplitTest::Sides(reach, bound) => reach >= bound,
        }
    }

    /// The split test of [`View::wants_split`] for a node, before its comparison.
    #[inline]
    fn split_test(&self, center: DVec3, radius: f64, deviation: f64, scale: f64) -> SplitTest {
        let k = self.kappa * scale;
        if deviation <= 0.0 || !k.is_finite() || !self.sees(center, radius) {
            return SplitTest::Exact;
        }
        if k == 0.0 {
            return SplitTest::AtEye;
        }
        let d = center - self.eye;
        let depth = d.dot(self.forward);
        let nearest = depth - radius;
        if nearest <= 0.0 {
            return SplitTest::AtEye;
        }
        let lateral = (d - self.forward * depth).length() + radius;
        let tangent = lateral / nearest;
        SplitTest::Sides(deviation * (1.0 + tangent * tangent).sqrt(), k * nearest)
    }
}

/// A node's split test: out of view or of no deviation (never refined), reaching the eye's
/// plane or at a tolerance of 0 (always refined), or its two sides, e·√(1 + t²) and κ·z_min.
enum SplitTest {
    Exact,
    AtEye,
    Sides(f64, f64),
}

#[cfg(test)]
mod tests {
    use super::*;

    const NONE: NormalCone = NormalCone::NONE;

    fn camera() -> Camera {
        Camera {
            eye: DVec3::new(0.0, 0.0, 10.0),
            target: DVec3::ZERO,
            up: DVec3::Y,
            fov_degrees: 60.0,
            width: 800,
            height: 600,
        }
    }

    #[test]
    fn the_frustum_holds_what_is_ahead_and_not_what_is_behind_or_aside() {
        let v = View::new(&camera(), 1.0).unwrap();
        assert!(v.sees(DVec3::ZERO, 0.1));
        assert!(!v.sees(DVec3::new(0.0, 0.0, 20.0), 1.0));
        // tan 30° · 10 ≈ 5.77 above the axis at the target's distance is the top edge.
        assert!(v.sees(DVec3::new(0.0, 5.5, 0.0), 0.01));
        assert!(!v.sees(DVec3::new(0.0, 7.0, 0.0), 0.5));
        assert!(v.sees(DVec3::new(0.0, 7.0, 0.0), 2.0));
        // Wider than tall: 7 aside is inside horizontally (tan_x ≈ 0.77).
        assert!(v.sees(DVec3::new(7.0, 0.0, 0.0), 0.01));
    }

    #[test]
    fn a_sphere_is_refined_while_it_spans_the_tolerance() {
        let v = View::new(&camera(), 2.0).unwrap();
        // At distance 10 a pixel is 2·tan 30°·10 / 600 ≈ 0.0192 units.
        let pixel = 2.0 * (30f64).to_radians().tan() * 10.0 / 600.0;
        assert!(v.wants_split(DVec3::ZERO, 2.1 * pixel, 2.1 * pixel, &NONE, 1.0));
        assert!(!v.wants_split(DVec3::ZERO, 1.9 * pixel, 1.9 * pixel, &NONE, 1.0));
        assert!(!v.wants_split(DVec3::ZERO, 2.1 * pixel, 2.1 * pixel, &NONE, 1.2));
        assert!(!v.wants_split(DVec3::new(0.0, 0.0, 30.0), 10.0, 10.0, &NONE, 1.0));
        // Off the axis a sphere's subtree can spread further on the screen: at the edge of
        // the view (tangent ≈ 0.5 here) 1.9 pixels' radius is refined.
        assert!(v.wants_split(
            DVec3::new(5.0, 0.0, 0.0),
            1.9 * pixel,
            1.9 * pixel,
            &NONE,
            1.0
        ));
        // A sphere reaching the eye's plane is.
        assert!(v.wants_split(DVec3::new(0.0, 0.5, 9.5), 0.6, 0.6, &NONE, 1.0));
        assert!(View::everything().wants_split(DVec3::ZERO, 1e-9, 1e-9, &NONE, 1.0));
        assert!(!View::nothing().wants_split(DVec3::ZERO, 1e9, 1e9, &NONE, 1.0));
        // A large sphere whose surface deviates little is left coarse; one that is exact
        // (deviation 0) is never refined, not even reaching the eye's plane.
        assert!(!v.wants_split(DVec3::ZERO, 10.0 * pixel, 1.9 * pixel, &NONE, 1.0));
        assert!(v.wants_split(DVec3::ZERO, 10.0 * pixel, 2.2 * pixel, &NONE, 1.0));
        assert!(!v.wants_split(DVec3::new(0.0, 0.5, 9.5), 0.6, 0.0, &NONE, 1.0));
    }

    #[test]
    fn a_node_facing_away_is_not_refined_unless_two_sided() {
        // The eye at +z 10 looks down -z; a sphere at the origin.
        let v = View::new(&camera(), 1.0).unwrap();
        let cone = |axis: [f32; 3], degrees: f64| NormalCone::new(axis, degrees.to_radians());
        let big = 0.5;
        // Normals along -z face away (the eye sees their backs); along +z they face the eye.
        assert!(v.faces_away(DVec3::ZERO, big, &cone([0.0, 0.0, -1.0], 30.0)));
        assert!(!v.wants_split(DVec3::ZERO, big, big, &cone([0.0, 0.0, -1.0], 30.0), 1.0));
        assert!(!v.faces_away(DVec3::ZERO, big, &cone([0.0, 0.0, 1.0], 30.0)));
        assert!(v.wants_split(DVec3::ZERO, big, big, &cone([0.0, 0.0, 1.0], 30.0), 1.0));
        // Sideways: a face seen edge-on is not culled; nor is a cone reaching past 90°.
        assert!(!v.faces_away(DVec3::ZERO, big, &cone([1.0, 0.0, 0.0], 5.0)));
        assert!(!v.faces_away(DVec3::ZERO, big, &cone([0.0, 0.0, -1.0], 88.0)));
        // The sphere's width counts: a cone of 60° facing away is culled when the sphere is
        // small, not when it spans 30° seen from the eye (sin 30° · 10 = 5).
        assert!(v.faces_away(DVec3::ZERO, 0.1, &cone([0.0, 0.0, -1.0], 60.0)));
        assert!(!v.faces_away(DVec3::ZERO, 5.0, &cone([0.0, 0.0, -1.0], 60.0)));
        // A sphere holding the eye, no cone, or a two-sided view: never.
        assert!(!v.faces_away(DVec3::ZERO, 11.0, &cone([0.0, 0.0, -1.0], 1.0)));
        assert!(!v.faces_away(DVec3::ZERO, big, &NONE));
        let two = v.clone().two_sided(true);
        assert!(!two.faces_away(DVec3::ZERO, big, &cone([0.0, 0.0, -1.0], 30.0)));
        assert!(two.wants_split(DVec3::ZERO, big, big, &cone([0.0, 0.0, -1.0], 30.0), 1.0));
    }

    #[test]
    fn facing_away_holds_for_every_point_of_the_sphere_and_normal_of_the_cone() {
        let v = View::new(&camera(), 1.0).unwrap();
        let state = std::cell::Cell::new(0x9e37_79b9_7f4a_7c15u64);
        let next = || {
            let mut x = state.get();
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            state.set(x);
            (x >> 11) as f64 / (1u64 << 53) as f64
        };
        let unit = || {
            let z: f64 = 2.0 * next() - 1.0;
            let t = std::f64::consts::TAU * next();
            let s = (1.0 - z * z).sqrt();
            DVec3::new(s * t.cos(), s * t.sin(), z)
        };
        let (mut culled, mut agreed) = (0, 0);
        for _ in 0..4000 {
            let center = unit() * 8.0 * next();
            let radius = 3.0 * next();
            let axis = unit();
            let alpha = 1.6 * next();
            let cone = NormalCone::new(axis.as_vec3().to_array(), alpha);
            let away = v.faces_away(center, radius, &cone);
            // The angle form of the test, away from its boundary.
            let w = center - v.eye();
            let d = w.length();
            if d > radius {
                let theta = w.cross(axis).length().atan2(w.dot(axis));
                let sum = theta + alpha + (radius / d).asin();
                if sum < std::f64::consts::FRAC_PI_2 - 1e-3 {
                    assert!(away, "θ + α + β = {sum}");
                    agreed += 1;
                } else if sum > std::f64::consts::FRAC_PI_2 + 1e-3 {
                    assert!(!away, "θ + α + β = {sum}");
                }
            }
            if !away {
                continue;
            }
            culled += 1;
            // Points of the sphere and normals at the cone's rim see each other from behind.
            let side = axis.any_orthonormal_vector();
            for k in 0..16 {
                let turn = std::f64::consts::TAU * k as f64 / 16.0;
                let rim = (side * turn.cos() + axis.cross(side) * turn.sin()) * alpha.sin();
                let normal = axis * alpha.cos() + rim;
                let p = center + unit() * radius;
                assert!((p - v.eye()).dot(normal) > 0.0);
            }
        }
        assert!(
            culled > 100 && agreed > 100,
            "{culled} culled, {agreed} agreed"
        );
    }

    #[test]
    fn bad_cameras_are_refused() {
        let mut c = camera();
        c.target = c.eye;
        assert!(View::new(&c, 1.0).is_err());
        let mut c = camera();
        c.up = DVec3::Z;
        assert!(View::new(&c, 1.0).is_err());
        let mut c = camera();
        c.fov_degrees = 180.0;
        assert!(View::new(&c, 1.0).is_err());
        assert!(View::new(&camera(), f64::NAN).is_err());
    }

    /// The screen error is what the split test compares with 1: at least 1 exactly where the
    /// test refines (away from the boundary, where rounding may fall either way), growing as
    /// the node nears the eye, infinite at the eye's plane, 0 out of view.
    #[test]
    fn screen_error_is_the_split_tests_ratio() {
        let view = View::new(&camera(), 1.0).unwrap();
        let mut previous = 0.0;
        for z in [-40.0, -20.0, -5.0, 0.0, 5.0, 8.0, 9.5] {
            let error = view.screen_error(DVec3::new(0.0, 0.0, z), 0.1, 0.01, 1.0);
            assert!(error > previous, "{error} at z = {z} after {previous}");
            previous = error;
        }
        assert_eq!(
            view.screen_error(DVec3::new(0.0, 0.0, 9.95), 0.1, 0.01, 1.0),
            f64::INFINITY
        );
        assert_eq!(
            view.screen_error(DVec3::new(0.0, 0.0, 30.0), 0.1, 0.01, 1.0),
            0.0
        );
        assert_eq!(view.screen_error(DVec3::ZERO, 0.1, 0.0, 1.0), 0.0);
        for i in 0..400 {
            let at = DVec3::new(
                (i % 20) as f64 - 10.0,
                ((i / 20) % 5) as f64 - 2.0,
                -(i as f64) / 10.0,
            );
            let deviation = 0.001 * (1 + i % 7) as f64;
            let error = view.screen_error(at, 0.05, deviation, 1.0);
            if (error - 1.0).abs() > 1e-9 {
                assert_eq!(
                    error >= 1.0,
                    view.wants_split(at, 0.05, deviation, &NONE, 1.0),
                    "{at} {deviation}"
                );
            }
        }
    }
}
