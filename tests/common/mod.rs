//! Helpers shared by the integration tests.

/// `bytes` with 1 to `max_flips` single bits flipped at pseudo-random places; `state` is the
/// xorshift generator's state, advanced in place.
#[allow(dead_code)]
pub fn flip_bits(bytes: &[u8], state: &mut u32, max_flips: usize) -> Vec<u8> {
    let mut out = bytes.to_vec();
    let flips = 1 + *state as usize % max_flips;
    for _ in 0..flips {
        *state ^= *state << 13;
        *state ^= *state >> 17;
        *state ^= *state << 5;
        let i = *state as usize % out.len();
        out[i] ^= 1 << (*state >> 29);
    }
    out
}

/// Walks a stream from M⁰ to Mⁿ and back, checking the mesh's invariants after every split and
/// collapse, and that the vertices of Mⁿ that share a cell (a vertex of a mesh cut to a
/// manifold and its copies) are all present from M⁰ on, at one position: no crack opens at any
/// level (`every_split`: after every split, else after every level, where invariants are not
/// checked). Returns how many such vertices there are.
#[allow(dead_code)]
pub fn walk_without_cracks(bytes: &[u8], every_split: bool) -> usize {
    let mut iter = meshcodec::codecs::pm::iter::PMeshIter::from_stream(bytes).unwrap();
    while iter.next().unwrap() {}
    let full = iter.mesh().clone();
    let mut by_cell: std::collections::HashMap<[i32; 3], Vec<usize>> = Default::default();
    for (v, c) in full.positions.iter().enumerate() {
        by_cell.entry(*c).or_default().push(v);
    }
    let groups: Vec<Vec<usize>> = by_cell.into_values().filter(|g| g.len() > 1).collect();
    let together = |iter: &meshcodec::codecs::pm::iter::PMeshIter| {
        let mesh = iter.mesh();
        if every_split {
            mesh.check_invariants().unwrap();
        }
        for group in &groups {
            let at: Vec<[i32; 3]> = group
                .iter()
                .map(|&v| *mesh.positions.get(v).expect("a copy is present from M⁰ on"))
                .collect();
            assert!(
                at.iter().all(|p| *p == at[0]),
                "copies {group:?} pulled apart at {} vertices: {at:?}",
                mesh.positions.len()
            );
        }
    };
    together(&iter);
    if every_split {
        while iter.prev() {
            together(&iter);
        }
        while iter.next().unwrap() {
            together(&iter);
        }
    } else {
        let mut iter = meshcodec::codecs::pm::iter::PMeshIter::from_stream(bytes).unwrap();
        together(&iter);
        while iter.next_level().unwrap() {
            together(&iter);
        }
    }
    groups.iter().map(Vec::len).sum()
}

/// spot with its uvs and normals that are smooth on most of it and flat (a crease at every edge)
/// on a sixth: normal groups of every shape, crossing the uv seams.
#[allow(dead_code)]
pub fn spot_with_creased_normals() -> meshcodec::mesh::attributes::AttributedMesh {
    use glam::DVec3;
    use meshcodec::mesh::attributes::{Attributes, Corner};
    let mut spot =
        meshcodec::mesh::io::read_attributed(&meshcodec::mesh::io::resolve("spot").unwrap())
            .unwrap();
    let (positions, faces) = (&spot.mesh.positions, &spot.mesh.faces);
    let face_normal = |f: &[u32; 3]| {
        let p = f.map(|v| positions[v as usize]);
        (p[1] - p[0]).cross(p[2] - p[0])
    };
    let mut smooth = vec![DVec3::ZERO; positions.len()];
    for f in faces {
        for &v in f {
            smooth[v as usize] += face_normal(f);
        }
    }
    // Flat on the sixth of the faces furthest along +x (a crease at every edge pins vertices).
    let centroid_x = |f: &[u32; 3]| f.iter().map(|&v| positions[v as usize].x).sum::<f64>();
    let mut xs: Vec<f64> = faces.iter().map(centroid_x).collect();
    xs.sort_by(f64::total_cmp);
    let threshold = xs[xs.len() * 5 / 6];
    let old = &spot.attributes;
    let corners: Vec<[Corner; 3]> = faces
        .iter()
        .enumerate()
        .map(|(i, f)| {
            let flat = centroid_x(f) > threshold;
            std::array::from_fn(|k| Corner {
                normal: Some(if flat {
                    face_normal(f)
                } else {
                    smooth[f[k] as usize]
                }),
                uv: old.uvs.as_ref().map(|t| t[old.corners[i][k] as usize]),
                colour: None,
            })
        })
        .collect();
    spot.attributes = Attributes::weld(faces, &corners).unwrap();
    spot
}
