//! Matrix Market: parsing never panics and never allocates by a declared size; a parsed file
//! is consistent (indices inside the declared shape, finite values, the declared number of
//! entries, symmetric files mirrored), errors point at a line of the text, and a symmetric
//! matrix written back by `symmetric_to_string` parses to the same entries, bit for bit.
//! A second `%%MatrixMarket` header in the input starts a second file, B: the pair then goes
//! through `SparsePencil::from_triplets` as `mechanica modes --sparse` does with two files.
#![no_main]

use libfuzzer_sys::fuzz_target;
use mechanica::modal::sparse::matrix_market::{MatrixMarket, parse_matrix_market, symmetric_to_string};
use mechanica::modal::{ModalError, SparsePencil};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let (first, second) = match text.get(1..).and_then(|rest| rest.find("%%MatrixMarket")) {
        Some(at) => (&text[..at + 1], Some(&text[at + 1..])),
        None => (text, None),
    };
    let a = check_file(first);
    let b = second.and_then(check_file);
    if let (Some(a), Some(b)) = (a, b)
        && a.nrows == a.ncols
    {
        let _ = SparsePencil::from_triplets(a.nrows, &a.entries, &b.entries);
    }
});

/// Parses one file and checks what the parser promises about it.
fn check_file(text: &str) -> Option<MatrixMarket> {
    match parse_matrix_market(text) {
        Ok(m) => {
            check_consistent(&m);
            if m.symmetric {
                check_round_trip(&m);
            }
            Some(m)
        }
        Err(ModalError::MatrixMarket { line, .. }) => {
            let lines = text.lines().count().max(1);
            assert!(
                (1..=lines + 1).contains(&line),
                "error on line {line} of a {lines}-line text"
            );
            None
        }
        Err(other) => panic!("a parse failure that is not a located Matrix Market error: {other}"),
    }
}

fn check_consistent(m: &MatrixMarket) {
    for e in &m.entries {
        assert!(
            e.row < m.nrows && e.col < m.ncols,
            "entry ({}, {}) outside {}×{}",
            e.row,
            e.col,
            m.nrows,
            m.ncols
        );
        assert!(e.val.is_finite(), "non-finite value {}", e.val);
    }
    if m.symmetric {
        assert_eq!(m.nrows, m.ncols, "a symmetric matrix that is not square");
        let lower = m.entries.iter().filter(|e| e.row > e.col).count();
        let upper = m.entries.iter().filter(|e| e.row < e.col).count();
        assert_eq!(lower, upper, "a symmetric file mirrored unevenly");
    }
}

fn check_round_trip(m: &MatrixMarket) {
    let written = symmetric_to_string(m.nrows, &m.entries);
    let again =
        parse_matrix_market(&written).unwrap_or_else(|e| panic!("the written file does not parse: {e}\n{written}"));
    assert_eq!((again.nrows, again.ncols, again.symmetric), (m.nrows, m.ncols, true));
    let key = |t: &mechanica::modal::faer::sparse::Triplet<usize, usize, f64>| (t.row, t.col, t.val.to_bits());
    let mut before: Vec<_> = m.entries.iter().map(key).collect();
    let mut after: Vec<_> = again.entries.iter().map(key).collect();
    before.sort_unstable();
    after.sort_unstable();
    assert_eq!(before, after, "symmetric_to_string did not round-trip");
}
