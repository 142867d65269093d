//! Hoppe's vertex-split records from the collapse records: base mesh, then the collapses in
//! reverse as Vsplits, made in parallel without replaying the splits.

use super::{vad_s_step, Simplified};
use crate::hierarchy::pmesh::{anchor, PmMesh, Rotation, Vsplit, NIL};
use rayon::prelude::*;

/// A progressive mesh: the base mesh and the splits that rebuild the full mesh, with the order
/// in which the full mesh's vertices and faces are created.
pub struct ProgressiveMesh {
    /// M⁰.
    pub base: PmMesh,
    /// vsplit₀ … vsplitₙ₋₁.
    pub vsplits: Vec<Vsplit>,
    /// Original vertex of each vertex of Mⁿ, in creation order.
    pub vertex_origin: Vec<u32>,
    /// Original face of each face of Mⁿ, in creation order.
    pub face_origin: Vec<u32>,
}

/// Builds the progressive mesh of a simplification: base mesh from what remains, then the
/// collapses in reverse as vertex splits with Hoppe's fields.
pub fn progressive_mesh(original_faces: &[[u32; 3]], s: &Simplified) -> ProgressiveMesh {
    let natural: Vec<usize> = (0..s.collapses.len()).rev().collect();
    build(original_faces, s, &natural)
}

/// The progressive mesh with the splits (collapse indices) applied in `order`, which must respect
/// their dependencies.
///
/// Every field of a split follows from its collapse record once the face ids a decoder will
/// assign are known (base faces, then fl and fr of each split in turn), so the records are made
/// in parallel without replaying the splits. Face corners keep their places through collapses
/// and splits; only the first corner differs: a split creates fl as (vs, vl, vt) and fr as
/// (vs, vt, vr), where the simplifier's face starts wherever the input face did.
pub(super) fn build(
    original_faces: &[[u32; 3]],
    s: &Simplified,
    order: &[usize],
) -> ProgressiveMesh {
    let n = s.vertex_alive.len();
    let mut vertex_origin: Vec<u32> = (0..n as u32)
        .filter(|&v| s.vertex_alive[v as usize])
        .collect();
    let mut new_id = vec![NIL; n];
    for (id, &v) in vertex_origin.iter().enumerate() {
        new_id[v as usize] = id as u32;
    }
    let mut face_id = vec![NIL; original_faces.len()];
    // Which of the simplifier's corners of each face is the decoder's first.
    let mut first_corner = vec![0u8; original_faces.len()];
    let mut base_faces = Vec::new();
    for (f, t) in s.faces.iter().enumerate() {
        if s.face_alive[f] {
            face_id[f] = base_faces.len() as u32;
            base_faces.push(t.map(|v| new_id[v as usize]));
        }
    }
    let mut next_face = base_faces.len() as u32;
    for c in order.iter().map(|&i| &s.collapses[i]) {
        for (f, corner) in [(c.fl, c.vs_corners[0]), (c.fr, c.vs_corners[1])] {
            if f != NIL {
                face_id[f as usize] = next_face;
                first_corner[f as usize] = corner;
                next_face += 1;
            }
        }
    }
    let base_positions: Vec<[i32; 3]> = vertex_origin
        .iter()
        .map(|&v| s.positions[v as usize])
        .collect();
    let base = PmMesh::from_triangles(base_positions, &base_faces)
        .expect("simplification keeps an oriented manifold");
    let vsplits: Vec<Vsplit> = order
        .par_iter()
        .map(|&i| {
            let c = &s.collapses[i];
            let f = c.flclw as usize;
            let vlr_rot = match (c.moved.len() as u32, c.vr == NIL) {
                (0, true) => Rotation::Empty,
                (0, false) => Rotation::EmptyAcrossGap,
                (_, true) => Rotation::ToBoundary,
                (k, false) => Rotation::Faces(k - 1),
            };
            let (ps, pt) = (c.before[0], c.before[1]);
            let vad_l = [pt[0] - ps[0], pt[1] - ps[1], pt[2] - ps[2]];
            let step = vad_s_step(vad_l);
            let (ii, vad_s) = (0..3u8)
                .map(|ii| {
                    let a = anchor(ii, ps, pt);
                    (
                        ii,
                        [a[0] - c.after[0], a[1] - c.after[1], a[2] - c.after[2]],
                    )
                })
                .filter(|(_, d)| d.iter().all(|x| x % step == 0))
                .min_by_key(|(ii, d)| {
                    (
                        d.iter().map(|x| x.unsigned_abs() as u64).sum::<u64>(),
                        2 - *ii as i32,
                    )
                })
                .expect("placements are snapped to an endpoint's step grid");
            Vsplit {
                flclw: face_id[f],
                vs_index: (c.flclw_corner + 3 - first_corner[f]) % 3,
                vlr_rot,
                ii,
                vad_l,
                vad_s,
            }
        })
        .collect();
    vertex_origin.extend(order.iter().map(|&i| s.collapses[i].vt));
    #[cfg(test)]
    {
        // The records rebuild the mesh: every split applies, keeps the invariants and puts vt
        // where it was.
        let mut mesh = base.clone();
        for (k, (split, &i)) in vsplits.iter().zip(order).enumerate() {
            let c = &s.collapses[i];
            let vt = mesh
                .vsplit(split)
                .unwrap_or_else(|e| panic!("split {k} {split:?} of {c:?}: {e:?}"));
            if let Err(e) = mesh.check_invariants() {
                panic!("after split {k} {split:?} of {c:?}: {e}");
            }
            assert_eq!(mesh.positions[vt as usize], c.before[1]);
        }
    }
    let mut face_origin = vec![NIL; next_face as usize];
    for (f, &id) in face_id.iter().enumerate() {
        if id != NIL {
            face_origin[id as usize] = f as u32;
        }
    }
    ProgressiveMesh {
        base,
        vsplits,
        vertex_origin,
        face_origin,
    }
}
