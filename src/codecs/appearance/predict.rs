//! Predictions of a new wedge's values from what both sides already hold: the decoded
//! positions and connectivity, and the wedges coded before it.

use glam::{DVec2, DVec3};

/// The uv of corner `p` of a triangle whose other corners `a`, `b` have uvs `ta`, `tb`: the
/// point that sits in uv space where `p` sits in 3D relative to the edge a–b (its foot on the
/// edge in proportion, its height scaled by the edge's uv length), on the side that gives the
/// uv triangle (p, a, b) the winding `winding` (+1 counter-clockwise, −1 clockwise). Draco's
/// texture-coordinate prediction does the same from the 3D triangle.
pub fn uv_from_triangle(p: DVec3, a: DVec3, b: DVec3, ta: DVec2, tb: DVec2, winding: f64) -> DVec2 {
    let edge = b - a;
    let length2 = edge.length_squared();
    let uv_edge = tb - ta;
    if length2 <= 0.0 || uv_edge.length_squared() <= 0.0 {
        return ta;
    }
    let along = (p - a).dot(edge) / length2;
    let foot = a + edge * along;
    let height = (p - foot).length() / length2.sqrt();
    let base = ta + uv_edge * along;
    let side = DVec2::new(-uv_edge.y, uv_edge.x) * height;
    // (p, a, b) counter-clockwise ⇔ p lies left of a→b.
    if winding >= 0.0 {
        base + side
    } else {
        base - side
    }
}

/// The sign of the uv triangle's winding, +1 or −1 (+1 when degenerate).
pub fn winding(t: [DVec2; 3]) -> f64 {
    let area = (t[1] - t[0]).perp_dot(t[2] - t[0]);
    if area < 0.0 {
        -1.0
    } else {
        1.0
    }
}

/// The normal of triangle (a, b, c) scaled by twice its area.
pub fn face_normal(a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    (b - a).cross(c - a)
}

/// The unit normal at a vertex from its faces' corners (each the vertex's position and its two
/// neighbours in the face, counter-clockwise), each face's normal weighted by its angle at the
/// vertex (Thürmer and Wüthrich); zero when the faces have no area. Such normals are what
/// modelling tools write for smooth surfaces, so they predict a file's normals best.
pub fn vertex_normal_by_angles(corners: impl IntoIterator<Item = [DVec3; 3]>) -> DVec3 {
    corners
        .into_iter()
        .map(|[p, a, b]| {
            let (u, v) = (a - p, b - p);
            u.cross(v).normalize_or_zero() * angle_between(u, v)
        })
        .sum::<DVec3>()
        .normalize_or_zero()
}

/// The angle between `u` and `v` in radians, within 0.002 of the true one, computed with + − × ÷
/// and √ alone. Those are exactly rounded in IEEE arithmetic, so an encoder and a decoder on
/// any platform predict alike; a maths library's `acos` or `atan2` may differ in its last bit,
/// and a prediction that differs by one code would decode another value.
pub fn angle_between(u: DVec3, v: DVec3) -> f64 {
    let y = u.cross(v).length();
    let x = u.dot(v);
    let (small, large) = if y <= x.abs() {
        (y, x.abs())
    } else {
        (x.abs(), y)
    };
    if large <= 0.0 {
        return 0.0;
    }
    // atan(t) for t in [0, 1] (Rajan et al. 2006's approximation).
    let t = small / large;
    let quarter = std::f64::consts::FRAC_PI_4;
    let mut angle = quarter * t - t * (t - 1.0) * (0.2447 + 0.0663 * t);
    if y > x.abs() {
        angle = 2.0 * quarter - angle;
    }
    if x < 0.0 {
        angle = 4.0 * quarter - angle;
    }
    angle
}

/// The uv of corner `p` of a triangle (p, a, b) from the triangle (a, b, c) across its edge a–b,
/// all of whose uvs are known and which shares a chart with it: the two triangles are unfolded
/// into one plane about the edge, and the affine map that takes (a, b, c) to their uvs is applied
/// to p. Unlike [`uv_from_triangle`], this follows a chart's stretch and its mirroring. `None`
/// when either triangle is degenerate.
pub fn uv_by_unfolding(p: DVec3, [a, b, c]: [DVec3; 3], [ta, tb, tc]: [DVec2; 3]) -> Option<DVec2> {
    let edge = b - a;
    let length = edge.length();
    if length <= 0.0 {
        return None;
    }
    let e = edge / length;
    let along = |x: DVec3| (x - a).dot(e);
    let height = |x: DVec3| (x - a - e * along(x)).length();
    let (along_c, height_c) = (along(c), height(c));
    if height_c <= length * 1e-9 {
        return None;
    }
    // In the unfolded plane: a = (0, 0), b = (length, 0), c above the edge, p below it.
    let per_along = (tb - ta) / length;
    let per_height = (tc - ta - per_along * along_c) / height_c;
    Some(ta + per_along * along(p) - per_height * height(p))
}

/// The uv of `p` by the affine map from the tangent plane of `normal` to uv space that fits
/// `pairs` — known (position, uv) corners of the chart around `p` — in the least-squares sense.
/// Where one neighbour triangle's unfolding follows that triangle's distortion alone, the fit
/// averages the chart's local stretch over the whole neighbourhood. `None` with fewer than four
/// pairs or when they do not span the plane.
pub fn uv_by_fit(p: DVec3, normal: DVec3, pairs: &[(DVec3, DVec2)]) -> Option<DVec2> {
    if pairs.len() < 4 {
        return None;
    }
    let n = normal.try_normalize()?;
    let e1 = n.any_orthonormal_vector();
    let e2 = n.cross(e1);
    let centre = pairs.iter().map(|(q, _)| *q).sum::<DVec3>() / pairs.len() as f64;
    let plane = |q: DVec3| DVec2::new((q - centre).dot(e1), (q - centre).dot(e2));
    // Normal equations of t = t0 + J·x over the pairs, x centred so t0 is the mean uv.
    let mean_t = pairs.iter().map(|(_, t)| *t).sum::<DVec2>() / pairs.len() as f64;
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    let (mut sxt, mut syt) = (DVec2::ZERO, DVec2::ZERO);
    let mean_x = pairs.iter().map(|(q, _)| plane(*q)).sum::<DVec2>() / pairs.len() as f64;
    for (q, t) in pairs {
        let x = plane(*q) - mean_x;
        let d = *t - mean_t;
        sxx += x.x * x.x;
        sxy += x.x * x.y;
        syy += x.y * x.y;
        sxt += d * x.x;
        syt += d * x.y;
    }
    let det = sxx * syy - sxy * sxy;
    if det <= 1e-12 * (sxx + syy) * (sxx + syy) {
        return None;
    }
    // J's columns: the uv change per unit along e1 and along e2.
    let j1 = (sxt * syy - syt * sxy) / det;
    let j2 = (syt * sxx - sxt * sxy) / det;
    let x = plane(p) - mean_x;
    let t = mean_t + j1 * x.x + j2 * x.y;
    t.is_finite().then_some(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn angles_are_close_to_the_true_ones_and_vertex_normals_weigh_by_them() {
        let mut worst: f64 = 0.0;
        for i in 0..=360 {
            let a = (i as f64).to_radians();
            let v = DVec3::new(a.cos(), a.sin(), 0.0) * 3.0;
            let truth = DVec3::X.angle_between(v);
            worst = worst.max((angle_between(DVec3::X * 2.0, v) - truth).abs());
        }
        assert!(worst < 0.002, "{worst}");
        // A corner of 90° and one of 45°, with normals +z and +x: weights 2:1.
        let n = vertex_normal_by_angles([
            [DVec3::ZERO, DVec3::X, DVec3::Y],
            [DVec3::ZERO, DVec3::Y, DVec3::new(0.0, 1.0, -1.0)],
        ]);
        let expected = (DVec3::Z * std::f64::consts::FRAC_PI_2
            - DVec3::X * std::f64::consts::FRAC_PI_4)
            .normalize();
        assert!((n - expected).length() < 2e-3, "{n} {expected}");
    }

    #[test]
    fn the_fit_recovers_an_affine_chart_exactly() {
        // A tilted plane whose uvs are an affine function of position.
        let chart = |p: DVec3| DVec2::new(0.3 * p.x - 0.2 * p.y + 5.0, 0.1 * p.x + 0.7 * p.y - 1.0);
        let tilt = |x: f64, y: f64| DVec3::new(x, y, 0.5 * x - 0.25 * y);
        let pairs: Vec<(DVec3, DVec2)> =
            [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.5), (-0.5, 0.7)]
                .iter()
                .map(|&(x, y)| (tilt(x, y), chart(tilt(x, y))))
                .collect();
        let normal = DVec3::new(-0.5, 0.25, 1.0);
        let p = tilt(0.6, -0.4);
        let t = uv_by_fit(p, normal, &pairs).unwrap();
        assert!((t - chart(p)).length() < 1e-9, "{t} {}", chart(p));
        // Too few corners, or corners on a line, fit nothing.
        assert!(uv_by_fit(p, normal, &pairs[..3]).is_none());
        let line: Vec<_> = (0..5)
            .map(|i| (tilt(i as f64, 0.0), DVec2::splat(i as f64)))
            .collect();
        assert!(uv_by_fit(p, normal, &line).is_none());
    }

    #[test]
    fn unfolding_follows_a_flat_chart() {
        let chart = |p: DVec3| DVec2::new(2.0 * p.x + 1.0, -p.y);
        let [a, b, c] = [DVec3::ZERO, DVec3::X, DVec3::new(0.3, 1.0, 0.0)];
        let p = DVec3::new(0.6, -0.8, 0.0);
        let t = uv_by_unfolding(p, [a, b, c], [a, b, c].map(chart)).unwrap();
        assert!((t - chart(p)).length() < 1e-12);
    }
}
