//! What the running CPU offers the hand-vectorised kernels.

/// Whether this CPU runs the FMA and AVX2 variants of the kernels (detected once, cached by the
/// standard library).
#[cfg(target_arch = "x86_64")]
pub(crate) fn fused_available() -> bool {
    std::arch::is_x86_feature_detected!("fma") && std::arch::is_x86_feature_detected!("avx2")
}
