//! A paging hint: records read in no order over hundreds of megabytes (a view-dependent front's
//! nodes and triangles) miss the TLB on nearly every read with 4 kB pages; backed by 2 MB pages
//! where the kernel allows it, far fewer do (BENCHMARKS.md, "The front's lists in huge pages").

/// Reserves room for `count` records in `list`, at once rather than by doubling (which would
/// move the pages already touched, small), and advises huge pages for it ([`advise`]). Only on
/// Linux, where a reservation costs address space, not memory, until it is touched.
pub(crate) fn reserve<T>(list: &mut Vec<T>, count: usize) {
    if cfg!(target_os = "linux") {
        list.reserve_exact(count.saturating_sub(list.len()));
        advise(list);
    }
}

/// Asks the kernel to back the 2 MB-aligned part of `list`'s buffer with huge pages (Linux's
/// `MADV_HUGEPAGE`, honoured when transparent huge pages are `always` or `madvise`). Only a
/// hint: nothing changes what the program reads, and nothing is done elsewhere or for a buffer
/// under 2 MB.
#[allow(unsafe_code)]
fn advise<T>(list: &Vec<T>) {
    #[cfg(target_os = "linux")]
    {
        const HUGE: usize = 2 << 20;
        let start = list.as_ptr() as usize;
        let bytes = list.capacity() * std::mem::size_of::<T>();
        let from = start.next_multiple_of(HUGE);
        let to = (start + bytes) / HUGE * HUGE;
        if to > from {
            // SAFETY: the range lies inside the buffer `list` owns and is page-aligned;
            // MADV_HUGEPAGE changes how its pages are backed, never their contents, and an
            // error (a kernel without it) is ignored.
            unsafe {
                libc::madvise(from as *mut libc::c_void, to - from, libc::MADV_HUGEPAGE);
            }
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = list;
}
