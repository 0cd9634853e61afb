//! Matrix Market files (the exchange format of SciPy, PETSc and the SuiteSparse collection):
//! `%%MatrixMarket matrix coordinate|array real|integer general|symmetric`.
//!
//! - **coordinate**: a size line `rows cols entries`, then one `row col value` per entry,
//!   1-based indices.
//! - **array** (what `scipy.io.mmwrite` writes for a dense array): a size line `rows cols`, then
//!   the values column by column, one per line; a symmetric array stores the lower triangle
//!   (diagonal included) column by column. Exact zeros are not kept as entries.
//!
//! Symmetric files store one triangle; the reader mirrors it so the result holds both
//! triangles, as [`crate::SparsePencil::from_triplets`] expects. Every malformed line gives
//! [`ModalError::MatrixMarket`] with its 1-based line number.

use crate::ModalError;
use faer::sparse::Triplet;
use std::path::Path;

/// A matrix read from a Matrix Market file: its shape and entries (both triangles).
#[derive(Debug, Clone)]
pub struct MatrixMarket {
    /// Number of rows.
    pub nrows: usize,
    /// Number of columns.
    pub ncols: usize,
    /// Entries (0-based indices); symmetric files are mirrored, duplicates kept (summed later).
    pub entries: Vec<Triplet<usize, usize, f64>>,
    /// Whether the file declared itself symmetric.
    pub symmetric: bool,
}

fn bad(line: usize, detail: impl Into<String>) -> ModalError {
    ModalError::MatrixMarket {
        line,
        detail: detail.into(),
    }
}

/// Reads a Matrix Market file.
pub fn read_matrix_market(path: &Path) -> Result<MatrixMarket, ModalError> {
    let text = std::fs::read_to_string(path).map_err(|e| ModalError::Io {
        path: path.display().to_string(),
        detail: e.to_string(),
    })?;
    parse_matrix_market(&text)
}

/// The storage format named by the header.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Format {
    Coordinate,
    Array,
}

/// The non-comment, non-blank lines of a file after its header, with 1-based line numbers.
fn data_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.lines()
        .enumerate()
        .skip(1)
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('%'))
}

/// Parses the text of a Matrix Market coordinate or array file.
pub fn parse_matrix_market(text: &str) -> Result<MatrixMarket, ModalError> {
    let header = text.lines().next().ok_or_else(|| bad(1, "empty file"))?;
    let (format, symmetric) = parse_header(header)?;
    match format {
        Format::Coordinate => parse_coordinate(text, symmetric),
        Format::Array => parse_array(text, symmetric),
    }
}

/// The body of an `array` file: size line `rows cols`, then the values column-major (the
/// lower triangle only when symmetric).
fn parse_array(text: &str, symmetric: bool) -> Result<MatrixMarket, ModalError> {
    let mut lines = data_lines(text);
    let (size_line, size) = lines
        .next()
        .ok_or_else(|| bad(2, "missing the size line 'rows cols'"))?;
    let tokens: Vec<&str> = size.split_whitespace().collect();
    if tokens.len() != 2 {
        return Err(bad(
            size_line,
            "an array's size line needs exactly 2 integers: rows cols",
        ));
    }
    let nrows = parse_usize(size_line, tokens[0], "rows")?;
    let ncols = parse_usize(size_line, tokens[1], "cols")?;
    if symmetric && nrows != ncols {
        return Err(bad(
            size_line,
            format!("a symmetric matrix must be square, got {nrows}×{ncols}"),
        ));
    }
    // Positions (row, col) in storage order; the count is checked against the text, not
    // allocated from the header.
    let mut positions = (0..ncols).flat_map(|c| ((if symmetric { c } else { 0 })..nrows).map(move |r| (r, c)));
    let mut entries = Vec::new();
    let mut last_line = size_line;
    for (number, line) in lines {
        last_line = number;
        let Some((r, c)) = positions.next() else {
            return Err(bad(number, format!("more values than a {nrows}×{ncols} array holds")));
        };
        let value = parse_value(number, line)?;
        if value != 0.0 {
            entries.push(Triplet::new(r, c, value));
            if symmetric && r != c {
                entries.push(Triplet::new(c, r, value));
            }
        }
    }
    if let Some((r, c)) = positions.next() {
        return Err(bad(
            last_line,
            format!("values end before entry ({}, {}) of the array", r + 1, c + 1),
        ));
    }
    Ok(MatrixMarket {
        nrows,
        ncols,
        entries,
        symmetric,
    })
}

/// One finite value alone on line `number`.
fn parse_value(number: usize, line: &str) -> Result<f64, ModalError> {
    let tokens: Vec<&str> = line.split_whitespace().collect();
    if tokens.len() != 1 {
        return Err(bad(
            number,
            format!("an array line holds one value, got {} tokens", tokens.len()),
        ));
    }
    let value: f64 = tokens[0]
        .parse()
        .map_err(|_| bad(number, format!("value '{}' is not a number", tokens[0])))?;
    if !value.is_finite() {
        return Err(bad(number, format!("value {value} is not finite")));
    }
    Ok(value)
}

/// The body of a `coordinate` file.
fn parse_coordinate(text: &str, symmetric: bool) -> Result<MatrixMarket, ModalError> {
    let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l)).skip(1);
    // Size line: the first line that is neither a comment nor blank.
    let (size_line, size) = lines
        .by_ref()
        .find(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('%'))
        .ok_or_else(|| bad(2, "missing the size line 'rows cols entries'"))?;
    let (nrows, ncols, nnz) = parse_size(size_line, size, symmetric)?;
    // Reserve only what the text can hold: an entry line "r c v" takes at least 6 bytes, so a
    // header declaring more entries than that reserves nothing it cannot fill.
    let entry_bound = nnz.min(text.len() / 6 + 1);
    let mut entries = Vec::with_capacity(if symmetric { 2 * entry_bound } else { entry_bound });
    let mut read = 0usize;
    let mut last_line = size_line;
    for (number, line) in lines {
        last_line = number;
        let trimmed = line.trim();
        if trimmed.is_empty() || trimmed.starts_with('%') {
            continue;
        }
        if read == nnz {
            return Err(bad(number, format!("more entries than the {nnz} declared")));
        }
        let (r, c, value) = parse_entry(number, trimmed, (nrows, ncols), symmetric)?;
        entries.push(Triplet::new(r, c, value));
        if symmetric && r != c {
            entries.push(Triplet::new(c, r, value));
        }
        read += 1;
    }
    if read != nnz {
        return Err(bad(last_line, format!("{read} entries found, {nnz} declared")));
    }
    Ok(MatrixMarket {
        nrows,
        ncols,
        entries,
        symmetric,
    })
}

/// The header `%%MatrixMarket matrix <coordinate|array> <real|integer|double>
/// <general|symmetric>` (case-insensitive): the format, and whether the matrix is stored
/// symmetric.
fn parse_header(header: &str) -> Result<(Format, bool), ModalError> {
    let words: Vec<String> = header.split_whitespace().map(str::to_ascii_lowercase).collect();
    if words.first().map(String::as_str) != Some("%%matrixmarket") {
        return Err(bad(1, "missing the %%MatrixMarket header"));
    }
    if words.len() != 5 {
        return Err(bad(
            1,
            "header needs: %%MatrixMarket matrix <coordinate|array> <field> <symmetry>",
        ));
    }
    let format = match (words[1].as_str(), words[2].as_str()) {
        ("matrix", "coordinate") => Format::Coordinate,
        ("matrix", "array") => Format::Array,
        (object, format) => {
            return Err(bad(
                1,
                format!("unsupported object/format '{object} {format}' (need 'matrix coordinate' or 'matrix array')"),
            ));
        }
    };
    if words[3] != "real" && words[3] != "integer" && words[3] != "double" {
        return Err(bad(
            1,
            format!("unsupported field '{}' (need real or integer)", words[3]),
        ));
    }
    match words[4].as_str() {
        "general" => Ok((format, false)),
        "symmetric" => Ok((format, true)),
        other => Err(bad(
            1,
            format!("unsupported symmetry '{other}' (need general or symmetric)"),
        )),
    }
}

/// A non-negative integer `token` of line `line` (`what` names it in the error).
fn parse_usize(line: usize, token: &str, what: &str) -> Result<usize, ModalError> {
    token
        .parse::<usize>()
        .map_err(|_| bad(line, format!("{what} '{token}' is not a non-negative integer")))
}

/// The size line `rows cols entries` (line `size_line`); a symmetric matrix must be square.
fn parse_size(size_line: usize, size: &str, symmetric: bool) -> Result<(usize, usize, usize), ModalError> {
    let tokens: Vec<&str> = size.split_whitespace().collect();
    if tokens.len() != 3 {
        return Err(bad(size_line, "size line needs exactly 3 integers: rows cols entries"));
    }
    let nrows = parse_usize(size_line, tokens[0], "rows")?;
    let ncols = parse_usize(size_line, tokens[1], "cols")?;
    let nnz = parse_usize(size_line, tokens[2], "entries")?;
    if symmetric && nrows != ncols {
        return Err(bad(
            size_line,
            format!("a symmetric matrix must be square, got {nrows}×{ncols}"),
        ));
    }
    Ok((nrows, ncols, nnz))
}

/// The entry `row col value` of line `number` as zero-based (row, col, value): indices within
/// the matrix's size, a finite value, and the lower triangle only when the file is symmetric.
fn parse_entry(
    number: usize,
    trimmed: &str,
    (nrows, ncols): (usize, usize),
    symmetric: bool,
) -> Result<(usize, usize, f64), ModalError> {
    let t: Vec<&str> = trimmed.split_whitespace().collect();
    if t.len() != 3 {
        return Err(bad(
            number,
            format!("entry needs 'row col value', got {} tokens", t.len()),
        ));
    }
    let row = parse_usize(number, t[0], "row")?;
    let col = parse_usize(number, t[1], "col")?;
    if row == 0 || row > nrows || col == 0 || col > ncols {
        return Err(bad(
            number,
            format!("index ({row}, {col}) outside 1..={nrows} × 1..={ncols}"),
        ));
    }
    let value: f64 = t[2]
        .parse()
        .map_err(|_| bad(number, format!("value '{}' is not a number", t[2])))?;
    if !value.is_finite() {
        return Err(bad(number, format!("value {value} is not finite")));
    }
    let (r, c) = (row - 1, col - 1);
    if symmetric && r < c {
        return Err(bad(
            number,
            "a symmetric file stores the lower triangle (row ≥ col) only",
        ));
    }
    Ok((r, c, value))
}

/// The text of a symmetric matrix (lower triangle of `entries`, which must hold both) in
/// Matrix Market coordinate format, for tests and tools.
pub fn symmetric_to_string(n: usize, entries: &[Triplet<usize, usize, f64>]) -> String {
    let lower: Vec<_> = entries.iter().filter(|e| e.row >= e.col).collect();
    let mut s = format!(
        "%%MatrixMarket matrix coordinate real symmetric\n{n} {n} {}\n",
        lower.len()
    );
    for e in lower {
        s.push_str(&format!("{} {} {:e}\n", e.row + 1, e.col + 1, e.val));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line_of(text: &str) -> usize {
        match parse_matrix_market(text) {
            Err(ModalError::MatrixMarket { line, .. }) => line,
            other => panic!("expected a located parse error, got {other:?}"),
        }
    }

    #[test]
    fn a_huge_declared_entry_count_is_a_located_error_not_an_allocation() {
        for declared in ["1000000000", "18446744073709551615"] {
            for kind in ["general", "symmetric"] {
                let text = format!("%%MatrixMarket matrix coordinate real {kind}\n2 2 {declared}\n1 1 1.0\n");
                match parse_matrix_market(&text) {
                    Err(ModalError::MatrixMarket { line, detail }) => {
                        assert_eq!(line, 3, "{kind} {declared}");
                        assert!(detail.contains("1 entries found"), "{detail}");
                    }
                    other => panic!("expected a located parse error, got {other:?}"),
                }
            }
        }
    }

    #[test]
    fn symmetric_file_is_mirrored() {
        let text = "%%MatrixMarket matrix coordinate real symmetric\n% comment\n2 2 3\n1 1 2.0\n2 1 -1\n2 2 2e0\n";
        let m = parse_matrix_market(text).expect("valid");
        assert_eq!((m.nrows, m.ncols, m.entries.len()), (2, 2, 4));
        let has = |r: usize, c: usize, v: f64| m.entries.iter().any(|e| (e.row, e.col, e.val) == (r, c, v));
        assert!(has(0, 1, -1.0) && has(1, 0, -1.0));
    }

    #[test]
    fn round_trip_through_text() {
        let entries = vec![
            Triplet::new(0, 0, 2.5),
            Triplet::new(1, 0, -1.0),
            Triplet::new(0, 1, -1.0),
        ];
        let text = symmetric_to_string(2, &entries);
        let m = parse_matrix_market(&text).expect("valid");
        assert_eq!(m.entries.len(), 3);
    }

    /// A dense matrix written as a general array, as a symmetric array and as coordinates reads
    /// back as the same entries, for random sizes with random zero entries.
    #[test]
    fn array_files_read_as_their_coordinate_twins() {
        let mut rng = crate::testing::graded::SplitMix::new(0x2545_f491_4f6c_dd1d);
        let mut next = move || rng.next_u64();
        for _ in 0..40 {
            let n = 1 + (next() % 7) as usize;
            let mut dense = vec![0.0; n * n];
            for j in 0..n {
                for i in j..n {
                    let v = if next() % 3 == 0 {
                        0.0
                    } else {
                        (next() % 2001) as f64 / 7.0 - 140.0
                    };
                    dense[i + n * j] = v;
                    dense[j + n * i] = v;
                }
            }
            let mut general =
                format!("%%MatrixMarket matrix array real general\n% written column by column\n{n} {n}\n");
            let mut symmetric = format!("%%MatrixMarket matrix array real symmetric\n{n} {n}\n");
            for j in 0..n {
                for i in 0..n {
                    general.push_str(&format!("{:e}\n", dense[i + n * j]));
                    if i >= j {
                        symmetric.push_str(&format!("{:.17e}\n", dense[i + n * j]));
                    }
                }
            }
            let sorted = |m: MatrixMarket| {
                let mut e: Vec<(usize, usize, f64)> = m.entries.iter().map(|t| (t.row, t.col, t.val)).collect();
                e.sort_by_key(|a| (a.0, a.1));
                e
            };
            let expected: Vec<(usize, usize, f64)> = (0..n)
                .flat_map(|i| (0..n).map(move |j| (i, j)))
                .filter(|&(i, j)| dense[i + n * j] != 0.0)
                .map(|(i, j)| (i, j, dense[i + n * j]))
                .collect();
            assert_eq!(sorted(parse_matrix_market(&general).expect("general array")), expected);
            assert_eq!(
                sorted(parse_matrix_market(&symmetric).expect("symmetric array")),
                expected
            );
        }
    }

    #[test]
    fn an_array_declaring_a_huge_size_is_a_located_error() {
        let text = "%%MatrixMarket matrix array real general\n1000000000 1000000000\n1\n";
        assert!(matches!(
            parse_matrix_market(text),
            Err(ModalError::MatrixMarket { line: 3, .. })
        ));
        let text = "%%MatrixMarket matrix array real symmetric\n2 3\n1\n";
        assert!(matches!(
            parse_matrix_market(text),
            Err(ModalError::MatrixMarket { line: 2, .. })
        ));
    }

    #[test]
    fn malformed_files_name_their_line() {
        assert_eq!(line_of(""), 1);
        assert_eq!(line_of("hello\n"), 1);
        assert_eq!(line_of("%%MatrixMarket vector array real general\n2 2\n"), 1);
        assert_eq!(line_of("%%MatrixMarket matrix array real general\n2 2\n1\n2\n"), 4);
        assert_eq!(line_of("%%MatrixMarket matrix array real general\n1 1\n1\n2\n"), 4);
        assert_eq!(line_of("%%MatrixMarket matrix array real general\n1 1\n1 2\n"), 3);
        assert_eq!(line_of("%%MatrixMarket matrix coordinate complex general\n"), 1);
        assert_eq!(line_of("%%MatrixMarket matrix coordinate real skew-symmetric\n"), 1);
        let h = "%%MatrixMarket matrix coordinate real general\n";
        assert_eq!(line_of(&format!("{h}%c\n2 x 1\n")), 3);
        assert_eq!(line_of(&format!("{h}2 2\n")), 2);
        assert_eq!(line_of(&format!("{h}2 2 2\n1 1 1.0\n3 1 1.0\n")), 4);
        assert_eq!(line_of(&format!("{h}2 2 1\n1 1 abc\n")), 3);
        assert_eq!(line_of(&format!("{h}2 2 1\n1 1 nan\n")), 3);
        assert_eq!(line_of(&format!("{h}2 2 1\n1 1\n")), 3);
        assert_eq!(line_of(&format!("{h}2 2 1\n1 1 1\n2 2 1\n")), 4);
        assert_eq!(line_of(&format!("{h}2 2 2\n1 1 1\n")), 3);
        assert_eq!(line_of(&format!("{h}2 2 1\n0 1 1\n")), 3);
        let s = "%%MatrixMarket matrix coordinate real symmetric\n";
        assert_eq!(line_of(&format!("{s}2 3 0\n")), 2);
        assert_eq!(line_of(&format!("{s}2 2 1\n1 2 1\n")), 3);
        assert!(matches!(
            read_matrix_market(Path::new("/nonexistent/file.mtx")),
            Err(ModalError::Io { .. })
        ));
    }
}
