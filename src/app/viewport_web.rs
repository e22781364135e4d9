//! The viewport's render loop in the browser, where the page has one thread: the same
//! progressive render as the desktop's render thread (`render_progressive_with`), run a time
//! slice per UI frame under a [`Slicer`] so that the page never waits for more than one slice.
//! Frames are the desktop's, bit for bit (`render::slicing`); they are mapped to display
//! colours here, as the desktop's render thread maps them before handing them over.

use super::tonemap::{Aov, ToneMap};
use super::viewport::{Display, ViewFrame, frame_image};
use crate::render::progressive::{
    ProgressiveFrame, render_progressive_derivative, render_progressive_with,
};
use crate::render::slicing::Slicer;
use crate::render::{RenderContext, RenderSettings};
use crate::scene::Camera;
use crate::shading::derivative::Motion;
use std::sync::{Arc, Mutex};
use web_time::Duration;

/// How long a slice may render before the page gets its thread back: the page stays at
/// 20 frames a second or more while the view renders.
const SLICE: Duration = Duration::from_millis(40);

/// A render in progress.
struct Running {
    generation: u64,
    ctx: Arc<RenderContext>,
    camera: Camera,
    settings: RenderSettings,
    max_passes: u32,
    /// The derivative along this motion instead of the plain image.
    derivative: Option<Motion>,
    slicer: Slicer,
    /// The newest frame published (coarsest level first, then passes): a slice replays
    /// the frames of finished levels and passes it still holds.
    published: Option<(std::cmp::Reverse<u32>, u32)>,
    started: web_time::Instant,
    slices: u32,
    /// Time spent rendering (the slices, replays included), against `started`'s wall time.
    busy: Duration,
}

/// The render loop and what the UI reads of it (the desktop's `RenderWorker`'s interface).
pub(crate) struct RenderWorker {
    /// Display settings new frames are mapped with.
    pub display: Arc<Mutex<Display>>,
    running: Option<Running>,
    latest: Option<Arc<ViewFrame>>,
    generation: u64,
    repaint: Arc<dyn Fn() + Send + Sync>,
}

impl RenderWorker {
    /// A render loop that runs in [`RenderWorker::tick`]; `repaint` asks for the next frame.
    pub(crate) fn start(repaint: impl Fn() + Send + Sync + 'static) -> Self {
        RenderWorker {
            display: Arc::new(Mutex::new(Display {
                aov: Aov::Final,
                exposure: 0.0,
                tonemap: ToneMap::Clamp,
            })),
            running: None,
            latest: None,
            generation: 0,
            repaint: Arc::new(repaint),
        }
    }

    /// Drops the running render and starts a new one; returns its generation.
    pub(crate) fn request(
        &mut self,
        ctx: Arc<RenderContext>,
        camera: Camera,
        settings: RenderSettings,
        max_passes: u32,
        derivative: Option<Motion>,
    ) -> u64 {
        self.generation += 1;
        self.running = Some(Running {
            generation: self.generation,
            ctx,
            camera,
            settings,
            max_passes,
            derivative,
            slicer: Slicer::new(),
            published: None,
            started: web_time::Instant::now(),
            slices: 0,
            busy: Duration::ZERO,
        });
        (self.repaint)();
        self.generation
    }

    /// Renders one slice of the running render and publishes the frames it finished.
    pub(crate) fn tick(&mut self) {
        let Some(run) = &mut self.running else {
            return;
        };
        let mut newest: Option<ProgressiveFrame> = None;
        run.slices += 1;
        let slice_start = web_time::Instant::now();
        let (result, finished) = run.slicer.run(SLICE, |cancel| {
            let mut keep = |f: &ProgressiveFrame| {
                let key = Some((std::cmp::Reverse(f.scale), f.passes));
                if key > run.published {
                    run.published = key;
                    newest = Some(f.clone());
                }
            };
            match &run.derivative {
                Some(motion) => render_progressive_derivative(
                    &run.ctx,
                    &run.camera,
                    &run.settings,
                    motion,
                    cancel,
                    &mut keep,
                ),
                None => render_progressive_with(
                    &run.ctx,
                    &run.camera,
                    &run.settings,
                    run.max_passes,
                    cancel,
                    false,
                    &mut keep,
                ),
            }
        });
        run.busy += slice_start.elapsed();
        let d = *self.display.lock().unwrap_or_else(|e| e.into_inner());
        // Only the newest frame of the slice is worth mapping.
        if let Some(mut frame) = newest {
            // Since the render started, not since this slice's replay did.
            frame.elapsed = run.started.elapsed().as_secs_f64();
            let display = frame_image(&frame, d.aov, d.exposure, d.tonemap)
                .map(|(img, range)| (d, img, range));
            self.latest = Some(Arc::new(ViewFrame {
                generation: run.generation,
                camera: run.camera,
                settings: run.settings,
                frame,
                display,
            }));
        }
        if let Err(e) = result {
            web_sys::console::error_1(&format!("render failed: {e}").into());
            self.running = None;
        } else if finished {
            // The browser's measure of render speed (docs/web.md): the whole progressive
            // render of the view, in slices, as the page saw it.
            super::platform::note(&format!(
                "render {} finished: {}×{} {} in {:.2} s, {:.2} s of it rendering ({} slices); \
                 the page's memory {} MB",
                run.generation,
                run.settings.width,
                run.settings.height,
                run.settings.method.name(),
                run.started.elapsed().as_secs_f64(),
                run.busy.as_secs_f64(),
                run.slices,
                core::arch::wasm32::memory_size(0) * 65536 / (1 << 20)
            ));
            self.running = None;
        }
        (self.repaint)();
    }

    /// The newest frame of the newest render, if any has been finished.
    pub(crate) fn latest(&self) -> Option<Arc<ViewFrame>> {
        self.latest
            .clone()
            .filter(|f| f.generation == self.generation)
    }

    /// Whether the newest render is still running.
    pub(crate) fn is_busy(&self) -> bool {
        self.running.is_some()
    }
}
