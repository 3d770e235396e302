//! A run's time series (`output.frames`): when its frames fall and what each holds ([`Frame`]).
//! Frame k of n stands at k/(n − 1) of the crush distance, the first at the start and the last
//! at the end. The run never stops for a frame, so a series never changes the results: a frame
//! is the state at the end of the first step that reaches its travel (within one step's travel
//! of it, a few µm; exact at the start, at the end and wherever a history row ends), and it
//! reports the travel and time it stands at. Units: mm, ms.

use super::kernel::Engine;
use super::observer::{Frame, Observer};
use crate::solver::model::case::Case;
use crate::solver::model::contact::Ramp;
use crate::solver::Real;

/// The frames still to come.
pub(super) struct Schedule {
    count: u32,
    next: u32,
    /// The time the plate would take at full speed, ms.
    duration: Real,
    ramp: Ramp,
    /// Two times closer than this are one, ms (the run loop's tolerance).
    tolerance: Real,
}

impl Schedule {
    /// The frames of `case`; a run continued from a checkpoint at `resumed_at` (ms) skips the
    /// frames the run before it sent (those due by then).
    pub(super) fn new(
        case: &Case,
        ramp: Ramp,
        duration: Real,
        resumed_at: Option<Real>,
    ) -> Schedule {
        let mut schedule = Schedule {
            count: case.spec().output.frames,
            next: 0,
            duration,
            ramp,
            tolerance: 1e-9 * duration,
        };
        if let Some(now) = resumed_at {
            while schedule.due(now) {
                schedule.next += 1;
            }
        }
        schedule
    }

    /// Whether the next frame is due at time `now`, ms.
    fn due(&self, now: Real) -> bool {
        if self.next >= self.count {
            return false;
        }
        let share = self.next as Real / (self.count - 1) as Real;
        self.ramp.time_at(self.duration * share) - now <= self.tolerance
    }

    /// Sends every frame due at the simulation's time, all of them this state (built only when
    /// the observer wants frames).
    pub(super) fn send_due<E: Engine>(
        &mut self,
        case: &Case,
        sim: &E,
        observer: &mut dyn Observer,
    ) {
        while self.due(sim.time()) {
            if observer.wants_frames() {
                let travel_mm =
                    case.spec().loading.plate_speed_m_s * self.ramp.full_speed_time(sim.time());
                observer.on_frame(&frame(case, sim, self.next, self.count, travel_mm));
            }
            self.next += 1;
        }
    }
}

/// The particles' state now, in the case's order and the scene's frame.
fn frame<E: Engine>(case: &Case, sim: &E, index: u32, count: u32, travel_mm: Real) -> Frame {
    let p = &sim.scene().particles;
    let geometry = case.geometry();
    Frame {
        index,
        count,
        time_ms: sim.time(),
        travel_mm,
        position_mm: p.in_original_order(|i| geometry.reported(&p.x[i])),
        velocity_m_s: p.in_original_order(|i| geometry.reported_vector(&p.v[i])),
        stress_mpa: p.in_original_order(|i| geometry.reported_stress(&p.stress[i])),
        volume_mm3: p.in_original_order(|i| p.vol[i]),
        plastic_strain: p.in_original_order(|i| p.plastic_strain[i]),
    }
}

#[cfg(test)]
mod tests;
