//! The `morphfx` command line: its commands and their options (clap).

use std::path::PathBuf;

use clap::{Parser, Subcommand};
use morphfx::track::TrackSettings;

use crate::io::{self};

#[derive(Parser)]
#[command(
    name = "morphfx",
    version,
    about = "Render MorphFX morphs through the OpenFX plugin bundle"
)]
pub struct Cli {
    /// The plugin bundle (MorphFX.ofx.bundle or its binary). Default: OFX_PLUGIN_PATH,
    /// then the bundle built in this checkout, then /usr/OFX/Plugins.
    #[arg(long, global = true)]
    pub bundle: Option<PathBuf>,
    /// Folders searched for MorphFX.ofx.bundle before OFX_PLUGIN_PATH
    /// (separated as PATH is); empty searches none (a farm template passes
    /// its PluginPath parameter here).
    #[arg(long, global = true, default_value = "")]
    pub plugin_path: String,
    /// Say more while rendering (method auto prints its work table per level).
    #[arg(short, long, global = true)]
    pub verbose: bool,
    #[command(subcommand)]
    pub command: Command,
}

#[derive(clap::Args, Clone)]
pub struct Common {
    /// Scene file (*.morph.json).
    #[arg(long, required_unless_present = "line")]
    pub scene: Option<PathBuf>,
    /// A line pair in the node's slot N, as a host would key it:
    /// `N=ax0,ay0,ax1,ay1,bx0,by0,bx1,by1` (constant) or `N@FRAME=...` (a key
    /// at FRAME; keys of one slot interpolate like a host's). Repeatable.
    #[arg(long = "line", value_name = "SPEC")]
    pub line: Vec<String>,
    /// Progress t in [0, 1]; overrides the scene's progress keys.
    #[arg(long)]
    pub t: Option<f64>,
    /// Any node param by its id, as a host would set it: `ID=VALUE`
    /// (constant) or `ID@FRAME=VALUE` (a key; keys interpolate like a
    /// host's). Choices by option name, booleans true/false, 2D values
    /// x,y. `morphfx params` lists the ids. Repeatable.
    #[arg(long = "param", value_name = "ID=VALUE")]
    pub param: Vec<String>,
    /// Frames to render, e.g. 1001-1048.
    #[arg(long)]
    pub frames: Option<String>,
    /// Output file or #-padded sequence.
    #[arg(short = 'o', long = "output")]
    pub output: String,
    /// Write half-float EXR (default: the precision of the first input).
    #[arg(long, conflicts_with = "float")]
    pub half: bool,
    /// Write 32-bit float EXR (default: the precision of the first input).
    #[arg(long)]
    pub float: bool,
    /// EXR compression: none, rle, zips, zip, piz, pxr24, b44, dwaa, dwab
    /// (default: the first input's; zip for PNG, JPEG and TIFF inputs).
    #[arg(long)]
    pub compression: Option<String>,
    /// Keep PNG, JPEG and TIFF code values as they are (default: decode
    /// their sRGB to linear light on read, encode PNG output to sRGB).
    #[arg(long)]
    pub raw: bool,
}

impl Common {
    pub fn colour(&self) -> io::Colour {
        if self.raw {
            io::Colour::Raw
        } else {
            io::Colour::Srgb
        }
    }
}

#[derive(Subcommand)]
pub enum Command {
    /// Render the in-between image(s) of A and B.
    Morph {
        #[command(flatten)]
        common: Common,
        /// Plate A (file or #-numbered sequence): the morph at t = 0.
        #[arg(long)]
        a: String,
        /// Plate B (file or #-numbered sequence): the morph at t = 1.
        #[arg(long)]
        b: String,
        /// Also write the ST map A was warped with (file or #-numbered
        /// sequence, 32-bit float EXR).
        #[arg(long = "stmap-a")]
        stmap_a: Option<String>,
        /// Also write the ST map B was warped with.
        #[arg(long = "stmap-b")]
        stmap_b: Option<String>,
        /// morph, warped-a, warped-b, stmap-a, stmap-b, transition, grid, ghost, folds
        #[arg(long, default_value = "morph")]
        view: String,
        /// The Mask input (file or #-numbered sequence): the morph shows
        /// where its alpha is, A elsewhere (with the `mix` param).
        #[arg(long)]
        mask: Option<String>,
        /// The Timing input (file or sequence): each pixel of A turns when
        /// its alpha says, spread by the `transition_spread` param.
        #[arg(long)]
        timing: Option<String>,
        /// general or transition
        #[arg(long, default_value = "general")]
        context: String,
    },
    /// Render A warped toward the features' positions at t.
    Warp {
        #[command(flatten)]
        common: Common,
        /// The plate to warp (file or #-numbered sequence).
        #[arg(long)]
        input: String,
        /// Also write the ST map the input was warped with (file or
        /// #-numbered sequence, 32-bit float EXR).
        #[arg(long)]
        stmap: Option<String>,
        /// warped, stmap, grid, folds
        #[arg(long, default_value = "warped")]
        view: String,
        /// The Mask input (file or #-numbered sequence): the warp shows
        /// where its alpha is, the input elsewhere (with the `mix` param).
        #[arg(long)]
        mask: Option<String>,
        /// The layers of a multi-layer EXR input to warp, all through the
        /// same warp into one EXR: rgba (the main picture alone), all, or
        /// a list (rgba,N,id).
        #[arg(long, default_value = "rgba")]
        layers: String,
        /// Layers sampled nearest (never blended) besides those whose
        /// names say they hold IDs or mattes (id, crypto*, *mask*,
        /// *matte*): a list.
        #[arg(long = "id-layers", default_value = "")]
        id_layers: String,
    },
    /// List every param of the nodes: id, type, default and range.
    Params {
        /// morph or warp (default: both).
        #[arg(long)]
        node: Option<String>,
    },
    /// Render a morph of built-in generated plates.
    Demo {
        /// The folder the demo's frames, contact sheet and notes go to.
        #[arg(short = 'o', long = "output", default_value = "morphfx-demo")]
        output: PathBuf,
    },
    /// Draw the node's viewer overlay (its line slots and the scene's
    /// features) over the plates, as a host's viewer shows them.
    Overlay {
        #[command(flatten)]
        common: Common,
        /// Source A (with --b: the Morph node's overlay).
        #[arg(long, conflicts_with = "input")]
        a: Option<String>,
        /// Source B (with --a: the Morph node's overlay; drawn on with --show b).
        #[arg(long, requires = "a")]
        b: Option<String>,
        /// The source of the Warp node's overlay.
        #[arg(long)]
        input: Option<String>,
        /// a, b, both or between: which lines, on which plate (B's for b).
        #[arg(long, default_value = "both")]
        show: String,
    },
    /// List the plugins in the bundle.
    Plugins,
    /// Refine the scene's polylines and curves onto nearby edges of A and B
    /// with snakes, and write the refined scene.
    Snap {
        /// The scene whose polylines and curves are refined.
        #[arg(long)]
        scene: PathBuf,
        /// Plate A: the features' A positions snap to its edges.
        #[arg(long)]
        a: String,
        /// Plate B: the features' B positions snap to its edges.
        #[arg(long)]
        b: String,
        /// The refined scene.
        #[arg(short = 'o', long = "output")]
        output: PathBuf,
        /// The keyframe to refine (scenes with keyframes), and the frame of
        /// #-numbered plates.
        #[arg(long)]
        frame: Option<f64>,
        /// Edge smoothing, pixels: edges attract snakes from about twice this.
        #[arg(long, default_value_t = 3.0)]
        sigma: f64,
        /// Iterations of the snake loop.
        #[arg(long, default_value_t = 200)]
        iterations: usize,
        /// Hold the samples on the primitives' control points still.
        #[arg(long)]
        clamp_controls: bool,
    },
    /// Propose feature pairs between plates A and B (points at corners of
    /// A, found on B and checked both ways), and write them as a scene.
    Suggest {
        /// Plate A: where the points are placed (with --frames, a
        /// #-numbered sequence).
        #[arg(long)]
        a: String,
        /// Plate B: where each point of A is looked for (its own size and
        /// coordinates; with --frames, a #-numbered sequence).
        #[arg(long)]
        b: String,
        /// Sequences: suggest at --at, then follow every feature through
        /// both sequences over this range (FIRST-LAST), keyed at every frame.
        #[arg(long)]
        frames: Option<String>,
        /// The frame of --frames the suggestions are made at (default: its
        /// first).
        #[arg(long)]
        at: Option<i64>,
        /// The scene written: the base scene's features, then the
        /// suggestions, each with its confidence.
        #[arg(short = 'o', long = "output")]
        output: PathBuf,
        /// A scene of the user's own features (static): kept exactly;
        /// suggestions keep clear of them.
        #[arg(long)]
        scene: Option<PathBuf>,
        /// Pairs proposed at most.
        #[arg(long, default_value_t = 40)]
        count: usize,
        /// Pairs less sure than this (0 to 1) are left out.
        #[arg(long, default_value_t = 0.5)]
        min_confidence: f64,
        /// The scene's warp method (default: the base scene's, else
        /// hybrid).
        #[arg(long)]
        method: Option<String>,
    },
    /// Follow the scene's keyed features through sequence A (and B) and
    /// write the scene with a keyframe at every frame of the range.
    Track {
        /// The scene whose keyed features are followed.
        #[arg(long)]
        scene: PathBuf,
        /// Sequence A, #-numbered (plate.####.exr).
        #[arg(long)]
        a: String,
        /// Sequence B: its features are tracked too; without it they keep
        /// their keyed (or interpolated) positions.
        #[arg(long)]
        b: Option<String>,
        /// The range to track, FIRST-LAST; it must hold a keyframe.
        #[arg(long)]
        frames: String,
        /// The tracked scene; standard output without it.
        #[arg(short = 'o', long = "output")]
        output: Option<PathBuf>,
        /// Half the side of the tracked patch, pixels.
        #[arg(long, default_value_t = TrackSettings::default().radius)]
        radius: usize,
        /// Correlation with the keyed patch below which a feature counts as lost.
        #[arg(long, default_value_t = TrackSettings::default().min_correlation)]
        min_correlation: f64,
    },
    /// Write a farm job for a morph or warp command line.
    Job {
        #[command(subcommand)]
        kind: JobKind,
    },
    /// Time a whole sequence morph on generated plates (EXR IO included) and
    /// say where the time went; with --drag, the re-render after one of 100
    /// lines moves, as while a compositor drags it.
    Bench {
        /// Where the plates and the morph are written and kept (default: a
        /// temporary folder, removed when the bench ends).
        #[arg(short = 'o', long = "output")]
        output: Option<PathBuf>,
        /// Frames of the generated shot.
        #[arg(long, default_value_t = 48)]
        frames: usize,
        /// Width of the generated plates, pixels.
        #[arg(long, default_value_t = 1920)]
        width: usize,
        /// Height of the generated plates, pixels.
        #[arg(long, default_value_t = 1080)]
        height: usize,
        /// Time renders after a line moves (in this process, no files).
        #[arg(long)]
        drag: bool,
        /// Renders timed per render scale with --drag.
        #[arg(long, default_value_t = 20)]
        moves: usize,
    },
}

#[derive(Subcommand)]
pub enum JobKind {
    /// An Open Job Description job bundle: template.yaml (the project's
    /// template), the command's values in parameter_values.yaml (as Deadline
    /// Cloud takes them) and openjd_parameters.json (for `openjd run`):
    /// `morphfx job openjd -o DIR -- morph --scene S --a A --b B
    /// --frames 1001-1048 -o OUT`. The command is checked first, as a worker
    /// would check it.
    Openjd {
        /// The job bundle's folder.
        #[arg(short = 'o', long = "output")]
        output: PathBuf,
        /// Frames per chunk (one morphfx call each).
        #[arg(long, default_value_t = 10)]
        chunk_size: u32,
        /// Seconds a chunk should take (the scheduler then sizes chunks);
        /// 0 keeps chunks of --chunk-size frames.
        #[arg(long, default_value_t = 0)]
        chunk_target_runtime: u32,
        /// The morphfx command on the workers (a path is made absolute).
        #[arg(long, default_value = "morphfx")]
        morphfx: String,
        /// The command line to run: `morph ...` or `warp ...`.
        #[arg(last = true, required = true)]
        command: Vec<String>,
    },
}

/// The command line with each `--extra-args "A B C"` (before a bare `--`)
/// replaced by its words: how a farm template, which hands a program a
/// fixed list of arguments, passes a job's further options.
pub fn expand_extra_args(
    args: impl IntoIterator<Item = std::ffi::OsString>,
) -> Vec<std::ffi::OsString> {
    let mut out = Vec::new();
    let mut args = args.into_iter();
    while let Some(arg) = args.next() {
        if arg == "--" {
            out.push(arg);
            out.extend(args.by_ref());
            break;
        }
        let words = if arg == "--extra-args" {
            args.next()
        } else {
            arg.to_str()
                .and_then(|a| a.strip_prefix("--extra-args="))
                .map(Into::into)
        };
        match words {
            Some(w) => out.extend(
                w.to_string_lossy()
                    .split_whitespace()
                    .map(std::ffi::OsString::from),
            ),
            None if arg == "--extra-args" => {}
            None => out.push(arg),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every option of every command says what it is in `--help`.
    #[test]
    fn every_option_has_help_text() {
        use clap::CommandFactory;
        fn check(c: &clap::Command, path: &str) {
            for arg in c.get_arguments() {
                let id = arg.get_id().as_str();
                if matches!(id, "help" | "version") {
                    continue;
                }
                assert!(arg.get_help().is_some(), "{path} --{id} has no help text");
            }
            for sub in c.get_subcommands() {
                check(sub, &format!("{path} {}", sub.get_name()));
            }
        }
        check(&Cli::command(), "morphfx");
    }

    fn expand(args: &[&str]) -> Vec<String> {
        expand_extra_args(args.iter().map(std::ffi::OsString::from))
            .into_iter()
            .map(|a| a.into_string().unwrap())
            .collect()
    }

    #[test]
    fn extra_args_become_words_of_the_command_line() {
        assert_eq!(
            expand(&[
                "morphfx",
                "morph",
                "--extra-args",
                " --t 0.5  --half",
                "-o",
                "x"
            ]),
            ["morphfx", "morph", "--t", "0.5", "--half", "-o", "x"]
        );
        assert_eq!(
            expand(&["morphfx", "warp", "--extra-args=", "-o", "x"]),
            ["morphfx", "warp", "-o", "x"]
        );
        assert_eq!(
            expand(&["morphfx", "warp", "--extra-args"]),
            ["morphfx", "warp"]
        );
        // After a bare `--` everything is the job's own command line.
        let job = [
            "morphfx",
            "job",
            "openjd",
            "--",
            "morph",
            "--extra-args",
            "--t 1",
        ];
        assert_eq!(expand(&job), job);
    }
}
