//! The command line's memory allocator: the system allocator, with large
//! blocks (meshes, one-rings, file buffers) asked to live on 2 MiB pages.
//!
//! Why: on a large mesh the host spends much of its time faulting in fresh
//! 4 KiB pages. With transparent huge pages in their usual `madvise` mode,
//! `madvise(MADV_HUGEPAGE)` on a block before its first touch takes 512× fewer
//! faults. The advice is given here, for shapecue's own blocks only: glibc's
//! own switch, which advises the OpenCL runtime's buffers too, made the first
//! run slower and erratic (measurements: `docs/notes/curvature-kernels.md`).
//!
//! Only the binary installs it; the library leaves the allocator to its
//! callers. The advice is a hint: where transparent huge pages are off, or on
//! another system, the blocks are ordinary ones.

use std::alloc::{GlobalAlloc, Layout, System};

/// Blocks from this size on are advised; smaller ones would hardly hold a
/// whole 2 MiB page.
const HUGE_MIN: usize = 4 << 20;

pub struct HugeBlocks;

#[cfg(target_os = "linux")]
fn advise(p: *mut u8, len: usize) {
    const PAGE: usize = 2 << 20;
    let start = (p as usize).next_multiple_of(PAGE);
    let end = (p as usize + len) & !(PAGE - 1);
    if end > start {
        // SAFETY: [start, end) lies inside the live block just allocated;
        // the advice changes no contents, and its failure changes nothing.
        unsafe { libc::madvise(start as *mut libc::c_void, end - start, libc::MADV_HUGEPAGE) };
    }
}

#[cfg(not(target_os = "linux"))]
fn advise(_: *mut u8, _: usize) {}

// SAFETY: every call is forwarded to the system allocator with the same
// arguments; `advise` only adds a hint on the memory it returned.
unsafe impl GlobalAlloc for HugeBlocks {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(layout) };
        if layout.size() >= HUGE_MIN && !p.is_null() {
            advise(p, layout.size());
        }
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        // A fresh mapping is zero without being touched, so the advice still
        // comes before the first fault.
        let p = unsafe { System.alloc_zeroed(layout) };
        if layout.size() >= HUGE_MIN && !p.is_null() {
            advise(p, layout.size());
        }
        p
    }

    unsafe fn dealloc(&self, p: *mut u8, layout: Layout) {
        unsafe { System.dealloc(p, layout) }
    }

    unsafe fn realloc(&self, p: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let q = unsafe { System.realloc(p, layout, new_size) };
        if new_size >= HUGE_MIN && !q.is_null() {
            advise(q, new_size);
        }
        q
    }
}
