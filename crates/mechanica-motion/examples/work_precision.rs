//! mechanica's side of the work-precision report of `tools/motion_work_precision.py`: planar
//! chains of links on revolute joints about y (a double pendulum, a 7-link arm with joint
//! springs and dampers, a stiff chain), each method at each step or tolerance, timed without
//! the companion run (the fastest of repeated runs) and run once more with it for the global
//! error estimate (M.13). The final state and the estimate are written as CSV; the script
//! computes the true errors against its own references.
//!
//! Usage: `cargo run --release -p mechanica-motion --example work_precision -- SPEC OUT.csv`.
//! SPEC is a text file of problems, one keyword line each:
//! `problem NAME T_END G`, then `mass`, `length`, `inertia` (central, about every axis),
//! `stiffness`, `damping` (per joint, on the relative angles), `q0`, `v0` with n numbers, and
//! `method KIND P1 P2 …` lines (KIND rk4, verlet, midpoint: steps; dopri: rtol, with
//! atol = rtol · 1e-2).
//! Link i hangs its point of mass m_i with inertia J_i at l_i below its joint along −z; joint
//! i + 1 sits at that point. Gravity G along −z.

use mechanica_dynamics::{Damper, Dynamics};
use mechanica_kinematics::tree::{Joint, TreeBuilder};
use mechanica_mass::MassProperties;
use mechanica_mechanism::Mechanism;
use mechanica_mechanism::potentials::JointSpring;
use mechanica_motion::{Method, Options, Simulation};
use nalgebra::{Isometry3, Matrix3, Translation3, Vector3};
use std::collections::HashMap;
use std::error::Error;
use std::fmt::Write as _;
use std::time::Instant;

type Res<T> = Result<T, Box<dyn Error>>;

#[derive(Default)]
struct Problem {
    name: String,
    t_end: f64,
    gravity: f64,
    vectors: HashMap<String, Vec<f64>>,
    methods: Vec<(String, f64)>,
}

fn parse(text: &str) -> Res<Vec<Problem>> {
    let mut problems: Vec<Problem> = Vec::new();
    for line in text.lines().filter(|l| !l.trim().is_empty()) {
        let words: Vec<&str> = line.split_whitespace().collect();
        let numbers =
            |from: usize| -> Res<Vec<f64>> { Ok(words[from..].iter().map(|w| w.parse()).collect::<Result<_, _>>()?) };
        if words[0] == "problem" {
            problems.push(Problem {
                name: words[1].to_string(),
                t_end: words[2].parse()?,
                gravity: words[3].parse()?,
                ..Problem::default()
            });
            continue;
        }
        let problem = problems.last_mut().ok_or("a line before the first problem")?;
        if words[0] == "method" {
            for p in numbers(2)? {
                problem.methods.push((words[1].to_string(), p));
            }
        } else {
            problem.vectors.insert(words[0].to_string(), numbers(1)?);
        }
    }
    Ok(problems)
}

fn chain(p: &Problem) -> Res<Dynamics> {
    let get = |k: &str| p.vectors.get(k).ok_or(format!("{}: no {k}", p.name));
    let (mass, length, inertia) = (get("mass")?, get("length")?, get("inertia")?);
    let mut builder = TreeBuilder::new();
    let mut bodies = Vec::new();
    for i in 0..mass.len() {
        let (parent, placement) = match i {
            0 => (None, Isometry3::identity()),
            _ => (
                Some(i - 1),
                Isometry3::from_parts(Translation3::new(0.0, 0.0, -length[i - 1]), Default::default()),
            ),
        };
        builder.add_body(parent, Joint::Revolute { axis: Vector3::y() }, placement);
        let centre = Vector3::new(0.0, 0.0, -length[i]);
        bodies.push(MassProperties::new(mass[i], centre, Matrix3::identity() * inertia[i])?);
    }
    let mut mechanism = Mechanism::new(builder.build()?, bodies)?;
    mechanism.set_gravity(Vector3::new(0.0, 0.0, -p.gravity))?;
    for (coordinate, &stiffness) in get("stiffness")?.iter().enumerate() {
        if stiffness > 0.0 {
            mechanism.add_potential(JointSpring {
                coordinate,
                stiffness,
                rest: 0.0,
            })?;
        }
    }
    let mut dynamics = Dynamics::new(mechanism)?;
    for (coordinate, &coefficient) in get("damping")?.iter().enumerate() {
        if coefficient > 0.0 {
            dynamics.add_damper(Damper::Joint {
                coordinate,
                coefficient,
            })?;
        }
    }
    Ok(dynamics)
}

fn method(kind: &str, parameter: f64) -> Res<Method> {
    Ok(match kind {
        "rk4" => Method::Rk4 { step: parameter },
        "verlet" => Method::StormerVerlet { step: parameter },
        "midpoint" => Method::ImplicitMidpoint { step: parameter },
        "dopri" => Method::DormandPrince {
            rtol: parameter,
            atol: parameter * 1e-2,
        },
        other => return Err(format!("unknown method {other}").into()),
    })
}

fn joined(values: &[f64]) -> String {
    values.iter().map(|v| format!("{v:e}")).collect::<Vec<_>>().join(" ")
}

/// One CSV row: the fastest of repeated timed runs without the estimate, then one run with it.
fn measure(p: &Problem, dynamics: &Dynamics, kind: &str, parameter: f64) -> Res<String> {
    let m = method(kind, parameter)?;
    let (q0, v0) = (&p.vectors["q0"], &p.vectors["v0"]);
    let quiet = Options {
        estimate_error: false,
        ..Options::default()
    };
    let timed = Simulation::new(dynamics.clone(), m, quiet)?;
    let (mut best, mut total, mut repeats) = (f64::INFINITY, 0.0, 0);
    while repeats < 3 || (total < 0.5 && repeats < 20) {
        let start = Instant::now();
        let run = timed.run(q0, v0, p.t_end, p.t_end);
        let seconds = start.elapsed().as_secs_f64();
        if let Err(error) = run {
            eprintln!("{} {kind} {parameter:e}: {error}", p.name);
            return Ok(format!(
                "{},mechanica,{kind},{parameter:e},{seconds:e},0,,,,,failed\n",
                p.name
            ));
        }
        best = best.min(seconds);
        total += seconds;
        repeats += 1;
    }
    let run = Simulation::new(dynamics.clone(), m, Options::default())?.run(q0, v0, p.t_end, p.t_end)?;
    let last = run.samples.last().ok_or("no sample")?;
    let estimate = last.error.ok_or("no estimate")?;
    Ok(format!(
        "{},mechanica,{kind},{parameter:e},{best:e},{},{},{},{:e},{:e},{:e}\n",
        p.name,
        run.steps,
        joined(&last.q),
        joined(&last.q_dot),
        estimate.q,
        estimate.q_dot,
        run.monitors.max_drift,
    ))
}

fn main() -> Res<()> {
    let args: Vec<String> = std::env::args().collect();
    let [_, spec, out] = args.as_slice() else {
        return Err("usage: work_precision SPEC OUT.csv".into());
    };
    let problems = parse(&std::fs::read_to_string(spec)?)?;
    let mut csv =
        String::from("problem,solver,method,parameter,time_s,steps,q,q_dot,estimate_q,estimate_q_dot,energy_drift\n");
    for p in &problems {
        let dynamics = chain(p)?;
        for (kind, parameter) in &p.methods {
            let row = measure(p, &dynamics, kind, *parameter)?;
            eprint!("{row}");
            write!(csv, "{row}")?;
        }
    }
    std::fs::write(out, csv)?;
    Ok(())
}
