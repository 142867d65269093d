//! `came`'s adaptive contexts, one set a unit, and the context classes both sides derive from
//! what they decoded (the parent's radius and cone, the nearer child).

use crate::coding::arith::{BitContext, IntContext, UintContext};
use crate::hierarchy::came::cones::{CodedCone, ANGLE_BITS, NO_CONE};
use crate::hierarchy::came::deviation::{DEVIATION_BITS, FINE_DEVIATION_BITS};

/// Bits of a radius ratio.
pub(super) const RADIUS_BITS: u8 = 4;
/// Depth contexts (paths are at most 52 bits).
pub(super) const DEPTHS: usize = 53;
/// Magnitude classes of the parent's radius, for the difference vector's contexts.
pub(super) const SCALES: usize = 40;

/// Path kinds, for the direction contexts.
#[derive(Clone, Copy)]
pub(super) enum Kind {
    N1 = 0,
    N2 = 1,
    N3 = 2,
    Dependency = 3,
}

impl Kind {
    /// The kind of a triangle's path by which corner of its birth split it is (0: n1, 1: n2,
    /// else n3).
    pub(super) fn of_corner(corner: u8) -> Kind {
        match corner {
            0 => Kind::N1,
            1 => Kind::N2,
            _ => Kind::N3,
        }
    }
}

/// Every adaptive context of one unit.
#[derive(Clone)]
pub(super) struct Contexts {
    pub(super) whole: BitContext,
    pub(super) leaf_child: Vec<[BitContext; 2]>,
    /// Per class of the parent's radius, made when first used: a unit meets only a few of the
    /// classes, and each is 3 KB of contexts to set up.
    pub(super) coordinate: Vec<Option<Box<[IntContext; 3]>>>,
    pub(super) ratio: [Vec<BitContext>; 2],
    /// One tree for both children (two by side, or by the left child's code, cost more:
    /// units are too small to learn them).
    pub(super) deviation: Vec<BitContext>,
    /// The quarter-step deviation codes' tree (syntax 6; empty before, so that the priors of
    /// earlier streams list the contexts they did).
    pub(super) deviation_fine: Vec<BitContext>,
    pub(super) triangles: [UintContext; 4],
    pub(super) up: UintContext,
    pub(super) towards: [BitContext; 4],
    pub(super) blind: [BitContext; 4],
    pub(super) leaf_on_path: Vec<BitContext>,
    pub(super) orientation: [BitContext; 3],
    pub(super) dependencies: UintContext,
    pub(super) dependency_on: UintContext,
    pub(super) dependency_rise: UintContext,
    pub(super) dependency_up: UintContext,
    pub(super) stop: [BitContext; 16],
    /// Per class of the parent's cone ([`cone_class`]): the half-angle code's tree; the two
    /// coordinates of an axis of its own (differences from the square's centre).
    pub(super) cone_angle: Vec<Vec<BitContext>>,
    pub(super) cone_axis: [IntContext; 2],
    /// A triangle's normal (syntax 4): whether it has no area; its code's two coordinates.
    /// Not among the priors: each unit learns them afresh.
    pub(super) face_no_area: BitContext,
    pub(super) face_normal: [IntContext; 2],
    /// Per radius class, where its difference vectors' contexts start when first used: the
    /// probability of a 1 of each binary context ([`IntContext::bits_mut`]'s order, the three
    /// axes in turn; 0: even odds), or nothing (syntax 2's priors, [`super::priors`]).
    pub(super) class_priors: Option<std::sync::Arc<Vec<Vec<u32>>>>,
}

impl Contexts {
    /// Fresh contexts for a unit of a stream with quarter-step deviation codes (syntax 6) or
    /// without.
    pub(super) fn new(fine_deviations: bool) -> Contexts {
        let fine = if fine_deviations {
            1 << FINE_DEVIATION_BITS
        } else {
            0
        };
        Contexts {
            whole: BitContext::default(),
            leaf_child: vec![[BitContext::default(); 2]; DEPTHS],
            coordinate: vec![None; SCALES],
            ratio: [
                vec![BitContext::default(); 1 << RADIUS_BITS],
                vec![BitContext::default(); 1 << RADIUS_BITS],
            ],
            deviation: vec![BitContext::default(); 1 << DEVIATION_BITS],
            deviation_fine: vec![BitContext::default(); fine],
            triangles: Default::default(),
            up: UintContext::default(),
            towards: [BitContext::default(); 4],
            blind: [BitContext::default(); 4],
            leaf_on_path: vec![BitContext::default(); DEPTHS],
            orientation: [BitContext::default(); 3],
            dependencies: UintContext::default(),
            dependency_on: UintContext::default(),
            dependency_rise: UintContext::default(),
            dependency_up: UintContext::default(),
            stop: [BitContext::default(); 16],
            cone_angle: vec![vec![BitContext::default(); 1 << ANGLE_BITS]; CONE_CLASSES],
            cone_axis: Default::default(),
            face_no_area: BitContext::default(),
            face_normal: Default::default(),
            class_priors: None,
        }
    }
}

impl Contexts {
    /// The difference vector's contexts for radius class `class`.
    pub(super) fn coordinates(&mut self, class: usize) -> &mut [IntContext; 3] {
        let priors = self.class_priors.as_ref().and_then(|p| p.get(class));
        self.coordinate[class].get_or_insert_with(|| {
            let mut axes: Box<[IntContext; 3]> = Default::default();
            if let Some(priors) = priors {
                let bits = axes.iter_mut().flat_map(|axis| axis.bits_mut());
                for (bit, &p1) in bits.zip(priors) {
                    seed(bit, p1);
                }
            }
            axes
        })
    }
}

/// Symbols a seeded context adapts as if it had already seen (its next updates move it by
/// 1/2^(PRIOR_SEEN + 1) and less): enough to keep the prior, few enough to follow a unit that
/// differs from the stream's mean.
const PRIOR_SEEN: u32 = 4;

/// Starts `bit` from probability `p1` of a 1 (of 2^16), or leaves it fresh for 0.
pub(super) fn seed(bit: &mut BitContext, p1: u32) {
    if p1 != 0 {
        *bit = BitContext::seeded(p1, PRIOR_SEEN);
    }
}

/// The context class of a parent radius: its bit length.
pub(super) fn scale(radius: f64) -> usize {
    let r = radius.ceil().min(u64::MAX as f64) as u64;
    ((64 - r.leading_zeros()) as usize).min(SCALES - 1)
}

/// Which child (true: v_u) lies nearer `target`; ties go to v_t.
pub(super) fn nearer(children: [[f64; 3]; 2], target: [f64; 3]) -> bool {
    let d = |p: [f64; 3]| {
        (p[0] - target[0]).powi(2) + (p[1] - target[1]).powi(2) + (p[2] - target[2]).powi(2)
    };
    d(children[1]) < d(children[0])
}

pub(super) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// Context classes of a cone: its parent has none, or the parent's half-angle code + 1 (a
/// child's faces are some of its parent's, so its cone is mostly as narrow or narrower).
pub(super) const CONE_CLASSES: usize = 1 + NO_CONE as usize;

pub(super) fn cone_class(parent: CodedCone) -> usize {
    if (parent.angle as u32) < NO_CONE {
        1 + parent.angle as usize
    } else {
        0
    }
}
