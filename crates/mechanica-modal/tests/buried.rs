//! A pencil whose softest modes lie below the rounding of its stiffest (|ω²| < u·n·max ω²),
//! too few to be told from the rigid-body modes of a free structure by their count: a 7-link
//! chain of point masses graded over six decades with springs over ten
//! (`tests/data/buried`, exact ω² by `tools/buried_modes_reference.py`, mpmath at 60 digits).
//! B is positive definite, so the solve reverses the pencil and resolves them.

use faer::Mat;
use mechanica_modal::{ModeKind, PencilProblem, Refinement, SolveOptions, read_matrix_market, solve};
use std::path::Path;

fn dense(name: &str) -> Mat<f64> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/buried")
        .join(name);
    let m = read_matrix_market(&path).expect("matrix");
    let mut dense = Mat::zeros(m.nrows, m.ncols);
    for t in &m.entries {
        dense[(t.row, t.col)] = t.val;
    }
    dense
}

#[test]
fn buried_soft_modes_are_resolved_in_every_mode_of_use() {
    let (a, b) = (dense("a.mtx"), dense("b.mtx"));
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/buried/omega_sq.txt"))
        .expect("reference");
    let exact: Vec<f64> = text.lines().map(|l| l.trim().parse().expect("number")).collect();
    let problem = PencilProblem::new(a.as_ref(), b.as_ref()).expect("pencil");
    for (refinement, vectors) in [
        (Refinement::Auto, true),
        (Refinement::Auto, false),
        (Refinement::Always, true),
    ] {
        let options = SolveOptions {
            refinement,
            vectors,
            ..SolveOptions::default()
        };
        let solution = solve(&problem, &options).expect("solve");
        for (mode, &w2) in solution.modes.iter().zip(&exact) {
            assert!(
                matches!(mode.kind, ModeKind::Oscillatory { .. }),
                "{refinement:?}: {:?}",
                mode.kind
            );
            assert!(
                (mode.omega_sq - w2).abs() <= mode.error_bound,
                "{refinement:?}, vectors {vectors}: ω² = {} against {w2}, bound {:.1e}",
                mode.omega_sq,
                mode.error_bound
            );
        }
        for (mode, &w2) in solution.modes.iter().zip(&exact).take(2) {
            assert!(
                (mode.omega_sq - w2).abs() <= 1e-8 * w2,
                "{refinement:?}: ω² = {} against {w2}",
                mode.omega_sq
            );
        }
    }
}
