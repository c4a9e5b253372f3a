//! Other processes' CPU use during calibration, from /proc.

#[allow(unused_imports)]
use super::*;

// ---------------------------------------------------------------------------------------------
// Background load

/// Background load (in CPUs) from which the machine counts as shared: a calibration is
/// flagged, a gate baseline refused, and a scaling study's loss of speedup is not attributed to
/// the code. Calibrating on a machine where another process keeps a CPU busy is the commonest
/// way to get a wrong ceiling: with 2 vCPUs and one busy, 2 threads measure ~1.0x even when
/// the vCPUs are independent cores.
pub const SHARED_MACHINE_CPUS: f64 = 0.25;

/// CPU time counters, in clock ticks (Linux `/proc`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct CpuTicks {
    /// Non-idle time of all CPUs (including time stolen by the hypervisor).
    pub(super) busy: u64,
    /// All time of all CPUs.
    pub(super) total: u64,
    /// CPUs counted.
    pub(super) cpus: usize,
    /// User and system time of this process, all threads.
    pub(super) own: u64,
}

impl CpuTicks {
    /// CPUs' worth of non-idle time not spent by this process between `self` and `later`.
    pub(super) fn background_cpus(&self, later: &CpuTicks) -> Option<f64> {
        let total = later.total.checked_sub(self.total).filter(|&t| t > 0)?;
        let busy = later.busy.saturating_sub(self.busy);
        let own = later.own.saturating_sub(self.own);
        Some(busy.saturating_sub(own) as f64 / total as f64 * self.cpus as f64)
    }
}

pub(super) fn cpu_ticks() -> Option<CpuTicks> {
    let (busy, total, cpus) = parse_proc_stat(&std::fs::read_to_string("/proc/stat").ok()?)?;
    let own = parse_own_ticks(&std::fs::read_to_string("/proc/self/stat").ok()?)?;
    Some(CpuTicks {
        busy,
        total,
        cpus,
        own,
    })
}

/// (busy, total, CPUs) from `/proc/stat`: the aggregate "cpu" line is user, nice, system,
/// idle, iowait, irq, softirq, steal, then guest times already counted in user and nice.
pub(super) fn parse_proc_stat(text: &str) -> Option<(u64, u64, usize)> {
    let line = text.lines().find(|l| l.starts_with("cpu "))?;
    let fields: Vec<u64> = line
        .split_whitespace()
        .skip(1)
        .take(8)
        .map(|f| f.parse().ok())
        .collect::<Option<_>>()?;
    if fields.len() < 5 {
        return None;
    }
    let total: u64 = fields.iter().sum();
    let busy = total - fields[3] - fields[4];
    let cpus = text
        .lines()
        .filter(|l| l.starts_with("cpu") && l.as_bytes().get(3).is_some_and(u8::is_ascii_digit))
        .count();
    (cpus > 0).then_some((busy, total, cpus))
}

/// utime + stime from `/proc/self/stat`: fields 14 and 15, counted after the command name,
/// which is in parentheses and may itself contain spaces and parentheses.
pub(super) fn parse_own_ticks(text: &str) -> Option<u64> {
    let fields: Vec<&str> = text.rsplit_once(')')?.1.split_whitespace().collect();
    let utime: u64 = fields.get(11)?.parse().ok()?;
    let stime: u64 = fields.get(12)?.parse().ok()?;
    Some(utime + stime)
}
