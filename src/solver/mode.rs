//! Collapse-mode detection from the final shape (placeholder: being built).
