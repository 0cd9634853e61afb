//! Störmer–Verlet on a double pendulum for 1e6 steps (h = 0.01 s, 1e4 s): prints the energy
//! drift relative to the largest kinetic energy, max and last, over each tenth of the run, to
//! show that it stays bounded. Run: `cargo run -p mechanica-motion --example verlet_drift`.

use mechanica_dynamics::Dynamics;
use mechanica_kinematics::tree::{Joint, TreeBuilder};
use mechanica_mass::MassProperties;
use mechanica_mechanism::Mechanism;
use mechanica_motion::{Method, Options, Simulation};
use nalgebra::{Isometry3, Matrix3, Translation3, Vector3};

fn double_pendulum() -> Result<Dynamics, Box<dyn std::error::Error>> {
    let mut builder = TreeBuilder::new();
    builder.add_body(None, Joint::Revolute { axis: Vector3::x() }, Isometry3::identity());
    let below = Isometry3::from_parts(Translation3::new(0.0, 0.0, -1.0), Default::default());
    builder.add_body(Some(0), Joint::Revolute { axis: Vector3::x() }, below);
    let tree = builder.build()?;
    let bob = MassProperties::new(1.0, Vector3::new(0.0, 0.0, -1.0), Matrix3::identity() * 0.01)?;
    let mut mechanism = Mechanism::new(tree, vec![bob, bob])?;
    mechanism.set_gravity(Vector3::new(0.0, 0.0, -9.81))?;
    Ok(Dynamics::new(mechanism)?)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let steps = 1_000_000.0;
    let h = 0.01;
    let options = Options {
        estimate_error: false,
        ..Options::default()
    };
    let simulation = Simulation::new(double_pendulum()?, Method::StormerVerlet { step: h }, options)?;
    let run = simulation.run(&[1.0, -0.5], &[0.0, 0.0], steps * h, 1.0)?;
    let (e0, scale) = (run.monitors.initial, run.monitors.scale);
    println!("steps {}, energy scale {scale:.6} J", run.steps);
    let tenth = run.samples.len() / 10;
    for (i, chunk) in run.samples.chunks(tenth).enumerate() {
        let drift = chunk.iter().fold(0.0f64, |m, s| m.max((s.energy - e0).abs())) / scale;
        println!("tenth {i}: max relative drift {drift:.3e}");
    }
    println!(
        "max drift {:.3e}, last drift {:.3e}",
        run.monitors.max_drift, run.monitors.last_drift
    );
    Ok(())
}
