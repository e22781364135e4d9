//! `penumbra bench` run from the workbench on the current view, in the background (a
//! low-priority thread), with its progress for a progress bar. The same `bench::runner` as
//! the command line; its files land in `out/bench/workbench/`.

use crate::bench::runner::{BenchConfig, render_reference, run_bench};
use crate::bench::{output, table::BenchReport};
use crate::render::RenderContext;
use crate::scene::Camera;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

/// What a finished bench run produced: the report and the files written.
pub(crate) type BenchOutcome = crate::Result<(BenchReport, Vec<PathBuf>)>;

/// Progress and outcome of a background bench run.
#[derive(Default)]
pub(crate) struct BenchProgress {
    pub done: usize,
    pub total: usize,
    pub label: String,
    pub result: Option<BenchOutcome>,
}

/// A running (or finished) bench.
pub(crate) struct BenchJob {
    pub progress: Arc<Mutex<BenchProgress>>,
}

impl BenchJob {
    /// Starts `penumbra bench` on `camera` at `width`×`height` with a short ladder.
    pub(crate) fn start(
        ctx: Arc<RenderContext>,
        scene: String,
        camera: Camera,
        width: u32,
        height: u32,
    ) -> Self {
        let progress = Arc::new(Mutex::new(BenchProgress {
            label: "reference".into(),
            ..Default::default()
        }));
        let p2 = progress.clone();
        let spawned = std::thread::Builder::new()
            .name("penumbra-bench".into())
            .spawn(move || {
                super::viewport::lower_priority();
                let pool = rayon::ThreadPoolBuilder::new()
                    .start_handler(|_| super::viewport::lower_priority())
                    .build();
                let result = match pool {
                    Ok(pool) => pool.install(|| run(&ctx, &scene, camera, width, height, &p2)),
                    Err(e) => Err(crate::Error::from(e.to_string())),
                };
                p2.lock().unwrap_or_else(|e| e.into_inner()).result = Some(result);
            });
        if let Err(e) = spawned {
            progress.lock().unwrap_or_else(|e| e.into_inner()).result =
                Some(Err(crate::Error::from(e.to_string())));
        }
        BenchJob { progress }
    }

    /// (fraction done, label, finished result).
    pub(crate) fn poll(&self) -> (f32, String, Option<BenchOutcome>) {
        let mut p = self.progress.lock().unwrap_or_else(|e| e.into_inner());
        let frac = if p.total > 0 {
            p.done as f32 / p.total as f32
        } else {
            0.0
        };
        (frac, p.label.clone(), p.result.take())
    }
}

fn run(
    ctx: &RenderContext,
    scene: &str,
    camera: Camera,
    width: u32,
    height: u32,
    progress: &Mutex<BenchProgress>,
) -> BenchOutcome {
    let label = std::path::Path::new(scene)
        .file_stem()
        .map_or(scene.to_string(), |s| s.to_string_lossy().into_owned());
    let mut config = BenchConfig::new(&label, camera, width, height);
    config.ladder = vec![1, 4, 16, 64];
    config.reference_spp = 1024;
    let reference = render_reference(ctx, &config, None)?;
    let (report, strip) = run_bench(ctx, &config, &reference, None, |done, total, what| {
        let mut p = progress.lock().unwrap_or_else(|e| e.into_inner());
        p.done = done;
        p.total = total;
        p.label = what.to_string();
    })?;
    let dir = PathBuf::from("out/bench/workbench");
    let files =
        output::write_bench_files(&report, &strip, &dir, 0.0).map_err(|e| format!("{e:#}"))?;
    Ok((report, files))
}
