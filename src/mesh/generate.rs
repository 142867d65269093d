//! Meshes made from a few numbers, for tests, benchmarks and examples: an icosphere, a torus, a
//! terrain (Delaunay triangulation of seeded random points under a height function), a
//! "messy" mesh with every defect a codec must survive, and a rounded cube of textured quads
//! whose six faces are six charts of a texture atlas.

use super::attributes::{AttributedMesh, Attributes};
use super::{TriMesh, VertexId};
use glam::{DVec2, DVec3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use spade::{DelaunayTriangulation, Point2, Triangulation};
use std::collections::HashMap;

/// A unit icosphere: the icosahedron with each triangle split in four `subdivisions` times
/// (20·4^s triangles, closed, genus 0).
pub fn icosphere(subdivisions: u32) -> TriMesh {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut positions: Vec<DVec3> = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .iter()
    .map(|&p| DVec3::from(p).normalize())
    .collect();
    let mut faces: Vec<[VertexId; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdivisions {
        let mut midpoint: HashMap<(VertexId, VertexId), VertexId> = HashMap::new();
        let mut split = |a: VertexId, b: VertexId, positions: &mut Vec<DVec3>| {
            *midpoint.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let m = (positions[a as usize] + positions[b as usize]).normalize();
                positions.push(m);
                (positions.len() - 1) as VertexId
            })
        };
        faces = faces
            .iter()
            .flat_map(|&[a, b, c]| {
                let ab = split(a, b, &mut positions);
                let bc = split(b, c, &mut positions);
                let ca = split(c, a, &mut positions);
                [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
            })
            .collect();
    }
    TriMesh::new(positions, faces)
}

/// Midpoint subdivision: each triangle split into four at its edge midpoints (shared edges share
/// their midpoint), so a closed manifold stays one. Used to make large test meshes.
pub fn subdivide(mesh: &TriMesh) -> TriMesh {
    let mut positions = mesh.positions.clone();
    let mut midpoint: HashMap<(VertexId, VertexId), VertexId> =
        HashMap::with_capacity(mesh.faces.len() * 2);
    let mut faces = Vec::with_capacity(mesh.faces.len() * 4);
    for &[a, b, c] in &mesh.faces {
        let mut mid = |u: VertexId, v: VertexId| {
            *midpoint.entry((u.min(v), u.max(v))).or_insert_with(|| {
                positions.push((positions[u as usize] + positions[v as usize]) * 0.5);
                (positions.len() - 1) as VertexId
            })
        };
        let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
        faces.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
    }
    TriMesh::new(positions, faces)
}

/// A torus of radii `major` and `minor` with `u` × `v` quads split into triangles (2uv faces,
/// closed, genus 1).
pub fn torus(major: f64, minor: f64, u: u32, v: u32) -> TriMesh {
    let mut positions = Vec::with_capacity((u * v) as usize);
    for i in 0..u {
        let a = i as f64 / u as f64 * std::f64::consts::TAU;
        for j in 0..v {
            let b = j as f64 / v as f64 * std::f64::consts::TAU;
            let r = major + minor * b.cos();
            positions.push(DVec3::new(r * a.cos(), r * a.sin(), minor * b.sin()));
        }
    }
    let id = |i: u32, j: u32| (i % u) * v + (j % v);
    let mut faces = Vec::with_capacity((2 * u * v) as usize);
    for i in 0..u {
        for j in 0..v {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            faces.push([a, b, c]);
            faces.push([a, c, d]);
        }
    }
    TriMesh::new(positions, faces)
}

/// A cube of `n` × `n` quads a side (each split into two triangles), bulged towards a sphere,
/// textured as a texture atlas of three by two squares, one a side: the cube's twelve edges are
/// uv seams (two wedges at each of their vertices, three at the corners), and each side's uvs
/// follow its quads. Closed, genus 0, 6n² + 2 vertices.
pub fn textured_cube(n: u32) -> AttributedMesh {
    let mut positions: Vec<DVec3> = Vec::new();
    let mut at: HashMap<[i64; 3], VertexId> = HashMap::new();
    let mut faces = Vec::new();
    let mut uvs = Vec::new();
    // (normal axis, sign): the six sides, and each side's two in-plane axes.
    for side in 0..6u32 {
        let (axis, sign) = ((side / 2) as usize, if side % 2 == 0 { 1 } else { -1 });
        let (u_axis, v_axis) = ((axis + 1) % 3, (axis + 2) % 3);
        let grid_point = |i: u32, j: u32| {
            let mut p = [0i64; 3];
            p[axis] = sign * n as i64;
            // Mirrored on the negative sides, so that every side's faces turn outwards.
            p[u_axis] = (2 * i as i64 - n as i64) * sign;
            p[v_axis] = 2 * j as i64 - n as i64;
            p
        };
        let atlas = DVec2::new((side % 3) as f64, (side / 3) as f64);
        let mut vertex = |i: u32, j: u32| -> (VertexId, DVec2) {
            let key = grid_point(i, j);
            let id = *at.entry(key).or_insert_with(|| {
                let q = DVec3::new(key[0] as f64, key[1] as f64, key[2] as f64) / n as f64;
                // Halfway between the cube and the sphere.
                positions.push((q + q.normalize() * 3f64.sqrt()) * 0.5);
                (positions.len() - 1) as VertexId
            });
            let uv = (atlas + DVec2::new(i as f64, j as f64) / n as f64 * 0.9 + 0.05)
                / DVec2::new(3.0, 2.0);
            (id, uv)
        };
        for i in 0..n {
            for j in 0..n {
                let corners =
                    [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)].map(|(a, b)| vertex(a, b));
                for tri in [[0, 1, 2], [0, 2, 3]] {
                    faces.push(tri.map(|k| corners[k].0));
                    uvs.push(tri.map(|k| corners[k].1));
                }
            }
        }
    }
    let corners = (0..faces.len() as u32)
        .map(|f| [3 * f, 3 * f + 1, 3 * f + 2])
        .collect();
    let wedge_vertex = faces.iter().flatten().copied().collect();
    AttributedMesh {
        mesh: TriMesh::new(positions, faces),
        attributes: Attributes {
            corners,
            wedge_vertex,
            uvs: Some(uvs.into_iter().flatten().collect()),
            ..Attributes::default()
        },
    }
}

/// A terrain over the unit square: the Delaunay triangulation of `points` seeded random points
/// (plus the square's corners), lifted by a smooth height function. Open, one boundary loop.
pub fn terrain(points: usize, seed: u64) -> TriMesh {
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut xy: Vec<Point2<f64>> = vec![
        Point2::new(0.0, 0.0),
        Point2::new(1.0, 0.0),
        Point2::new(1.0, 1.0),
        Point2::new(0.0, 1.0),
    ];
    xy.extend((0..points).map(|_| Point2::new(rng.gen::<f64>(), rng.gen::<f64>())));
    let height = |x: f64, y: f64| {
        0.15 * (6.0 * x).sin() * (4.0 * y).cos() + 0.05 * (17.0 * x + 11.0 * y).sin()
    };
    let delaunay: DelaunayTriangulation<Point2<f64>> =
        DelaunayTriangulation::bulk_load_stable(xy).expect("finite points triangulate");
    let positions = delaunay
        .vertices()
        .map(|v| {
            let p = v.position();
            DVec3::new(p.x, p.y, height(p.x, p.y))
        })
        .collect();
    let faces = delaunay
        .inner_faces()
        .map(|f| f.vertices().map(|v| v.fix().index() as VertexId))
        .collect();
    TriMesh::new(positions, faces)
}

/// A mesh with the defects real files have, chosen by `seed`: several components, open
/// boundaries, non-manifold edges (fins) and vertices (bow-ties), duplicate and reversed faces,
/// coincident and nearly coincident vertices, an unreferenced vertex and a degenerate face.
pub fn messy(seed: u64) -> TriMesh {
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut mesh = TriMesh::default();
    let spread = |rng: &mut Pcg64| {
        DVec3::new(
            rng.gen_range(-3.0..3.0),
            rng.gen_range(-3.0..3.0),
            rng.gen_range(-3.0..3.0),
        )
    };
    // Closed components.
    for _ in 0..rng.gen_range(1..=2) {
        let sphere = icosphere(rng.gen_range(0..=1));
        let (offset, scale) = (spread(&mut rng), rng.gen_range(0.3..1.5));
        mesh.append(&sphere, offset, scale);
    }
    // An open patch with a boundary.
    let patch = terrain(rng.gen_range(3..25), rng.gen());
    let (offset, scale) = (spread(&mut rng), rng.gen_range(0.5..2.0));
    mesh.append(&patch, offset, scale);
    let pick_face =
        |mesh: &TriMesh, rng: &mut Pcg64| mesh.faces[rng.gen_range(0..mesh.faces.len())];
    // Fins: a third (and fourth) face on an existing edge.
    for _ in 0..rng.gen_range(0..=2) {
        let [a, b, _] = pick_face(&mesh, &mut rng);
        let tip = (mesh.positions[a as usize] + mesh.positions[b as usize]) * 0.5
            + spread(&mut rng) * 0.1;
        mesh.positions.push(tip);
        let t = (mesh.positions.len() - 1) as VertexId;
        mesh.faces.push([a, b, t]);
    }
    // Bow-tie: two triangles that share one vertex only.
    if rng.gen_bool(0.7) {
        let c = spread(&mut rng);
        let base = mesh.positions.len() as VertexId;
        for d in [
            DVec3::ZERO,
            DVec3::new(0.4, 0.1, 0.0),
            DVec3::new(0.3, 0.5, 0.1),
            DVec3::new(-0.4, -0.1, 0.0),
            DVec3::new(-0.3, -0.5, 0.2),
        ] {
            mesh.positions.push(c + d);
        }
        mesh.faces.push([base, base + 1, base + 2]);
        mesh.faces.push([base, base + 3, base + 4]);
    }
    // Repeated, rotated and reversed faces.
    for _ in 0..rng.gen_range(0..=3) {
        let f = pick_face(&mesh, &mut rng);
        mesh.faces.push(match rng.gen_range(0..3) {
            0 => f,
            1 => [f[1], f[2], f[0]],
            _ => [f[0], f[2], f[1]],
        });
    }
    // Coincident vertex: a copy of a vertex that some faces use instead of the original.
    if rng.gen_bool(0.6) {
        let fi = rng.gen_range(0..mesh.faces.len());
        let v = mesh.faces[fi][0];
        mesh.positions.push(mesh.positions[v as usize]);
        mesh.faces[fi][0] = (mesh.positions.len() - 1) as VertexId;
    }
    // Nearly coincident vertex: welds onto its twin at coarse quantization only.
    if rng.gen_bool(0.5) {
        let [a, b, _] = pick_face(&mesh, &mut rng);
        let twin = mesh.positions[a as usize] + DVec3::splat(1e-6);
        mesh.positions.push(twin);
        let t = (mesh.positions.len() - 1) as VertexId;
        mesh.faces.push([t, b, a]);
    }
    // Unreferenced vertex and a degenerate face.
    if rng.gen_bool(0.5) {
        mesh.positions.push(spread(&mut rng) * 2.0);
    }
    if rng.gen_bool(0.3) {
        let [a, b, _] = pick_face(&mesh, &mut rng);
        mesh.faces.push([a, b, a]);
    }
    mesh
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::topology::analyze;

    #[test]
    fn closed_generators_are_closed_manifolds() {
        for mesh in [icosphere(2), torus(2.0, 0.5, 16, 9)] {
            mesh.validate().unwrap();
            let t = analyze(&mesh);
            assert_eq!(t.boundary_edges, 0);
            assert!(t.is_manifold());
            assert_eq!(t.components, 1);
        }
        assert_eq!(icosphere(2).faces.len(), 320);
        let torus = torus(2.0, 0.5, 16, 9);
        // Euler characteristic of a torus is 0.
        assert_eq!(
            torus.positions.len() as i64 * 2 - torus.faces.len() as i64,
            0
        );
    }

    #[test]
    fn the_textured_cube_is_closed_with_seams_along_its_edges() {
        let cube = textured_cube(4);
        let mesh = &cube.mesh;
        mesh.validate().unwrap();
        cube.attributes.validate(mesh).unwrap();
        let t = analyze(mesh);
        assert!(t.boundary_edges == 0 && t.is_manifold() && t.components == 1);
        assert_eq!(mesh.positions.len(), 6 * 16 + 2);
        // Every face turns away from the centre.
        for f in &mesh.faces {
            let [a, b, c] = mesh.corners(*f);
            assert!((b - a).cross(c - a).dot(a + b + c) > 0.0);
        }
        // Wedges: a vertex on an edge of the cube has two uvs, a corner three.
        let uvs = cube.attributes.uvs.as_ref().unwrap();
        let mut distinct: Vec<Vec<[u64; 2]>> = vec![Vec::new(); mesh.positions.len()];
        for (w, &v) in cube.attributes.wedge_vertex.iter().enumerate() {
            let key = [uvs[w].x.to_bits(), uvs[w].y.to_bits()];
            if !distinct[v as usize].contains(&key) {
                distinct[v as usize].push(key);
            }
        }
        let count = |k: usize| distinct.iter().filter(|d| d.len() == k).count();
        assert_eq!((count(1), count(2), count(3)), (6 * 9, 12 * 3, 8));
    }

    #[test]
    fn terrain_is_an_open_disk_with_upward_faces() {
        let mesh = terrain(200, 7);
        mesh.validate().unwrap();
        let t = analyze(&mesh);
        assert!(t.boundary_edges >= 4 && t.is_manifold() && t.components == 1);
        for f in &mesh.faces {
            let [a, b, c] = mesh.corners(*f);
            assert!((b - a).cross(c - a).z > 0.0);
        }
    }

    #[test]
    fn messy_meshes_are_messy_but_valid() {
        let mut defects = 0;
        for seed in 0..20 {
            let mesh = messy(seed);
            mesh.validate().unwrap();
            let t = analyze(&mesh);
            assert!(t.components >= 2);
            defects += usize::from(!t.is_manifold());
        }
        assert!(defects > 10, "most messy meshes should be non-manifold");
    }
}
