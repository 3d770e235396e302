//! The analysis: what a run means. Its summary ([`summary`]: mean load, energy books, the
//! collapse mode from [`mode`] and the folds from [`folds`], a rectangular tube's read from its
//! [`faces`]; the crash measures, [`measures`]), the closed-form references of its loading
//! ([`reference`]), and what a case would cost before it runs ([`estimate`]).
//! Units: mm, N, mJ, s.
//!
//! The top floor: imports the model and the engine; nothing imports it but the solver's root.

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
