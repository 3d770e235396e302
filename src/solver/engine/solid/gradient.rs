//! The type a step stores each particle's velocity gradient in between the kinematics gather
//! and the stress update (1/ms). Imports nothing of the solid model; `workspace.rs`,
//! `averages.rs` and `deformation.rs` import it.

use nalgebra::Matrix3;

/// A velocity gradient as the workspace stores it between two passes, 1/ms. f32 holds it to a
/// relative 6·10⁻⁸: the strain increment L·dt of a step is ~10⁻⁵, so the stress it adds is
/// rounded at ~10⁻¹² of the yield strain, far below what any result shows, and the array is
/// half the bytes (36 instead of 72 per particle, written once and read twice a step). The
/// stress update widens it back to f64; everything it accumulates stays in f64.
pub type Gradient = Matrix3<f32>;
