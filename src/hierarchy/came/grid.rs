//! Points bucketed in a uniform grid of cubic cells, for the searches of close and nearest
//! pairs: the points of a cell are one slice of an index array sorted by cell.

use glam::DVec3;
use rayon::prelude::*;
use std::collections::HashMap;

/// A cell's integer coordinates.
pub type CellKey = [i64; 3];

/// The grid.
pub struct CellGrid {
    origin: DVec3,
    size: f64,
    /// Point indices sorted by cell.
    order: Vec<u32>,
    /// Each occupied cell's range of `order`.
    cells: HashMap<CellKey, (u32, u32), foldhash::fast::FixedState>,
}

impl CellGrid {
    /// Buckets `points` into cells of edge `size` from `origin`.
    pub fn new(points: &[DVec3], origin: DVec3, size: f64) -> CellGrid {
        let key = |p: DVec3| ((p - origin) / size).floor().to_array().map(|x| x as i64);
        let mut keyed: Vec<(CellKey, u32)> = points
            .par_iter()
            .enumerate()
            .map(|(i, &p)| (key(p), i as u32))
            .collect();
        keyed.par_sort_unstable();
        let mut cells = HashMap::with_capacity_and_hasher(keyed.len(), Default::default());
        let mut start = 0;
        while start < keyed.len() {
            let k = keyed[start].0;
            let end = start + keyed[start..].iter().take_while(|e| e.0 == k).count();
            cells.insert(k, (start as u32, end as u32));
            start = end;
        }
        CellGrid {
            origin,
            size,
            order: keyed.into_iter().map(|(_, i)| i).collect(),
            cells,
        }
    }

    /// The cell of `p`.
    pub fn key(&self, p: DVec3) -> CellKey {
        ((p - self.origin) / self.size)
            .floor()
            .to_array()
            .map(|x| x as i64)
    }

    /// The points in cell `key`.
    pub fn cell(&self, key: CellKey) -> &[u32] {
        match self.cells.get(&key) {
            Some(&(start, end)) => &self.order[start as usize..end as usize],
            None => &[],
        }
    }
}
