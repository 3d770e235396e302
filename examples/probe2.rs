use crush::solver::scene::Scene;
use crush::solver::step::Simulation;
use crush::solver::*;
fn main() {
    let text = std::fs::read_to_string(std::env::args().nth(1).unwrap()).unwrap();
    let case = Case::from_json(&text, &Limits::default()).unwrap();
    let mut scene = Scene::from_case(&case);

    if let Ok(c) = std::env::var("CFL") {
        scene.cfl = c.parse().unwrap();
    }
    let steps: usize = std::env::var("STEPS")
        .map(|v| v.parse().unwrap())
        .unwrap_or(40);
    let mut sim = Simulation::new(scene);
    for s in 0..steps {
        match sim.step(1.0) {
            Ok(info) => {
                let e = sim.energy;
                if s % (steps / 40).max(1) == 0 {
                    println!(
                        "step {s} dt {:.3e} KE {:.4e} IE {:.4e} W {:.4e} load {:.1} blocks {}",
                        info.dt,
                        info.kinetic,
                        e.internal,
                        e.external,
                        info.contact.impulse[0] / info.dt,
                        sim.grid.len()
                    );
                }
            }
            Err(e) => {
                println!("{e}");
                break;
            }
        }
    }
}
