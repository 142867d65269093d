//! Hoppe's reordering of the vertex splits (§6.2, Table 4) along their dependency graph, so that
//! successive records name nearby faces.

use super::records::{build, ProgressiveMesh};
use super::Simplified;
use crate::hierarchy::pmesh::NIL;

/// The progressive mesh of a simplification with its splits reordered so that successive
/// records name nearby faces (Hoppe §6.2, Table 4): among the splits whose dependencies are met,
/// always the one whose `flclw` is the next highest after the previous record's (circularly).
///
/// Dependencies: a split reads and rewrites its moved faces and the two faces it re-links (fl's
/// and fr's outer neighbours); it must come after the last split that wrote any of them and
/// before the next one, after the splits that created vs, vl and vr, and after the previous split
/// of vs (positions are deltas). The full mesh is the same in any order that keeps them.
pub fn reordered_progressive_mesh(original_faces: &[[u32; 3]], s: &Simplified) -> ProgressiveMesh {
    let splits: Vec<usize> = (0..s.collapses.len()).rev().collect();
    let n = splits.len();
    let mut successors: Vec<Vec<u32>> = vec![Vec::new(); n];
    let mut last_writer: std::collections::HashMap<u32, u32> = std::collections::HashMap::new();
    let mut readers: std::collections::HashMap<u32, Vec<u32>> = std::collections::HashMap::new();
    let mut creator: std::collections::HashMap<u32, u32> = std::collections::HashMap::new();
    let mut last_split_of: std::collections::HashMap<u32, u32> = std::collections::HashMap::new();
    for (j, &ci) in splits.iter().enumerate() {
        let c = &s.collapses[ci];
        let j = j as u32;
        let touched: Vec<u32> = c
            .moved
            .iter()
            .copied()
            .chain(c.beside)
            .filter(|&f| f != NIL)
            .collect();
        let mut preds: Vec<u32> = Vec::new();
        for &f in &touched {
            if let Some(&w) = last_writer.get(&f) {
                preds.push(w);
            }
            for &r in readers.get(&f).map(|v| v.as_slice()).unwrap_or(&[]) {
                preds.push(r);
            }
        }
        for v in [c.vs, c.vl, c.vr] {
            if let Some(&k) = creator.get(&v) {
                preds.push(k);
            }
        }
        if let Some(&k) = last_split_of.get(&c.vs) {
            preds.push(k);
        }
        preds.retain(|&p| p != j);
        preds.sort_unstable();
        preds.dedup();
        for p in preds {
            successors[p as usize].push(j);
        }
        for &f in &touched {
            last_writer.insert(f, j);
            readers.insert(f, Vec::new());
        }
        for f in [c.fl, c.fr] {
            if f != NIL {
                last_writer.insert(f, j);
            }
        }
        creator.insert(c.vt, j);
        last_split_of.insert(c.vs, j);
    }
    let mut indegree = vec![0u32; n];
    for list in &successors {
        for &k in list {
            indegree[k as usize] += 1;
        }
    }
    let flclw_origin: Vec<u32> = splits.iter().map(|&ci| s.collapses[ci].flclw).collect();
    // Face ids in the new order, assigned as faces are created.
    let mut face_id = vec![NIL; original_faces.len()];
    let mut next_face = 0u32;
    for (f, &alive) in s.face_alive.iter().enumerate() {
        if alive {
            face_id[f] = next_face;
            next_face += 1;
        }
    }
    let mut ready: std::collections::BTreeSet<(u32, u32)> = std::collections::BTreeSet::new();
    for j in 0..n {
        if indegree[j] == 0 {
            ready.insert((face_id[flclw_origin[j] as usize], j as u32));
        }
    }
    let mut order = Vec::with_capacity(n);
    let mut previous = 0u32;
    while let Some(&(key, j)) = ready
        .range((previous, 0)..)
        .next()
        .or_else(|| ready.iter().next())
    {
        ready.remove(&(key, j));
        previous = key;
        let c = &s.collapses[splits[j as usize]];
        face_id[c.fl as usize] = next_face;
        next_face += 1;
        if c.fr != NIL {
            face_id[c.fr as usize] = next_face;
            next_face += 1;
        }
        order.push(splits[j as usize]);
        for &k in &successors[j as usize] {
            indegree[k as usize] -= 1;
            if indegree[k as usize] == 0 {
                ready.insert((face_id[flclw_origin[k as usize] as usize], k));
            }
        }
    }
    debug_assert_eq!(order.len(), n, "the dependency graph is acyclic");
    build(original_faces, s, &order)
}
