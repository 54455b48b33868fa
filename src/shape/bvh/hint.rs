//! Hints to the memory system for the triangle BVH: the crate's only `unsafe` code.
//!
//! Incoherent rays through a large mesh (the full Stanford dragon: 50 MB of nodes and
//! triangle blocks) spend most of their time waiting for memory: a node's box test needs
//! all its cache lines, and the child to visit next is known only after that test. Two
//! hints overlap or shorten those waits, as Embree does (docs/performance.md, round 5):
//!
//! - [`prefetch_node`] / [`prefetch_blocks`]: when a node's children are known, their
//!   lines are requested at once, so the pending ones arrive while the nearest is visited;
//! - [`advise_huge_pages`]: the node and block arrays are backed by 2 MiB pages where the
//!   kernel agrees, so a miss to memory no longer also misses the TLB (48 MB in 4 KiB
//!   pages is 12,288 translations; the L2 TLB holds about 3,000). The build's own arrays
//!   are advised too, for fewer page faults while they are first written.
//!
//! Neither changes a value the program computes: a prefetch only moves a line into the
//! cache, and `madvise(MADV_HUGEPAGE)` / `madvise(MADV_COLLAPSE)` only change how pages
//! are mapped (their contents are kept). Both need `unsafe` for a reason unrelated to
//! memory safety, each explained where it is used; safe Rust has neither (a plain load
//! used as a prefetch measured no gain: it occupies the reorder buffer until the line
//! arrives). Off Linux or off x86-64 the functions do nothing.
#![allow(unsafe_code)]

/// Requests the cache lines of the value of `T` at `p`, a node aligned to 64 bytes (two
/// lines for a 128-byte node, four for the mesh tree's 256-byte node).
#[inline(always)]
pub(super) fn prefetch_node<T>(p: *const T) {
    let p = p.cast::<u8>();
    for line in 0..size_of::<T>().div_ceil(64) {
        prefetch(p.wrapping_add(64 * line));
    }
}

/// Requests the cache line holding `p` (an index entry read once the traversal ends).
#[inline(always)]
pub(super) fn prefetch_line<T>(p: *const T) {
    prefetch(p.cast::<u8>());
}

/// Requests every cache line of `n` consecutive values of `T` starting at `p` (a leaf's
/// triangle blocks: 144 bytes each, 16-byte aligned, so one block spans three lines).
#[inline(always)]
pub(super) fn prefetch_blocks<T>(p: *const T, n: usize) {
    let bytes = size_of::<T>() * n;
    let p = p.cast::<u8>();
    let first = p as usize & !63;
    let last = (p as usize).wrapping_add(bytes.max(1) - 1);
    let mut line = 0;
    while first.wrapping_add(line) <= last {
        prefetch(p.wrapping_add(line));
        line += 64;
    }
}

/// A prefetch of the line holding `p` into all cache levels (`prefetcht0`). Any address
/// is allowed: a prefetch never faults, so `p` need not point into an allocation.
#[inline(always)]
fn prefetch(p: *const u8) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        // `_mm_prefetch` is a safe function, but one compiled for SSE, and Rust asks
        // callers outside such a function for `unsafe` even when the whole build
        // enables SSE. The only requirement is that the CPU has SSE, which every
        // x86-64 CPU has (it is part of the architecture's baseline).
        #[target_feature(enable = "sse")]
        fn go(p: *const u8) {
            _mm_prefetch::<_MM_HINT_T0>(p.cast::<i8>());
        }
        // SAFETY: x86-64 always has SSE (see above).
        unsafe { go(p) }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = p;
}

/// Asks the kernel to back the 2 MiB-aligned part of `data` with huge pages: first
/// `MADV_HUGEPAGE` (future faults in the range may get them), then `MADV_COLLAPSE`
/// (Linux 6.1 and later: the pages already there are merged now, their contents kept).
/// A hint only: failures (an older kernel, huge pages disabled, no free 2 MiB page) are
/// ignored, and a slice shorter than one aligned 2 MiB span is left alone. Returns the
/// number of bytes advised. `data` may be a vector's spare capacity
/// (`Vec::spare_capacity_mut`, not yet written): pages first touched after the advice are
/// mapped as huge pages directly, which is cheaper than merging them later.
pub(super) fn advise_huge_pages<T>(data: &[T]) -> usize {
    const HUGE: usize = 2 << 20;
    let start = data.as_ptr() as usize;
    let end = start + std::mem::size_of_val(data);
    let lo = start.next_multiple_of(HUGE);
    let hi = end / HUGE * HUGE;
    if hi <= lo {
        return 0;
    }
    #[cfg(target_os = "linux")]
    {
        /// `MADV_COLLAPSE` from the kernel's `uapi/asm-generic/mman-common.h` (the
        /// `libc` crate does not name it yet).
        const MADV_COLLAPSE: libc::c_int = 25;
        let (addr, len) = (lo as *mut libc::c_void, hi - lo);
        // SAFETY: `addr..addr + len` lies inside `data`, memory this process owns and
        // that stays allocated during the calls. Neither advice changes the contents
        // of the range or its protection, so no reference into `data` is affected;
        // only the page size behind the range may change.
        unsafe {
            libc::madvise(addr, len, libc::MADV_HUGEPAGE);
            libc::madvise(addr, len, MADV_COLLAPSE);
        }
    }
    hi - lo
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bytes of huge pages backing the mapping that contains `addr`, from
    /// `/proc/self/smaps`; `None` if the file cannot be read.
    #[cfg(target_os = "linux")]
    fn huge_kib_at(addr: usize) -> Option<usize> {
        let smaps = std::fs::read_to_string("/proc/self/smaps").ok()?;
        let mut inside = false;
        for line in smaps.lines() {
            let first = line.split_whitespace().next().unwrap_or("");
            if let Some((a, b)) = first.split_once('-')
                && let (Ok(a), Ok(b)) = (usize::from_str_radix(a, 16), usize::from_str_radix(b, 16))
            {
                inside = (a..b).contains(&addr);
            } else if inside && let Some(kb) = line.strip_prefix("AnonHugePages:") {
                return kb.trim().trim_end_matches("kB").trim().parse().ok();
            }
        }
        None
    }

    #[test]
    fn advice_keeps_contents_and_skips_short_slices() {
        assert_eq!(advise_huge_pages::<u64>(&[]), 0);
        assert_eq!(advise_huge_pages(&[1u8; 4096]), 0);
        let data: Vec<u32> = (0..3_000_000u32).map(|i| i.wrapping_mul(2_654_435_761)).collect();
        let advised = advise_huge_pages(&data);
        // 12 MB hold at least four whole aligned 2 MiB spans, wherever they start.
        assert!(advised >= 4 << 21 && advised <= data.len() * 4, "{advised}");
        assert!(data.iter().enumerate().all(|(i, &x)| x == (i as u32).wrapping_mul(2_654_435_761)));
        // Prefetches of any address, inside the data or not, change nothing.
        for k in [0, 1000, data.len() - 1] {
            prefetch_node(&data[k]);
            prefetch_line(&data[k]);
            prefetch_blocks(&data[k], 1 + k % 3);
        }
        prefetch_blocks(std::ptr::null::<u8>(), 3);
        prefetch_node(usize::MAX as *const u8);
        assert_eq!(data[1000], 1000u32.wrapping_mul(2_654_435_761));
    }

    /// Where the kernel offers huge pages, the advice gets them: this is what the BVH
    /// relies on for its speed (not its results). Skipped, with the reason printed, where
    /// transparent huge pages are off or the kernel predates `MADV_COLLAPSE` (6.1).
    #[cfg(target_os = "linux")]
    #[test]
    fn advice_gets_huge_pages_where_the_kernel_offers_them() {
        let setting = std::fs::read_to_string("/sys/kernel/mm/transparent_hugepage/enabled").unwrap_or_default();
        let release = std::fs::read_to_string("/proc/sys/kernel/osrelease").unwrap_or_default();
        let version: Vec<u32> = release.split(['.', '-']).take(2).map(|x| x.trim().parse().unwrap_or(0)).collect();
        if !setting.contains("[always]") && !setting.contains("[madvise]") {
            eprintln!("skipped: transparent huge pages are off here ({:?})", setting.trim());
            return;
        }
        if version.len() < 2 || (version[0], version[1]) < (6, 1) {
            eprintln!("skipped: Linux {:?} predates MADV_COLLAPSE", release.trim());
            return;
        }
        let data = vec![7u8; 16 << 20];
        let advised = advise_huge_pages(&data);
        let kib = huge_kib_at(data.as_ptr() as usize + data.len() / 2).expect("/proc/self/smaps lists the data");
        assert!(kib * 1024 >= advised, "{kib} KiB of huge pages for {advised} advised bytes");
        assert!(data.iter().all(|&x| x == 7));
    }
}
