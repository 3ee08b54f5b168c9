//! Cache lines asked for ahead of their use, so that a miss on a table read at random (the
//! environment map's, a texture's) overlaps other work instead of stalling the path that
//! reads it.

/// Asks for the cache line of `values[i]` (if any) to be loaded ahead of its use.
#[inline(always)]
pub(crate) fn prefetch<T>(values: &[T], i: usize) {
    #[cfg(target_arch = "x86_64")]
    if let Some(value) = values.get(i) {
        // SAFETY: a prefetch reads nothing and cannot fault; the address is `value`'s.
        unsafe {
            use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
            _mm_prefetch::<_MM_HINT_T0>(std::ptr::from_ref(value).cast());
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (values, i);
}
