//! CPU time of this process, for honest timings on a shared machine where
//! wall-clock time includes waiting for other processes' work.

/// Seconds of CPU this process has used (all threads, user + system), from
/// `/proc/self/task/*/schedstat` (nanoseconds). `None` where unavailable.
/// Threads that already exited are not counted: compare readings taken
/// while the same thread pool is alive.
pub fn process_cpu_seconds() -> Option<f64> {
    let mut total = 0u64;
    for entry in std::fs::read_dir("/proc/self/task").ok()? {
        let path = entry.ok()?.path().join("schedstat");
        let text = std::fs::read_to_string(path).ok()?;
        total += text.split_whitespace().next()?.parse::<u64>().ok()?;
    }
    Some(total as f64 * 1e-9)
}
