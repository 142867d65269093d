//! Magnor & Girod's EMC in the lab: Table 1 and Figs. 4–5 beside the paper's ([`tables`]), and
//! how `emc`'s cost grows with the mesh ([`scale`]).

pub mod scale;
pub mod tables;
