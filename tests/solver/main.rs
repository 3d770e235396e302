//! The solver and the command line as a user drives them: physics against closed forms
//! (`physics`), whole crushes (`crush`), the reduced models (`reduced`), the studies
//! (`studies`), the case parser under generated input (`case_fuzz`), the CLI (`cli`), the
//! validation suite (`validate`) and the
//! costs the README's examples state (`readme`). One test binary.

mod case_fuzz;
mod cli;
mod crush;
mod physics;
mod readme;
mod reduced;
mod studies;
mod validate;
