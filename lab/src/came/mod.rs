//! Grabner's CAME in the lab: what the papers' Tables 2–3 and Fig. 4 need beyond the harness's
//! runs ([`extras`]) and their tables ([`tables`]); view-dependent refinement measured: the
//! table of far, middle and near views ([`vd`], [`vd_table`]), the fly-through
//! ([`flythrough`]), and the screen-space error they report ([`screen_error`]).

pub mod extras;
pub mod flythrough;
pub mod screen_error;
pub mod tables;
pub mod vd;
pub mod vd_table;
