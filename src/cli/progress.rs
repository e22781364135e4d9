//! A progress bar on the terminal for work that takes more than a second: tiles done, the
//! rate, the time left. Quiet when standard error is not a terminal (piped, redirected, CI).

use penumbra::render::progress::TileProgress;
use std::io::{IsTerminal, Write};
use std::sync::mpsc::RecvTimeoutError;
use std::time::{Duration, Instant};

/// The bar appears once the work has run this long.
const DELAY: Duration = Duration::from_secs(1);
const REFRESH: Duration = Duration::from_millis(200);

/// Runs `work`, counting the tiles of its renders, with a bar on standard error while it
/// runs (once it has taken more than [`DELAY`], and only on a terminal).
pub(crate) fn with_tile_bar<R>(work: impl FnOnce() -> R) -> R {
    if !std::io::stderr().is_terminal() {
        return work();
    }
    let progress = TileProgress::new();
    let (finished, wait) = std::sync::mpsc::channel::<()>();
    std::thread::scope(|s| {
        let progress = &progress;
        s.spawn(move || {
            let start = Instant::now();
            let mut shown = false;
            // Until the work ends (a message, or the sender dropped by a panic).
            while let Err(RecvTimeoutError::Timeout) = wait.recv_timeout(REFRESH) {
                let elapsed = start.elapsed();
                if elapsed < DELAY {
                    continue;
                }
                let (done, total) = progress.counts();
                eprint!("\r{}", bar_line(done, total, elapsed.as_secs_f64()));
                let _ = std::io::stderr().flush();
                shown = true;
            }
            if shown {
                // Clear the line for what the command prints next.
                eprint!("\r{}\r", " ".repeat(78));
            }
        });
        let out = progress.watch(work);
        let _ = finished.send(());
        out
    })
}

/// "[#####-----] 120/480 tiles, 35.2 tiles/s, 10 s left".
fn bar_line(done: u64, total: u64, seconds: f64) -> String {
    const WIDTH: usize = 30;
    let fraction = if total == 0 {
        0.0
    } else {
        done as f64 / total as f64
    };
    let filled = ((fraction * WIDTH as f64) as usize).min(WIDTH);
    let rate = done as f64 / seconds.max(1e-9);
    let left = if done == 0 {
        "time left unknown".to_string()
    } else {
        format!("{:.0} s left", (total - done.min(total)) as f64 / rate)
    };
    format!(
        "[{}{}] {done}/{total} tiles, {rate:.1} tiles/s, {left}",
        "#".repeat(filled),
        "-".repeat(WIDTH - filled)
    )
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_bar_says_how_far_and_how_long() {
        assert_eq!(
            super::bar_line(120, 480, 4.0),
            "[#######-----------------------] 120/480 tiles, 30.0 tiles/s, 12 s left"
        );
        assert!(super::bar_line(0, 480, 1.5).ends_with("time left unknown"));
    }
}
