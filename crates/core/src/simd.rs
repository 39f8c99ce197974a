//! The one place the CPU is asked which vector instructions it has.

/// Whether this CPU has AVX2, FMA and POPCNT, the instruction sets of the vector kernels: asked
/// once, then remembered. Each kernel with an AVX2 path runs it only where this holds, and its
/// scalar reference elsewhere; the two give the same bytes (each kernel's tests hold them so).
pub fn avx2_available() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        static AVAILABLE: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
        *AVAILABLE.get_or_init(|| {
            is_x86_feature_detected!("avx2")
                && is_x86_feature_detected!("fma")
                && is_x86_feature_detected!("popcnt")
        })
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}
