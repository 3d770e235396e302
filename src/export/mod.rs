//! The files a finished run is exported as, written to any [`std::io::Write`] by the CLI
//! (`crush run --out DIR`) and the server (its downloads) alike: the history and the particles
//! as CSV ([`csv`]), the final state as a VTK XML file for ParaView and as the server stores it
//! ([`vtu`]), and the time series of the particle states (a `.pvd` and its frames, [`series`]). The pictures are in `crate::plot`.

pub mod csv;
pub mod series;
pub mod vtu;

pub use vtu::{FinalState, BYTES_PER_PARTICLE};
