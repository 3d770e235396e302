//! Accuracy and stability studies over sets of runs: pure analysis of the runs' figures,
//! shared by the command line (`crush study`) and the job service's sweep tables.

pub mod convergence;
pub mod ensemble;
pub mod figures;
pub mod step;

pub use figures::Figures;
