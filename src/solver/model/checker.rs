//! The [`Checker`] every check of a spec writes its failures into: one [`FieldError`] per
//! refused field, with the reason. Imports the limits' error type only; the checks of the case
//! (`checks.rs`, `material/checks.rs`) and of its cost import it.

use super::limits::FieldError;

/// The failures found so far.
#[derive(Default)]
pub(super) struct Checker {
    pub(super) errors: Vec<FieldError>,
}

impl Checker {
    pub(super) fn fail(&mut self, field: &str, reason: &str) {
        self.errors.push(FieldError {
            field: field.into(),
            reason: reason.into(),
        });
    }
    pub(super) fn positive(&mut self, field: &str, v: f64) {
        if !(v.is_finite() && v > 0.0) {
            self.fail(field, "must be a finite number > 0");
        }
    }
    pub(super) fn range(&mut self, field: &str, v: f64, lo: f64, hi: f64, reason: &str) {
        if !(v.is_finite() && v >= lo && v <= hi) {
            self.fail(field, reason);
        }
    }
    pub(super) fn fail_all(&mut self, fields: &[&str], reason: &str) {
        for f in fields {
            self.fail(f, reason);
        }
    }
}
