//! Criterion benchmarks of mechanica; see `benches/`.
