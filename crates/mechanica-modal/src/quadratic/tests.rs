//! Tests of the quadratic eigensolver.
