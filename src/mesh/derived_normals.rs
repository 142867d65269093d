//! Normals derived from geometry over normal wedges (docs/CONTRACT.md §2.1): Hoppe 1998 §4's
//! Table 4 mode, where "the Δnormal field is omitted entirely, and normals are computed based on
//! the vertex positions and the wedge information (which indicates the presence of creases)"
//! (../shared/papers/000_54780623804685d2.txt).
//!
//! A **normal group** is a set of corners of one vertex that share a normal: a smooth vertex
//! has one, a vertex on a crease one for each side. A group's normal is the sum of its faces'
//! cross products (so each face weighs by its area), normalized and coded octahedrally.
//!
//! The sums are taken exactly, in integers over the grid's cells, and turned into a direction
//! once: the code then depends neither on the order faces are met in (the encoder's canonical
//! order and a decoder's level order differ) nor on a platform's maths library. Weights by
//! corner angle would need `acos`, whose last bit differs between libraries.

use super::attribute_quantization::octahedral_code;
use glam::DVec3;

/// The octahedral code (`bits` a coordinate) of each of `groups` normal groups. Face `f` has
/// the vertices `faces[f]`, at grid cells `cell(v)` of sides `cell_size`, and its corner k
/// belongs to group `group[f][k]` (below `groups`). A group whose faces have no area takes the
/// code of +z.
pub fn group_normal_codes(
    faces: &[[u32; 3]],
    group: &[[u32; 3]],
    groups: usize,
    cell: impl Fn(u32) -> [i32; 3],
    cell_size: [f64; 3],
    bits: u8,
) -> Vec<[u32; 2]> {
    let mut sums = vec![[0i128; 3]; groups];
    for (face, group) in faces.iter().zip(group) {
        let n = cell_cross(face.map(&cell));
        for &g in group {
            if let Some(sum) = sums.get_mut(g as usize) {
                for (s, x) in sum.iter_mut().zip(n) {
                    *s += x as i128;
                }
            }
        }
    }
    sums.iter()
        .map(|s| {
            // Cells scale the axes: a cross product of world edges is the cell one with each
            // coordinate divided by its axis's cell side (times the cells' volume, which the
            // normalization removes).
            let n = DVec3::new(
                s[0] as f64 / cell_size[0],
                s[1] as f64 / cell_size[1],
                s[2] as f64 / cell_size[2],
            );
            octahedral_code(n, bits)
        })
        .collect()
}

/// The normal groups of corners keyed by `keys` (one a corner, face by face): the corners of
/// one vertex with one key are a group. Returns each corner's group, groups numbered in order of
/// first corner, and their count.
pub fn groups_by_key<K: Copy + Eq + std::hash::Hash>(
    faces: &[[u32; 3]],
    keys: impl IntoIterator<Item = [K; 3]>,
) -> (Vec<[u32; 3]>, usize) {
    let mut group_of: std::collections::HashMap<(u32, K), u32> =
        std::collections::HashMap::with_capacity(faces.len() * 3 / 2);
    let group = faces
        .iter()
        .zip(keys)
        .map(|(face, key)| {
            std::array::from_fn(|k| {
                let next = group_of.len() as u32;
                *group_of.entry((face[k], key[k])).or_insert(next)
            })
        })
        .collect();
    (group, group_of.len())
}

/// The cross product of a triangle's edges in cell units (exact: cells fit in 25 bits).
fn cell_cross(p: [[i32; 3]; 3]) -> [i64; 3] {
    let d = |a: [i32; 3], b: [i32; 3]| [0, 1, 2].map(|i| b[i] as i64 - a[i] as i64);
    let (u, v) = (d(p[0], p[1]), d(p[0], p[2]));
    [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::attribute_quantization::octahedral_normal;

    /// A tent: two faces meeting at the ridge x = 0, sloping down to ±x.
    fn tent() -> (Vec<[i32; 3]>, Vec<[u32; 3]>) {
        let cells = vec![
            [0, 0, 4],
            [0, 8, 4],
            [4, 0, 0],
            [-4, 0, 0],
            [4, 8, 0],
            [-4, 8, 0],
        ];
        let faces = vec![[0, 2, 1], [1, 2, 4], [0, 1, 3], [1, 5, 3]];
        (cells, faces)
    }

    #[test]
    fn a_crease_gives_each_side_its_own_normal_and_a_smooth_vertex_their_mean() {
        let (cells, faces) = tent();
        let cell = |v: u32| cells[v as usize];
        // Vertex 0 and 1 on the ridge: one group each side (groups 0/1 at vertex 0, 2/3 at 1),
        // the slope vertices one group each (4..).
        let creased = vec![[0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]];
        let codes = group_normal_codes(&faces, &creased, 8, cell, [1.0; 3], 10);
        let right = octahedral_normal(codes[0], 10);
        let left = octahedral_normal(codes[1], 10);
        assert!((right - DVec3::new(1.0, 0.0, 1.0).normalize()).length() < 1e-2);
        assert!((left - DVec3::new(-1.0, 0.0, 1.0).normalize()).length() < 1e-2);
        // Smooth at the ridge: both sides average to +z.
        let smooth = vec![[0, 4, 2], [2, 4, 6], [0, 2, 5], [2, 7, 5]];
        let codes = group_normal_codes(&faces, &smooth, 8, cell, [1.0; 3], 10);
        assert!((octahedral_normal(codes[0], 10) - DVec3::Z).length() < 1e-9);
    }

    #[test]
    fn the_codes_do_not_depend_on_face_order_and_cells_scale_the_axes() {
        let (cells, faces) = tent();
        let cell = |v: u32| cells[v as usize];
        let group = vec![[0, 1, 1], [1, 1, 1], [0, 1, 1], [1, 1, 1]];
        let forward = group_normal_codes(&faces, &group, 2, cell, [1.0, 1.0, 3.0], 12);
        let mut reversed_faces = faces.clone();
        let mut reversed_group = group.clone();
        reversed_faces.reverse();
        reversed_group.reverse();
        let backward = group_normal_codes(
            &reversed_faces,
            &reversed_group,
            2,
            cell,
            [1.0, 1.0, 3.0],
            12,
        );
        assert_eq!(forward, backward);
        // Stretching z threefold steepens the slopes: their normals lean towards x.
        let right = octahedral_normal(
            group_normal_codes(&faces[..1], &group[..1], 1, cell, [1.0, 1.0, 3.0], 12)[0],
            12,
        );
        assert!(
            (right - DVec3::new(3.0, 0.0, 1.0).normalize()).length() < 1e-2,
            "{right}"
        );
    }

    #[test]
    fn a_group_without_area_points_up() {
        let cells = [[0, 0, 0], [1, 1, 1], [2, 2, 2]];
        let codes = group_normal_codes(
            &[[0, 1, 2]],
            &[[0, 0, 0]],
            2,
            |v| cells[v as usize],
            [1.0; 3],
            8,
        );
        for c in codes {
            assert!((octahedral_normal(c, 8) - DVec3::Z).length() < 1e-9);
        }
    }
}
