//! The allocator of unitrace's binaries: the system allocator, with every block of at
//! least [`LARGE`] bytes advised onto transparent huge pages (`MADV_HUGEPAGE`).
//!
//! A large scene is a few large arrays filled once: the decoded soup, the tree's nodes and
//! leaf lists, the triangles in leaf order. Linux's usual setting gives huge pages only to
//! memory that asks for them, so each 4 KiB page of those arrays costs a page fault when
//! first written, and every later cache miss walks 4 KiB page tables. On a
//! 10.7-million-triangle scene the faults were about a fifth of `kd2exr`'s time; advised,
//! the arrays fault once per 2 MiB and the renderer loads in two thirds of the time
//! (docs/PERFORMANCE.md, "Where the time goes").
//!
//! `unity2soup`, `kd2exr` and `raycast` install it. `soup2kd` does not: its build frees and
//! allocates event lists all the time, and on the same scene huge pages raised its peak
//! memory by a tenth for 2 % of build time.
//!
//! Only the whole 2 MiB pages inside a block are advised, so small allocations and the
//! memory around a large one are untouched. Where the kernel has no transparent huge pages,
//! or on another system than Linux, the advice is nothing.

use std::alloc::{GlobalAlloc, Layout, System};

/// Blocks of at least this many bytes are advised: two huge pages, so that a block
/// placed anywhere holds at least one whole huge page.
pub const LARGE: usize = 2 * HUGE_PAGE;

/// The x86_64 and aarch64 (4 KiB granule) transparent huge page.
const HUGE_PAGE: usize = 2 << 20;

/// [`System`], with large blocks advised onto huge pages.
pub struct HugePages;

// SAFETY: every block comes from `System` with the caller's layout and goes back to it
// unchanged; the advice changes how the kernel backs a block's pages, never their contents
// or ownership.
unsafe impl GlobalAlloc for HugePages {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: the caller's contract for `alloc`, passed on.
        let p = unsafe { System.alloc(layout) };
        advise(p, layout.size());
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        // SAFETY: as for `alloc`.
        let p = unsafe { System.alloc_zeroed(layout) };
        advise(p, layout.size());
        p
    }

    unsafe fn dealloc(&self, p: *mut u8, layout: Layout) {
        // SAFETY: `p` came from `System` with this layout (`alloc`, `realloc` above).
        unsafe { System.dealloc(p, layout) }
    }

    unsafe fn realloc(&self, p: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: as for `dealloc`; the caller vouches for `new_size`.
        let q = unsafe { System.realloc(p, layout, new_size) };
        advise(q, new_size);
        q
    }
}

/// Asks for huge pages on the whole 2 MiB pages of the block at `p` of `len` bytes.
fn advise(p: *mut u8, len: usize) {
    if p.is_null() || len < LARGE {
        return;
    }
    let (start, end) = huge_pages_within(p as usize, len);
    if start < end {
        #[cfg(target_os = "linux")]
        // SAFETY: [start, end) lies inside the block just allocated, which this process
        // owns; MADV_HUGEPAGE never changes what the memory holds. Its result is ignored:
        // a kernel without transparent huge pages refuses the advice and nothing changes.
        unsafe {
            libc::madvise(start as *mut libc::c_void, end - start, libc::MADV_HUGEPAGE);
        }
    }
}

/// The largest range of whole huge pages inside [p, p + len).
fn huge_pages_within(p: usize, len: usize) -> (usize, usize) {
    let start = p.next_multiple_of(HUGE_PAGE);
    let end = (p + len) / HUGE_PAGE * HUGE_PAGE;
    (start, end)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_whole_huge_pages_inside_the_block_are_advised() {
        const MB: usize = 1 << 20;
        // A block from 1 MiB to 7 MiB holds the huge pages at 2 and 4 MiB.
        assert_eq!(huge_pages_within(MB, 6 * MB), (2 * MB, 6 * MB));
        // Aligned at both ends: all of it.
        assert_eq!(huge_pages_within(4 * MB, 4 * MB), (4 * MB, 8 * MB));
        // A block of `LARGE` bytes anywhere holds at least one.
        for offset in [0, 16, 4096, MB, 2 * MB - 16] {
            let (s, e) = huge_pages_within(16 * MB + offset, LARGE);
            assert!(e - s >= HUGE_PAGE, "offset {offset}: {s}..{e}");
        }
        // Less than a huge page: an empty range.
        let (s, e) = huge_pages_within(MB + 16, MB);
        assert!(s >= e);
    }

    #[test]
    fn large_blocks_allocate_grow_and_keep_their_contents() {
        // Through the allocator itself (tests do not install it globally).
        let a = HugePages;
        let layout = Layout::from_size_align(LARGE + 12_345, 16).unwrap();
        // SAFETY: a non-zero-size layout; the block is written within its size, grown
        // with `realloc` under the same alignment and freed with its final layout.
        unsafe {
            let p = a.alloc_zeroed(layout);
            assert!(!p.is_null());
            let words = std::slice::from_raw_parts_mut(p.cast::<u32>(), layout.size() / 4);
            assert!(words.iter().all(|&w| w == 0));
            for (i, w) in words.iter_mut().enumerate() {
                *w = i as u32;
            }
            let bigger = 3 * LARGE;
            let q = a.realloc(p, layout, bigger);
            assert!(!q.is_null());
            let kept = std::slice::from_raw_parts(q.cast::<u32>(), layout.size() / 4);
            assert!(kept.iter().enumerate().all(|(i, &w)| w == i as u32));
            a.dealloc(q, Layout::from_size_align(bigger, 16).unwrap());
        }
    }
}
