//! `morphfx`: render the MorphFX bundle on plates (docs/command-line.md).

use std::path::{Path, PathBuf};
use std::process::Stdio;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use clap::{Parser, Subcommand};
use morphfx::geom::RectI;
use morphfx::image::Image;
use morphfx::scene::Scene;
use morphfx::snake::SnakeSettings;
use morphfx::track::TrackSettings;
use morphfx_harness::host::overlay::Overlay;
use morphfx_harness::host::{
    Bundle, ErrorKind, Frame, FrameSource, HostError, HostOptions, Instance, OutputSpec,
};
use morphfx_harness::interrupt;
use morphfx_harness::io::{self, ExrPrecision, Plate};
use morphfx_harness::pipeline::{ReadAhead, WriteBehind};
use morphfx_harness::progress::Progress;
use morphfx_harness::sequence::{frame_path, is_sequence, parse_frames};
use morphfx_harness::snap::Snap;
use morphfx_harness::track::Track;

const MORPH_ID: &str = "net.morphfx.Morph";
const WARP_ID: &str = "net.morphfx.Warp";

#[derive(Parser)]
#[command(
    name = "morphfx",
    version,
    about = "Render MorphFX morphs through the OpenFX plugin bundle"
)]
struct Cli {
    /// The plugin bundle (MorphFX.ofx.bundle or its binary). Default: OFX_PLUGIN_PATH,
    /// then the bundle built in this checkout, then /usr/OFX/Plugins.
    #[arg(long, global = true)]
    bundle: Option<PathBuf>,
    /// Say more while rendering (method auto prints its work table per level).
    #[arg(short, long, global = true)]
    verbose: bool,
    #[command(subcommand)]
    command: Command,
}

#[derive(clap::Args, Clone)]
struct Common {
    /// Scene file (*.morph.json).
    #[arg(long, required_unless_present = "line")]
    scene: Option<PathBuf>,
    /// A line pair in the node's slot N, as a host would key it:
    /// `N=ax0,ay0,ax1,ay1,bx0,by0,bx1,by1` (constant) or `N@FRAME=...` (a key
    /// at FRAME; keys of one slot interpolate like a host's). Repeatable.
    #[arg(long = "line", value_name = "SPEC")]
    line: Vec<String>,
    /// Progress t in [0, 1]; overrides the scene's progress keys.
    #[arg(long)]
    t: Option<f64>,
    /// Frames to render, e.g. 1001-1048.
    #[arg(long)]
    frames: Option<String>,
    /// Output file or #-padded sequence.
    #[arg(short = 'o', long = "output")]
    output: String,
    /// Write half-float EXR (default: the precision of the first input).
    #[arg(long, conflicts_with = "float")]
    half: bool,
    /// Write 32-bit float EXR (default: the precision of the first input).
    #[arg(long)]
    float: bool,
    /// EXR compression: none, rle, zips, zip, piz, pxr24, b44, dwaa, dwab
    /// (default: the first input's; zip for PNG, JPEG and TIFF inputs).
    #[arg(long)]
    compression: Option<String>,
    /// Keep PNG, JPEG and TIFF code values as they are (default: decode
    /// their sRGB to linear light on read, encode PNG output to sRGB).
    #[arg(long)]
    raw: bool,
}

impl Common {
    /// How outputs are written: precision and compression follow the first
    /// input unless the options say otherwise.
    fn output_format(&self, inputs: &Inputs) -> Result<io::OutputFormat, HostError> {
        let precision = if self.half || (inputs.half && !self.float) {
            ExrPrecision::Half
        } else {
            ExrPrecision::Float
        };
        let compression = match &self.compression {
            Some(name) => io::compression_named(name).ok_or_else(|| {
                let names: Vec<&str> = io::COMPRESSIONS.iter().map(|(n, _)| *n).collect();
                HostError::bad(format!(
                    "--compression {name}: expected one of {}",
                    names.join(", ")
                ))
            })?,
            None => inputs
                .compression
                .unwrap_or(io::OutputFormat::new(precision).compression),
        };
        Ok(io::OutputFormat {
            precision,
            compression,
            colour: self.colour(),
        })
    }

    fn colour(&self) -> io::Colour {
        if self.raw {
            io::Colour::Raw
        } else {
            io::Colour::Srgb
        }
    }
}

#[derive(Subcommand)]
enum Command {
    /// Render the in-between image(s) of A and B.
    Morph {
        #[command(flatten)]
        common: Common,
        #[arg(long)]
        a: String,
        #[arg(long)]
        b: String,
        #[arg(long = "stmap-a")]
        stmap_a: Option<String>,
        #[arg(long = "stmap-b")]
        stmap_b: Option<String>,
        /// morph, warped-a, warped-b, stmap-a, stmap-b, transition, grid
        #[arg(long, default_value = "morph")]
        view: String,
        /// general or transition
        #[arg(long, default_value = "general")]
        context: String,
    },
    /// Render A warped toward the features' positions at t.
    Warp {
        #[command(flatten)]
        common: Common,
        #[arg(long)]
        input: String,
        #[arg(long)]
        stmap: Option<String>,
        /// warped, stmap, grid
        #[arg(long, default_value = "warped")]
        view: String,
    },
    /// Render a morph of built-in generated plates.
    Demo {
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
        #[arg(long)]
        scene: PathBuf,
        #[arg(long)]
        a: String,
        #[arg(long)]
        b: String,
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
    /// Follow the scene's keyed features through sequence A (and B) and
    /// write the scene with a keyframe at every frame of the range.
    Track {
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
    /// Time a whole sequence morph on generated plates (EXR IO included) and
    /// say where the time went.
    Bench {
        #[arg(short = 'o', long = "output", default_value = "morphfx-bench")]
        output: PathBuf,
        #[arg(long, default_value_t = 48)]
        frames: usize,
        #[arg(long, default_value_t = 1920)]
        width: usize,
        #[arg(long, default_value_t = 1080)]
        height: usize,
    },
}

fn main() {
    morphfx_harness::host::allocator::tune_for_frames();
    let cli = Cli::parse();
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
    let bundle_path = || find_bundle(cli.bundle.as_deref());
    match cli.command {
        Command::Plugins => list_plugins(&bundle_path()?),
        Command::Morph {
            common,
            a,
            b,
            stmap_a,
            stmap_b,
            view,
            context,
        } => morph_job(common, a, b, [stmap_a, stmap_b], view, &context)?.run(&bundle_path()?),
        Command::Warp {
            common,
            input,
            stmap,
            view,
        } => {
            let job = Job {
                plugin: WARP_ID,
                context: "OfxImageEffectContextFilter",
                sources: vec![("Source".to_owned(), input)],
                view,
                extra: stmap
                    .map(|s| vec![("stmap".to_owned(), s)])
                    .unwrap_or_default(),
                common,
            };
            job.run(&bundle_path()?)
        }
        Command::Demo { output } => demo(&bundle_path()?, &output),
        Command::Overlay {
            common,
            a,
            b,
            input,
            show,
        } => overlay_job(common, a, b, input)?.run_overlay(&bundle_path()?, &show),
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
        .run(),
        Command::Track {
            scene,
            a,
            b,
            frames,
            output,
            radius,
            min_correlation,
        } => track_job(
            &scene,
            &a,
            b.as_deref(),
            &frames,
            output.as_deref(),
            radius,
            min_correlation,
        ),
        Command::Bench {
            output,
            frames,
            width,
            height,
        } => bench(&bundle_path()?, &output, frames, (width, height)),
    }
}

/// `morphfx track`, its options checked.
fn track_job(
    scene: &Path,
    a: &str,
    b: Option<&str>,
    frames: &str,
    output: Option<&Path>,
    radius: usize,
    min_correlation: f64,
) -> Result<(), HostError> {
    if !(2..=64).contains(&radius) {
        return Err(HostError::bad(format!(
            "--radius {radius}: must be 2 to 64 pixels"
        )));
    }
    if !(0.0..1.0).contains(&min_correlation) {
        return Err(HostError::bad(format!(
            "--min-correlation {min_correlation}: must be at least 0 and below 1"
        )));
    }
    Track {
        scene,
        a,
        b,
        frames: parse_frames(frames)?,
        output,
        settings: TrackSettings {
            radius,
            min_correlation,
            ..TrackSettings::default()
        },
    }
    .run()
}

/// `morphfx plugins`: each plugin of the bundle with its version.
fn list_plugins(bundle_path: &Path) -> Result<(), HostError> {
    let bundle = Bundle::load(bundle_path)?;
    println!("bundle: {}", bundle.binary.display());
    for p in &bundle.plugins {
        let served_by = p
            .served_by
            .as_ref()
            .and_then(|b| b.file_name())
            .map(|b| b.to_string_lossy().into_owned())
            .unwrap_or_default();
        println!("{}\t{}.{}\t{served_by}", p.id, p.version.0, p.version.1);
    }
    Ok(())
}

/// `morphfx overlay`: the Morph node's overlay with A and B, else the Warp
/// node's with its input.
fn overlay_job(
    common: Common,
    a: Option<String>,
    b: Option<String>,
    input: Option<String>,
) -> Result<Job, HostError> {
    match (a, b, input) {
        (Some(a), Some(b), None) => {
            morph_job(common, a, b, [None, None], "morph".into(), "general")
        }
        (None, None, Some(input)) => Ok(Job {
            plugin: WARP_ID,
            context: "OfxImageEffectContextFilter",
            sources: vec![("Source".to_owned(), input)],
            view: "warped".into(),
            extra: Vec::new(),
            common,
        }),
        _ => Err(HostError::bad(
            "overlay needs --a and --b (Morph) or --input (Warp)",
        )),
    }
}

/// `morphfx morph`: the morph node in the general or transition context.
fn morph_job(
    common: Common,
    a: String,
    b: String,
    [stmap_a, stmap_b]: [Option<String>; 2],
    view: String,
    context: &str,
) -> Result<Job, HostError> {
    let (ctx, [ca, cb]) = match context {
        "general" => ("OfxImageEffectContextGeneral", ["SourceA", "SourceB"]),
        "transition" => (
            "OfxImageEffectContextTransition",
            ["SourceFrom", "SourceTo"],
        ),
        other => {
            return Err(HostError::bad(format!(
                "--context {other}: expected general or transition"
            )))
        }
    };
    Ok(Job {
        plugin: MORPH_ID,
        context: ctx,
        sources: vec![(ca.to_owned(), a), (cb.to_owned(), b)],
        view,
        extra: [("stmap-a", stmap_a), ("stmap-b", stmap_b)]
            .into_iter()
            .filter_map(|(v, o)| o.map(|o| (v.to_owned(), o)))
            .collect(),
        common,
    })
}

fn find_bundle(given: Option<&Path>) -> Result<PathBuf, HostError> {
    const NAME: &str = "MorphFX.ofx.bundle";
    if let Some(p) = given {
        return Ok(p.to_path_buf());
    }
    let mut candidates = Vec::new();
    if let Ok(paths) = std::env::var("OFX_PLUGIN_PATH") {
        candidates.extend(std::env::split_paths(&paths).map(|d| d.join(NAME)));
    }
    if let Some(dir) = std::env::current_exe()
        .ok()
        .and_then(|e| e.parent().map(Path::to_path_buf))
    {
        // target/<profile>/morphfx → target/bundle/MorphFX.ofx.bundle (cargo xtask bundle),
        // or the cdylib cargo left beside the binary.
        candidates.push(dir.join("..").join("bundle").join(NAME));
        candidates.push(dir.join("libmorphfx_ofx.so"));
    }
    candidates.push(PathBuf::from("/usr/OFX/Plugins").join(NAME));
    candidates
        .into_iter()
        .find(|c| morphfx_harness::host::bundle_binary(c).is_file())
        .ok_or_else(|| HostError::bad("no MorphFX bundle found: pass --bundle, set OFX_PLUGIN_PATH, or build one with `cargo xtask bundle`"))
}

/// A frame read from disk: its number, pixels and display-window size.
type CachedPlate = (i64, Arc<Frame>, (usize, usize));

/// Reads frames of a file or sequence on demand.
struct Plates {
    pattern: String,
    colour: io::Colour,
    cache: Mutex<Vec<CachedPlate>>,
    /// The next frame, read ahead on another thread.
    ahead: Mutex<ReadAhead<Loaded>>,
    /// Time spent reading files, for the end-of-run summary.
    read_time: Mutex<Duration>,
    /// The first read that failed: the plugin only learns "no image", so the
    /// harness reports the file and why itself.
    error: Mutex<Option<HostError>>,
}

/// A plate as the host hands it over, with its display window's size.
type Loaded = (Arc<Frame>, (usize, usize));

impl Plates {
    fn new(pattern: &str, colour: io::Colour) -> Arc<Plates> {
        Arc::new(Plates {
            pattern: pattern.to_owned(),
            colour,
            cache: Mutex::new(Vec::new()),
            ahead: Mutex::new(ReadAhead::default()),
            read_time: Mutex::new(Duration::ZERO),
            error: Mutex::new(None),
        })
    }

    fn file_frame(&self, frame: i64) -> i64 {
        if is_sequence(&self.pattern) {
            frame
        } else {
            0
        }
    }

    fn load(&self, frame: i64) -> Result<Loaded, HostError> {
        let path = frame_path(&self.pattern, frame);
        let started = Instant::now();
        let plate = io::read_as(&path, self.colour)?;
        *self.read_time.lock().unwrap_or_else(|e| e.into_inner()) += started.elapsed();
        let size = plate.size;
        Ok((Arc::new(Frame::from_float_image(plate.image)), size))
    }

    /// Starts reading `frame` on another thread, unless it is at hand.
    fn read_ahead(self: &Arc<Self>, frame: i64) {
        let frame = self.file_frame(frame);
        let mut ahead = lock(&self.ahead);
        // A frame read ahead but never asked for (the plugin did not need
        // it) is kept once read, and makes room.
        if let Some((k, Ok(loaded))) = ahead.take_finished() {
            self.keep(k, &loaded);
        }
        if !lock(&self.cache).iter().any(|(k, _, _)| *k == frame) {
            let me = self.clone();
            ahead.start(frame, move || me.load(frame));
        }
    }

    fn plate(&self, frame: i64) -> Result<Loaded, HostError> {
        let frame = self.file_frame(frame);
        if let Some((_, f, size)) = lock(&self.cache).iter().find(|(k, _, _)| *k == frame) {
            return Ok((f.clone(), *size));
        }
        let pending = lock(&self.ahead).take(frame);
        let loaded = pending
            .unwrap_or_else(|| self.load(frame))
            .inspect_err(|e| {
                lock(&self.error).get_or_insert_with(|| e.clone());
            })?;
        self.keep(frame, &loaded);
        Ok(loaded)
    }

    /// Keeps `frame` at hand, and the next (read ahead); the others go: a
    /// sequence is rendered in order, each frame once.
    fn keep(&self, frame: i64, (f, size): &Loaded) {
        let mut cache = lock(&self.cache);
        cache.retain(|(k, _, _)| *k == frame + 1);
        cache.push((frame, f.clone(), *size));
    }
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

impl FrameSource for Plates {
    fn frame(&self, time: f64) -> Result<Arc<Frame>, String> {
        self.plate(time.round() as i64)
            .map(|(f, _)| f)
            .map_err(|e| e.message)
    }
}

/// One `--line` value: slot, optional key frame, A start/end then B start/end.
struct LineKey {
    slot: usize,
    frame: Option<f64>,
    coords: [f64; 8],
}

impl LineKey {
    /// The nodes' line slots (Line Count at most).
    const SLOTS: usize = 64;

    fn parse(spec: &str) -> Result<LineKey, HostError> {
        let bad = |why: &str| {
            HostError::bad(format!(
                "--line {spec}: {why} (expected N=ax0,ay0,ax1,ay1,bx0,by0,bx1,by1 or N@FRAME=...)"
            ))
        };
        let (head, values) = spec.split_once('=').ok_or_else(|| bad("no '='"))?;
        let (slot, frame) = match head.split_once('@') {
            Some((n, f)) => (
                n,
                Some(f.trim().parse::<f64>().map_err(|_| bad("bad frame"))?),
            ),
            None => (head, None),
        };
        let slot: usize = slot.trim().parse().map_err(|_| bad("bad slot number"))?;
        if !(1..=Self::SLOTS).contains(&slot) {
            return Err(bad(&format!("slot must be 1 to {}", Self::SLOTS)));
        }
        let numbers: Vec<f64> = values
            .split(',')
            .map(|v| v.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| bad("bad number"))?;
        let coords: [f64; 8] = numbers
            .try_into()
            .map_err(|_| bad("needs exactly 8 numbers"))?;
        if coords.iter().any(|v| !v.is_finite()) || frame.is_some_and(|f| !f.is_finite()) {
            return Err(bad("numbers must be finite"));
        }
        Ok(LineKey {
            slot,
            frame,
            coords,
        })
    }
}

/// The Show Lines option `--show` names.
fn show_option(show: &str) -> Result<&'static str, HostError> {
    Ok(match show {
        "both" => "A and B",
        "a" => "A only",
        "b" => "B only",
        "between" => "in-between",
        other => {
            return Err(HostError::bad(format!(
                "--show {other}: expected a, b, both or between"
            )))
        }
    })
}

/// What a job reads before it loads the bundle.
struct Prepared {
    scene: Option<Scene>,
    lines: Vec<LineKey>,
    frames: Vec<i64>,
    plates: Vec<(String, Arc<Plates>)>,
    inputs: Inputs,
}

impl Prepared {
    /// Whether features or progress change over the frames (keyframes,
    /// keyed line slots, progress keys not overridden by a fixed `--t`).
    fn animated(&self, fixed_t: bool) -> bool {
        let keyed_lines = self.lines.iter().filter(|l| l.frame.is_some()).count() > 1;
        let scene = self.scene.as_ref().is_some_and(|s| {
            let progress = !fixed_t && s.progress.windows(2).any(|w| w[0].1 != w[1].1);
            s.keyframes.len() > 1 || s.meshes.len() > 1 || progress
        });
        keyed_lines || scene
    }
}

struct Job {
    plugin: &'static str,
    context: &'static str,
    sources: Vec<(String, String)>,
    view: String,
    /// Extra outputs: (view, path pattern).
    extra: Vec<(String, String)>,
    common: Common,
}

impl Job {
    fn run(&self, bundle_path: &Path) -> Result<(), HostError> {
        let job = self.prepare()?;
        let bundle = Bundle::load(bundle_path)?;
        let inst = bundle.instance(self.plugin, self.context)?;
        self.set_up(&inst, &job.lines, &job.plates, job.inputs.size)?;
        self.render_frames(&inst, &job)
    }

    /// `morphfx overlay`: the plugin's overlay drawn over the plates.
    fn run_overlay(&self, bundle_path: &Path, show: &str) -> Result<(), HostError> {
        show_option(show)?;
        let job = self.prepare()?;
        let options = HostOptions {
            overlays: true,
            draw_suite: true,
        };
        let bundle = Bundle::load_with(bundle_path, options)?;
        let inst = bundle.instance(self.plugin, self.context)?;
        self.set_up(&inst, &job.lines, &job.plates, job.inputs.size)?;
        self.draw_overlays(&inst, &job, show)
    }

    /// Everything a run reads before it loads the bundle: the scene, the
    /// lines, the frames and every input's header.
    fn prepare(&self) -> Result<Prepared, HostError> {
        let c = &self.common;
        let scene = read_scene(c.scene.as_deref())?;
        let lines = c
            .line
            .iter()
            .map(|spec| LineKey::parse(spec))
            .collect::<Result<Vec<_>, _>>()?;
        if let Some(t) = c.t {
            if !(0.0..=1.0).contains(&t) {
                return Err(HostError::bad(format!("--t {t}: must be in [0, 1]")));
            }
        }
        let frames = self.frames(scene.as_ref(), &lines)?;
        let plates: Vec<(String, Arc<Plates>)> = self
            .sources
            .iter()
            .map(|(clip, p)| (clip.clone(), Plates::new(p, c.colour())))
            .collect();
        let inputs = check_inputs(&plates, &frames)?;
        Ok(Prepared {
            scene,
            lines,
            frames,
            plates,
            inputs,
        })
    }

    /// Each frame's plate (B's with `--show b`, else the first source's)
    /// with the overlay drawn on it, written where the output says.
    fn draw_overlays(
        &self,
        inst: &Instance<'_>,
        job: &Prepared,
        show: &str,
    ) -> Result<(), HostError> {
        inst.set_choice("overlay_show", show_option(show)?)?;
        let source = match (show, self.sources.get(1)) {
            ("b", Some((_, b))) => b,
            _ => &self.sources[0].1,
        };
        let overlay = Overlay::new(inst, true)?
            .ok_or_else(|| HostError::failed("the plugin declares no overlay"))?;
        let format = self.common.output_format(&job.inputs)?;
        let progress = Progress::new(job.frames.len());
        for (n, &f) in job.frames.iter().enumerate() {
            let mut plate = io::read_as(&frame_path(source, f), format.colour)?;
            let calls = overlay.draw(f as f64, (1.0, 1.0))?;
            morphfx_harness::raster::paint(&mut plate.image, &calls, (1.0, 1.0));
            io::write_as(&frame_path(&self.common.output, f), &plate, format)?;
            progress.tick(n + 1, f);
        }
        progress.done("overlays drawn");
        Ok(())
    }

    /// The frames to render: `--frames`, else the one frame the scene or
    /// the keyed lines start at.
    fn frames(&self, scene: Option<&Scene>, lines: &[LineKey]) -> Result<Vec<i64>, HostError> {
        let c = &self.common;
        match &c.frames {
            Some(spec) => parse_frames(spec),
            None if self.sources.iter().any(|(_, p)| is_sequence(p)) || is_sequence(&c.output) => {
                Err(HostError::bad(
                    "sequences need --frames (e.g. --frames 1001-1048)",
                ))
            }
            None => Ok(vec![scene
                .and_then(|s| {
                    s.keyframes
                        .first()
                        .map(|k| k.frame)
                        .or(s.progress.first().map(|p| p.0))
                })
                .or(lines.iter().find_map(|l| l.frame))
                .unwrap_or(0.0) as i64]),
        }
    }

    /// The instance's params from the command line, its project and clips.
    fn set_up(
        &self,
        inst: &Instance<'_>,
        lines: &[LineKey],
        plates: &[(String, Arc<Plates>)],
        size: (usize, usize),
    ) -> Result<(), HostError> {
        let c = &self.common;
        if let Some(path) = &c.scene {
            let path = std::fs::canonicalize(path).unwrap_or_else(|_| path.clone());
            inst.set_string("scene_file", &path.to_string_lossy())?;
        }
        if let Some(count) = lines.iter().map(|l| l.slot).max() {
            inst.set_int("line_count", count as i32)?;
            for l in lines {
                for (k, id) in ["a_start", "a_end", "b_start", "b_end"].iter().enumerate() {
                    let xy = [l.coords[2 * k], l.coords[2 * k + 1]];
                    inst.set_double(&format!("line{}_{id}", l.slot), &xy, l.frame)?;
                }
            }
        }
        if let Some(t) = c.t {
            inst.set_double("progress", &[t], None)?;
            inst.set_int("use_scene_progress", 0)?;
        }
        inst.set_project(size.0 as f64, size.1 as f64);
        for (clip, p) in plates {
            inst.connect(clip, p.clone())?;
        }
        // Hosts ask for clip preferences once the clips are connected.
        inst.clip_preferences()?;
        Ok(())
    }

    /// Renders every frame of every output as one sequence, and says where
    /// the time went.
    fn render_frames(&self, inst: &Instance<'_>, job: &Prepared) -> Result<(), HostError> {
        let (frames, plates, inputs) = (&job.frames, &job.plates, &job.inputs);
        let scene = job.scene.as_ref();
        let c = &self.common;
        let transition = self.context == "OfxImageEffectContextTransition";
        // A frame's warps serve it alone when what they are made from moves
        // from frame to frame: the plugin's caches are purged after each,
        // so memory stays flat however long the shot.
        let purge = transition || job.animated(c.t.is_some());
        // Half in, half out, and the input's compression, unless the user
        // says otherwise.
        let format = c.output_format(inputs)?;
        let outputs: Vec<(String, String)> = std::iter::once((self.view.clone(), c.output.clone()))
            .chain(self.extra.iter().cloned())
            .collect();
        let progress = Progress::new(frames.len());
        let range = (
            frames[0] as f64,
            *frames.last().unwrap_or(&frames[0]) as f64,
        );
        inst.begin_sequence(range.0, range.1)?;
        // A plate that fails to decode surfaces as a failed action; name it.
        let read_error = |e: HostError| {
            plates
                .iter()
                .find_map(|(_, p)| p.error.lock().unwrap_or_else(|p| p.into_inner()).take())
                .unwrap_or(e)
        };
        let mut rendering = Duration::ZERO;
        // Frame n is written while frame n + 1 renders.
        let writer = WriteBehind::new(0);
        for (n, &f) in frames.iter().enumerate() {
            if interrupt::requested() {
                return Err(interrupted(writer, &frames[..n], frame_path(&c.output, f)));
            }
            if transition {
                // The host drives the context's mandated Transition param, as
                // an editor does from where the frame sits in the transition.
                let t = c.t.or_else(|| scene.and_then(|s| s.progress_at(f as f64)));
                let t = t.unwrap_or_else(|| match frames.len() {
                    1 => 0.5,
                    k => n as f64 / (k - 1) as f64,
                });
                inst.set_double("Transition", &[t], None)?;
            }
            // The next frame's plates are read while this one renders.
            if let Some(&next) = frames.get(n + 1) {
                for (_, p) in plates {
                    p.read_ahead(next);
                }
            }
            for (view, pattern) in &outputs {
                inst.set_choice("view", view)?;
                // Frame after frame on one instance: a sequential render.
                let spec = OutputSpec {
                    sequential: true,
                    ..OutputSpec::default()
                };
                let started = Instant::now();
                let out = inst.render(f as f64, spec);
                if interrupt::requested() {
                    // Its picture may be unfinished (the render was told to abort).
                    return Err(interrupted(writer, &frames[..n], frame_path(pattern, f)));
                }
                let out = out.map_err(read_error)?;
                rendering += started.elapsed();
                let plate = Plate {
                    image: out.into_image(),
                    size: inputs.size,
                    origin: inputs.windows.get(&f).map_or((0, 0), |w| w.origin),
                };
                writer.write(frame_path(pattern, f), plate, format)?;
            }
            if purge {
                inst.purge_caches()?;
            }
            progress.tick(n + 1, f);
        }
        let writing = writer.finish()?;
        inst.end_sequence(range.0, range.1)?;
        // Reading and writing run on their own threads beside the render;
        // a render that had to wait for its plates counts that wait.
        let reading: Duration = plates
            .iter()
            .map(|(_, p)| *p.read_time.lock().unwrap_or_else(|e| e.into_inner()))
            .sum();
        progress.done(&format!(
            "render {:.2} s (waits for plates included); alongside it, read {:.2} s, write {:.2} s",
            rendering.as_secs_f64(),
            reading.as_secs_f64(),
            writing.as_secs_f64()
        ));
        Ok(())
    }
}

/// The run stopped by a signal before `missing` was written, once the
/// frames `done` are written whole: the error that says what is on disk.
fn interrupted(writer: WriteBehind, done: &[i64], missing: PathBuf) -> HostError {
    if let Err(e) = writer.finish() {
        return e;
    }
    let whole = match (done.first(), done.last()) {
        (Some(first), Some(last)) => {
            format!("{} frame(s) written whole, {first} to {last}", done.len())
        }
        _ => "no frame written".to_owned(),
    };
    HostError::bad(format!(
        "{}: not written: interrupted; {whole}, none after",
        missing.display()
    ))
}

/// The scene file, parsed, if one is given.
fn read_scene(path: Option<&Path>) -> Result<Option<Scene>, HostError> {
    let Some(path) = path else {
        return Ok(None);
    };
    let bad = |e: &dyn std::fmt::Display| HostError::bad(format!("scene {}: {e}", path.display()));
    let text = std::fs::read_to_string(path).map_err(|e| bad(&e))?;
    Scene::parse(&text).map(Some).map_err(|e| bad(&e))
}

/// What the input files' headers say, for every frame.
struct Inputs {
    /// The display window size every input shares.
    size: (usize, usize),
    /// The first input is half float.
    half: bool,
    /// The first input's EXR compression.
    compression: Option<exr::prelude::Compression>,
    /// The first source's display window at each frame.
    windows: std::collections::BTreeMap<i64, io::DisplayWindow>,
}

/// Checks every input frame up front: a missing frame, or one whose display
/// window differs, is reported before anything is written. Data windows may
/// differ (overscan, bbox-cropped plates): each is its clip's region of
/// definition, and the Morph node's output covers their union. The output
/// keeps the first source's display window, frame by frame (its size is
/// every source's; its origin may move in a sequence).
fn check_inputs(plates: &[(String, Arc<Plates>)], frames: &[i64]) -> Result<Inputs, HostError> {
    let mut first: Option<((usize, usize), String)> = None;
    let mut half = false;
    let mut compression = None;
    let mut windows = std::collections::BTreeMap::new();
    for &f in frames {
        for (k, (_, p)) in plates.iter().enumerate() {
            let path = frame_path(&p.pattern, if is_sequence(&p.pattern) { f } else { 0 });
            let header = io::probe(&path)?;
            let (window, s) = (header.window, header.window.size);
            if k == 0 {
                windows.insert(f, window);
                if first.is_none() {
                    half = header.half;
                    compression = header.compression;
                }
            }
            let name = path.display().to_string();
            match &first {
                None => first = Some((s, name)),
                Some((s0, n0)) if *s0 != s => {
                    return Err(HostError::bad(format!(
                        "size mismatch: the display window of {name} is {}x{} but that of {n0} is {}x{}",
                        s.0, s.1, s0.0, s0.1
                    )))
                }
                _ => {}
            }
        }
    }
    Ok(Inputs {
        size: first.map(|(s, _)| s).unwrap_or_default(),
        half,
        compression,
        windows,
    })
}

/// Plate sequences A and B of `frames` frames (a drifting pattern each), a
/// scene of 20 keyframed lines, then the morph of the whole range timed as a
/// user runs it: read plates, render through the bundle, write float EXR.
fn bench(
    bundle_path: &Path,
    dir: &Path,
    frames: usize,
    (w, h): (usize, usize),
) -> Result<(), HostError> {
    if frames == 0 || w < 16 || h < 16 {
        return Err(HostError::bad("bench needs at least 1 frame of 16x16"));
    }
    let plates = dir.join("plates");
    eprintln!(
        "writing {frames} frames of {w}x{h} plates A and B to {}",
        plates.display()
    );
    for f in 1..=frames as i64 {
        for (name, seed) in [("a", 0.0f32), ("b", 2.1)] {
            let drift = f as f32 * 1.5;
            let image = Image::from_fn(RectI::from_size(w, h), 4, |i, j, c| {
                let (x, y) = (i as f32 + drift, j as f32);
                if c == 3 {
                    1.0
                } else {
                    0.5 + 0.4 * ((x * 0.013 + seed) * (c as f32 + 1.0)).sin() * (y * 0.021).cos()
                }
            });
            io::write(
                &frame_path(
                    &plates.join(format!("{name}.####.exr")).to_string_lossy(),
                    f,
                ),
                &Plate::new(image, (w, h)),
                // Half float, as camera plates and their scans come.
                ExrPrecision::Half,
            )?;
        }
    }
    // 20 lines over the frame, moving a little between the first and last key.
    let (fw, fh) = (w as f64, h as f64);
    let line = |k: usize, shift: f64| {
        let (x, y) = (
            fw * (0.1 + 0.8 * ((k * 7) % 20) as f64 / 20.0),
            fh * (0.1 + 0.8 * ((k * 13) % 20) as f64 / 20.0),
        );
        let len = fw * 0.06;
        serde_json::json!({
            "type": "line",
            "a": [[x, y], [x + len, y + 0.3 * len]],
            "b": [[x + shift, y - shift], [x + len + shift, y + 0.3 * len + 0.5 * shift]]
        })
    };
    let key = |frame: usize, shift: f64| serde_json::json!({ "frame": frame, "features": (0..20).map(|k| line(k, shift)).collect::<Vec<_>>() });
    let scene = serde_json::json!({
        "format": "morphfx-scene", "version": 1, "method": "field",
        "keyframes": [key(1, fw * 0.01), key(frames, fw * 0.02)],
        "progress": [[1, 0.0], [frames, 1.0]]
    });
    let scene_path = dir.join("bench.morph.json");
    std::fs::write(&scene_path, scene.to_string())
        .map_err(|e| HostError::failed(format!("{}: {e}", scene_path.display())))?;
    let s = |p: PathBuf| p.to_string_lossy().into_owned();
    eprintln!("rendering the morph of frames 1-{frames}");
    let started = Instant::now();
    Job {
        plugin: MORPH_ID,
        context: "OfxImageEffectContextGeneral",
        sources: vec![
            ("SourceA".into(), s(plates.join("a.####.exr"))),
            ("SourceB".into(), s(plates.join("b.####.exr"))),
        ],
        view: "morph".into(),
        extra: vec![],
        common: Common {
            scene: Some(scene_path),
            line: Vec::new(),
            t: None,
            frames: Some(format!("1-{frames}")),
            output: s(dir.join("morph.####.exr")),
            half: false,
            float: false,
            compression: None,
            raw: false,
        },
    }
    .run(bundle_path)?;
    let took = started.elapsed().as_secs_f64();
    compare_with_oiiotool(&plates, frames, took);
    Ok(())
}

/// Times OpenImageIO copying sequence A (read and write, no render), when
/// `oiiotool` is installed, and says how the morph compares: a peer run on
/// the same machine, in the same run.
fn compare_with_oiiotool(plates: &Path, frames: usize, morph_secs: f64) {
    let copy = plates.with_file_name("oiiotool-copy");
    let _ = std::fs::create_dir_all(&copy);
    let started = Instant::now();
    let status = std::process::Command::new("oiiotool")
        .arg("--frames")
        .arg(format!("1-{frames}"))
        .arg(plates.join("a.#.exr"))
        .arg("-o")
        .arg(copy.join("a.#.exr"))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status();
    match status {
        Ok(s) if s.success() => {
            let secs = started.elapsed().as_secs_f64();
            eprintln!(
                "oiiotool copies sequence A ({frames} frames) in {secs:.2} s: the morph took {:.2}x that",
                morph_secs / secs.max(1e-9)
            );
            if let Ok(ours) = copy_sequence(plates, &copy, frames) {
                eprintln!(
                    "morphfx's own EXR IO copies it in {ours:.2} s: {:.2}x oiiotool",
                    ours / secs.max(1e-9)
                );
            }
        }
        _ => eprintln!("(oiiotool not found: install openimageio-tools to compare with it)"),
    }
    let _ = std::fs::remove_dir_all(&copy);
}

/// Seconds to read and write sequence A frame by frame with our EXR IO, in
/// the plates' own format: the IO alone, as oiiotool's copy measures it.
fn copy_sequence(plates: &Path, to: &Path, frames: usize) -> Result<f64, HostError> {
    let started = Instant::now();
    for f in 1..=frames as i64 {
        let from = frame_path(&plates.join("a.####.exr").to_string_lossy(), f);
        let header = io::probe(&from)?;
        let precision = if header.half {
            ExrPrecision::Half
        } else {
            ExrPrecision::Float
        };
        let format = io::OutputFormat {
            compression: header
                .compression
                .unwrap_or(exr::prelude::Compression::ZIP16),
            ..io::OutputFormat::new(precision)
        };
        let plate = io::read(&from)?;
        io::write_as(
            &frame_path(&to.join("a.####.exr").to_string_lossy(), f),
            &plate,
            format,
        )?;
    }
    Ok(started.elapsed().as_secs_f64())
}

/// Two procedural plates with recognisable features: a warm disc face on A,
/// a cool rounded square face on B, eyes and mouth in different places.
fn demo(bundle_path: &Path, dir: &Path) -> Result<(), HostError> {
    let (w, h) = (320usize, 240usize);
    let b = RectI::from_size(w, h);
    let a = Image::from_fn(b, 4, |i, j, c| demo_face(i, j, c, false, (w, h)));
    let bb = Image::from_fn(b, 4, |i, j, c| demo_face(i, j, c, true, (w, h)));
    let plates = dir.join("plates");
    io::write(
        &plates.join("a.exr"),
        &Plate::new(a, (w, h)),
        ExrPrecision::Float,
    )?;
    io::write(
        &plates.join("b.exr"),
        &Plate::new(bb, (w, h)),
        ExrPrecision::Float,
    )?;
    let (cx, cy) = (160.0, 120.0);
    let scene = demo_scene((cx, cy));
    let s = |p: PathBuf| p.to_string_lossy().into_owned();
    // Writes `scene` to `name.morph.json` and renders frames 1-12 of the morph
    // of the two plates through it into `output` (plus `extra` views).
    let render =
        |name: &str, scene: &serde_json::Value, output: PathBuf, extra: Vec<(String, String)>| {
            let path = dir.join(format!("{name}.morph.json"));
            std::fs::write(
                &path,
                serde_json::to_string_pretty(scene).unwrap_or_default(),
            )
            .map_err(|e| HostError::failed(format!("{}: {e}", path.display())))?;
            Job {
                plugin: MORPH_ID,
                context: "OfxImageEffectContextGeneral",
                sources: vec![
                    ("SourceA".into(), s(plates.join("a.exr"))),
                    ("SourceB".into(), s(plates.join("b.exr"))),
                ],
                view: "morph".into(),
                extra,
                common: Common {
                    scene: Some(path),
                    line: Vec::new(),
                    t: None,
                    frames: Some("1-12".into()),
                    output: s(output),
                    half: false,
                    float: true,
                    compression: None,
                    raw: false,
                },
            }
            .run(bundle_path)
        };
    render(
        "demo",
        &scene,
        dir.join("morph.####.exr"),
        vec![
            ("morph".into(), s(dir.join("preview/morph.####.png"))),
            ("stmap-a".into(), s(dir.join("stmap_a.####.exr"))),
        ],
    )?;

    // The same morph through the mesh and triangle methods: a 5 × 5 mesh whose
    // inner ring opens from the round face to the square one, and the
    // features above triangulated.
    let (nodes_a, nodes_b) = demo_mesh((w, h), (cx, cy));
    let mut mesh_scene = scene.clone();
    mesh_scene["method"] = "mesh".into();
    mesh_scene["mesh"] = serde_json::json!({ "rows": 5, "cols": 5, "a": nodes_a, "b": nodes_b });
    let mut triangles_scene = scene.clone();
    triangles_scene["method"] = "triangles".into();
    // And found from the plates alone, the features as anchors.
    let mut auto_scene = scene.clone();
    auto_scene["method"] = "auto".into();
    for (name, scene) in [
        ("mesh", mesh_scene),
        ("triangles", triangles_scene),
        ("auto", auto_scene),
    ] {
        render(
            name,
            &scene,
            dir.join(format!("{name}/morph.####.png")),
            Vec::new(),
        )?;
    }
    demo_report(bundle_path, dir);
    Ok(())
}

/// The demo plates: a round face (A) and a square one (B) on a gradient.
fn demo_face(i: i32, j: i32, c: usize, square: bool, (w, h): (usize, usize)) -> f32 {
    let (x, y) = (i as f32 + 0.5 - 160.0, j as f32 + 0.5 - 120.0);
    let inside = if square {
        x.abs().max(y.abs() * 1.1) < 85.0
    } else {
        (x * x + y * y).sqrt() < 90.0
    };
    let eyes = if square {
        [(-35.0, 35.0), (35.0, 35.0)]
    } else {
        [(-30.0, 25.0), (30.0, 25.0)]
    };
    let eye = eyes
        .iter()
        .any(|(ex, ey)| ((x - ex).powi(2) + (y - ey).powi(2)).sqrt() < 9.0);
    let mouth_y = if square { -40.0 } else { -35.0 };
    let mouth = (y - mouth_y).abs() < 4.0 && x.abs() < if square { 45.0 } else { 35.0 };
    let bg = [
        0.05 + 0.2 * (j as f32 / h as f32),
        0.08,
        0.12 + 0.2 * (i as f32 / w as f32),
        1.0,
    ];
    let skin = if square {
        [0.3, 0.55, 0.9, 1.0]
    } else {
        [0.95, 0.6, 0.3, 1.0]
    };
    if eye || mouth {
        [0.02, 0.02, 0.02, 1.0][c]
    } else if inside {
        skin[c] * (1.0 + 0.15 * ((x * 0.15).sin() * (y * 0.15).cos()))
    } else {
        bg[c]
    }
}

/// The demo scene: eyes, mouth and the face's outline, keyed over frames 1-12.
fn demo_scene((cx, cy): (f64, f64)) -> serde_json::Value {
    serde_json::json!({
        "format": "morphfx-scene", "version": 1, "method": "field",
        "field": { "a": 0.5, "b": 1.5, "p": 0.5, "interpolation": "endpoints" },
        "features": [
            { "name": "left eye", "type": "point", "a": [[cx - 30.0, cy + 25.0]], "b": [[cx - 35.0, cy + 35.0]] },
            { "name": "right eye", "type": "point", "a": [[cx + 30.0, cy + 25.0]], "b": [[cx + 35.0, cy + 35.0]] },
            { "name": "mouth", "type": "line", "a": [[cx - 35.0, cy - 35.0], [cx + 35.0, cy - 35.0]], "b": [[cx - 45.0, cy - 40.0], [cx + 45.0, cy - 40.0]] },
            { "name": "top", "type": "line", "a": [[cx - 60.0, cy + 66.0], [cx + 60.0, cy + 66.0]], "b": [[cx - 80.0, cy + 77.0], [cx + 80.0, cy + 77.0]] },
            { "name": "bottom", "type": "line", "a": [[cx + 60.0, cy - 66.0], [cx - 60.0, cy - 66.0]], "b": [[cx + 80.0, cy - 77.0], [cx - 80.0, cy - 77.0]] },
            { "name": "left", "type": "line", "a": [[cx - 90.0, cy - 30.0], [cx - 90.0, cy + 30.0]], "b": [[cx - 85.0, cy - 40.0], [cx - 85.0, cy + 40.0]] },
            { "name": "right", "type": "line", "a": [[cx + 90.0, cy + 30.0], [cx + 90.0, cy - 30.0]], "b": [[cx + 85.0, cy + 40.0], [cx + 85.0, cy - 40.0]] }
        ],
        "progress": [[1, 0.0], [12, 1.0]]
    })
}

/// A 5 × 5 mesh over the frame whose inner ring opens from the round
/// face to the square one: (A's nodes, B's nodes).
fn demo_mesh((w, h): (usize, usize), (cx, cy): (f64, f64)) -> (Vec<[f64; 2]>, Vec<[f64; 2]>) {
    let mut nodes_a = Vec::new();
    let mut nodes_b = Vec::new();
    for r in 0..5 {
        for c in 0..5 {
            let p = [c as f64 * w as f64 / 4.0, r as f64 * h as f64 / 4.0];
            let inner = (1..4).contains(&r) && (1..4).contains(&c);
            let q = if inner && (r, c) != (2, 2) {
                [cx + (p[0] - cx) * 1.12, cy + (p[1] - cy) * 1.12]
            } else {
                p
            };
            nodes_a.push(p);
            nodes_b.push(q);
        }
    }
    (nodes_a, nodes_b)
}

/// Says where the demo wrote what.
fn demo_report(bundle_path: &Path, dir: &Path) {
    let plates = dir.join("plates");
    let scene_path = dir.join("demo.morph.json");
    println!(
        "MorphFX demo rendered through {}",
        morphfx_harness::host::bundle_binary(bundle_path).display()
    );
    println!("  plates:   {}", plates.display());
    println!("  scene:    {}", scene_path.display());
    println!(
        "  morph:    {} (frames 1-12, float EXR)",
        dir.join("morph.####.exr").display()
    );
    println!(
        "  previews: {}",
        dir.join("preview/morph.####.png").display()
    );
    println!(
        "  ST maps:  {} (A's warp per frame)",
        dir.join("stmap_a.####.exr").display()
    );
    println!(
        "  methods:  {}, {} and {} (the same morph by mesh, by triangles and by auto, PNG)",
        dir.join("mesh/morph.####.png").display(),
        dir.join("triangles/morph.####.png").display(),
        dir.join("auto/morph.####.png").display()
    );
}
