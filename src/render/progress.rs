//! How far a render is: the tiles finished out of the tiles started, for a progress bar.
//!
//! A caller that wants to watch a render runs it inside [`TileProgress::watch`]; every
//! `super::render_tiles` call made on that thread (a render may make several: passes, the
//! environment's term) adds its tiles to the total and counts each finished tile, from
//! whichever worker finished it. Without a watch nothing is counted.

use std::cell::RefCell;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

/// Tiles finished and tiles started, shared between the render and whoever watches it.
#[derive(Debug, Default)]
pub struct TileProgress {
    done: AtomicU64,
    total: AtomicU64,
}

thread_local! {
    static CURRENT: RefCell<Option<Arc<TileProgress>>> = const { RefCell::new(None) };
}

impl TileProgress {
    pub fn new() -> Arc<Self> {
        Arc::new(Self::default())
    }

    /// Runs `work` with `self` counting the tiles of the renders it makes on this thread.
    pub fn watch<R>(self: &Arc<Self>, work: impl FnOnce() -> R) -> R {
        let previous = CURRENT.with(|c| c.replace(Some(self.clone())));
        // Put the previous watch back however `work` ends.
        struct Restore(Option<Arc<TileProgress>>);
        impl Drop for Restore {
            fn drop(&mut self) {
                CURRENT.with(|c| *c.borrow_mut() = self.0.take());
            }
        }
        let _restore = Restore(previous);
        work()
    }

    /// (tiles finished, tiles started).
    pub fn counts(&self) -> (u64, u64) {
        (
            self.done.load(Ordering::Relaxed),
            self.total.load(Ordering::Relaxed),
        )
    }

    /// The watch of this thread, if any.
    pub fn current() -> Option<Arc<TileProgress>> {
        CURRENT.with(|c| c.borrow().clone())
    }

    pub(crate) fn started(&self, tiles: usize) {
        self.total.fetch_add(tiles as u64, Ordering::Relaxed);
    }

    pub(crate) fn finished_one(&self) {
        self.done.fetch_add(1, Ordering::Relaxed);
    }
}
