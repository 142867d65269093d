//! A cache hint: where a loop knows which far-apart records it reads next (a breadth-first
//! queue, the neighbours of a vertex a few visits ahead), asking for them early lets the
//! loads overlap the work in between instead of stalling it one after another.

/// Asks the processor to bring the cache line at `at` in. Only a hint, not an access: `at`
/// need not be valid to read (nothing is done where the processor has no such hint).
#[inline(always)]
#[allow(unsafe_code)]
pub(crate) fn prefetch<T>(at: *const T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch reads nothing the program sees and never faults, whatever the address.
    unsafe {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        _mm_prefetch::<_MM_HINT_T0>(at.cast());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = at;
}
