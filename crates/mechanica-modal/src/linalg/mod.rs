//! Dense linear-algebra kernels of the modal solvers, below every solver and certificate: the
//! Cholesky factorization, the reduction C = L⁻¹BL⁻ᵀ and the back-transformation ([`reduce`]),
//! the symmetric eigensolver with its tridiagonal stages ([`eigen`]), one-pass norms, exact
//! scaling by powers of two, and the leaves-first order of a forest-patterned matrix.
//!
//! They form their own layer, not part of the dense solver, because the certificates (the
//! bottom-of-spectrum Cholesky, the a-priori bound's ‖A⁻¹‖) and the refinement (corrections
//! through L and the tridiagonal form) use them as well: the dense solver, the certificates and
//! the refinement all depend on these kernels, and the kernels on none of them.

pub mod eigen;
pub(crate) mod forest_order;
pub(crate) mod norms;
pub(crate) mod powers_of_two;
pub mod reduce;
