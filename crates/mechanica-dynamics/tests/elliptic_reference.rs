//! The special functions of `free_body` against mpmath (tools/elliptic_reference.py, 50
//! digits): the largest error of each function over its reference points, in units in the last
//! place of the reference value.

use mechanica_dynamics::free_body::{
    EllipticModulus, carlson_rc, carlson_rd, carlson_rf, carlson_rj, elliptic_f, elliptic_k, elliptic_pi,
    elliptic_pi_complete,
};
use serde_json::Value;

fn reference() -> Value {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tools/elliptic_reference.json");
    let text = std::fs::read_to_string(path).expect("tools/elliptic_reference.json is committed");
    serde_json::from_str(&text).expect("the reference file is JSON")
}

fn rows(reference: &Value, key: &str) -> Vec<Vec<f64>> {
    let rows = reference[key].as_array().expect("a list of rows");
    rows.iter()
        .map(|row| row.as_array().expect("a row").iter().map(number).collect())
        .collect()
}

/// A number written as a string (std's parser rounds correctly).
fn number(value: &Value) -> f64 {
    value
        .as_str()
        .expect("a number as text")
        .parse()
        .expect("a decimal number")
}

/// |computed − exact| in units of the spacing of f64 at |exact|.
fn ulps(computed: f64, exact: f64) -> f64 {
    if exact == 0.0 {
        return if computed.abs() < 1e-300 { 0.0 } else { f64::INFINITY };
    }
    let exponent = exact.abs().log2().floor();
    let spacing = 2f64.powf(exponent - 52.0).max(f64::MIN_POSITIVE * f64::EPSILON);
    (computed - exact).abs() / spacing
}

/// The worst error over `rows`, printed with the row where it occurs.
fn worst(name: &str, rows: &[Vec<f64>], mut error: impl FnMut(&[f64]) -> f64) -> f64 {
    let mut worst = (0.0, Vec::new());
    for row in rows {
        let e = error(row);
        assert!(!e.is_nan(), "{name}: NaN error at {row:?}");
        if e >= worst.0 {
            worst = (e, row.clone());
        }
    }
    println!(
        "{name}: {} points, max {:.2} ulps at {:?}",
        rows.len(),
        worst.0,
        worst.1
    );
    worst.0
}

#[test]
fn carlson_integrals_are_within_a_few_ulps() {
    let reference = reference();
    let rf = worst("R_F", &rows(&reference, "rf"), |r| {
        ulps(carlson_rf(r[0], r[1], r[2]).expect("inside the domain"), r[3])
    });
    let rd = worst("R_D", &rows(&reference, "rd"), |r| {
        ulps(carlson_rd(r[0], r[1], r[2]).expect("inside the domain"), r[3])
    });
    let rj = worst("R_J", &rows(&reference, "rj"), |r| {
        ulps(carlson_rj(r[0], r[1], r[2], r[3]).expect("inside the domain"), r[4])
    });
    let rc = worst("R_C", &rows(&reference, "rc"), |r| {
        ulps(carlson_rc(r[0], r[1]).expect("inside the domain"), r[2])
    });
    assert!(rf <= 8.0 && rd <= 8.0 && rj <= 8.0 && rc <= 8.0, "{rf} {rd} {rj} {rc}");
}

#[test]
fn legendre_integrals_are_within_a_few_ulps() {
    let reference = reference();
    let k = worst("K", &rows(&reference, "k"), |r| {
        ulps(elliptic_k(r[0]).expect("inside the domain"), r[1])
    });
    let f = worst("F", &rows(&reference, "f"), |r| {
        ulps(elliptic_f(r[0], r[1]).expect("inside the domain"), r[2])
    });
    assert!(k <= 4.0, "K: {k} ulps");
    assert!(f <= 8.0, "F: {f} ulps");
}

/// Π for n ≥ −5 within 16 ulps; for n = −100 the two terms of DLMF 19.25.14 cancel to about a
/// fifteenth of their size, and the contract is 16 ulps of the larger term.
#[test]
fn third_kind_is_within_a_few_ulps_of_its_terms() {
    let reference = reference();
    let (moderate, strongly_negative): (Vec<_>, Vec<_>) =
        rows(&reference, "pi").into_iter().partition(|r| r[0] >= -5.0);
    let pi = worst("Π, n ≥ −5", &moderate, |r| {
        ulps(elliptic_pi(r[0], r[1], r[2]).expect("inside the domain"), r[3])
    });
    let (complete_moderate, complete_negative): (Vec<_>, Vec<_>) =
        rows(&reference, "pi_complete").into_iter().partition(|r| r[0] >= -5.0);
    let pic = worst("Π complete, n ≥ −5", &complete_moderate, |r| {
        ulps(elliptic_pi_complete(r[0], r[1]).expect("inside the domain"), r[2])
    });
    assert!(pi <= 16.0 && pic <= 16.0, "Π: {pi}, complete {pic} ulps");
    let term_ulps = |computed: f64, exact: f64, n: f64, phi: f64, k: f64| {
        let first = elliptic_f(phi, k).expect("inside the domain").abs();
        let second = (exact - elliptic_f(phi, k).expect("inside the domain")).abs();
        let _ = n;
        ulps(computed, exact) * ulp_ratio(exact, first.max(second))
    };
    let negative = worst("Π, n = −100 (ulps of Π)", &strongly_negative, |r| {
        ulps(elliptic_pi(r[0], r[1], r[2]).expect("inside the domain"), r[3])
    });
    let negative_terms = worst("Π, n = −100 (ulps of the larger term)", &strongly_negative, |r| {
        term_ulps(
            elliptic_pi(r[0], r[1], r[2]).expect("inside the domain"),
            r[3],
            r[0],
            r[1],
            r[2],
        )
    });
    let complete_terms = worst(
        "Π complete, n = −100 (ulps of the larger term)",
        &complete_negative,
        |r| {
            term_ulps(
                elliptic_pi_complete(r[0], r[1]).expect("inside the domain"),
                r[2],
                r[0],
                std::f64::consts::FRAC_PI_2,
                r[1],
            )
        },
    );
    assert!(!strongly_negative.is_empty() && negative.is_finite());
    assert!(
        negative_terms <= 16.0 && complete_terms <= 16.0,
        "{negative_terms} {complete_terms}"
    );
}

/// ulp(small) / ulp(large): converts an error in ulps of `small` to ulps of `large`.
fn ulp_ratio(small: f64, large: f64) -> f64 {
    2f64.powf(small.abs().log2().floor() - large.abs().log2().floor())
}

/// sn, cn, dn and am within 2 ulps, including k = 1 − 1e-12, |u| up to 1e4 and k = 0, 1.
#[test]
fn jacobi_functions_are_within_a_few_ulps() {
    let reference = reference();
    let points = rows(&reference, "jacobi");
    let modulus = |r: &[f64]| EllipticModulus::new(r[1]).expect("inside the domain");
    let value = |r: &[f64]| modulus(r).jacobi(r[0]).expect("inside the domain");
    let sn = worst("sn", &points, |r| ulps(value(r).sn, r[2]));
    let cn = worst("cn", &points, |r| ulps(value(r).cn, r[3]));
    let dn = worst("dn", &points, |r| ulps(value(r).dn, r[4]));
    let am = worst("am", &points, |r| {
        ulps(modulus(r).amplitude(r[0]).expect("inside the domain"), r[5])
    });
    assert!(
        sn <= 2.0 && cn <= 2.0 && dn <= 2.0 && am <= 2.0,
        "sn {sn}, cn {cn}, dn {dn}, am {am} ulps"
    );
}
