//! Where every unit's contexts start (syntax 2, docs/FORMAT.md §8.2): a probability per context
//! learnt by the encoder over the whole stream and coded once, at the head of the first unit.
//!
//! A unit must decode from its own bytes and its ancestors', so its contexts cannot carry over
//! from the units before it; started afresh, they spend most of a small unit learning what every
//! unit shares (a leaf flag's odds at a depth, a difference vector's size at a radius). Coding
//! those odds once costs a few hundred bytes and saves 7–8% of the stream of a mesh of tens of
//! thousands of vertices (meta-nodes of 8 levels), 14–15% of a few thousand, and more the
//! smaller the meta-nodes.

use super::contexts::{seed, Contexts, SCALES};
use crate::coding::arith::{ArithDecoder, ArithEncoder, BitContext, IntContext};
use crate::coding::SyntaxClass;
use std::sync::Arc;

/// Units a context must have coded in for its prior to be coded (a context that learns once
/// gains nothing from a prior).
const TRAINED_UNITS: u32 = 2;
/// Magnitude codes: the less likely symbol's probability in half-octave steps from 1/2.
const MAGNITUDES: u32 = 16;
const MAGNITUDE_BITS: u8 = 4;

/// The probability of a 1 (of 2^16) that prior code (`one_likelier`, `k`) stands for: the less
/// likely symbol has probability 2^−(1 + k/2), in integers as 2^15 ≫ ⌊k/2⌋, times 46341/2^16
/// (1/√2) for odd k.
fn prior_probability(one_likelier: bool, k: u32) -> u32 {
    let half_octaves = (1u32 << 15) >> (k / 2);
    let less = if k % 2 == 1 {
        (half_octaves * 46341) >> 16
    } else {
        half_octaves
    };
    if one_likelier {
        (1 << 16) - less
    } else {
        less
    }
}

/// The code nearest (in bits) to probability `p1` of a 1.
fn prior_code(p1: u32) -> (bool, u32) {
    let one_likelier = p1 > 1 << 15;
    let less = if one_likelier { (1 << 16) - p1 } else { p1 }.max(1);
    let off = |k: u32| (f64::from(prior_probability(false, k)).ln() - f64::from(less).ln()).abs();
    let k = (0..MAGNITUDES)
        .min_by(|&a, &b| off(a).total_cmp(&off(b)))
        .unwrap_or(0);
    (one_likelier, k)
}

/// Visits every binary context of `ctx` but the difference vectors', in the order of
/// docs/FORMAT.md §8.2.
fn each_fixed(ctx: &mut Contexts, f: &mut dyn FnMut(&mut BitContext)) {
    f(&mut ctx.whole);
    ctx.leaf_child.iter_mut().flatten().for_each(&mut *f);
    ctx.ratio.iter_mut().flatten().for_each(&mut *f);
    ctx.deviation.iter_mut().for_each(&mut *f);
    ctx.deviation_fine.iter_mut().for_each(&mut *f);
    for t in &mut ctx.triangles {
        t.bits_mut().for_each(&mut *f);
    }
    ctx.up.bits_mut().for_each(&mut *f);
    ctx.towards.iter_mut().for_each(&mut *f);
    ctx.blind.iter_mut().for_each(&mut *f);
    ctx.leaf_on_path.iter_mut().for_each(&mut *f);
    ctx.orientation.iter_mut().for_each(&mut *f);
    for u in [
        &mut ctx.dependencies,
        &mut ctx.dependency_on,
        &mut ctx.dependency_rise,
        &mut ctx.dependency_up,
    ] {
        u.bits_mut().for_each(&mut *f);
    }
    ctx.stop.iter_mut().for_each(&mut *f);
    ctx.cone_angle.iter_mut().flatten().for_each(&mut *f);
    for axis in &mut ctx.cone_axis {
        axis.bits_mut().for_each(&mut *f);
    }
}

/// Binary contexts [`each_fixed`] visits.
fn fixed_count(fine_deviations: bool) -> usize {
    let mut count = 0;
    each_fixed(&mut Contexts::new(fine_deviations), &mut |_| count += 1);
    count
}

/// Binary contexts of one radius class's difference vectors (three integer contexts).
fn per_class() -> usize {
    3 * IntContext::default().bits_mut().count()
}

/// The difference vectors' binary contexts of radius class `class` (none if it was not used).
fn class_bits(ctx: &mut Contexts, class: usize) -> Vec<BitContext> {
    ctx.coordinate[class]
        .as_mut()
        .map(|axes| {
            axes.iter_mut()
                .flat_map(|axis| axis.bits_mut().map(|b| *b))
                .collect()
        })
        .unwrap_or_default()
}

/// Every binary context of `ctx` in the priors' order, a class not used as fresh ones.
fn flatten(ctx: &mut Contexts) -> Vec<BitContext> {
    let mut bits = Vec::new();
    each_fixed(ctx, &mut |bit| bits.push(*bit));
    let per_class = per_class();
    for class in 0..SCALES {
        let mut of_class = class_bits(ctx, class);
        of_class.resize(per_class, BitContext::NEW);
        bits.extend(of_class);
    }
    bits
}

/// What the encoder learns for the priors: it codes every unit in stream order with one set of
/// contexts and, per context, averages its slow estimate at the end of each unit that used it.
/// (The estimate at the end of the stream alone would speak for the last, deepest units.)
pub(super) struct Learning {
    pub(super) contexts: Contexts,
    before: Vec<BitContext>,
    sums: Vec<u64>,
    units: Vec<u32>,
}

impl Learning {
    pub(super) fn new(fine_deviations: bool) -> Learning {
        let mut contexts = Contexts::new(fine_deviations);
        let before = flatten(&mut contexts);
        Learning {
            contexts,
            sums: vec![0; before.len()],
            units: vec![0; before.len()],
            before,
        }
    }

    /// Takes in the contexts as a unit left them.
    pub(super) fn unit_done(&mut self) {
        let after = flatten(&mut self.contexts);
        for (i, (a, b)) in after.iter().zip(&self.before).enumerate() {
            if a != b {
                self.sums[i] += a.learnt() as u64;
                self.units[i] += 1;
            }
        }
        self.before = after;
    }

    /// The probability of a 1 (of 2^16) the priors should give context `i`, if it learnt in
    /// enough units.
    fn prior(&self, i: usize) -> Option<u32> {
        (self.units[i] >= TRAINED_UNITS).then(|| (self.sums[i] / self.units[i] as u64) as u32)
    }
}

/// Where every unit's contexts start: per binary context its probability of a 1 (0: even
/// odds), in the order of [`each_fixed`], then per radius class (empty: even odds throughout).
#[derive(Clone, Debug)]
pub(super) struct Priors {
    /// Whether the units code quarter-step deviations (syntax 6).
    fine_deviations: bool,
    fixed: Vec<u32>,
    classes: Arc<Vec<Vec<u32>>>,
}

impl Priors {
    /// Even odds for every context.
    pub(super) fn even(fine_deviations: bool) -> Priors {
        Priors {
            fine_deviations,
            fixed: Vec::new(),
            classes: Arc::default(),
        }
    }

    /// The contexts a unit starts from.
    pub(super) fn start(&self) -> Contexts {
        let mut ctx = Contexts::new(self.fine_deviations);
        if self.fixed.is_empty() {
            return ctx;
        }
        let mut at = 0;
        each_fixed(&mut ctx, &mut |bit| {
            seed(bit, self.fixed[at]);
            at += 1;
        });
        ctx.class_priors = Some(self.classes.clone());
        ctx
    }
}

/// The contexts that code the priors.
struct PriorContexts {
    trained: [BitContext; 2],
    class: BitContext,
    one_likelier: BitContext,
    magnitude: [BitContext; 1 << MAGNITUDE_BITS],
}

impl PriorContexts {
    fn new() -> PriorContexts {
        PriorContexts {
            trained: [BitContext::NEW; 2],
            class: BitContext::NEW,
            one_likelier: BitContext::NEW,
            magnitude: [BitContext::NEW; 1 << MAGNITUDE_BITS],
        }
    }

    /// Codes one context's prior (`None`: even odds); returns its probability (0: none).
    fn put(&mut self, enc: &mut ArithEncoder, prior: Option<u32>, previous: &mut bool) -> u32 {
        let g = SyntaxClass::Geometry;
        enc.bit(
            &mut self.trained[*previous as usize],
            prior.is_some(),
            g,
            "priors",
        );
        *previous = prior.is_some();
        let Some(p1) = prior else {
            return 0;
        };
        let (one_likelier, k) = prior_code(p1);
        enc.bit(&mut self.one_likelier, one_likelier, g, "priors");
        let mut node = 1usize;
        for i in (0..MAGNITUDE_BITS).rev() {
            let bit = k >> i & 1 == 1;
            enc.bit(&mut self.magnitude[node], bit, g, "priors");
            node = node * 2 + bit as usize;
        }
        prior_probability(one_likelier, k)
    }

    /// Decodes one context's prior (`None`: cut).
    fn get(&mut self, dec: &mut ArithDecoder, previous: &mut bool) -> Option<u32> {
        let trained = dec.bit(&mut self.trained[*previous as usize])?;
        *previous = trained;
        if !trained {
            return Some(0);
        }
        let one_likelier = dec.bit(&mut self.one_likelier)?;
        let mut node = 1usize;
        for _ in 0..MAGNITUDE_BITS {
            let bit = dec.bit(&mut self.magnitude[node])?;
            node = node * 2 + bit as usize;
        }
        Some(prior_probability(
            one_likelier,
            (node - (1 << MAGNITUDE_BITS)) as u32,
        ))
    }
}

/// Codes the priors `learning` gives and returns them as the decoder will have them.
pub(super) fn put_priors(enc: &mut ArithEncoder, learning: &Learning) -> Priors {
    let mut pc = PriorContexts::new();
    let mut previous = false;
    let fine_deviations = !learning.contexts.deviation_fine.is_empty();
    let count = fixed_count(fine_deviations);
    let fixed = (0..count)
        .map(|i| pc.put(enc, learning.prior(i), &mut previous))
        .collect();
    let per_class = per_class();
    let classes = (0..SCALES)
        .map(|class| {
            let first = count + class * per_class;
            let any = (first..first + per_class).any(|i| learning.prior(i).is_some());
            enc.bit(&mut pc.class, any, SyntaxClass::Geometry, "priors");
            if !any {
                return Vec::new();
            }
            (first..first + per_class)
                .map(|i| pc.put(enc, learning.prior(i), &mut previous))
                .collect()
        })
        .collect();
    Priors {
        fine_deviations,
        fixed,
        classes: Arc::new(classes),
    }
}

/// Decodes the priors of a stream with quarter-step deviations or without (`None`: the unit
/// is cut).
pub(super) fn get_priors(dec: &mut ArithDecoder, fine_deviations: bool) -> Option<Priors> {
    let mut pc = PriorContexts::new();
    let mut previous = false;
    let count = fixed_count(fine_deviations);
    let fixed = (0..count)
        .map(|_| pc.get(dec, &mut previous))
        .collect::<Option<Vec<u32>>>()?;
    let per_class = per_class();
    let mut classes = Vec::with_capacity(SCALES);
    for _ in 0..SCALES {
        classes.push(if dec.bit(&mut pc.class)? {
            (0..per_class)
                .map(|_| pc.get(dec, &mut previous))
                .collect::<Option<Vec<u32>>>()?
        } else {
            Vec::new()
        });
    }
    Some(Priors {
        fine_deviations,
        fixed,
        classes: Arc::new(classes),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn prior_codes_span_even_odds_to_a_few_in_a_thousand_and_round_trip() {
        assert_eq!(prior_probability(false, 0), 1 << 15);
        assert_eq!(prior_probability(true, 0), 1 << 15);
        assert_eq!(prior_probability(false, 2), 1 << 14);
        assert!(prior_probability(false, 15) < 200);
        for k in 0..MAGNITUDES {
            for side in [false, true].into_iter().filter(|&side| !side || k > 0) {
                assert_eq!(prior_code(prior_probability(side, k)), (side, k));
            }
        }
    }
}
