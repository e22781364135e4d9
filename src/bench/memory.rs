//! Peak resident memory of this process, for the reports of `bench` and `stress`.
//!
//! Linux keeps the peak (`VmHWM` in `/proc/self/status`) and resets it when `5` is written to
//! `/proc/self/clear_refs`, so a report can give each row its own peak: reset, run, read.
//! Elsewhere (and in the browser) both are absent: the reports then say nothing of memory.

/// Resets the peak to the current resident size; false where the system cannot.
pub(crate) fn reset_peak() -> bool {
    #[cfg(target_os = "linux")]
    {
        std::fs::write("/proc/self/clear_refs", "5").is_ok()
    }
    #[cfg(not(target_os = "linux"))]
    {
        false
    }
}

/// The peak resident size since the process started or the last [`reset_peak`], in MB
/// (10⁶ bytes).
pub(crate) fn peak_mb() -> Option<f64> {
    #[cfg(target_os = "linux")]
    {
        let status = std::fs::read_to_string("/proc/self/status").ok()?;
        let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
        let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
        Some(kb * 1024.0 / 1e6)
    }
    #[cfg(not(target_os = "linux"))]
    {
        None
    }
}

#[cfg(test)]
mod tests {
    #[cfg(target_os = "linux")]
    #[test]
    fn the_peak_sees_an_allocation_and_resets() {
        assert!(super::reset_peak());
        let before = super::peak_mb().unwrap();
        // 64 MB touched page by page.
        // black_box: a release build would drop an allocation nothing reads.
        let big = std::hint::black_box(vec![1u8; 64 << 20]);
        let during = super::peak_mb().unwrap();
        assert!(during >= before + 60.0, "{before} MB, then {during} MB");
        drop(big);
        assert!(super::reset_peak());
        let after = super::peak_mb().unwrap();
        assert!(
            after < during - 60.0,
            "{during} MB, after the reset {after} MB"
        );
    }
}
