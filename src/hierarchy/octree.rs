//! EMC's octree: three interleaved binary trees over the quantization grid.
//!
//! Top-down, level l (1..=L) halves every cell along each axis in turn, longest box side first:
//! step s = 3(l − 1) + k refines axis `axes[k]` by bit (Q − l) of the cell index. A vertex's path
//! through all 3L steps is its *key*: the bits it takes at each step, step 0 most significant.
//! Vertices sorted by key form a binary trie in which each cluster of the hierarchy is a
//! contiguous range; a cluster splits at the first step where its smallest and largest keys
//! differ. The surviving vertex of a merge (the left half) is the range's first vertex, so the
//! representative of every cluster is its smallest key.

/// The order of steps: L levels, and the axes of each level from the longest box side to the
/// shortest.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StepOrder {
    /// Levels L (= quantization bits Q).
    pub levels: u8,
    /// Axis refined by the 1st, 2nd and 3rd step of each level.
    pub axes: [u8; 3],
}

impl StepOrder {
    /// Number of steps, 3L.
    pub fn steps(&self) -> usize {
        3 * self.levels as usize
    }

    /// Axis refined at `step`.
    pub fn axis(&self, step: usize) -> usize {
        self.axes[step % 3] as usize
    }

    /// Level (1-based) that `step` belongs to.
    pub fn level(&self, step: usize) -> usize {
        step / 3 + 1
    }

    /// The key of a cell: its bit at every step, step 0 most significant, in the low 3L bits.
    pub fn key(&self, cell: [u32; 3]) -> u128 {
        let mut key = 0u128;
        for step in 0..self.steps() {
            let shift = self.levels as usize - self.level(step);
            let bit = (cell[self.axis(step)] >> shift) & 1;
            key = (key << 1) | bit as u128;
        }
        key
    }

    /// The bit a key takes at `step`.
    pub fn bit(&self, key: u128, step: usize) -> u32 {
        ((key >> (self.steps() - 1 - step)) & 1) as u32
    }

    /// First step at which two keys differ, if any.
    pub fn first_difference(&self, a: u128, b: u128) -> Option<usize> {
        let diff = a ^ b;
        (diff != 0).then(|| diff.leading_zeros() as usize - (128 - self.steps()))
    }

    /// Cell bits per axis after `steps_done` steps.
    pub fn bits_per_axis(&self, steps_done: usize) -> [u8; 3] {
        let mut bits = [0u8; 3];
        for step in 0..steps_done.min(self.steps()) {
            bits[self.axis(step)] += 1;
        }
        bits
    }
}

/// Axes ordered from the longest extent to the shortest (ties: lower axis first).
pub fn axes_by_extent(extent: [f64; 3]) -> [u8; 3] {
    let mut axes = [0u8, 1, 2];
    axes.sort_by(|&a, &b| {
        extent[b as usize]
            .total_cmp(&extent[a as usize])
            .then(a.cmp(&b))
    });
    axes
}

/// Vertices sorted by key: the trie of the octree hierarchy.
pub struct KeyTrie {
    /// The step order the keys follow.
    pub order: StepOrder,
    /// Vertex ids in key order.
    pub vertices: Vec<u32>,
    /// Their keys, ascending.
    pub keys: Vec<u128>,
}

impl KeyTrie {
    /// The trie of `cells` (one per vertex, all distinct).
    pub fn new(order: StepOrder, cells: &[[u32; 3]]) -> KeyTrie {
        let mut pairs: Vec<(u128, u32)> = cells
            .iter()
            .enumerate()
            .map(|(v, &c)| (order.key(c), v as u32))
            .collect();
        pairs.sort_unstable();
        KeyTrie {
            order,
            vertices: pairs.iter().map(|p| p.1).collect(),
            keys: pairs.iter().map(|p| p.0).collect(),
        }
    }

    /// The step at which the cluster `range` next splits, searching from `from` on.
    pub fn next_split(&self, range: std::ops::Range<usize>) -> Option<usize> {
        if range.len() < 2 {
            return None;
        }
        self.order
            .first_difference(self.keys[range.start], self.keys[range.end - 1])
    }

    /// Where `range` divides at `step`: the first position whose bit is 1.
    pub fn partition(&self, range: std::ops::Range<usize>, step: usize) -> usize {
        let slice = &self.keys[range.clone()];
        range.start + slice.partition_point(|&k| self.order.bit(k, step) == 0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_interleave_levels_and_axes() {
        let order = StepOrder {
            levels: 2,
            axes: [2, 0, 1],
        };
        // Cell (x=0b10, y=0b01, z=0b11): level 1 takes z1 x1 y0, level 2 takes z1 x0 y1.
        assert_eq!(order.key([0b10, 0b01, 0b11]), 0b110_101);
        assert_eq!(order.first_difference(0b110_101, 0b110_001), Some(3));
        assert_eq!(order.bits_per_axis(4), [1, 1, 2]);
        assert_eq!(axes_by_extent([1.0, 3.0, 2.0]), [1, 2, 0]);
    }

    #[test]
    fn clusters_are_ranges_that_split_where_keys_differ() {
        let order = StepOrder {
            levels: 3,
            axes: [0, 1, 2],
        };
        let cells = [[0, 0, 0], [7, 7, 7], [1, 0, 0], [0, 0, 1]];
        let trie = KeyTrie::new(order, &cells);
        assert_eq!(trie.vertices[0], 0);
        assert_eq!(trie.next_split(0..4), Some(0));
        let mid = trie.partition(0..4, 0);
        assert_eq!(mid, 3);
        assert_eq!(trie.vertices[3], 1);
        assert_eq!(trie.next_split(3..4), None);
        // [0,0,0], [0,0,1], [1,0,0] first differ at level 3, axis z (step 8) vs x (step 6).
        assert_eq!(trie.next_split(0..3), Some(6));
    }
}
