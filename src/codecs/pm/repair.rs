//! How a PM stream of a mesh that is no oriented manifold gets back to it.
//!
//! The encoder cuts such a mesh into an oriented 2-manifold (`mesh::manifold`): vertices where
//! fans meet get copies in their own cells, and faces turned against their component are
//! flipped. The progressive mesh is built on the manifold with every copied vertex pinned (it
//! never vanishes and never moves), so copies coincide at every level and no crack opens. The
//! decoder's last level is the manifold Mⁿ; getting the canonical mesh back from it takes:
//!
//! - **the weld**, which costs nothing: the canonical mesh has one vertex a cell, so the
//!   vertices of Mⁿ that share a cell are one vertex;
//! - **the flips**, coded at the end of the last level, the one level whose faces they concern
//!   (intermediate levels show the manifold's consistent orientation, which is what a renderer
//!   wants of them): a bit "some face is flipped" and, if so, one bit a face of Mⁿ in face
//!   order under a context of how many of its neighbours already read are flipped and how many
//!   are not (flips come in patches: whole regions turned the other way). Reading them costs
//!   one pass over faces the decoder holds already, so a hostile stream cannot make it loop
//!   longer than its mesh.

use crate::codecs::stats::PmField;
use crate::coding::arith::{ArithDecoder, ArithEncoder, BitContext};
use crate::coding::SyntaxClass;
use crate::hierarchy::pmesh::{PmMesh, NIL};
use crate::mesh::{Grid, TriMesh};

/// Contexts of the flip bits.
#[derive(Clone, Debug, Default)]
pub struct FlipContexts {
    any: BitContext,
    /// By (flipped, not flipped) neighbours read before the face, each 0 … 3.
    face: [BitContext; 16],
}

/// The context of face `f`'s bit: its neighbours before it in face order, flipped or not.
fn context(mesh: &PmMesh, flips: &[bool], f: usize) -> usize {
    let (mut on, mut off) = (0, 0);
    for &g in &mesh.faces[f].nei {
        if g != NIL && (g as usize) < f {
            if flips[g as usize] {
                on += 1;
            } else {
                off += 1;
            }
        }
    }
    on * 4 + off
}

/// Codes which faces of `mesh` (the manifold Mⁿ) are flipped.
pub fn put_flips(enc: &mut ArithEncoder, mesh: &PmMesh, flips: &[bool]) {
    let mut ctx = FlipContexts::default();
    let field = PmField::Repair.name();
    let any = flips.contains(&true);
    enc.bit(&mut ctx.any, any, SyntaxClass::Connectivity, field);
    if any {
        for f in 0..mesh.faces.len() {
            let c = context(mesh, flips, f);
            enc.bit(&mut ctx.face[c], flips[f], SyntaxClass::Connectivity, field);
        }
    }
}

/// Reads which faces of `mesh` (the manifold Mⁿ) are flipped.
pub fn get_flips(dec: &mut ArithDecoder, mesh: &PmMesh) -> Option<Vec<bool>> {
    let mut ctx = FlipContexts::default();
    let mut flips = vec![false; mesh.faces.len()];
    if dec.bit(&mut ctx.any)? {
        for f in 0..mesh.faces.len() {
            let c = context(mesh, &flips, f);
            flips[f] = dec.bit(&mut ctx.face[c])?;
        }
    }
    Some(flips)
}

/// Whether welding the vertices of `mesh` that share a cell leaves every face three distinct
/// corners: what the encoder's Mⁿ always does, and a corrupt stream's may not.
pub fn welds_cleanly(mesh: &PmMesh) -> bool {
    let welded = weld(mesh).0;
    mesh.faces.iter().all(|face| {
        let [a, b, c] = face.v.map(|v| welded[v as usize]);
        a != b && b != c && a != c
    })
}

/// The vertex each vertex of `mesh` welds into, and the cells of the welded vertices.
fn weld(mesh: &PmMesh) -> (Vec<u32>, Vec<[i32; 3]>) {
    let mut index: std::collections::HashMap<[i32; 3], u32> =
        std::collections::HashMap::with_capacity(mesh.positions.len());
    let mut cells = Vec::with_capacity(mesh.positions.len());
    let welded = mesh
        .positions
        .iter()
        .map(|&c| {
            *index.entry(c).or_insert_with(|| {
                cells.push(c);
                cells.len() as u32 - 1
            })
        })
        .collect();
    (welded, cells)
}

/// The values of each face's corners once flipped faces are turned back (their last two
/// corners swapped), as [`restore`] turns the faces.
pub fn restore_corners<T: Copy>(values: &[[T; 3]], flips: &[bool]) -> Vec<[T; 3]> {
    values
        .iter()
        .zip(flips)
        .map(|(&[a, b, c], &flipped)| if flipped { [a, c, b] } else { [a, b, c] })
        .collect()
}

/// The mesh the manifold Mⁿ stands for: vertices sharing a cell welded (the first keeps its
/// place), flipped faces turned back.
pub fn restore(mesh: &PmMesh, flips: &[bool], grid: &Grid) -> TriMesh {
    let (welded, cells) = weld(mesh);
    let faces = mesh
        .faces
        .iter()
        .zip(flips)
        .map(|(face, &flipped)| {
            let [a, b, c] = face.v.map(|v| welded[v as usize]);
            if flipped {
                [a, c, b]
            } else {
                [a, b, c]
            }
        })
        .collect();
    TriMesh::new(
        cells
            .iter()
            .map(|c| grid.dequantize(c.map(|x| x.max(0) as u32)))
            .collect(),
        faces,
    )
}
