//! The one place the CPU is asked which vector instructions it has, and the one place the
//! process decides which loops its kernels run ([`kernels`]).
//!
//! Each kernel with a vector path has one public function that runs the loops [`kernels`]
//! chose, and a readable scalar reference beside it with the same API (`*_reference`, or the
//! scalar loop the kernel's tests compare with); a test holds the two byte-equal.

use std::sync::OnceLock;

/// Whether this CPU has AVX2, FMA and POPCNT, the instruction sets of the vector kernels: asked
/// once, then remembered. Each kernel with an AVX2 path runs it only where this holds, and its
/// scalar reference elsewhere; the two give the same bytes (each kernel's tests hold them so).
pub fn avx2_available() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        static AVAILABLE: OnceLock<bool> = OnceLock::new();
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

/// Which loops a kernel with a vector path runs. The bytes are the same either way; only the
/// speed differs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kernels {
    /// The scalar loops: each kernel's readable reference, what a CPU without AVX2 runs.
    Scalar,
    /// The AVX2 loops, where [`avx2_available`] holds (elsewhere the scalar ones).
    Avx2,
}

impl Kernels {
    /// Whether the AVX2 loops run: asked for, and this CPU has them ([`avx2_available`]). The
    /// one condition every unsafe call into an AVX2 kernel rests on.
    #[inline]
    pub fn avx2(self) -> bool {
        self == Kernels::Avx2 && avx2_available()
    }
}

/// Whether the fast paths run their AVX2 loops in this process: the CPU has AVX2
/// ([`avx2_available`]) and the environment variable `STEREOLAB_SCALAR` is not set (empty or `0`
/// count as not set). Decided once, on first use; `STEREOLAB_SCALAR=1` runs every pass on the
/// scalar loops, each kernel's readable reference, with the same bytes.
pub fn uses_avx2() -> bool {
    kernels().avx2()
}

/// The loops every kernel runs in this process, decided once on first use: [`Kernels::Avx2`]
/// where [`avx2_available`] holds and the environment variable `STEREOLAB_SCALAR` is not set
/// (empty or `0` count as not set), else [`Kernels::Scalar`]. `STEREOLAB_SCALAR=1` thus runs
/// every pass on the scalar loops, what a CPU without AVX2 runs, with the same bytes.
pub fn kernels() -> Kernels {
    static KERNELS: OnceLock<Kernels> = OnceLock::new();
    *KERNELS.get_or_init(|| {
        if avx2_available() && !scalar_requested() {
            Kernels::Avx2
        } else {
            Kernels::Scalar
        }
    })
}

/// `STEREOLAB_SCALAR` set to anything but empty or `0`.
fn scalar_requested() -> bool {
    asks_for_scalar(std::env::var_os("STEREOLAB_SCALAR").as_deref())
}

/// Whether a value of `STEREOLAB_SCALAR` asks for the scalar loops: any but none, empty or `0`.
fn asks_for_scalar(value: Option<&std::ffi::OsStr>) -> bool {
    value.is_some_and(|v| !v.is_empty() && v != "0")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `STEREOLAB_SCALAR` unset, empty or `0` leaves the AVX2 loops on; any other value turns
    /// them off.
    #[test]
    fn scalar_is_asked_for_by_any_value_but_empty_or_zero() {
        for (value, scalar) in [
            (None, false),
            (Some(""), false),
            (Some("0"), false),
            (Some("1"), true),
            (Some("yes"), true),
            (Some("00"), true),
        ] {
            assert_eq!(
                asks_for_scalar(value.map(std::ffi::OsStr::new)),
                scalar,
                "{value:?}"
            );
        }
    }

    /// The choice holds only what the CPU can run, and asking for the AVX2 loops runs them
    /// exactly where the CPU has them.
    #[test]
    fn the_avx2_loops_run_only_where_the_cpu_has_them() {
        assert!(kernels() == Kernels::Scalar || avx2_available());
        assert_eq!(Kernels::Avx2.avx2(), avx2_available());
        assert!(!Kernels::Scalar.avx2());
        assert_eq!(kernels().avx2(), kernels() == Kernels::Avx2);
    }
}
