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
