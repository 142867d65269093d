//! What each question's context is chosen from: a vertex's decoded neighbours' moments, the
//! regression estimate of where it lies inside its cell, and the leaf contexts it selects.

use super::super::contexts;

/// Steepest regression plane used for prediction (squared gradient).
pub(super) const SLOPE: f64 = 1.5;

/// 1 / 2^`shift`, exactly: the factor from the centres' units to half-widths of a cell whose
/// half-width is 2^`shift` (multiplying is cheaper than dividing).
pub(super) fn per_half_width(shift: u8) -> f64 {
    f64::from_bits((1023 - shift as u64) << 52)
}

/// 2^`shift`, exactly.
#[inline]
pub(super) fn power_of_two(shift: u8) -> f64 {
    f64::from_bits((1023 + shift as u64) << 52)
}

/// `if choose { a } else { b }` without a branch: which one is as good as random to a branch
/// predictor.
#[inline]
pub(super) fn select(choose: bool, a: f64, b: f64) -> f64 {
    let mask = (choose as u64).wrapping_neg();
    f64::from_bits((a.to_bits() & mask) | (b.to_bits() & !mask))
}

/// Where a vertex is expected along `axis`, relative to its centre, and the expected squared
/// error, both in the units of the centres, from its neighbours' moments `m` (relative to its
/// centre) and the shifts of its cell's half-widths. The prediction is the neighbours'
/// regression plane (the coordinate along the axis as a linear function of the other two,
/// evaluated at the vertex's own place across the axis) where the neighbours span the other two
/// axes, else their mean; the error is the neighbours' residual spread plus what the vertex's
/// own cell leaves open.
#[inline(always)]
pub(in crate::codecs::emc::modelled) fn estimate(
    m: &Moments,
    axis: usize,
    shifts: [u8; 3],
) -> (f64, f64) {
    let (b, c) = ((axis + 1) % 3, (axis + 2) % 3);
    let var_a = m.cov[axis][axis].max(0.0);
    let (cbb, ccc, cbc) = (m.cov[b][b], m.cov[c][c], m.cov[b][c]);
    let (cab, cac) = (m.cov[axis][b], m.cov[axis][c]);
    // The plane's gradient is (nb, nc) / det; it is used where the neighbours span the
    // other two axes and it is no steeper than SLOPE.
    let det = cbb * ccc - cbc * cbc;
    let (nb, nc) = (cab * ccc - cac * cbc, cac * cbb - cab * cbc);
    let spread = cbb + ccc;
    let plane =
        (m.k >= 4) & (det > 1e-2 * spread * spread) & (nb * nb + nc * nc <= SLOPE * det * det);
    // Both estimates are computed and one is kept (the plane's may be meaningless where it is
    // not used).
    let inverse = 1.0 / det;
    let (beta_b, beta_c) = (nb * inverse, nc * inverse);
    let residual = (var_a - beta_b * cab - beta_c * cac).max(0.0);
    // The vertex's own place across the axis: the neighbours' mean, kept inside its cell.
    let (wb, wc) = (power_of_two(shifts[b]), power_of_two(shifts[c]));
    let (mb, mc) = (m.mean[b], m.mean[c]);
    let (eb, ec) = (mb.max(-wb).min(wb), mc.max(-wc).min(wc));
    let own_cell =
        beta_b * beta_b * (wb * wb / 3.0).min(cbb) + beta_c * beta_c * (wc * wc / 3.0).min(ccc);
    let on_plane = m.mean[axis] + beta_b * (eb - mb) + beta_c * (ec - mc);
    (
        select(plane, on_plane, m.mean[axis]),
        select(plane, residual + own_cell, var_a),
    )
}

/// [`estimate`] and the "which half" context of a leaf on all three axes at once (lane `a`:
/// axis `a`; a fourth lane repeats the first so that the lanes fill vector registers): the same
/// operations in the same order, so the same values, in a form the compiler vectorizes.
/// Returns each axis's context index and whether the prediction is below the split plane.
#[inline(always)]
pub(super) fn leaf_contexts(m: &Moments, shifts: [u8; 3]) -> ([usize; 3], [bool; 3]) {
    type Lanes = [f64; 4];
    fn each(f: impl Fn(usize) -> f64) -> Lanes {
        [f(0), f(1), f(2), f(3)]
    }
    let cov = &m.cov;
    // Lane a reads axis a, b = a + 1 and c = a + 2 (mod 3).
    let at = |lane: usize, shift: usize| (lane + shift) % 3;
    let var_a = each(|l| cov[at(l, 0)][at(l, 0)].max(0.0));
    let cbb = each(|l| cov[at(l, 1)][at(l, 1)]);
    let ccc = each(|l| cov[at(l, 2)][at(l, 2)]);
    let cbc = each(|l| cov[at(l, 1)][at(l, 2)]);
    let cab = each(|l| cov[at(l, 0)][at(l, 1)]);
    let cac = each(|l| cov[at(l, 0)][at(l, 2)]);
    let mean_a = each(|l| m.mean[at(l, 0)]);
    let mb = each(|l| m.mean[at(l, 1)]);
    let mc = each(|l| m.mean[at(l, 2)]);
    let wb = each(|l| power_of_two(shifts[at(l, 1)]));
    let wc = each(|l| power_of_two(shifts[at(l, 2)]));
    let scale = each(|l| per_half_width(shifts[at(l, 0)]));
    let det = each(|l| cbb[l] * ccc[l] - cbc[l] * cbc[l]);
    let nb = each(|l| cab[l] * ccc[l] - cac[l] * cbc[l]);
    let nc = each(|l| cac[l] * cbb[l] - cab[l] * cbc[l]);
    let spread = each(|l| cbb[l] + ccc[l]);
    let inverse = each(|l| 1.0 / det[l]);
    let beta_b = each(|l| nb[l] * inverse[l]);
    let beta_c = each(|l| nc[l] * inverse[l]);
    let residual = each(|l| (var_a[l] - beta_b[l] * cab[l] - beta_c[l] * cac[l]).max(0.0));
    let eb = each(|l| mb[l].max(-wb[l]).min(wb[l]));
    let ec = each(|l| mc[l].max(-wc[l]).min(wc[l]));
    let own_cell = each(|l| {
        beta_b[l] * beta_b[l] * (wb[l] * wb[l] / 3.0).min(cbb[l])
            + beta_c[l] * beta_c[l] * (wc[l] * wc[l] / 3.0).min(ccc[l])
    });
    let on_plane = each(|l| mean_a[l] + beta_b[l] * (eb[l] - mb[l]) + beta_c[l] * (ec[l] - mc[l]));
    let mut index = [0; 3];
    let mut below = [false; 3];
    let kind = contexts::half_kind(true, m.k);
    for l in 0..3 {
        let plane = (m.k >= 4)
            & (det[l] > 1e-2 * spread[l] * spread[l])
            & (nb[l] * nb[l] + nc[l] * nc[l] <= SLOPE * det[l] * det[l]);
        let prediction = select(plane, on_plane[l], mean_a[l]);
        let variance = select(plane, residual[l] + own_cell[l], var_a[l]);
        index[l] = contexts::half_in(
            kind,
            prediction.abs() * scale[l],
            variance * scale[l] * scale[l],
        )
        .index;
        below[l] = prediction < 0.0;
    }
    (index, below)
}

/// Count, mean and covariance of a vertex's neighbours (see [`neighbour_moments`]).
pub(in crate::codecs::emc::modelled) struct Moments {
    pub(super) k: usize,
    pub(in crate::codecs::emc::modelled) mean: [f64; 3],
    pub(in crate::codecs::emc::modelled) cov: [[f64; 3]; 3],
}

/// Count, mean and covariance of the cell centres of `neighbours` (`centre` gives each), relative
/// to `origin`; `None` without neighbours.
#[inline(always)]
pub(super) fn neighbour_moments(
    origin: [i32; 3],
    neighbours: &[u32],
    centre: impl Fn(usize) -> [i32; 3],
) -> Option<Moments> {
    if neighbours.is_empty() {
        return None;
    }
    // Sums of the offsets and their products: x, y, z, xx, yy, zz, xy, xz, yz.
    let mut s = [0f64; 9];
    for &n in neighbours {
        let c = centre(n as usize);
        let d = [0, 1, 2].map(|a| (c[a] - origin[a]) as f64);
        s[0] += d[0];
        s[1] += d[1];
        s[2] += d[2];
        s[3] += d[0] * d[0];
        s[4] += d[1] * d[1];
        s[5] += d[2] * d[2];
        s[6] += d[0] * d[1];
        s[7] += d[0] * d[2];
        s[8] += d[1] * d[2];
    }
    let k = neighbours.len();
    let inv = 1.0 / k as f64;
    let mean = [s[0] * inv, s[1] * inv, s[2] * inv];
    let (xy, xz, yz) = (
        s[6] * inv - mean[0] * mean[1],
        s[7] * inv - mean[0] * mean[2],
        s[8] * inv - mean[1] * mean[2],
    );
    let cov = [
        [s[3] * inv - mean[0] * mean[0], xy, xz],
        [xy, s[4] * inv - mean[1] * mean[1], yz],
        [xz, yz, s[5] * inv - mean[2] * mean[2]],
    ];
    Some(Moments { k, mean, cov })
}
