//! Hot loops run as wide as the CPU allows, chosen at run time. The binary
//! is built for any x86-64 (SSE2: two f64 lanes); the year's hot loops (the
//! Perez sky over the sphere bins' cells, the coefficient products) are
//! compiled again for AVX2 (four lanes) and AVX-512 (eight) and the widest
//! the CPU has runs. No fused multiply-add is ever formed (Rust does not
//! contract) and every lane does the scalar's own operations, so every
//! width gives the same bits.

/// Runs `work` compiled for the widest vector unit the CPU has. What `work`
/// does must be inlined into it to run wide: mark the closure and the
/// functions it calls `#[inline(always)]`.
#[inline(always)]
pub(crate) fn widest<R>(work: impl FnOnce() -> R) -> R {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx512f") {
            // SAFETY: the CPU has AVX-512F, checked just above.
            return unsafe { avx512(work) };
        }
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2, checked just above.
            return unsafe { avx2(work) };
        }
    }
    work()
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn avx512<R>(work: impl FnOnce() -> R) -> R {
    work()
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn avx2<R>(work: impl FnOnce() -> R) -> R {
    work()
}
