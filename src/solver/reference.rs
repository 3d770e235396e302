//! Closed-form reference loads (placeholder: being built).
use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct References {}
