//! The view a front is adapted to: the eye, the frustum's side and near planes, and κ.

use crate::error::{Error, Result};
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
        })
    }

    /// A view that wants every node refined (no frustum, no tolerance): the full mesh.
    pub fn everything() -> View {
        View {
            eye: DVec3::ZERO,
            forward: DVec3::ZERO,
            planes: Vec::new(),
            kappa: 0.0,
        }
    }

    /// A view that wants no node refined: the root alone.
    pub fn nothing() -> View {
        View {
            eye: DVec3::ZERO,
            forward: DVec3::ZERO,
            planes: Vec::new(),
            kappa: f64::INFINITY,
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

    /// Whether a sphere at `center` of `radius` meets the frustum.
    pub fn sees(&self, center: DVec3, radius: f64) -> bool {
        let d = center - self.eye;
        self.planes.iter().all(|n| d.dot(*n) >= -radius)
    }

    /// Whether a node with this error sphere is to be refined, κ scaled by `scale` (the face
    /// budget's regulation): visible and spanning the tolerance or more.
    ///
    /// "Spanning" is bounded from above, so that no vertex of the node's subtree lands τ
    /// pixels or more from the node on the screen while the node stands for it: over the
    /// sphere, the projection (x/z, y/z) stretches lengths by at most √(1 + t²) / z, with z
    /// the least depth and t the largest tangent off the axis, so the node is refined while
    /// r·√(1 + t²) ≥ κ·z_min (z_min = depth of the centre − r; t = (lateral distance + r) /
    /// z_min). A sphere reaching the eye's plane is always refined.
    pub fn wants_split(&self, center: DVec3, radius: f64, scale: f64) -> bool {
        let k = self.kappa * scale;
        if radius <= 0.0 || !k.is_finite() || !self.sees(center, radius) {
            return false;
        }
        if k == 0.0 {
            return true;
        }
        let d = center - self.eye;
        let depth = d.dot(self.forward);
        let nearest = depth - radius;
        if nearest <= 0.0 {
            return true;
        }
        let lateral = (d - self.forward * depth).length() + radius;
        let tangent = lateral / nearest;
        radius * (1.0 + tangent * tangent).sqrt() >= k * nearest
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
        assert!(v.wants_split(DVec3::ZERO, 2.1 * pixel, 1.0));
        assert!(!v.wants_split(DVec3::ZERO, 1.9 * pixel, 1.0));
        assert!(!v.wants_split(DVec3::ZERO, 2.1 * pixel, 1.2));
        assert!(!v.wants_split(DVec3::new(0.0, 0.0, 30.0), 10.0, 1.0));
        // Off the axis a sphere's subtree can spread further on the screen: at the edge of
        // the view (tangent ≈ 0.5 here) 1.9 pixels' radius is refined.
        assert!(v.wants_split(DVec3::new(5.0, 0.0, 0.0), 1.9 * pixel, 1.0));
        // A sphere reaching the eye's plane is.
        assert!(v.wants_split(DVec3::new(0.0, 0.5, 9.5), 0.6, 1.0));
        assert!(View::everything().wants_split(DVec3::ZERO, 1e-9, 1.0));
        assert!(!View::nothing().wants_split(DVec3::ZERO, 1e9, 1.0));
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
}
