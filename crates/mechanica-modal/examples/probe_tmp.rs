use mechanica_modal::faer::Mat;
use mechanica_modal::{PencilProblem, SolveOptions, families, solve};
fn show(label: &str, a: &Mat<f64>, b: &Mat<f64>) {
    let p = PencilProblem::new(a.as_ref(), b.as_ref()).unwrap();
    for vectors in [true, false] {
        let sol = solve(&p, &SolveOptions { vectors, ..SolveOptions::default() }).unwrap();
        for (i, m) in sol.modes.iter().take(7).enumerate() {
            println!("{label} v {vectors} mode {i}: {:.3e} bound {:.2e} kind {:?} bk {:?} steps {}", m.omega_sq, m.error_bound, m.kind, sol.accuracy.bound_kinds[i], sol.accuracy.refinement_steps[i]);
        }
    }
}
fn main() {
    let (a1, b1) = families::free_chain(30);
    let n1 = a1.nrows(); let n = 2 * n1;
    let blk = |m: &Mat<f64>| Mat::from_fn(n, n, |i, j| if i % 2 != j % 2 { 0.0 } else { m[(i / 2, j / 2)] });
    let (a, b) = families::rotate(&blk(&a1), &blk(&b1), &families::random_orthogonal(n, 3));
    show("free2", &a, &b);
    let (a1, b1) = families::ring(12);
    let (a, b) = families::rotate(&a1, &b1, &families::random_orthogonal(12, 3));
    show("ring", &a, &b);
    // six copies of a free chain: a cluster of six zero modes
    let m = 6; let n = m * n1;
    let (a1, b1) = families::free_chain(30);
    let blk6 = |x: &Mat<f64>| Mat::from_fn(n, n, |i, j| if i % m != j % m { 0.0 } else { x[(i / m, j / m)] });
    let (a, b) = families::rotate(&blk6(&a1), &blk6(&b1), &families::random_orthogonal(n, 5));
    show("free6", &a, &b);
}
