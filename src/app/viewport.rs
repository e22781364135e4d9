//! The viewport's render thread: progressive renders of the current view, restarted (and the
//! old one cancelled between tiles) whenever the camera, scene or settings change. The UI
//! thread never renders; it only uploads the latest frame as a texture. (In the browser,
//! which has no threads, `viewport_web` runs the same render a time slice per frame.)

use super::tonemap::{Aov, ToneMap, aov_values, display};
use crate::render::progressive::ProgressiveFrame;
#[cfg(not(target_arch = "wasm32"))]
use crate::render::progressive::{render_progressive_derivative, render_progressive_with};
use crate::render::{RenderContext, RenderSettings};
use crate::scene::Camera;
use crate::shading::derivative::Motion;
use egui::{Color32, ColorImage};
use std::sync::Arc;
#[cfg(not(target_arch = "wasm32"))]
use std::sync::Mutex;
use std::sync::atomic::AtomicBool;
#[cfg(not(target_arch = "wasm32"))]
use std::sync::atomic::{AtomicU64, Ordering};
#[cfg(not(target_arch = "wasm32"))]
use std::sync::mpsc::{Receiver, Sender, channel};
#[cfg(not(target_arch = "wasm32"))]
use std::thread::JoinHandle;

/// What to render.
#[derive(Clone)]
pub struct RenderJob {
    pub generation: u64,
    pub ctx: Arc<RenderContext>,
    pub camera: Camera,
    pub settings: RenderSettings,
    pub max_passes: u32,
    /// The derivative along this motion instead of the plain image (the derivative AOV).
    pub derivative: Option<Motion>,
    pub cancel: Arc<AtomicBool>,
}

/// A progressive step of the current job, ready to show.
pub struct ViewFrame {
    pub generation: u64,
    pub camera: Camera,
    pub settings: RenderSettings,
    pub frame: ProgressiveFrame,
    /// The display image, mapped on the render thread with the display settings current when
    /// the frame was finished (so the UI thread only uploads it).
    pub display: Option<MappedFrame>,
}

/// A frame mapped to display colours: the settings used, the image, the scalar range.
pub(crate) type MappedFrame = (Display, ColorImage, Option<(f64, f64)>);

/// How frames are mapped to display colours.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Display {
    pub aov: Aov,
    pub exposure: f64,
    pub tonemap: ToneMap,
}

#[cfg(not(target_arch = "wasm32"))]
/// A frame waiting for the denoiser on the compose thread.
struct Pending {
    generation: u64,
    camera: Camera,
    settings: RenderSettings,
    cancel: Arc<AtomicBool>,
    frame: ProgressiveFrame,
}

#[cfg(not(target_arch = "wasm32"))]
/// Publishes finished frames to the UI: maps them to display colours (on the calling thread,
/// never the UI's) and wakes the UI.
#[cfg(not(target_arch = "wasm32"))]
#[derive(Clone)]
struct Publisher {
    latest: Arc<Mutex<Option<Arc<ViewFrame>>>>,
    display: Arc<Mutex<Display>>,
    repaint: Arc<dyn Fn() + Send + Sync>,
}

#[cfg(not(target_arch = "wasm32"))]
impl Publisher {
    fn publish(
        &self,
        generation: u64,
        camera: Camera,
        settings: RenderSettings,
        frame: ProgressiveFrame,
    ) {
        let d = *self.display.lock().unwrap_or_else(|e| e.into_inner());
        let display =
            frame_image(&frame, d.aov, d.exposure, d.tonemap).map(|(img, range)| (d, img, range));
        let mut latest = self.latest.lock().unwrap_or_else(|e| e.into_inner());
        // A late frame of an older view never replaces a newer one.
        if latest.as_ref().is_some_and(|f| f.generation > generation) {
            return;
        }
        *latest = Some(Arc::new(ViewFrame {
            generation,
            camera,
            settings,
            frame,
            display,
        }));
        drop(latest);
        (self.repaint)();
    }
}

#[cfg(not(target_arch = "wasm32"))]
/// The render thread and what it shares with the UI.
pub struct RenderWorker {
    /// Display settings the render thread maps new frames with.
    pub display: Arc<Mutex<Display>>,
    tx: Option<Sender<RenderJob>>,
    handle: Option<JoinHandle<()>>,
    compose_handle: Option<JoinHandle<()>>,
    latest: Arc<Mutex<Option<Arc<ViewFrame>>>>,
    cancel: Arc<AtomicBool>,
    generation: u64,
    /// Generation of the job the thread is working on (0: idle).
    working: Arc<AtomicU64>,
}

#[cfg(not(target_arch = "wasm32"))]
impl RenderWorker {
    /// Starts the render thread and the compose thread; `repaint` is called whenever a new
    /// frame is ready.
    ///
    /// The render thread never runs the whole-image denoiser (it cannot be interrupted): it
    /// hands frames of the denoised methods to the compose thread, which denoises the newest
    /// one still current and publishes it. A change of view therefore waits for one tile.
    pub fn start(repaint: impl Fn() + Send + Sync + 'static) -> Self {
        let repaint: Arc<dyn Fn() + Send + Sync> = Arc::new(repaint);
        let display = Arc::new(Mutex::new(Display {
            aov: Aov::Final,
            exposure: 0.0,
            tonemap: ToneMap::Clamp,
        }));
        let (tx, rx): (Sender<RenderJob>, Receiver<RenderJob>) = channel();
        let (ctx_tx, ctx_rx): (Sender<Pending>, Receiver<Pending>) = channel();
        let latest: Arc<Mutex<Option<Arc<ViewFrame>>>> = Arc::new(Mutex::new(None));
        let working = Arc::new(AtomicU64::new(0));
        // Render threads run at a lower priority than the UI thread, so that the window stays
        // responsive while every core renders. The denoiser gets a pool of its own: a rayon
        // worker that waits inside a job steals other jobs of its pool, so with one shared
        // pool a render job could not return (and the next view not start) until a whole
        // denoising pass it had stolen was done.
        let make_pool = |name: &'static str, nice: i32, threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .thread_name(move |i| format!("penumbra-{name}-{i}"))
                .start_handler(move |_| set_nice(nice))
                .build()
                .map(Arc::new)
                .map_err(|e| eprintln!("{name} thread pool: {e}"))
                .ok()
        };
        let cores = std::thread::available_parallelism().map_or(2, |n| n.get());
        let pool = make_pool("render", RENDER_NICE, cores);
        let pool2 = make_pool("denoise", DENOISE_NICE, (cores / 2).max(1));
        let publisher = Publisher {
            latest: latest.clone(),
            display: display.clone(),
            repaint: repaint.clone(),
        };
        let p2 = publisher.clone();
        let compose_handle = std::thread::Builder::new()
            .name("penumbra-compose".into())
            .spawn(move || {
                set_nice(DENOISE_NICE);
                while let Ok(mut item) = ctx_rx.recv() {
                    while let Ok(newer) = ctx_rx.try_recv() {
                        item = newer;
                    }
                    if item.cancel.load(Ordering::Relaxed) {
                        continue;
                    }
                    let method = item.settings.method;
                    let cancel = Some(&*item.cancel);
                    match &pool2 {
                        Some(pool) => {
                            pool.install(|| item.frame.compose_cancellable(method, cancel))
                        }
                        None => item.frame.compose_cancellable(method, cancel),
                    }
                    if !item.cancel.load(Ordering::Relaxed) {
                        p2.publish(item.generation, item.camera, item.settings, item.frame);
                    }
                }
            })
            .ok();
        let w2 = working.clone();
        let handle = std::thread::Builder::new()
            .name("penumbra-render".into())
            .spawn(move || {
                lower_priority();
                let Some(pool) = pool else {
                    return;
                };
                while let Ok(mut job) = rx.recv() {
                    // Only the newest request matters.
                    while let Ok(newer) = rx.try_recv() {
                        job = newer;
                    }
                    if job.cancel.load(Ordering::Relaxed) {
                        continue;
                    }
                    w2.store(job.generation, Ordering::Relaxed);
                    let result = pool.install(|| {
                        let publish = |f: &ProgressiveFrame| {
                            if !job.cancel.load(Ordering::Relaxed) {
                                publisher.publish(
                                    job.generation,
                                    job.camera,
                                    job.settings,
                                    f.clone(),
                                );
                            }
                        };
                        // The derivative only when it is shown: the plain image's levels
                        // stay as they are.
                        if let Some(motion) = &job.derivative {
                            return render_progressive_derivative(
                                &job.ctx,
                                &job.camera,
                                &job.settings,
                                motion,
                                &job.cancel,
                                publish,
                            );
                        }
                        render_progressive_with(
                            &job.ctx,
                            &job.camera,
                            &job.settings,
                            job.max_passes,
                            &job.cancel,
                            true,
                            |f| {
                                if job.cancel.load(Ordering::Relaxed) {
                                    return;
                                }
                                if f.composed {
                                    publisher.publish(
                                        job.generation,
                                        job.camera,
                                        job.settings,
                                        f.clone(),
                                    );
                                } else {
                                    let _ = ctx_tx.send(Pending {
                                        generation: job.generation,
                                        camera: job.camera,
                                        settings: job.settings,
                                        cancel: job.cancel.clone(),
                                        frame: f.clone(),
                                    });
                                }
                            },
                        )
                    });
                    if let Err(e) = result {
                        eprintln!("render failed: {e}");
                    }
                    w2.store(0, Ordering::Relaxed);
                    (publisher.repaint)();
                }
                drop(ctx_tx); // ends the compose thread
            })
            .expect("spawning the render thread");
        RenderWorker {
            display,
            tx: Some(tx),
            handle: Some(handle),
            compose_handle,
            latest,
            cancel: Arc::new(AtomicBool::new(false)),
            generation: 0,
            working,
        }
    }

    /// Cancels the running render and starts a new one (of the image's derivative along
    /// `derivative`, when given); returns its generation.
    pub fn request(
        &mut self,
        ctx: Arc<RenderContext>,
        camera: Camera,
        settings: RenderSettings,
        max_passes: u32,
        derivative: Option<Motion>,
    ) -> u64 {
        self.cancel.store(true, Ordering::Relaxed);
        self.cancel = Arc::new(AtomicBool::new(false));
        self.generation += 1;
        let job = RenderJob {
            generation: self.generation,
            ctx,
            camera,
            settings,
            max_passes,
            derivative,
            cancel: self.cancel.clone(),
        };
        if let Some(tx) = &self.tx {
            let _ = tx.send(job);
        }
        self.generation
    }

    /// The generation of the last request.
    pub(crate) fn generation(&self) -> u64 {
        self.generation
    }

    /// The newest frame of the newest job, if any has arrived.
    pub fn latest(&self) -> Option<Arc<ViewFrame>> {
        self.latest
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .clone()
            .filter(|f| f.generation == self.generation)
    }

    /// Whether the thread is still rendering the newest job.
    pub(crate) fn is_busy(&self) -> bool {
        self.working.load(Ordering::Relaxed) == self.generation
    }

    /// Nothing: the render thread works on its own (the browser's loop renders here).
    pub(crate) fn tick(&mut self) {}
}

#[cfg(not(target_arch = "wasm32"))]
impl Drop for RenderWorker {
    fn drop(&mut self) {
        self.cancel.store(true, Ordering::Relaxed);
        self.tx = None; // closes the channel: the thread's loop ends
        if let Some(h) = self.handle.take() {
            let _ = h.join();
        }
        if let Some(h) = self.compose_handle.take() {
            let _ = h.join();
        }
    }
}

/// The display image of a frame for an AOV; `None` when the method did not compute it.
pub(crate) fn frame_image(
    frame: &ProgressiveFrame,
    aov: Aov,
    exposure: f64,
    tonemap: ToneMap,
) -> Option<(ColorImage, Option<(f64, f64)>)> {
    let out = &frame.output;
    let values = aov_values(out, aov)?;
    let (w, h) = (out.image.width as usize, out.image.height as usize);
    let (pixels, range): (Vec<Color32>, _) = display(&values, exposure, tonemap);
    if pixels.len() != w * h {
        return None;
    }
    Some((
        ColorImage {
            size: [w, h],
            source_size: egui::vec2(w as f32, h as f32),
            pixels,
        },
        range,
    ))
}

/// Nice value of the render threads: low enough that the UI thread wins the CPU when it needs
/// it, high enough that a continuously repainting UI does not starve the render (measured with
/// `penumbra gui --measure`, docs/workbench.md).
const RENDER_NICE: i32 = 10;

#[cfg(not(target_arch = "wasm32"))]
/// Nice value of the denoiser's threads: below the render's, so that the first tiles of a new
/// view (and the UI) win the CPU over denoising an image that may already be out of date.
const DENOISE_NICE: i32 = 13;

/// Lowers the calling thread's scheduling priority (to [`RENDER_NICE`]) where the platform
/// allows it.
pub(crate) fn lower_priority() {
    set_nice(RENDER_NICE)
}

/// Sets the calling thread's nice value where the platform allows it.
fn set_nice(nice: i32) {
    #[cfg(target_os = "linux")]
    // SAFETY: setpriority only reads its integer arguments; on Linux, PRIO_PROCESS with
    // who = 0 applies to the calling thread.
    unsafe {
        libc::setpriority(libc::PRIO_PROCESS, 0, nice);
    }
    #[cfg(not(target_os = "linux"))]
    let _ = nice;
}
