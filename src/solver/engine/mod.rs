//! The engine: how a case is computed. The shared kernel lives here — the [`Engine`] trait
//! every model implements, the [`State`] it carries from step to step, the clock, the energy
//! books and the per-particle stress loop (`stress.rs`) — with the two models beneath it as
//! siblings: [`solid`], the whole tube in 3D, and [`reduced`], a tube's section on two axes
//! (axisymmetric or plane strain). Beside them: the grid, the shape functions, the particles,
//! the scene a case becomes, the run loop with its observer, history rows and checkpoints.
//! Units: mm, ms, g, N, MPa, mJ.
//!
//! May import the model floor (`super::model`), never the analysis floor. The models import
//! the kernel and the shared pieces here, never each other.
//!
//! The shape function is a type, `S`: [`simulate`] turns the case's choice into it once, and
//! the model with it. What a model carries from step to step is its [`State`] (the scene, the
//! clock, the energy books); everything recomputed within a step is the model's working
//! memory. [`Engine::step`] wraps any model's phases ([`Engine::advance`]) in what every step
//! does before and after them.

pub mod checkpoint;
mod frames;
pub mod grid;
pub mod history;
pub mod observer;
pub mod particles;
pub mod reduced;
mod run;
pub mod scene;
pub mod shape;
pub mod solid;
mod status;
pub(crate) mod stress;

pub mod kernel;

pub use kernel::{Clock, Energies, Engine, PhaseTimes, Phases, SolveError, State, StepInfo};
pub use run::{resume, run, run_scene, simulate, Driver, Finished, RunCost, Snapshot};
