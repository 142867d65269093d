//! Error spheres (Grabner §3.3.2): a ball at each node bounding every vertex of its subtree,
//! coded top-down as ratios rounded up, so that a decoded radius never underestimates.
//!
//! A child's true radius r_c is at most r_s + |v_c − v_s| (every vertex under c is under s), so
//! the coded ratio is taken against that bound: q = r_c / (r̂_s + |v̂_c − v̂_s|) ≤ 1, rounded up
//! to a multiple of 1/2^bits, and r̂_c = q̂ · (r̂_s + |v̂_c − v̂_s|) ≥ r_c. Ratios never overflow
//! their bits, whatever the placement of inner nodes.

/// The exact radius of every node's sphere about `positions` (leaves: 0), bottom-up from the
/// leaves' positions.
pub fn exact_radii(leaves: &[[f64; 3]], children: &[[u32; 2]], positions: &[[f64; 3]]) -> Vec<f64> {
    // Children are created before parents: node order is bottom-up. A node's subtree's leaves
    // are gathered through its children's ranges of a leaf order built once.
    let n = leaves.len();
    let total = n + children.len();
    let mut first = vec![0u32; total];
    let mut count = vec![1u32; total];
    // Leaf order: depth-first from the root puts every subtree's leaves in one run.
    let mut order: Vec<u32> = Vec::with_capacity(n);
    if total > 0 {
        let mut stack = vec![(total - 1) as u32];
        while let Some(v) = stack.pop() {
            match (v as usize).checked_sub(n) {
                None => order.push(v),
                Some(i) => {
                    let [t, u] = children[i];
                    stack.push(u);
                    stack.push(t);
                }
            }
        }
    }
    for (rank, &leaf) in order.iter().enumerate() {
        first[leaf as usize] = rank as u32;
    }
    for (i, &[t, u]) in children.iter().enumerate() {
        first[n + i] = first[t as usize].min(first[u as usize]);
        count[n + i] = count[t as usize] + count[u as usize];
    }
    (0..total)
        .map(|v| {
            if v < n {
                return 0.0;
            }
            let c = glam::DVec3::from_array(positions[v]);
            let run = &order[first[v] as usize..(first[v] + count[v]) as usize];
            run.iter()
                .map(|&l| c.distance(glam::DVec3::from_array(leaves[l as usize])))
                .fold(0.0, f64::max)
        })
        .collect()
}

/// The bound a child's ratio is taken against: r̂_s + |v̂_c − v̂_s|.
pub fn ratio_base(parent_radius: f64, parent: [f64; 3], child: [f64; 3]) -> f64 {
    parent_radius + glam::DVec3::from_array(parent).distance(glam::DVec3::from_array(child))
}

/// The ratio step of `bits` bits: q̂ ∈ {1, 2, …, 2^bits} / 2^bits.
pub fn ratio_code(radius: f64, base: f64, bits: u8) -> u32 {
    let steps = 1u32 << bits;
    if base <= 0.0 {
        return 0;
    }
    let q = (radius / base).clamp(0.0, 1.0);
    let mut code = ((q * steps as f64).ceil() as u32).clamp(1, steps) - 1;
    // Rounding must never make the decoded radius smaller than the true one.
    while code + 1 < steps && decoded_radius(code, base, bits) < radius {
        code += 1;
    }
    code
}

/// The radius a ratio code stands for.
pub fn decoded_radius(code: u32, base: f64, bits: u8) -> f64 {
    base * (code + 1) as f64 / (1u32 << bits) as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coded_radii_never_underestimate() {
        for bits in 1..=4 {
            for i in 0..1000 {
                let base = 0.37 + i as f64 * 1.3;
                let radius = base * ((i * 7919) % 1000) as f64 / 999.0;
                let code = ratio_code(radius, base, bits);
                assert!(code < 1 << bits);
                assert!(decoded_radius(code, base, bits) >= radius);
            }
        }
    }
}
