//! The two node passes of a step, over the owned nodes (units: mm, ms, g, N, mJ): the grid
//! update turns momentum and force into velocity and velocity change and applies the plates
//! (booked); the remap turns the remapped momentum into the velocity the particles move with
//! and applies the plates again (booked too: see [`Simulation::remap_nodes`]).

use super::Simulation;
use crate::solver::engine::grid::{Node, OWNED};
use crate::solver::engine::shape::Stencil;
use crate::solver::model::contact::{self, ContactSums};
use crate::solver::Real;
use nalgebra::Vector3;
use rayon::prelude::*;

impl<S: Stencil> Simulation<S> {
    /// Owned nodes, after the `Full` scatter: momentum → velocity, add force·dt, apply the
    /// plates. Returns the contact sums.
    pub(super) fn update_nodes(&mut self, dt: Real) -> ContactSums {
        self.plate_pass(Some(dt))
    }

    /// Owned nodes, after the `Remap` scatter: remapped momentum → velocity, with the plates
    /// applied again, so that the velocities that move the particles and strain them do not run
    /// into a plate. The plates' change of each node's velocity is left in its `hi` lanes for
    /// the particles (`gather_change`), and booked as an impulse of the plate: the particles
    /// then move, strain and carry momentum alike at a plate. (Projected for the strain only,
    /// the particles' own velocities would keep approaching the plate: strained as if stopped,
    /// they would be caught again in the next step's grid update, and the energy books would
    /// lose that difference, measured at −1.6 % of the plates' work on a thin tube's section
    /// on μ 0.3 and −2.7 % in 3D: docs/folding.md §5.) Returns the contact sums of the catch.
    pub(super) fn remap_nodes(&mut self) -> ContactSums {
        self.plate_pass(None)
    }

    /// Momentum → velocity on every owned node, plus force·`dt` when given (the grid update;
    /// the remap has no force), with the plates applied and booked. The grid update leaves the
    /// velocity change and the plate's tangential impulse ([`Node::set_stepped`]), whose
    /// friction the remap finishes booking against the remapped velocity
    /// ([`contact::apply_slip_deferred`]); the remap leaves the velocity and its change.
    fn plate_pass(&mut self, dt: Option<Real>) -> ContactSums {
        let (plates, mu) = (&self.state.scene.plates, self.state.scene.friction);
        let floor = self.state.mass_floor;
        let sums = &mut self.workspace.block_sums;
        each_node(&mut self.grid.owned, sums, |n, sums| {
            let m = n.mass();
            if m <= floor {
                n.set_updated(&Vector3::zeros(), &Vector3::zeros());
                return;
            }
            let old = n.momentum() / m;
            let plate = contact::plate_of(plates, n.touch());
            match dt {
                Some(dt) => {
                    let mut v = old + n.force() * (dt / m);
                    let slip = match plate {
                        Some(k) => {
                            contact::apply_slip_deferred(k, &plates[k], mu, m, &old, &mut v, sums)
                        }
                        None => [0.0; 2],
                    };
                    n.set_stepped(&(v - old), slip);
                }
                None => {
                    let slip = n.slip_impulse();
                    if slip != [0.0; 2] {
                        contact::book_slip_end(slip, &old, sums);
                    }
                    let mut v = old;
                    if let Some(k) = plate {
                        contact::apply(k, &plates[k], mu, m, &old, &mut v, sums);
                    }
                    n.set_updated(&v, &(v - old));
                }
            }
        })
    }
}

/// `visit` on every owned node, block by block in parallel, each block with its own contact
/// sums (`sums`, one per block); returns their total, added in block order (the same bits on
/// any thread count).
fn each_node(
    owned: &mut [Node],
    sums: &mut Vec<ContactSums>,
    visit: impl Fn(&mut Node, &mut ContactSums) + Sync,
) -> ContactSums {
    sums.resize(owned.len().div_ceil(OWNED), ContactSums::default());
    owned
        .par_chunks_mut(OWNED)
        .zip(sums.par_iter_mut())
        .for_each(|(own, sums)| {
            *sums = ContactSums::default();
            for n in own.iter_mut() {
                visit(n, sums);
            }
        });
    let mut total = ContactSums::default();
    for s in sums.iter() {
        total.add(s);
    }
    total
}
