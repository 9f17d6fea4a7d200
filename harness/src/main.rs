//! `morphfx`: the command line of our OpenFX host. Parses, dispatches to
//! the library's commands, and turns the outcome into an exit status (0
//! done, 2 bad input, 1 an internal failure).

use clap::Parser;
use morphfx::choice::Choice;
use morphfx::make_warp::Method;
use morphfx::snake::SnakeSettings;
use morphfx::suggest::SuggestSettings;
use morphfx_harness::cli::{Cli, Command, JobKind};
use morphfx_harness::commands::snap::Snap;
use morphfx_harness::commands::suggest::Suggest;
use morphfx_harness::commands::{bench, demo, job, openjd, overlay, params, plugins, track};
use morphfx_harness::host::{ErrorKind, HostError};
use morphfx_harness::interrupt;
use morphfx_harness::locate::find_bundle;

fn main() {
    morphfx_harness::host::allocator::tune_for_frames();
    let cli = Cli::parse_from(morphfx_harness::cli::expand_extra_args(std::env::args_os()));
    interrupt::install();
    if cli.verbose {
        // The plugin is told through its environment (set before it is
        // loaded; nothing else runs yet): it prints what it measures to stderr.
        std::env::set_var("MORPHFX_VERBOSE", "1");
    }
    match run(cli) {
        Ok(()) => {}
        Err(e) => {
            eprintln!("morphfx: error: {}", e.message);
            std::process::exit(if e.kind == ErrorKind::BadInput { 2 } else { 1 });
        }
    }
}

fn run(cli: Cli) -> Result<(), HostError> {
    // Looked for by the commands that render; `snap` runs the core's snakes
    // on the plates and needs no bundle.
    let bundle_path = || find_bundle(cli.bundle.as_deref(), &cli.plugin_path);
    match cli.command {
        Command::Plugins => plugins::list_plugins(&bundle_path()?),
        command @ (Command::Morph { .. } | Command::Warp { .. }) => {
            render_job(command)?.run(&bundle_path()?)
        }
        Command::Params { node } => params::list_params(&bundle_path()?, node.as_deref()),
        Command::Demo { output } => demo::demo(&bundle_path()?, &output),
        Command::Overlay {
            common,
            a,
            b,
            input,
            show,
        } => overlay::overlay_job(common, a, b, input)?.run_overlay(&bundle_path()?, &show),
        Command::Snap {
            scene,
            a,
            b,
            output,
            frame,
            sigma,
            iterations,
            clamp_controls,
        } => Snap {
            scene: &scene,
            a: &a,
            b: &b,
            output: &output,
            frame,
            sigma,
            settings: SnakeSettings {
                iterations,
                clamp_controls,
                ..SnakeSettings::default()
            },
        }
        .run()
        .map(|said| println!("{said}")),
        Command::Suggest {
            a,
            b,
            frames,
            at,
            output,
            scene,
            count,
            min_confidence,
            method,
        } => Suggest {
            a: &a,
            b: &b,
            frames: frames.as_deref(),
            at,
            output: &output,
            scene: scene.as_deref(),
            method: method.as_deref().map(parse_method).transpose()?,
            settings: SuggestSettings {
                count,
                min_confidence,
                ..SuggestSettings::default()
            },
        }
        .run()
        .map(|said| println!("{said}")),
        Command::Track {
            scene,
            a,
            b,
            frames,
            output,
            radius,
            min_correlation,
        } => track::track_job(
            &scene,
            &a,
            b.as_deref(),
            &frames,
            output.as_deref(),
            radius,
            min_correlation,
        ),
        Command::Job {
            kind:
                JobKind::Openjd {
                    output,
                    chunk_size,
                    chunk_target_runtime,
                    morphfx,
                    command,
                },
        } => {
            let job = openjd::Job {
                dir: &output,
                chunk_size,
                chunk_target_runtime,
                morphfx: &morphfx,
                plugin_path: cli.bundle.as_deref(),
                command: &command,
            };
            // Checked as a worker would check it: a job that cannot run
            // is refused at submission, not on the farm.
            openjd::write_bundle(&job, || {
                submitted_job(&command)?.check_submission(&bundle_path()?)
            })
        }
        Command::Bench {
            drag: true,
            width,
            height,
            moves,
            ..
        } => bench::drag::drag(&bundle_path()?, (width, height), moves),
        Command::Bench {
            output,
            frames,
            width,
            height,
            ..
        } => bench::bench_in(&bundle_path()?, output.as_deref(), frames, (width, height)),
    }
}

/// The render a `morph` or `warp` command asks for.
fn render_job(command: Command) -> Result<job::Job, HostError> {
    match command {
        Command::Morph {
            common,
            a,
            b,
            stmap_a,
            stmap_b,
            view,
            mask,
            timing,
            context,
        } => Ok(
            job::morph_job(common, a, b, [stmap_a, stmap_b], view, &context)?
                .with_mattes(mask, timing),
        ),
        Command::Warp {
            common,
            input,
            stmap,
            view,
            mask,
            layers,
            id_layers,
        } => job::warp_job(common, input, stmap, view)
            .with_mattes(mask, None)
            .with_layers(&layers, &id_layers),
        _ => Err(HostError::bad(
            "morphfx job openjd: a farm job runs morph or warp",
        )),
    }
}

/// The render a farm job's command line (`morph ...` or `warp ...`) asks
/// for, parsed as the workers will parse it.
fn submitted_job(command: &[String]) -> Result<job::Job, HostError> {
    let words = std::iter::once("morphfx".to_owned()).chain(command.iter().cloned());
    let words = morphfx_harness::cli::expand_extra_args(words.map(Into::into));
    let cli = Cli::try_parse_from(words).map_err(|e| {
        let first = e.to_string();
        let first = first
            .lines()
            .next()
            .unwrap_or_default()
            .trim_start_matches("error: ")
            .to_owned();
        HostError::bad(format!("morphfx job openjd: the command after --: {first}"))
    })?;
    render_job(cli.command)
}

/// `--method NAME`, by the scene format's names.
fn parse_method(name: &str) -> Result<Method, HostError> {
    Method::ALL
        .iter()
        .copied()
        .find(|m| m.name() == name)
        .ok_or_else(|| {
            let names: Vec<_> = Method::ALL.iter().map(|m| m.name()).collect();
            HostError::bad(format!("--method {name}: one of {}", names.join(", ")))
        })
}
