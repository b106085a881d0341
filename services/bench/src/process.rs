//! A process's CPU time and memory, as the benchmarks report them (Linux `/proc`;
//! `None` elsewhere, printed as such rather than made up): this process's, or a child's
//! by its id (the router `roam bench fleet` runs in its own process).

/// CPU seconds (user + system) used by this process so far, in 100 Hz ticks.
pub fn process_cpu_seconds() -> Option<f64> {
    cpu_seconds_in("/proc/self/stat")
}

/// CPU seconds (user + system) used so far by the process `pid`, in 100 Hz ticks.
pub fn cpu_seconds_of(pid: u32) -> Option<f64> {
    cpu_seconds_in(&format!("/proc/{pid}/stat"))
}

fn cpu_seconds_in(path: &str) -> Option<f64> {
    let stat = std::fs::read_to_string(path).ok()?;
    // The fields after the command name, which is in parentheses and may hold spaces.
    let rest = stat.rsplit_once(')')?.1;
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let utime: f64 = fields.get(11)?.parse().ok()?;
    let stime: f64 = fields.get(12)?.parse().ok()?;
    Some((utime + stime) / 100.0)
}

/// The resident set size now (`VmRSS`), MiB.
pub fn rss_mib() -> Option<f64> {
    status_mib("/proc/self/status", "VmRSS:")
}

/// The peak resident set size so far (`VmHWM`), MiB.
pub fn peak_rss_mib() -> Option<f64> {
    status_mib("/proc/self/status", "VmHWM:")
}

/// The process `pid`'s resident set size now (`VmRSS`), MiB.
pub fn rss_mib_of(pid: u32) -> Option<f64> {
    status_mib(&format!("/proc/{pid}/status"), "VmRSS:")
}

/// The process `pid`'s peak resident set size so far (`VmHWM`), MiB.
pub fn peak_rss_mib_of(pid: u32) -> Option<f64> {
    status_mib(&format!("/proc/{pid}/status"), "VmHWM:")
}

fn status_mib(path: &str, field: &str) -> Option<f64> {
    let status = std::fs::read_to_string(path).ok()?;
    let line = status.lines().find(|l| l.starts_with(field))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

#[cfg(all(test, target_os = "linux"))]
mod tests {
    use super::*;

    #[test]
    fn a_running_process_has_cpu_time_and_memory() {
        let spin: f64 = (0..2_000_000).map(|k| f64::from(k).sqrt()).sum();
        assert!(spin > 0.0);
        assert!(process_cpu_seconds().is_some_and(|s| s >= 0.0));
        let (now, peak) = (rss_mib().expect("VmRSS"), peak_rss_mib().expect("VmHWM"));
        assert!(now > 0.0 && peak >= now, "{now} {peak}");
        let me = std::process::id();
        assert!(cpu_seconds_of(me).is_some_and(|s| s >= 0.0));
        assert!(rss_mib_of(me).is_some_and(|m| m > 0.0));
        assert!(peak_rss_mib_of(me).is_some_and(|m| m > 0.0));
        assert_eq!(rss_mib_of(u32::MAX), None);
    }
}
