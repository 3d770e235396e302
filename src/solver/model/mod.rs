//! The model: what the user asked for. The case — its JSON ([`case`]'s spec), the checks that
//! make it a valid [`case::Case`], its limits and cost — and the physics it names: the tube's
//! cross-section, the material law ([`material`]) and the plates' contact law ([`contact`]).
//! Units: mm, ms, g, MPa, N.
//!
//! The ground floor: imports nothing of the engine or the analysis.

pub mod case;
pub mod case_defaults;
mod checker;
mod checks;
pub mod contact;
mod cost;
pub mod geometry;
pub mod input;
pub mod ladder;
pub mod limits;
pub mod material;
pub mod schema;
pub mod shape_policy;
pub mod spec;
pub mod step_policy;
