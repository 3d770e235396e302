//! The kernel every model shares: the [`Engine`] trait and the [`Phases`] of a step, the
//! [`State`] a model carries from step to step, the clock of the phases, the energy books, and
//! why a run stops ([`SolveError`]). The per-particle stress loop is its sibling, `stress.rs`.
//! Units: mm, ms, g, N, MPa, mJ.
//!
//! Imports the scene and the grid's transfer kinds of the engine, and the model; never a model
//! (`solid`, `reduced`) or the run loop.

use super::grid;
use super::scene::Scene;
use crate::solver::model::contact::ContactSums;
use crate::solver::Real;

/// Why a run ended without a result.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SolveError {
    #[error("cancelled at step {step}")]
    Cancelled { step: u64 },
    /// The numbers went bad: which quantity, where and when.
    #[error("unstable at step {step} (t = {time_ms:.6} ms): {what}")]
    Unstable {
        step: u64,
        time_ms: f64,
        what: String,
    },
}

/// Energy integrals since the start, mJ. What the plates put in (`work`) goes to kinetic energy,
/// `internal` energy, the projection's `catch` and `friction`; what is left is numerical.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Energies {
    /// ∫ σ:D dV dt: elastic energy plus plastic work.
    pub internal: Real,
    pub plastic: Real,
    /// Work of each plate (top, bottom) on the tube.
    pub work: [Real; 2],
    /// Dissipated by the normal part of the contact projection (nodes caught by a plate).
    pub catch: Real,
    /// Dissipated by friction at the plates.
    pub friction: Real,
}

impl Energies {
    /// Work of both plates on the tube, mJ.
    pub fn external(&self) -> Real {
        self.work[0] + self.work[1]
    }
}

/// What the last step did.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StepInfo {
    /// The step taken, ms.
    pub dt: Real,
    /// The step the CFL condition allowed (larger than `dt` when a history row was due), ms.
    pub stable_dt: Real,
    pub contact: ContactSums,
    /// Kinetic energy after the step, mJ.
    pub kinetic: Real,
}

/// Wall time spent in each phase since the start, s.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PhaseTimes {
    /// Binning particles into blocks and building the sparse grid.
    pub bin: f64,
    /// Particle → grid transfers (both).
    pub p2g: f64,
    /// Reductions and grid updates with contact.
    pub grid: f64,
    /// Grid → particle transfers (velocity; gradient and position).
    pub g2p: f64,
    /// Cell averages and the stress update.
    pub stress: f64,
}

/// Times the phases of a step.
pub struct Clock(std::time::Instant);

impl Clock {
    pub fn start() -> Clock {
        Clock(std::time::Instant::now())
    }
    /// Adds the time since the last lap (or the start) to `into`.
    pub fn lap(&mut self, into: &mut f64) {
        let now = std::time::Instant::now();
        *into += (now - self.0).as_secs_f64();
        self.0 = now;
    }
}

/// What a model carries from step to step besides its grid: the scene, the clock, the energy
/// books, and the two figures the next step needs (its signal speed and the grid's mass floor).
#[derive(Debug)]
pub struct State {
    pub scene: Scene,
    /// Simulated time, ms.
    pub time: Real,
    pub steps: u64,
    pub energy: Energies,
    pub phases: PhaseTimes,
    /// Largest c + |v| over the particles after the last step, mm/ms.
    pub(crate) signal: Real,
    /// Nodes lighter than this carry no velocity (guards divisions by tiny masses), g.
    pub(crate) mass_floor: Real,
}

impl State {
    /// At time 0, before the first step.
    pub fn new(scene: Scene) -> State {
        let n = scene.particles.len();
        let mean_mass = scene.particles.mass.iter().sum::<Real>() / n.max(1) as Real;
        let vmax = scene
            .particles
            .v
            .iter()
            .map(|v| v.norm())
            .fold(0.0, Real::max);
        State {
            signal: scene.wave_speed() + vmax,
            mass_floor: 1e-14 * mean_mass,
            scene,
            time: 0.0,
            steps: 0,
            energy: Energies::default(),
            phases: PhaseTimes::default(),
        }
    }

    /// The time step the CFL condition allows now, ms.
    pub fn stable_dt(&self) -> Real {
        self.scene.cfl * self.scene.cell / self.signal
    }
}

/// The phases of one explicit MUSL step of a model, each its own method, which
/// [`Engine::advance`] runs in this order (units: mm, ms, g, N, MPa, mJ):
///
/// 1. [`Phases::bin`]: the grid fitted to the particles;
/// 2. [`Phases::scatter`] [`grid::Full`]: mass, momentum, internal force and plate touch;
/// 3. [`Phases::grid_update`] with the plates: velocity and velocity change per node;
/// 4. [`Phases::g2p_velocity`]: FLIP, each particle adds its stencil's velocity change;
/// 5. [`Phases::scatter`] [`grid::Remap`]: the new particle momenta onto the same masses;
/// 6. [`Phases::remap`] with the plates: the velocity the particles move and strain with
///    (booked), and [`Phases::g2p_catch`]: what the plates caught of it added to the
///    particles' own velocities;
/// 7. [`Phases::g2p_kinematics`]: velocity gradient and position;
/// 8. [`Phases::update_stress`]: the engine's shared stress loop with the model's geometry.
///
/// `lp` is the particle half-size in grid units. A phase that interleaves two kinds of work
/// (the 3D scatter's transfers and reductions) laps `clock` itself.
pub trait Phases {
    fn bin(&mut self, lp: Real);
    fn scatter<T: grid::Transfer>(&mut self, lp: Real, clock: &mut Clock);
    fn grid_update(&mut self, dt: Real) -> ContactSums;
    fn g2p_velocity(&mut self, lp: Real);
    fn remap(&mut self) -> ContactSums;
    /// After a remap that caught nodes: their change added to the velocities of the particles
    /// that reach them.
    fn g2p_catch(&mut self, lp: Real);
    fn g2p_kinematics(&mut self, lp: Real, dt: Real);
    /// Returns the kinetic energy after the step, mJ.
    fn update_stress(&mut self, dt: Real) -> Result<Real, SolveError>;
}

/// A model's time stepping: the 3D [`Simulation`](super::solid::Simulation) or a reduced
/// model's [`Reduced`](super::reduced::Reduced). Each has the [`Phases`] of a step, which
/// every model runs in the same order ([`Engine::advance`]); what comes before and after them
/// (the step's size, the plates, the clock, the contact's books) is [`Engine::step`], the same
/// for all.
pub trait Engine: Phases {
    fn state(&self) -> &State;
    fn state_mut(&mut self) -> &mut State;
    /// Grid cells the last step spanned.
    fn active_cells(&self) -> u64;
    /// Bytes held by the particles, the grid and the working memory.
    fn bytes(&self) -> usize;

    /// The phases of one step of `dt` (ms), with the plates' velocities over it set: particles
    /// and grid advance, the state's signal speed, internal energy and phase times are
    /// updated. Returns the contact sums and the kinetic energy after the step. Called by
    /// [`Engine::step`].
    fn advance(&mut self, dt: Real) -> Result<(ContactSums, Real), SolveError> {
        let lp = self.state().scene.half_size / self.state().scene.cell;
        let mut clock = Clock::start();
        let lap = |m: &mut Self, clock: &mut Clock, phase: fn(&mut PhaseTimes) -> &mut f64| {
            clock.lap(phase(&mut m.state_mut().phases))
        };
        self.bin(lp);
        lap(self, &mut clock, |p| &mut p.bin);
        self.scatter::<grid::Full>(lp, &mut clock);
        lap(self, &mut clock, |p| &mut p.p2g);
        let mut contact = self.grid_update(dt);
        lap(self, &mut clock, |p| &mut p.grid);
        self.g2p_velocity(lp);
        lap(self, &mut clock, |p| &mut p.g2p);
        self.scatter::<grid::Remap>(lp, &mut clock);
        lap(self, &mut clock, |p| &mut p.p2g);
        let caught = self.remap();
        lap(self, &mut clock, |p| &mut p.grid);
        if caught.caught_any() {
            self.g2p_catch(lp);
            lap(self, &mut clock, |p| &mut p.g2p);
        }
        contact.add(&caught);
        self.g2p_kinematics(lp, dt);
        lap(self, &mut clock, |p| &mut p.g2p);
        let kinetic = self.update_stress(dt)?;
        lap(self, &mut clock, |p| &mut p.stress);
        Ok((contact, kinetic))
    }

    /// Advances one step of at most `dt_cap` ms.
    fn step(&mut self, dt_cap: Real) -> Result<StepInfo, SolveError> {
        let state = self.state_mut();
        let stable_dt = state.stable_dt();
        let dt = stable_dt.min(dt_cap);
        state.scene.set_plate_velocities(state.time, dt);
        let (contact, kinetic) = self.advance(dt)?;
        let state = self.state_mut();
        let energy = &mut state.energy;
        energy.work[0] += contact.work[0];
        energy.work[1] += contact.work[1];
        energy.catch += contact.catch;
        energy.friction += contact.friction;
        state.scene.move_plates(dt);
        state.time += dt;
        state.steps += 1;
        Ok(StepInfo {
            dt,
            stable_dt,
            contact,
            kinetic,
        })
    }
    fn scene(&self) -> &Scene {
        &self.state().scene
    }
    /// Simulated time, ms.
    fn time(&self) -> Real {
        self.state().time
    }
    fn steps(&self) -> u64 {
        self.state().steps
    }
    fn energy(&self) -> &Energies {
        &self.state().energy
    }
    fn phases(&self) -> &PhaseTimes {
        &self.state().phases
    }
}
