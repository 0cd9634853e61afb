//! Prints the backward error of the articulated-body algorithm on random trees by grading.
#[path = "../tests/common/mod.rs"]
mod common;
use common::{Rng, random_mechanism, random_state};
use mechanica_dynamics::{Dynamics, State};
use nalgebra::Vector3;

fn main() {
    for grading in [0.0, 3.0, 6.0, 9.0, 12.0] {
        let mut worst: f64 = 0.0;
        let mut worst_rel: f64 = 0.0;
        for seed in 0..200u64 {
            let mut rng = Rng::new(seed);
            let bodies = 1 + rng.below(11);
            let mut m = random_mechanism(&mut rng, bodies, grading, seed % 2 == 0);
            m.set_gravity(Vector3::new(0.3, -9.81, 1.2)).expect("g");
            let mut d = Dynamics::new(m).expect("d");
            let (q, qd, qdd) = random_state(&mut rng, d.mechanism());
            let s = State::new(&q, &qd);
            let tau = d.inverse_dynamics(&s, &qdd).expect("rnea").tau;
            let f = d.forward_dynamics(&s, &tau).expect("aba");
            let c = d.forward_dynamics_crba(&s, &tau).expect("crba");
            worst = worst.max(f.backward_error);
            worst_rel = worst_rel.max(c.backward_error);
        }
        println!("grading {grading}: worst ABA η {worst:e}, worst CRBA η {worst_rel:e}");
    }
}
