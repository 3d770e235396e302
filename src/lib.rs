//! crush: explicit 3D material point method simulations of thin-walled tubes crushed between
//! rigid plates, as a library ([`solver`]), a command-line runner ([`cli`]) and an HTTP job
//! server ([`service`]), which export runs alike ([`export`], [`plot`]).

pub mod cli;
pub mod export;
pub mod plot;
pub mod service;
pub mod solver;
pub mod study;

#[cfg(test)]
mod import_tree_tests;
