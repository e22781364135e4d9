//! The `penumbra` command line: a thin layer over the library, one module per subcommand
//! (`cli`), and the workbench window when built with the feature `gui` (the default). Built
//! for `wasm32-unknown-unknown`, it is the workbench in a browser page (docs/web.md).

/// `println!` that ignores a closed stdout (e.g. piped into `head`) instead of panicking.
#[cfg(not(target_arch = "wasm32"))]
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($arg)*);
    }};
}

#[cfg(not(target_arch = "wasm32"))]
mod cli;

#[cfg(not(target_arch = "wasm32"))]
use anyhow::Result;
#[cfg(not(target_arch = "wasm32"))]
use cli::{Cli, Command, command_line};

/// The browser's page: the workbench on its canvas (no command line there).
#[cfg(target_arch = "wasm32")]
fn main() {
    penumbra::app::web::start();
}

/// Errors are printed alone, with their causes, whatever `RUST_BACKTRACE` says.
#[cfg(not(target_arch = "wasm32"))]
fn main() -> std::process::ExitCode {
    match run() {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}

#[cfg(not(target_arch = "wasm32"))]
fn run() -> Result<()> {
    use clap::FromArgMatches;
    let cli = Cli::from_arg_matches(&command_line().get_matches()).unwrap_or_else(|e| e.exit());
    match cli.command {
        #[cfg(feature = "gui")]
        None => penumbra::app::run(Default::default(), cli::process_env::prepare_config())
            .map_err(|e| anyhow::anyhow!("{e}")),
        #[cfg(feature = "gui")]
        Some(Command::Gui(args)) => {
            penumbra::app::run(args.options(), cli::process_env::prepare_config())
                .map_err(|e| anyhow::anyhow!("{e}"))
        }
        // Built without the workbench (`--no-default-features`): the command line only.
        #[cfg(not(feature = "gui"))]
        None => {
            command_line().print_help()?;
            Ok(())
        }
        Some(Command::Render(args)) => cli::render::render(&args),
        Some(Command::Bench(args)) => cli::bench::bench(&args),
        Some(Command::Reference { render, samples }) => {
            cli::render::reference(&render, samples, render.seed)
        }
        Some(Command::Compare {
            image,
            reference,
            stderr,
        }) => cli::render::compare(&image, &reference, stderr.as_deref()),
        Some(Command::Stress {
            only: Some(index),
            seed,
            rays,
            family,
            ..
        }) => cli::stress::describe_case(family, seed, index, rays),
        Some(Command::Stress {
            cases,
            seed,
            rays,
            json,
            family,
            ..
        }) => cli::stress::stress(family, cases, seed, rays, json.as_deref()),
        Some(Command::LtcError {
            tables,
            fit,
            out,
            grid,
            samples,
        }) => cli::ltc::ltc_error(&tables, &fit, &out, grid, samples),
        Some(Command::LtcImportThree { js, out }) => cli::ltc::import_three(&js, &out),
        Some(Command::FitLtc {
            out,
            size,
            objective,
            no_renorm,
            no_cosine_tail,
            rows,
            base,
            report,
        }) => cli::ltc::fit_ltc(&cli::ltc::FitRequest {
            out: &out,
            size,
            objective,
            no_renorm,
            no_cosine_tail,
            rows,
            base: base.as_deref(),
            report: report.as_deref(),
        }),
        Some(Command::Probe {
            render,
            pixel,
            gh_steps,
            json,
        }) => cli::probe::probe(&render, pixel, gh_steps, &json),
        Some(Command::Figure { render, figure }) => cli::figure::figure(&render, &figure),
        Some(Command::Cache { clear, trim, json }) => {
            cli::cache::cache(clear, trim, json.as_deref())
        }
        Some(Command::Edit {
            scene,
            object,
            translate,
            rotate_y,
            pivot,
            out,
        }) => cli::edit::edit(&scene, &object, translate, rotate_y, pivot, &out),
        Some(Command::Scenes) => {
            for name in penumbra::scene::scene_file::embedded_scene_names() {
                say!("{name}");
            }
            Ok(())
        }
    }
}
