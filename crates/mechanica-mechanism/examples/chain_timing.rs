//! Times the stages of the modes of an n-link hanging chain (the mechanism of
//! `tools/urdf_chain.py`: rods of 1 kg and 0.1 m, revolute axes alternating y and x, gravity
//! −9.81 z): the potential with its Hessian, the mass matrix, the modal solve (with the modal
//! crate's stage timings and the number of refined modes) and the whole `mechanism_modes`
//! (which adds the shapes in space to the solve).
//! With `off`, the modal solves skip refinement (`Refinement::Off`).
//! `cargo run --release -p mechanica-mechanism --example chain_timing -- 1000 [off]`
use mechanica_kinematics::tree::{Joint, TreeBuilder};
use mechanica_mass::MassProperties;
use mechanica_mechanism::{Mechanism, mechanism_modes};
use mechanica_modal::{PencilProblem, Refinement, SolveOptions, solve};
use nalgebra::{Isometry3, Matrix3, Vector3};
use std::time::Instant;

fn chain(n: usize) -> Result<Mechanism, Box<dyn std::error::Error>> {
    let (length, mass) = (0.1, 1.0);
    let mut builder = TreeBuilder::new();
    for i in 0..n {
        let axis = if i % 2 == 0 { Vector3::y() } else { Vector3::x() };
        let drop = if i == 0 { 0.0 } else { -length };
        builder.add_body(
            i.checked_sub(1),
            Joint::Revolute { axis },
            Isometry3::translation(0.0, 0.0, drop),
        );
    }
    let moment = mass * length * length / 12.0;
    let rod = MassProperties::new(
        mass,
        Vector3::new(0.0, 0.0, -0.5 * length),
        Matrix3::from_diagonal(&Vector3::new(moment, moment, 1e-6 * moment)),
    )?;
    let mut mechanism = Mechanism::new(builder.build()?, vec![rod; n])?;
    mechanism.set_gravity(Vector3::new(0.0, 0.0, -9.81))?;
    Ok(mechanism)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let n: usize = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(1000);
    let refinement = match std::env::args().nth(2).as_deref() {
        Some("off") => Refinement::Off,
        _ => Refinement::Auto,
    };
    let mut mechanism = chain(n)?;
    let q = vec![0.0; n];
    let start = Instant::now();
    let b = mechanism.potential(&q, true)?.hessian.ok_or("no Hessian")?;
    println!("potential with Hessian  {:8.3} s", start.elapsed().as_secs_f64());
    let start = Instant::now();
    let a = mechanism.mass_matrix(&q)?;
    println!("mass matrix             {:8.3} s", start.elapsed().as_secs_f64());
    let start = Instant::now();
    let problem = PencilProblem::new(a.as_ref(), b.as_ref())?;
    let options = SolveOptions {
        vectors: true,
        refinement,
        ..SolveOptions::default()
    };
    let solution = solve(&problem, &options)?;
    let t = solution.timings;
    println!(
        "modal solve             {:8.3} s (factor {:.3}, eigen {:.3}, accuracy {:.3}, refine {:.3}, inertia {:.3}; {} refined)",
        start.elapsed().as_secs_f64(),
        t.factor.as_secs_f64(),
        t.eigen.as_secs_f64(),
        t.accuracy.as_secs_f64(),
        t.refine.as_secs_f64(),
        t.inertia.as_secs_f64(),
        solution.accuracy.refinement_steps.iter().filter(|&&s| s > 0).count(),
    );
    let start = Instant::now();
    let modes = mechanism_modes(&mut mechanism, &q, &options)?;
    println!(
        "mechanism_modes         {:8.3} s (lowest ω² = {:.6e})",
        start.elapsed().as_secs_f64(),
        modes.solution.modes[0].omega_sq
    );
    Ok(())
}
