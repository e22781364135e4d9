//! `penumbra bench`: run time against error (one mode per function).

use super::args::*;
use super::render::{camera, load_scene, stderr_path};
use anyhow::{Context, Result, bail};
use penumbra::raster::Image;
use penumbra::raster::io as image_io;
use penumbra::scene::environment_spec::EnvironmentSpec;
use penumbra::scene::scene_file;
use std::path::{Path, PathBuf};

pub(crate) fn bench(args: &BenchArgs) -> Result<()> {
    use penumbra::bench::{output, runner, scaling};
    if let Some(json) = &args.from_json {
        let report = penumbra::bench::table::read_json(json)
            .with_context(|| format!("{}", json.display()))?;
        let dir = args.out_dir.clone().unwrap_or_else(|| {
            json.parent()
                .map_or_else(|| PathBuf::from("."), Path::to_path_buf)
        });
        say!("{}", output::equal_time_markdown(&report));
        for f in output::write_bench_files(&report, &[], &dir, args.exposure)? {
            say!("wrote {}", f.display());
        }
        return Ok(());
    }
    match args.suite {
        Some(BenchSuite::Realworld) => return bench_realworld(args),
        Some(BenchSuite::Speed) => return bench_speed(args),
        None => {}
    }
    if let Some(name) = &args.env {
        return bench_environment(args, name);
    }
    if args.polyhedra {
        let report = penumbra::bench::polyhedra::run_polyhedra(
            args.size.0,
            args.size.1,
            args.repeats,
            &super::process_env::prepare_config(),
            |m| eprintln!("{m}"),
        )
        .map_err(anyhow::Error::msg)?;
        let dir = args
            .out_dir
            .clone()
            .unwrap_or_else(|| PathBuf::from("out/bench/polyhedra"));
        std::fs::create_dir_all(&dir).with_context(|| format!("{}", dir.display()))?;
        let md = penumbra::bench::polyhedra::polyhedra_markdown(&report);
        say!("{md}");
        let files = [
            (dir.join("polyhedra.md"), md),
            (
                dir.join("polyhedra.json"),
                serde_json::to_string_pretty(&report)?,
            ),
        ];
        for (path, text) in files {
            std::fs::write(&path, text).with_context(|| format!("{}", path.display()))?;
            say!("wrote {}", path.display());
        }
        return Ok(());
    }
    if args.scaling {
        let base = scene_file::load_embedded("fig4")?;
        let config = scaling::ScalingConfig {
            max_copies: args.max_copies.max(2),
            max_level: args.max_level,
            width: args.size.0,
            height: args.size.1,
            repeats: args.repeats,
            prepare: super::process_env::prepare_config(),
        };
        let report = scaling::run_scaling(&base, &config, |m| eprintln!("{m}"))
            .map_err(anyhow::Error::msg)?;
        let dir = args
            .out_dir
            .clone()
            .unwrap_or_else(|| PathBuf::from("out/bench/scaling"));
        say!("{}", output::scaling_markdown(&report));
        for f in output::write_scaling_files(&report, &dir)? {
            say!("wrote {}", f.display());
        }
        return Ok(());
    }
    let Some(scene_name) = args.scene.clone() else {
        bail!("bench needs a SCENE (or --scaling)");
    };
    let scene = load_scene(&scene_name)?;
    let cam = camera(&args.camera, &scene)?;
    let label = Path::new(&scene_name)
        .file_stem()
        .map_or(scene_name.clone(), |s| s.to_string_lossy().into_owned());
    let dir = args
        .out_dir
        .clone()
        .unwrap_or_else(|| PathBuf::from("out/bench").join(&label));
    std::fs::create_dir_all(&dir).with_context(|| format!("{}", dir.display()))?;
    let mut config = runner::BenchConfig::new(&label, cam, args.size.0, args.size.1);
    config.aa = args.aa;
    config.ladder = args.ladder.clone();
    if !args.methods.is_empty() {
        config.methods = args.methods.clone();
    }
    config.reference_spp = args.reference_spp;
    config.seed = args.seed;
    config.repeats = args.repeats;
    config.derivative = args.derivative.clone();
    config.prepare = super::process_env::prepare_config();
    let ctx = config.prepare(&scene);
    let reference = match &args.reference {
        Some(path) => {
            let read = |p: &Path| -> Result<Image> {
                image_io::read_pfm_image(p).with_context(|| format!("{}", p.display()))
            };
            runner::ReferenceImage {
                image: read(path)?,
                stderr: read(&stderr_path(path))?,
                spp: args.reference_spp,
                seconds: f64::NAN,
            }
        }
        None => {
            eprintln!(
                "rendering the reference ({} spp, {}x{})...",
                config.reference_spp, config.width, config.height
            );
            let r = runner::render_reference(&ctx, &config, None).map_err(anyhow::Error::msg)?;
            let p = dir.join("reference.pfm");
            image_io::write_pfm(&p, r.image.width, r.image.height, &r.image.to_rgb32())?;
            let e = stderr_path(&p);
            image_io::write_pfm(&e, r.stderr.width, r.stderr.height, &r.stderr.to_rgb32())?;
            say!(
                "reference: {:.1} s; wrote {} and {}",
                r.seconds,
                p.display(),
                e.display()
            );
            r
        }
    };
    let (report, strip) = runner::run_bench(&ctx, &config, &reference, None, |k, n, what| {
        eprintln!("[{k}/{n}] {what}")
    })
    .map_err(anyhow::Error::msg)?;
    say!("{}", output::equal_time_markdown(&report));
    let seconds = |name: &str| {
        report
            .rows
            .iter()
            .find(|r| r.method == name)
            .map(|r| r.seconds)
    };
    if let (Some(d), Some(a)) = (seconds("analytic+derivative"), seconds("analytic")) {
        say!(
            "the image with its derivative along {}: {d:.3} s, {:.2}x the analytic render ({a:.3} s)",
            config.derivative.as_deref().unwrap_or(""),
            d / a
        );
    }
    for f in output::write_bench_files(&report, &strip, &dir, args.exposure)? {
        say!("wrote {}", f.display());
    }
    Ok(())
}

/// `penumbra bench --env SCENE`.
pub fn bench_environment(args: &BenchArgs, name: &str) -> Result<()> {
    use penumbra::bench::environment_tables::{
        EnvBenchOptions, environment_markdown, run_environment_bench,
    };
    let mut scene = load_scene(name)?;
    if scene.environment.is_none() {
        scene.environment =
            Some(EnvironmentSpec::new("sky", None, None, None, None).map_err(anyhow::Error::msg)?);
    }
    let cam = camera(&args.camera, &scene)?;
    let ladder = if args.ladder == [1, 2, 4, 8, 16, 32, 64, 128, 256] {
        vec![16, 32, 64, 128, 256, 512]
    } else {
        args.ladder.clone()
    };
    let opts = EnvBenchOptions {
        width: args.size.0,
        height: args.size.1,
        aa: args.aa,
        reference_spp: args.reference_spp,
        ladder,
        repeats: args.repeats,
        seed: args.seed,
        prepare: super::process_env::prepare_config(),
    };
    let report = run_environment_bench(name, &scene, &cam, &opts, |m| eprintln!("{m}"))
        .map_err(anyhow::Error::msg)?;
    let stem = Path::new(name)
        .file_stem()
        .map_or_else(|| name.to_string(), |s| s.to_string_lossy().into_owned());
    let dir = args
        .out_dir
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("out/bench/env_{stem}")));
    std::fs::create_dir_all(&dir).with_context(|| format!("{}", dir.display()))?;
    let md = environment_markdown(&report);
    say!("{md}");
    for (path, text) in [
        (dir.join("environment.md"), md),
        (
            dir.join("environment.json"),
            serde_json::to_string_pretty(&report)?,
        ),
    ] {
        std::fs::write(&path, text).with_context(|| format!("{}", path.display()))?;
        say!("wrote {}", path.display());
    }
    Ok(())
}

/// `penumbra bench --suite realworld`.
pub fn bench_realworld(args: &BenchArgs) -> Result<()> {
    use penumbra::bench::realworld::{RealWorldConfig, realworld_markdown, run_realworld};
    let config = RealWorldConfig {
        width: args.size.0,
        height: args.size.1,
        aa: args.aa,
        reference_spp: args.reference_spp,
        repeats: args.repeats,
        seed: args.seed,
        only: args.only.clone(),
        prepare: super::process_env::prepare_config(),
    };
    let dir = args
        .out_dir
        .clone()
        .unwrap_or_else(|| PathBuf::from("out/bench/realworld"));
    std::fs::create_dir_all(&dir).with_context(|| format!("{}", dir.display()))?;
    // The tables are written again after every scene, so that a long run leaves what it did.
    let write = |report: &penumbra::bench::realworld::RealWorldReport| -> Result<[PathBuf; 2]> {
        let files = [
            (dir.join("realworld.md"), realworld_markdown(report)),
            (
                dir.join("realworld.json"),
                serde_json::to_string_pretty(report)?,
            ),
        ];
        for (path, text) in &files {
            std::fs::write(path, text).with_context(|| format!("{}", path.display()))?;
        }
        Ok(files.map(|f| f.0))
    };
    let report = run_realworld(
        &dir,
        &config,
        |m| eprintln!("{m}"),
        |partial| {
            if let Err(e) = write(partial) {
                eprintln!("warning: {e:#}");
            }
        },
    )
    .map_err(anyhow::Error::msg)?;
    let md = realworld_markdown(&report);
    say!("{md}");
    for row in &report.scenes {
        for n in row.warnings.iter().chain(&row.notes) {
            say!("{}: {n}", row.scene);
        }
    }
    for path in write(&report)? {
        say!("wrote {}", path.display());
    }
    Ok(())
}

/// `penumbra bench --suite speed`: the speed guard. Fails (exit status 1) when a ratio grew
/// past the baseline's tolerance in two measurements of its scene.
pub fn bench_speed(args: &BenchArgs) -> Result<()> {
    use penumbra::bench::speed::{
        SpeedBaseline, SpeedConfig, SpeedRow, measure_named, run_speed, speed_markdown,
    };
    if let (Some(name), Some(config)) = (&args.measure_scene, &args.speed_config) {
        let mut config: SpeedConfig = serde_json::from_str(config).context("--speed-config")?;
        config.prepare = super::process_env::prepare_config();
        let row = measure_named(name, &config).map_err(anyhow::Error::msg)?;
        println!("{}", serde_json::to_string(&row)?);
        return Ok(());
    }
    let baseline: Option<SpeedBaseline> = match &args.baseline {
        Some(p) => Some(
            serde_json::from_str(
                &std::fs::read_to_string(p).with_context(|| format!("{}", p.display()))?,
            )
            .with_context(|| format!("{}: not a speed baseline", p.display()))?,
        ),
        None => None,
    };
    let mut config = baseline
        .as_ref()
        .map_or_else(SpeedConfig::default, |b| b.config.clone());
    config.prepare = super::process_env::prepare_config();
    let dir = args
        .out_dir
        .clone()
        .unwrap_or_else(|| PathBuf::from("out/bench/speed"));
    std::fs::create_dir_all(&dir).with_context(|| format!("{}", dir.display()))?;
    // Each scene in a process of its own: one scene's render ran 20 % slower after the
    // scenes before it than in a fresh process, with the same code (docs/speed.md).
    let exe = std::env::current_exe().context("the path of this program")?;
    let config_json = serde_json::to_string(&config)?;
    let measure = |name: &str| -> penumbra::Result<SpeedRow> {
        let out = std::process::Command::new(&exe)
            .args(["bench", "--suite", "speed", "--measure-scene", name])
            .args(["--speed-config", &config_json])
            .stderr(std::process::Stdio::inherit())
            .output()
            .map_err(|e| format!("{}: {e}", exe.display()))?;
        if !out.status.success() {
            return Err(format!("measuring {name}: {}", out.status).into());
        }
        let text = String::from_utf8_lossy(&out.stdout);
        let line = text.lines().last().unwrap_or_default();
        serde_json::from_str(line).map_err(|e| format!("measuring {name}: {e}: {line}").into())
    };
    let outcome = run_speed(
        &config,
        baseline.as_ref(),
        &args.only,
        |m| eprintln!("{m}"),
        measure,
    )
    .map_err(anyhow::Error::msg)?;
    let md = speed_markdown(&outcome.report, baseline.as_ref());
    say!("{md}");
    for path in [
        (dir.join("speed.md"), md),
        (
            dir.join("speed.json"),
            serde_json::to_string_pretty(&outcome)?,
        ),
    ]
    .into_iter()
    .map(|(path, text)| {
        std::fs::write(&path, text)
            .with_context(|| format!("{}", path.display()))
            .map(|()| path)
    }) {
        say!("wrote {}", path?.display());
    }
    if let Some(path) = &args.write_baseline {
        let why = args.why.as_deref().unwrap_or_default();
        let tolerance = baseline.as_ref().map_or(0.10, |b| b.tolerance);
        let new = SpeedBaseline::from_report(&outcome.report, tolerance, why);
        std::fs::write(path, serde_json::to_string_pretty(&new)? + "\n")
            .with_context(|| format!("{}", path.display()))?;
        say!("wrote {} (the new baseline)", path.display());
    }
    for u in &outcome.unmatched {
        say!("note: {u}");
    }
    let violations: u64 = outcome.report.rows.iter().map(|r| r.violations).sum();
    if violations > 0 {
        bail!("{violations} invariant violations in the speed suite's renders");
    }
    if !outcome.regressions.is_empty() {
        let lines: Vec<String> = outcome.regressions.iter().map(|r| r.to_string()).collect();
        bail!(
            "the speed guard failed: {} ratio(s) grew past the baseline's tolerance of {:.0} % \
             in two measurements:\n  {}",
            lines.len(),
            100.0 * baseline.as_ref().map_or(0.0, |b| b.tolerance),
            lines.join("\n  ")
        );
    }
    if baseline.is_some() {
        say!("speed guard: every ratio within the baseline's tolerance");
    }
    Ok(())
}
