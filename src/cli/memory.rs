//! How much memory a render may take: the least of three limits, so that a
//! render too big for its process is refused before the first pass instead of
//! aborting after minutes of work with nothing written.
//!
//! - what the machine has available (`MemAvailable` in `/proc/meminfo`);
//! - what the process's address-space limit leaves (`RLIMIT_AS`, as `ulimit -v`
//!   sets it, read from `/proc/self/limits`, minus the address space already in
//!   use, `VmSize` in `/proc/self/status`): an allocation beyond it fails however
//!   much memory the machine has;
//! - what the process's cgroup leaves (cgroup v2: `memory.max` minus
//!   `memory.current` of the group named in `/proc/self/cgroup`; containers, batch
//!   schedulers and systemd units set it).
//!
//! Where a file is missing (not Linux, cgroup v1) that limit is not counted.

use std::path::Path;

/// The memory a render may take, and the limit that sets it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Budget {
    /// Bytes.
    pub bytes: u64,
    /// Which limit binds, for the message.
    pub limit: &'static str,
}

/// The least of the limits this process can read (None: none could be read).
pub(super) fn budget() -> Option<Budget> {
    budget_from(
        read("/proc/meminfo").as_deref(),
        read("/proc/self/limits").as_deref(),
        read("/proc/self/status").as_deref(),
        cgroup_left(),
    )
}

/// [`budget`] from the files' contents (`None`: not readable) and the cgroup's
/// room (see [`cgroup_left`]).
fn budget_from(
    meminfo: Option<&str>,
    limits: Option<&str>,
    status: Option<&str>,
    cgroup: Option<u64>,
) -> Option<Budget> {
    let available = meminfo.and_then(|m| kb_field(m, "MemAvailable:"));
    let address_space = limits.and_then(address_space_limit).map(|max| {
        let used = status.and_then(|s| kb_field(s, "VmSize:")).unwrap_or(0);
        max.saturating_sub(used)
    });
    [
        available.map(|bytes| Budget { bytes, limit: "this machine has available" }),
        address_space.map(|bytes| Budget { bytes, limit: "the process's address-space limit (ulimit -v) leaves" }),
        cgroup.map(|bytes| Budget { bytes, limit: "the process's cgroup memory limit leaves" }),
    ]
    .into_iter()
    .flatten()
    .min_by_key(|b| b.bytes)
}

fn read(path: &str) -> Option<String> {
    std::fs::read_to_string(path).ok()
}

/// A `Name:   1234 kB` line's value in bytes.
fn kb_field(text: &str, name: &str) -> Option<u64> {
    let line = text.lines().find(|l| l.starts_with(name))?;
    let kb: u64 = line[name.len()..].split_whitespace().next()?.parse().ok()?;
    Some(kb * 1024)
}

/// The soft limit of `Max address space` in `/proc/self/limits` (bytes;
/// `None` when unlimited).
fn address_space_limit(limits: &str) -> Option<u64> {
    let line = limits.lines().find(|l| l.starts_with("Max address space"))?;
    line["Max address space".len()..].split_whitespace().next()?.parse().ok()
}

/// cgroup v2: `memory.max - memory.current` of this process's group (`None`
/// without a limit or without cgroup v2).
fn cgroup_left() -> Option<u64> {
    let groups = read("/proc/self/cgroup")?;
    let path = groups.lines().find_map(|l| l.strip_prefix("0::"))?;
    let dir = Path::new("/sys/fs/cgroup").join(path.trim_start_matches('/'));
    let max: u64 = std::fs::read_to_string(dir.join("memory.max")).ok()?.trim().parse().ok()?;
    let current: u64 = std::fs::read_to_string(dir.join("memory.current")).ok()?.trim().parse().ok()?;
    Some(max.saturating_sub(current))
}

#[cfg(test)]
mod tests {
    use super::*;

    const MEMINFO: &str = "MemTotal:       24000000 kB\nMemFree:        1000 kB\nMemAvailable:   20000000 kB\n";
    const STATUS: &str = "Name:\trust-v\nVmPeak:\t  300000 kB\nVmSize:\t  200000 kB\n";

    fn limits(soft: &str) -> String {
        format!(
            "Limit                     Soft Limit           Hard Limit           Units     \n\
             Max cpu time              unlimited            unlimited            seconds   \n\
             Max address space         {soft:<20} unlimited            bytes     \n"
        )
    }

    #[test]
    fn the_least_limit_binds() {
        // Only the machine's memory.
        let b = budget_from(Some(MEMINFO), Some(&limits("unlimited")), Some(STATUS), None).unwrap();
        assert_eq!(b, Budget { bytes: 20000000 * 1024, limit: "this machine has available" });
        // ulimit -v 4194304 (4 GiB), 200000 kB already in use.
        let b = budget_from(Some(MEMINFO), Some(&limits("4294967296")), Some(STATUS), None).unwrap();
        assert_eq!(b.bytes, 4294967296 - 200000 * 1024);
        assert!(b.limit.contains("ulimit -v"));
        // A cgroup with 1 GB left.
        let b = budget_from(Some(MEMINFO), Some(&limits("4294967296")), Some(STATUS), Some(1_000_000_000)).unwrap();
        assert_eq!(b.bytes, 1_000_000_000);
        assert!(b.limit.contains("cgroup"));
        // Nothing readable: no budget, nothing refused.
        assert_eq!(budget_from(None, None, None, None), None);
    }

    #[test]
    fn this_process_has_a_budget_on_linux() {
        if Path::new("/proc/meminfo").exists() {
            assert!(budget().is_some_and(|b| b.bytes > 0));
        }
    }
}
