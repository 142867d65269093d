//! Garland–Heckbert quadrics: a symmetric 4 × 4 matrix per vertex, summed from the planes of its
//! faces (area-weighted) and, on boundaries, from constraint planes through the boundary edges.

use super::engine::{to_f, Topology};
use glam::DVec3;
use rayon::prelude::*;

/// A symmetric 4 × 4 quadric: a2 ab ac ad b2 bc bd c2 cd d2.
#[derive(Clone, Copy, Debug, Default)]
pub struct Quadric(pub(super) [f64; 10]);

impl Quadric {
    /// `w` times the squared distance from the plane n·p + d = 0 (`n` of unit length).
    pub fn plane(n: DVec3, d: f64, w: f64) -> Quadric {
        let (a, b, c) = (n.x, n.y, n.z);
        Quadric(
            [
                a * a,
                a * b,
                a * c,
                a * d,
                b * b,
                b * c,
                b * d,
                c * c,
                c * d,
                d * d,
            ]
            .map(|x| x * w),
        )
    }
    /// `w` times the squared distance from point `p`.
    pub fn point(p: DVec3, w: f64) -> Quadric {
        Quadric(
            [
                1.0,
                0.0,
                0.0,
                -p.x,
                1.0,
                0.0,
                -p.y,
                1.0,
                -p.z,
                p.length_squared(),
            ]
            .map(|x| x * w),
        )
    }
    pub fn add(&mut self, o: &Quadric) {
        for i in 0..10 {
            self.0[i] += o.0[i];
        }
    }
    pub fn sum(a: &Quadric, b: &Quadric) -> Quadric {
        let mut q = *a;
        q.add(b);
        q
    }
    /// `a` less `b` (as of prefix sums).
    pub fn difference(a: &Quadric, b: &Quadric) -> Quadric {
        Quadric(std::array::from_fn(|i| a.0[i] - b.0[i]))
    }
    /// The quadric's value at `p`.
    pub fn error(&self, p: DVec3) -> f64 {
        let q = &self.0;
        let (x, y, z) = (p.x, p.y, p.z);
        x * x * q[0]
            + 2.0 * x * y * q[1]
            + 2.0 * x * z * q[2]
            + 2.0 * x * q[3]
            + y * y * q[4]
            + 2.0 * y * z * q[5]
            + 2.0 * y * q[6]
            + z * z * q[7]
            + 2.0 * z * q[8]
            + q[9]
    }
    /// Where it is least, if its 3 × 3 part is not near singular.
    pub fn minimizer(&self) -> Option<DVec3> {
        let q = &self.0;
        let m = glam::DMat3::from_cols(
            DVec3::new(q[0], q[1], q[2]),
            DVec3::new(q[1], q[4], q[5]),
            DVec3::new(q[2], q[5], q[7]),
        );
        let det = m.determinant();
        let scale = (q[0] + q[4] + q[7]).powi(3).abs().max(f64::MIN_POSITIVE);
        if det.abs() < 1e-9 * scale {
            return None;
        }
        Some(m.inverse() * -DVec3::new(q[3], q[6], q[8]))
    }
}

/// Face planes (area-weighted) and boundary constraint planes, summed per vertex in parallel.
pub(in crate::hierarchy) fn initial_quadrics(
    cells: &[[i32; 3]],
    faces: &[[u32; 3]],
    topology: &Topology,
) -> Vec<Quadric> {
    let Topology {
        vfaces,
        edges,
        edge_faces,
        vedges,
    } = topology;
    let face_quadric = |t: &[u32; 3]| {
        let [a, b, c] = t.map(|v| to_f(cells[v as usize]));
        let cross = (b - a).cross(c - a);
        let area2 = cross.length();
        if area2 == 0.0 {
            return Quadric::default();
        }
        let n = cross / area2;
        Quadric::plane(n, -n.dot(a), area2 * 0.5)
    };
    let is_boundary = |v: u32, w: u32| {
        vedges[v as usize]
            .iter()
            .any(|&e| edges[e as usize].contains(&w) && edge_faces[e as usize] == 1)
    };
    (0..cells.len())
        .into_par_iter()
        .map(|v| {
            let mut q = Quadric::default();
            let on_boundary = vedges[v].iter().any(|&e| edge_faces[e as usize] == 1);
            for &f in &vfaces[v] {
                let t = faces[f as usize];
                q.add(&face_quadric(&t));
                if !on_boundary {
                    continue;
                }
                for k in 0..3 {
                    let (u, w) = (t[k], t[(k + 1) % 3]);
                    if (u == v as u32 || w == v as u32) && is_boundary(u, w) {
                        let (pu, pw) = (to_f(cells[u as usize]), to_f(cells[w as usize]));
                        let [a, b, c] = t.map(|x| to_f(cells[x as usize]));
                        let normal = (b - a).cross(c - a);
                        let side = (pw - pu).cross(normal);
                        if side.length_squared() > 0.0 {
                            let m = side.normalize();
                            let weight = 100.0 * (pw - pu).length_squared();
                            q.add(&Quadric::plane(m, -m.dot(pu), weight));
                        }
                    }
                }
            }
            q
        })
        .collect()
}

/// Adds constraint planes through the seam edges (`seam[e]` for each edge of `topology`): on
/// each face beside a seam, the plane through the edge perpendicular to the face, so that a
/// seam keeps its course as a boundary does.
pub(in crate::hierarchy) fn add_seam_planes(
    quadrics: &mut [Quadric],
    cells: &[[i32; 3]],
    faces: &[[u32; 3]],
    topology: &Topology,
    seam: &[bool],
) {
    for (e, &[u, w]) in topology.edges.iter().enumerate() {
        if !seam[e] {
            continue;
        }
        let (pu, pw) = (to_f(cells[u as usize]), to_f(cells[w as usize]));
        for &f in &topology.vfaces[u as usize] {
            let t = faces[f as usize];
            if !t.contains(&w) {
                continue;
            }
            let [a, b, c] = t.map(|x| to_f(cells[x as usize]));
            let side = (pw - pu).cross((b - a).cross(c - a));
            if side.length_squared() > 0.0 {
                let m = side.normalize();
                let plane = Quadric::plane(m, -m.dot(pu), 100.0 * (pw - pu).length_squared());
                quadrics[u as usize].add(&plane);
                quadrics[w as usize].add(&plane);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_point_quadric_is_the_weighted_squared_distance_and_differences_undo_sums() {
        let p = DVec3::new(1.0, -2.0, 0.5);
        let q = Quadric::point(p, 3.0);
        let x = DVec3::new(0.25, 4.0, -1.0);
        assert!((q.error(x) - 3.0 * x.distance_squared(p)).abs() < 1e-9);
        assert!((q.minimizer().unwrap() - p).length() < 1e-12);
        let plane = Quadric::plane(DVec3::Z, -0.5, 2.0);
        let back = Quadric::difference(&Quadric::sum(&q, &plane), &plane);
        assert!((back.error(x) - q.error(x)).abs() < 1e-9);
    }
}
