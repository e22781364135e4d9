//! Time slices: a render that runs on a thread which must not block for long (a browser page
//! has only one) is run again and again, a slice of its tiles at a time, until it is done.
//!
//! Every renderer evaluates its pixels through `render_tiles`. While a
//! [`Slicer`] is installed on the calling thread ([`Slicer::run`], as rayon's
//! `ThreadPool::install` installs a pool), `render_tiles` keeps each call's finished tiles in
//! the slicer's memo, computes new tiles until the slice's deadline, and then answers as a
//! cancelled render does: `None`, with the slicer's cancel flag raised, so that every caller
//! stops as it stops for a change of view. The next slice runs the same work again from the
//! start; calls already finished are answered from the memo at once and the first unfinished
//! one continues where it stopped. Since a render makes the same calls in the same order
//! each time, the n-th call of a run is the n-th call of the memo, and the image is the one
//! an uninterrupted render makes, bit for bit (`tests::a_sliced_render_is_the_whole_render`).
//!
//! What lies between the tile calls (assembling an image, the denoiser, accumulating passes)
//! would run again in every slice. The work marks such stretches as [`step`]s: once a step has
//! finished, later slices take a copy of its result and skip it (and its tile calls), so a
//! slice replays each finished level or pass of a progressive render at the cost of a copy;
//! and once a later level or pass has finished, an earlier one is skipped altogether.

use std::any::Any;
use std::cell::{Cell, RefCell};
use std::sync::atomic::{AtomicBool, Ordering};
use web_time::{Duration, Instant};

/// The tiles of one slice-spanning render: its memo and the current slice's deadline.
#[derive(Default)]
pub struct Slicer {
    /// Per `render_tiles` call of the work, in call order: a `Vec<Vec<T>>` of finished tiles.
    memo: RefCell<Vec<Box<dyn Any>>>,
    /// The next call's index in this slice.
    call: Cell<usize>,
    deadline: Cell<Option<Instant>>,
    /// A tile was computed in this slice (each slice computes at least one, so work advances
    /// however short the slice).
    progressed: Cell<bool>,
    /// Raised when the slice's time is up: the work's cancel flag.
    out_of_time: AtomicBool,
    /// Per [`step`] of the work, in order: its result once it finished, and how many
    /// `render_tiles` calls it made (skipped with it).
    steps: RefCell<Vec<Option<Kept>>>,
    /// The next step's index in this slice.
    step: Cell<usize>,
}

/// Runs `compute`, a stretch of sliced work (outside a slicer, any render: then this is just
/// `Some(compute())`), and keeps its result once it has finished within a slice, so that later
/// slices take a copy instead of running it again. A step cut short by its slice's end runs
/// again from its start in the next slice, its finished tiles kept.
///
/// Steps made at the same place in the code form a series (the levels of a progressive
/// render; its passes), of which each supersedes the one before: once a step has finished, the
/// earlier ones of its series are dropped (their results and tiles) and answer `None`, and
/// the caller skips them. So what a slicer keeps is bounded by a render's series, not by its
/// length.
#[track_caller]
pub fn step<T: Clone + 'static>(compute: impl FnOnce() -> T) -> Option<T> {
    let site = std::panic::Location::caller();
    let p = CURRENT.with(|c| c.get());
    if p.is_null() {
        return Some(compute());
    }
    // SAFETY: as in `Slicer::with_current`.
    let slicer = unsafe { &*p };
    let i = slicer.step.get();
    slicer.step.set(i + 1);
    let kept = slicer.steps.borrow().get(i).and_then(|s| match s {
        Some(Kept::Done { value, calls, .. }) => {
            value.downcast_ref::<T>().map(|v| (Some(v.clone()), *calls))
        }
        Some(Kept::Superseded { calls }) => Some((None, *calls)),
        None => None,
    });
    if let Some((value, calls)) = kept {
        slicer.call.set(slicer.call.get() + calls);
        return value;
    }
    let before = slicer.call.get();
    let value = compute();
    if !slicer.out_of_time.load(Ordering::Relaxed) {
        let after = slicer.call.get();
        // Its tiles are not needed again: the step is skipped with them from now on.
        for tiles in slicer.memo.borrow_mut().iter_mut().take(after).skip(before) {
            *tiles = Box::new(());
        }
        let mut steps = slicer.steps.borrow_mut();
        for earlier in steps.iter_mut().take(i) {
            if let Some(Kept::Done { site: s, calls, .. }) = earlier
                && *s == site
            {
                *earlier = Some(Kept::Superseded { calls: *calls });
            }
        }
        if steps.len() <= i {
            steps.resize_with(i + 1, || None);
        }
        steps[i] = Some(Kept::Done {
            value: Box::new(value.clone()),
            calls: after - before,
            site,
        });
    }
    Some(value)
}

/// A finished step: its result, the number of `render_tiles` calls it made, and where in the
/// code it was made; or, once a later step made there has finished, only the calls to skip.
enum Kept {
    Done {
        value: Box<dyn Any>,
        calls: usize,
        site: &'static std::panic::Location<'static>,
    },
    Superseded {
        calls: usize,
    },
}

thread_local! {
    static CURRENT: Cell<*const Slicer> = const { Cell::new(std::ptr::null()) };
}

impl Slicer {
    pub fn new() -> Self {
        Self::default()
    }

    /// Runs `work` for one slice of at most about `budget` of new tiles. `work` gets the flag
    /// to pass as its cancel flag; it is raised when the slice ends before the work does.
    /// Returns what `work` returns and whether the work was finished (no tile was left).
    pub fn run<R>(&self, budget: Duration, work: impl FnOnce(&AtomicBool) -> R) -> (R, bool) {
        self.call.set(0);
        self.step.set(0);
        self.progressed.set(false);
        self.out_of_time.store(false, Ordering::Relaxed);
        self.deadline.set(Some(Instant::now() + budget));
        struct Restore(*const Slicer);
        impl Drop for Restore {
            fn drop(&mut self) {
                CURRENT.with(|c| c.set(self.0));
            }
        }
        let _restore = Restore(CURRENT.with(|c| c.replace(self as *const Slicer)));
        let r = work(&self.out_of_time);
        (r, !self.out_of_time.load(Ordering::Relaxed))
    }

    /// What the slicer holds: the results of finished steps it keeps, and the `render_tiles`
    /// calls whose tiles it keeps.
    pub fn held(&self) -> (usize, usize) {
        let results = self
            .steps
            .borrow()
            .iter()
            .filter(|s| matches!(s, Some(Kept::Done { .. })))
            .count();
        let tiles = self.memo.borrow().iter().filter(|t| !t.is::<()>()).count();
        (results, tiles)
    }

    /// The slicer installed on this thread by [`Slicer::run`], if any.
    pub(crate) fn with_current<R>(f: impl FnOnce(&Slicer) -> R) -> Option<R> {
        let p = CURRENT.with(|c| c.get());
        // SAFETY: `p` is set only by `run`, which borrows the slicer for as long as it is
        // installed and puts the previous value back when it returns or unwinds.
        (!p.is_null()).then(|| f(unsafe { &*p }))
    }

    /// The tiles of the current `render_tiles` call: from the memo, then computed in order
    /// (`tile(scratch, t)`) until the slice's deadline. `None` when time ran out first.
    pub(crate) fn tiles<T: Clone + 'static, S>(
        &self,
        count: usize,
        init: impl Fn() -> S,
        tile: impl Fn(&mut S, usize) -> Vec<T>,
    ) -> Option<Vec<Vec<T>>> {
        if self.out_of_time.load(Ordering::Relaxed) {
            return None;
        }
        let call = self.call.get();
        self.call.set(call + 1);
        let mut memo = self.memo.borrow_mut();
        while memo.len() <= call {
            memo.push(Box::new(()));
        }
        // A new call; or one of another pixel type at this index, which would mean the work
        // changed: start the call afresh rather than misread it.
        if !memo[call].is::<Vec<Vec<T>>>() {
            memo[call] = Box::new(Vec::<Vec<T>>::new());
        }
        let done = memo[call]
            .downcast_mut::<Vec<Vec<T>>>()
            .expect("the memo entry was just made of this type");
        let mut scratch = None;
        while done.len() < count {
            let late = self.deadline.get().is_some_and(|d| Instant::now() >= d);
            if late && self.progressed.get() {
                self.out_of_time.store(true, Ordering::Relaxed);
                return None;
            }
            let s = scratch.get_or_insert_with(&init);
            done.push(tile(s, done.len()));
            self.progressed.set(true);
        }
        Some(done.clone())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::progressive::render_progressive;
    use crate::render::{RenderContext, RenderMethod, RenderSettings};
    use crate::scene::scene_file;

    /// Every frame a sliced progressive render emits, in order, equals the frame the whole
    /// render emits at that place, bit for bit, however short the slices: for every method,
    /// which holds only if each makes the same tile calls in the same order every time.
    #[test]
    fn a_sliced_render_is_the_whole_render() {
        let scene = scene_file::load_embedded("default").expect("the default scene");
        let ctx = RenderContext::new(&scene);
        let camera = scene.camera.expect("a camera");
        for method in RenderMethod::ALL {
            // Several passes for the stochastic methods, whose passes accumulate.
            let passes = if method.analytic().is_some() { 1 } else { 3 };
            let settings = RenderSettings {
                width: 96,
                height: 64,
                method,
                spp: 2,
                ..RenderSettings::default()
            };
            let mut whole = Vec::new();
            let never = AtomicBool::new(false);
            render_progressive(&ctx, &camera, &settings, passes, &never, |f| {
                whole.push(f.output.image.clone())
            })
            .unwrap();
            let slicer = Slicer::new();
            let mut sliced = Vec::new();
            let mut slices = 0;
            let mut newest = None;
            loop {
                slices += 1;
                let (_, finished) = slicer.run(Duration::from_micros(50), |cancel| {
                    render_progressive(&ctx, &camera, &settings, passes, cancel, |f| {
                        // A slice replays the frames of finished levels and passes it holds.
                        let key = Some((std::cmp::Reverse(f.scale), f.passes));
                        if key > newest {
                            newest = key;
                            sliced.push(f.output.image.clone());
                        }
                    })
                    .unwrap()
                });
                if finished {
                    break;
                }
                assert!(slices < 100_000, "the slices do not advance");
            }
            // Bounded by the render's series (its levels, its passes), not by its length: the
            // newest level's and the newest pass's results, and no tiles of finished steps.
            let (results, tiles) = slicer.held();
            assert!(results <= 2, "{method:?}: {results} results held");
            assert_eq!(tiles, 0, "{method:?}: tiles of finished steps held");
            assert!(
                slices > 10,
                "{method:?}: {slices} slices: the test slices nothing"
            );
            assert_eq!(whole.len(), sliced.len(), "{method:?}");
            for (k, (a, b)) in whole.iter().zip(&sliced).enumerate() {
                assert_eq!(a.pixels, b.pixels, "{method:?}: frame {k}");
            }
        }
    }
}
