//! Minimal safe wrappers of the LAPACK routines the modal benches compare against, called
//! through the Fortran ABI of the system OpenBLAS (linked by `build.rs` when found).
//!
//! Conventions: column-major n×n buffers with leading dimension n; `char` arguments are passed
//! as pointers with the hidden string lengths gfortran appends. Sign convention of the peer:
//! LAPACK solves K z = ω² M z with M positive definite, i.e. (8.89) with A = M (mass) and
//! B = K (stiffness). Without OpenBLAS every call returns [`LapackError::Unavailable`].

use std::fmt;

/// Why a LAPACK call did not return a result.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LapackError {
    /// The benches were built without OpenBLAS.
    Unavailable,
    /// A buffer does not hold n·n entries.
    BadSize {
        /// Entries found.
        len: usize,
        /// n·n expected.
        expected: usize,
    },
    /// INFO < 0: argument −INFO had an illegal value.
    IllegalArgument(i32),
    /// The mass matrix is not positive definite: its leading minor of this order failed.
    NotPositiveDefinite(usize),
    /// INFO > 0 in the eigensolver: it did not converge.
    NoConvergence(i32),
}

impl fmt::Display for LapackError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Unavailable => write!(f, "built without OpenBLAS (install libopenblas-dev)"),
            Self::BadSize { len, expected } => write!(f, "buffer has {len} entries, expected {expected}"),
            Self::IllegalArgument(i) => write!(f, "LAPACK argument {i} is illegal"),
            Self::NotPositiveDefinite(k) => write!(f, "mass matrix not positive definite (minor {k})"),
            Self::NoConvergence(i) => write!(f, "LAPACK eigensolver did not converge (INFO = {i})"),
        }
    }
}

impl std::error::Error for LapackError {}

/// Eigenvalues (ascending) and optionally eigenvectors (n×n column-major) of a solve.
#[derive(Debug, Clone)]
pub struct Eigen {
    /// ω² ascending.
    pub values: Vec<f64>,
    /// Column j is the eigenvector of `values[j]` (M-orthonormal for [`dsygvd`]).
    pub vectors: Option<Vec<f64>>,
}

/// Whether the benches were linked against OpenBLAS.
pub fn available() -> bool {
    cfg!(mechanica_openblas)
}

/// Threads OpenBLAS uses (None without OpenBLAS).
pub fn threads() -> Option<usize> {
    ffi::threads()
}

/// The kernel family OpenBLAS selected for this CPU (None without OpenBLAS). Older OpenBLAS
/// builds fall back to `Prescott` (SSE3) on CPUs they do not know, which makes them several
/// times slower; `OPENBLAS_CORETYPE=Haswell` (or `SkylakeX`) in the environment overrides it.
pub fn core_name() -> Option<String> {
    ffi::core_name()
}

fn check(len: usize, n: usize) -> Result<(), LapackError> {
    let expected = n * n;
    if len == expected {
        Ok(())
    } else {
        Err(LapackError::BadSize { len, expected })
    }
}

/// `dsygvd` (itype 1, lower): K z = ω² M z for symmetric K and positive definite M, both n×n
/// column-major; all eigenvalues, with eigenvectors when `vectors` (divide and conquer).
pub fn dsygvd(stiffness: &[f64], mass: &[f64], n: usize, vectors: bool) -> Result<Eigen, LapackError> {
    check(stiffness.len(), n)?;
    check(mass.len(), n)?;
    let mut k = stiffness.to_vec();
    let mut m = mass.to_vec();
    let values = ffi::sygvd(&mut k, &mut m, n, vectors)?;
    Ok(Eigen {
        values,
        vectors: vectors.then_some(k),
    })
}

/// `dpotrf` (lower) in place: the lower triangle of `a` becomes L with A = L Lᵀ.
pub fn dpotrf(a: &mut [f64], n: usize) -> Result<(), LapackError> {
    check(a.len(), n)?;
    ffi::potrf(a, n)
}

/// `dsygst` (itype 1, lower) in place: the lower triangle of `b` becomes that of L⁻¹ B L⁻ᵀ,
/// with `l` from [`dpotrf`].
pub fn dsygst(b: &mut [f64], l: &[f64], n: usize) -> Result<(), LapackError> {
    check(b.len(), n)?;
    check(l.len(), n)?;
    ffi::sygst(b, l, n)
}

/// `dsyevd` (lower, divide and conquer) in place on a symmetric `c`: eigenvalues ascending,
/// and with `vectors` the eigenvectors overwrite `c`.
pub fn dsyevd(c: &mut [f64], n: usize, vectors: bool) -> Result<Vec<f64>, LapackError> {
    check(c.len(), n)?;
    ffi::syevd(c, n, vectors)
}

/// `dtrsm` (left, lower, transposed): Y ← L⁻ᵀ Y, the back-transformation of eigenvectors.
pub fn back_transform(l: &[f64], y: &mut [f64], n: usize) -> Result<(), LapackError> {
    check(l.len(), n)?;
    check(y.len(), n)?;
    ffi::trsm_lower_transposed(l, y, n)
}

#[cfg(mechanica_openblas)]
mod ffi {
    use super::LapackError;
    use std::ffi::{c_char, c_int};

    // Fortran ABI (gfortran): every argument by reference, hidden `char` lengths at the end.
    unsafe extern "C" {
        fn dsygvd_(
            itype: *const c_int,
            jobz: *const c_char,
            uplo: *const c_char,
            n: *const c_int,
            a: *mut f64,
            lda: *const c_int,
            b: *mut f64,
            ldb: *const c_int,
            w: *mut f64,
            work: *mut f64,
            lwork: *const c_int,
            iwork: *mut c_int,
            liwork: *const c_int,
            info: *mut c_int,
            jobz_len: usize,
            uplo_len: usize,
        );
        fn dsyevd_(
            jobz: *const c_char,
            uplo: *const c_char,
            n: *const c_int,
            a: *mut f64,
            lda: *const c_int,
            w: *mut f64,
            work: *mut f64,
            lwork: *const c_int,
            iwork: *mut c_int,
            liwork: *const c_int,
            info: *mut c_int,
            jobz_len: usize,
            uplo_len: usize,
        );
        fn dpotrf_(uplo: *const c_char, n: *const c_int, a: *mut f64, lda: *const c_int, info: *mut c_int, len: usize);
        fn dsygst_(
            itype: *const c_int,
            uplo: *const c_char,
            n: *const c_int,
            a: *mut f64,
            lda: *const c_int,
            b: *const f64,
            ldb: *const c_int,
            info: *mut c_int,
            uplo_len: usize,
        );
        fn dtrsm_(
            side: *const c_char,
            uplo: *const c_char,
            transa: *const c_char,
            diag: *const c_char,
            m: *const c_int,
            n: *const c_int,
            alpha: *const f64,
            a: *const f64,
            lda: *const c_int,
            b: *mut f64,
            ldb: *const c_int,
            side_len: usize,
            uplo_len: usize,
            transa_len: usize,
            diag_len: usize,
        );
        fn openblas_get_num_threads() -> c_int;
        fn openblas_get_corename() -> *const c_char;
    }

    const LOWER: c_char = b'L' as c_char;
    const fn jobz(vectors: bool) -> c_char {
        (if vectors { b'V' } else { b'N' }) as c_char
    }

    /// N as a Fortran integer (callers return early for n = 0, where LDA would be illegal).
    fn order(n: usize) -> Result<c_int, LapackError> {
        c_int::try_from(n).map_err(|_| LapackError::IllegalArgument(4))
    }

    pub(super) fn threads() -> Option<usize> {
        // SAFETY: a plain query without arguments.
        let t = unsafe { openblas_get_num_threads() };
        usize::try_from(t).ok()
    }

    pub(super) fn core_name() -> Option<String> {
        // SAFETY: OpenBLAS returns a pointer to a static NUL-terminated string (or NULL).
        let p = unsafe { openblas_get_corename() };
        if p.is_null() {
            return None;
        }
        // SAFETY: non-null, NUL-terminated, static lifetime.
        let name = unsafe { std::ffi::CStr::from_ptr(p) };
        Some(name.to_string_lossy().into_owned())
    }

    /// Runs `call(work, lwork, iwork, liwork)` (one LAPACK call, returning INFO) as a workspace
    /// query (lwork = liwork = −1), then with the optimal workspace. INFO of the query if nonzero,
    /// else of the real call.
    fn with_workspace(mut call: impl FnMut(&mut [f64], c_int, &mut [c_int], c_int) -> c_int) -> c_int {
        let (mut qwork, mut qiwork) = ([0.0_f64], [0 as c_int]);
        let info = call(&mut qwork, -1, &mut qiwork, -1);
        if info != 0 {
            return info;
        }
        let (lwork, liwork) = (qwork[0].ceil() as c_int, qiwork[0].max(1));
        let mut work = vec![0.0; lwork.max(1) as usize];
        let mut iwork = vec![0 as c_int; (liwork as usize).max(1)];
        call(&mut work, lwork, &mut iwork, liwork)
    }

    pub(super) fn sygvd(k: &mut [f64], m: &mut [f64], n: usize, vectors: bool) -> Result<Vec<f64>, LapackError> {
        if n == 0 {
            return Ok(Vec::new());
        }
        let nn = order(n)?;
        let (itype, jz) = (1 as c_int, jobz(vectors));
        let mut w = vec![0.0; n];
        let info = with_workspace(|work, lwork, iwork, liwork| {
            let mut info: c_int = 0;
            // SAFETY: every pointer is valid for the sizes LAPACK reads: k, m hold n·n entries
            // with leading dimension n, w holds n, work and iwork at least lwork and liwork
            // (one entry each for a query).
            unsafe {
                dsygvd_(
                    &itype,
                    &jz,
                    &LOWER,
                    &nn,
                    k.as_mut_ptr(),
                    &nn,
                    m.as_mut_ptr(),
                    &nn,
                    w.as_mut_ptr(),
                    work.as_mut_ptr(),
                    &lwork,
                    iwork.as_mut_ptr(),
                    &liwork,
                    &mut info,
                    1,
                    1,
                );
            }
            info
        });
        status(info, n)?;
        Ok(w)
    }

    /// dsygvd: 0 < INFO ≤ n is an eigensolver failure, INFO > n a failed minor INFO − n of M.
    fn status(info: c_int, n: usize) -> Result<(), LapackError> {
        let nn = n as c_int;
        match info {
            0 => Ok(()),
            i if i < 0 => Err(LapackError::IllegalArgument(-i)),
            i if i > nn => Err(LapackError::NotPositiveDefinite((i - nn) as usize)),
            i => Err(LapackError::NoConvergence(i)),
        }
    }

    pub(super) fn syevd(c: &mut [f64], n: usize, vectors: bool) -> Result<Vec<f64>, LapackError> {
        if n == 0 {
            return Ok(Vec::new());
        }
        let nn = order(n)?;
        let jz = jobz(vectors);
        let mut w = vec![0.0; n];
        let info = with_workspace(|work, lwork, iwork, liwork| {
            let mut info: c_int = 0;
            // SAFETY: c holds n·n entries (leading dimension n), w holds n, work and iwork at
            // least lwork and liwork (one entry each for a query).
            unsafe {
                dsyevd_(
                    &jz,
                    &LOWER,
                    &nn,
                    c.as_mut_ptr(),
                    &nn,
                    w.as_mut_ptr(),
                    work.as_mut_ptr(),
                    &lwork,
                    iwork.as_mut_ptr(),
                    &liwork,
                    &mut info,
                    1,
                    1,
                );
            }
            info
        });
        match info {
            0 => Ok(w),
            i if i < 0 => Err(LapackError::IllegalArgument(-i)),
            i => Err(LapackError::NoConvergence(i)),
        }
    }

    pub(super) fn potrf(a: &mut [f64], n: usize) -> Result<(), LapackError> {
        if n == 0 {
            return Ok(());
        }
        let nn = order(n)?;
        let mut info: c_int = 0;
        // SAFETY: a holds n·n entries with leading dimension n.
        unsafe { dpotrf_(&LOWER, &nn, a.as_mut_ptr(), &nn, &mut info, 1) };
        match info {
            0 => Ok(()),
            i if i < 0 => Err(LapackError::IllegalArgument(-i)),
            i => Err(LapackError::NotPositiveDefinite(i as usize)),
        }
    }

    pub(super) fn sygst(b: &mut [f64], l: &[f64], n: usize) -> Result<(), LapackError> {
        if n == 0 {
            return Ok(());
        }
        let nn = order(n)?;
        let itype: c_int = 1;
        let mut info: c_int = 0;
        // SAFETY: b and l hold n·n entries with leading dimension n; l is only read.
        unsafe { dsygst_(&itype, &LOWER, &nn, b.as_mut_ptr(), &nn, l.as_ptr(), &nn, &mut info, 1) };
        if info < 0 {
            return Err(LapackError::IllegalArgument(-info));
        }
        Ok(())
    }

    pub(super) fn trsm_lower_transposed(l: &[f64], y: &mut [f64], n: usize) -> Result<(), LapackError> {
        if n == 0 {
            return Ok(());
        }
        let nn = order(n)?;
        let (side, trans, diag) = (b'L' as c_char, b'T' as c_char, b'N' as c_char);
        let one = 1.0_f64;
        // SAFETY: l and y hold n·n entries with leading dimension n; l is only read.
        unsafe {
            dtrsm_(
                &side,
                &LOWER,
                &trans,
                &diag,
                &nn,
                &nn,
                &one,
                l.as_ptr(),
                &nn,
                y.as_mut_ptr(),
                &nn,
                1,
                1,
                1,
                1,
            );
        }
        Ok(())
    }
}

#[cfg(not(mechanica_openblas))]
mod ffi {
    use super::LapackError;

    pub(super) fn threads() -> Option<usize> {
        None
    }
    pub(super) fn core_name() -> Option<String> {
        None
    }
    pub(super) fn sygvd(_: &mut [f64], _: &mut [f64], _: usize, _: bool) -> Result<Vec<f64>, LapackError> {
        Err(LapackError::Unavailable)
    }
    pub(super) fn syevd(_: &mut [f64], _: usize, _: bool) -> Result<Vec<f64>, LapackError> {
        Err(LapackError::Unavailable)
    }
    pub(super) fn potrf(_: &mut [f64], _: usize) -> Result<(), LapackError> {
        Err(LapackError::Unavailable)
    }
    pub(super) fn sygst(_: &mut [f64], _: &[f64], _: usize) -> Result<(), LapackError> {
        Err(LapackError::Unavailable)
    }
    pub(super) fn trsm_lower_transposed(_: &[f64], _: &mut [f64], _: usize) -> Result<(), LapackError> {
        Err(LapackError::Unavailable)
    }
}
