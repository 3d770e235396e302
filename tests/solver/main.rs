//! The solver and the command line as a user drives them: physics against closed forms
//! (`physics`), whole crushes (`crush`), the reduced models (`reduced`), the studies
//! (`studies`), the case parser under generated input (`case_fuzz`) and the CLI (`cli`). One
//! test binary.

mod case_fuzz;
mod cli;
mod crush;
mod physics;
mod reduced;
mod studies;
