//! Hoppe's progressive meshes in the lab: Tables 2–4 and the wedge table ([`tables`]), the
//! decimation timings ([`decimation`]) and what cutting to a manifold costs ([`repair_cost`]).

pub mod decimation;
pub mod repair_cost;
pub mod tables;
