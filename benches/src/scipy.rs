//! SciPy's `scipy.linalg.eigh(B, A)` (LAPACK `dsygvd`, all pairs) as a peer in the same run as
//! the Rust methods: the pencil goes to a scratch file and `tools/scipy_eigh_point.py` times the
//! solve in a Python process (its start-up, imports and file reading are outside the timed
//! region). Without python3, NumPy or SciPy the series is skipped.

use mechanica::modal::faer::MatRef;
use std::io::Write as _;
use std::path::PathBuf;
use std::process::Command;

/// One timed SciPy solve.
#[derive(Debug, Clone)]
pub struct EighPoint {
    /// Median wall time of the solve, s.
    pub seconds: f64,
    /// The eigenvalues ω², ascending.
    pub values: Vec<f64>,
    /// max_j ‖Bx − ω²Ax‖/((‖B‖_F + |ω²|‖A‖_F)‖x‖) over the pairs.
    pub backward: f64,
    /// SciPy's version.
    pub version: String,
}

/// Times `runs` solves of det(B − ω²A) = 0 by SciPy; Err with the reason when it cannot run.
pub fn eigh(a: MatRef<'_, f64>, b: MatRef<'_, f64>, runs: usize) -> Result<EighPoint, String> {
    let n = a.nrows();
    let path = std::env::temp_dir().join(format!("mechanica-scipy-{}-{n}.bin", std::process::id()));
    write_pencil(&path, a, b).map_err(|e| format!("scratch file: {e}"))?;
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../tools/scipy_eigh_point.py");
    let output = Command::new("python3")
        .arg(&script)
        .arg(&path)
        .arg(n.to_string())
        .arg(runs.to_string())
        .output();
    let _ = std::fs::remove_file(&path);
    let output = output.map_err(|e| format!("python3: {e}"))?;
    let text = String::from_utf8_lossy(&output.stdout);
    if !output.status.success() {
        return Err(format!(
            "{} {}",
            text.trim(),
            String::from_utf8_lossy(&output.stderr).trim()
        ));
    }
    parse(&text).ok_or_else(|| format!("unreadable output: {}", text.chars().take(200).collect::<String>()))
}

/// A then B, column-major little-endian doubles.
fn write_pencil(path: &PathBuf, a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> std::io::Result<()> {
    let mut file = std::io::BufWriter::new(std::fs::File::create(path)?);
    for m in [a, b] {
        for j in 0..m.ncols() {
            for i in 0..m.nrows() {
                file.write_all(&m[(i, j)].to_le_bytes())?;
            }
        }
    }
    file.flush()
}

/// "seconds backward version" then the values.
fn parse(text: &str) -> Option<EighPoint> {
    let mut lines = text.lines();
    let mut head = lines.next()?.split_whitespace();
    let seconds = head.next()?.parse().ok()?;
    let backward = head.next()?.parse().ok()?;
    let version = head.next()?.to_string();
    let values = lines
        .next()?
        .split_whitespace()
        .map(|v| v.parse().ok())
        .collect::<Option<Vec<f64>>>()?;
    Some(EighPoint {
        seconds,
        values,
        backward,
        version,
    })
}
