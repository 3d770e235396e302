//! The analysis: what a run means. Its summary ([`summary`]: mean load, energy books, the
//! collapse mode from [`mode`] and the folds from [`folds`], a rectangular tube's read from its
//! [`faces`]; the crash measures, [`measures`]; the verdict, [`verdict`]), the load history's
//! curves it reads ([`curve`]), the closed-form references of its loading ([`reference`]), and
//! what a case would cost before it runs ([`estimate`]). Units: mm, N, mJ, s.
//!
//! The top floor: imports the model and the engine; nothing imports it but the solver's root.
//! Inside, a tree: [`summary::summarize`] at the top assembles the run's analysis; the parts it
//! calls take the figures they read, not the summary; leaves such as [`curve`], [`peaks`] and
//! the closed forms of [`reference`] import nothing above them.

pub mod curve;
pub mod error_bar;
pub mod estimate;
pub mod expected;
pub mod faces;
pub mod folds;
pub mod measures;
pub mod mode;
pub mod peaks;
pub mod plan;
pub mod rates;
pub mod reference;
pub mod richardson;
pub mod summary;
pub mod verdict;
