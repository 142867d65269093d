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

/// Mⁿ of a mesh cut to a manifold with what turns it back into the mesh: which faces are
/// flipped, and the weld of the vertices that share a cell (computed once, when read).
#[derive(Clone, Debug)]
pub struct Restoration {
    flips: Vec<bool>,
    /// The welded vertex of each vertex of Mⁿ (the first of a cell keeps its place).
    welded: Vec<u32>,
    /// Cell of each welded vertex.
    cells: Vec<[i32; 3]>,
}

impl Restoration {
    /// Reads which faces of `mesh` (the manifold Mⁿ) are flipped and welds it; an error when
    /// the flips cannot be read or the weld leaves a face fewer than three corners (what the
    /// encoder's Mⁿ never does, and a corrupt stream's may).
    pub fn read(dec: &mut ArithDecoder, mesh: &PmMesh) -> Result<Restoration, &'static str> {
        let flips =
            get_flips(dec, mesh).ok_or("the flipped faces of the last level cannot be read")?;
        let (welded, cells) = weld(mesh);
        let restoration = Restoration {
            flips,
            welded,
            cells,
        };
        let clean = restoration
            .faces(mesh)
            .iter()
            .all(|&[a, b, c]| a != b && b != c && a != c);
        if !clean {
            return Err("the last level welds two corners of a face into one vertex");
        }
        Ok(restoration)
    }

    /// The mesh's faces: Mⁿ's over the welded vertices, flipped faces turned back.
    pub fn faces(&self, mesh: &PmMesh) -> Vec<[u32; 3]> {
        let faces: Vec<[u32; 3]> = mesh
            .faces
            .iter()
            .map(|face| face.v.map(|v| self.welded[v as usize]))
            .collect();
        self.corners(&faces)
    }

    /// The values of each face's corners once flipped faces are turned back (their last two
    /// corners swapped).
    pub fn corners<T: Copy>(&self, values: &[[T; 3]]) -> Vec<[T; 3]> {
        values
            .iter()
            .zip(&self.flips)
            .map(|(&[a, b, c], &flipped)| if flipped { [a, c, b] } else { [a, b, c] })
            .collect()
    }

    /// Number of vertices of the mesh.
    pub fn vertex_count(&self) -> usize {
        self.cells.len()
    }

    /// Cell of each vertex of the mesh.
    pub fn cells(&self) -> &[[i32; 3]] {
        &self.cells
    }

    /// The mesh the manifold Mⁿ stands for, on `grid`.
    pub fn mesh(&self, mesh: &PmMesh, grid: &Grid) -> TriMesh {
        TriMesh::new(
            self.cells
                .iter()
                .map(|c| grid.dequantize(c.map(|x| x.max(0) as u32)))
                .collect(),
            self.faces(mesh),
        )
    }
}

/// Reads which faces of `mesh` (the manifold Mⁿ) are flipped.
fn get_flips(dec: &mut ArithDecoder, mesh: &PmMesh) -> Option<Vec<bool>> {
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
