//! `morphfx morph` and `morphfx warp`: a node over plates, rendered frame
//! by frame through the bundle, the outputs written behind the render.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

use morphfx::scene::Scene;

use crate::args::line_key::LineKey;
use crate::args::param_value::ParamSetting;
use crate::cli::Common;
use crate::commands::layers::{self, LayerChoice, LayeredRun};
use crate::host::{Bundle, HostError, Instance, OutputSpec};
use crate::interrupt;
use crate::io::{self, ExrPrecision, Plate};
use crate::pipeline::WriteBehind;
use crate::plates::Plates;
use crate::progress::Progress;
use crate::sequence::{frame_path, is_sequence, parse_frames};
use crate::sync::Locked;

pub const MORPH_ID: &str = "net.morphfx.Morph";
pub const WARP_ID: &str = "net.morphfx.Warp";

/// `morphfx warp`: the Warp node in the filter context.
pub fn warp_job(common: Common, input: String, stmap: Option<String>, view: String) -> Job {
    Job {
        plugin: WARP_ID,
        context: "OfxImageEffectContextFilter",
        sources: vec![("Source".to_owned(), input)],
        view,
        extra: stmap
            .map(|s| vec![("stmap".to_owned(), s)])
            .unwrap_or_default(),
        mattes: Vec::new(),
        common,
        layers: None,
    }
}

/// `morphfx morph`: the morph node in the general or transition context.
pub fn morph_job(
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
        mattes: Vec::new(),
        common,
        layers: None,
    })
}

/// What a job reads before it loads the bundle.
pub struct Prepared {
    pub scene: Option<Scene>,
    pub lines: Vec<LineKey>,
    pub frames: Vec<i64>,
    pub plates: Vec<(String, Arc<Plates>)>,
    /// The mattes' plates (Mask, Timing), by clip.
    pub mattes: Vec<(String, Arc<Plates>)>,
    pub params: Vec<ParamSetting>,
    pub inputs: Inputs,
}

impl Prepared {
    /// Whether features or progress change over the frames (keyframes,
    /// keyed line slots, progress keys not overridden by a fixed `--t`).
    pub fn animated(&self, fixed_t: bool) -> bool {
        let keyed_lines = self.lines.iter().filter(|l| l.frame.is_some()).count() > 1;
        let scene = self.scene.as_ref().is_some_and(|s| {
            let progress = !fixed_t && s.progress.windows(2).any(|w| w[0].1 != w[1].1);
            s.keyframes.len() > 1 || s.meshes.len() > 1 || progress
        });
        keyed_lines || scene
    }
}

/// What the command line itself says, read before any plate.
struct Command {
    scene: Option<Scene>,
    lines: Vec<LineKey>,
    frames: Vec<i64>,
    params: Vec<ParamSetting>,
}

pub struct Job {
    pub plugin: &'static str,
    pub context: &'static str,
    pub sources: Vec<(String, String)>,
    pub view: String,
    /// Extra outputs: (view, path pattern).
    pub extra: Vec<(String, String)>,
    /// Optional matte clips and their plates: (clip, path pattern).
    pub mattes: Vec<(String, String)>,
    pub common: Common,
    /// `warp --layers`: the layers of a multi-layer EXR to warp (`None`:
    /// the main picture, as any render).
    pub layers: Option<LayerChoice>,
}

impl Job {
    /// The job with its Mask and Timing inputs, where given.
    pub fn with_mattes(mut self, mask: Option<String>, timing: Option<String>) -> Job {
        self.mattes = [("Mask", mask), ("Timing", timing)]
            .into_iter()
            .filter_map(|(clip, p)| p.map(|p| (clip.to_owned(), p)))
            .collect();
        self
    }

    /// The job warping `--layers SPEC` (with `--id-layers IDS`) of its
    /// input, checked against the rest of the command line.
    pub fn with_layers(mut self, spec: &str, ids: &str) -> Result<Job, HostError> {
        self.layers = LayerChoice::parse(spec, ids)?;
        if self.layers.is_some() {
            let (_, input) = &self.sources[0];
            layers::check(input, &self.common.output, &self.view, self.extra.len())?;
        }
        Ok(self)
    }

    /// Everything a run reads before it loads the bundle: the scene, the
    /// lines, the frames and every input's header.
    pub fn prepare(&self) -> Result<Prepared, HostError> {
        let c = &self.common;
        let Command {
            scene,
            lines,
            frames,
            params,
        } = self.command()?;
        let plates: Vec<(String, Arc<Plates>)> = self
            .sources
            .iter()
            .map(|(clip, p)| (clip.clone(), Plates::new(p, c.colour())))
            .collect();
        let inputs = check_inputs(&plates, &frames)?;
        let mattes: Vec<(String, Arc<Plates>)> = self
            .mattes
            .iter()
            .map(|(clip, p)| (clip.clone(), Plates::matte(p, c.colour())))
            .collect();
        check_mattes(&mattes, &frames)?;
        Ok(Prepared {
            scene,
            lines,
            frames,
            plates,
            mattes,
            params,
            inputs,
        })
    }

    /// The command line's own words read and checked: the scene, the
    /// lines, `--t`, the frames against the outputs, the `--param`s.
    fn command(&self) -> Result<Command, HostError> {
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
        self.check_outputs(&frames)?;
        let params = c
            .param
            .iter()
            .map(|spec| ParamSetting::parse(spec))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Command {
            scene,
            lines,
            frames,
            params,
        })
    }

    /// The output patterns: the view's and every extra output's.
    fn output_patterns(&self) -> impl Iterator<Item = &str> {
        std::iter::once(self.common.output.as_str())
            .chain(self.extra.iter().map(|(_, p)| p.as_str()))
    }

    /// Several frames need outputs numbered by `#`: one name for all would
    /// be overwritten frame after frame (and raced on by a farm's chunks).
    fn check_outputs(&self, frames: &[i64]) -> Result<(), HostError> {
        if frames.len() < 2 {
            return Ok(());
        }
        match self.output_patterns().find(|p| !is_sequence(p)) {
            Some(p) => Err(HostError::bad(format!(
                "{p}: {} frames would overwrite one file: number the output with # \
                 (e.g. out.####.exr)",
                frames.len()
            ))),
            None => Ok(()),
        }
    }

    /// What a farm job can be checked for where it is submitted, before any
    /// worker starts: the scene, the lines, the frames and outputs, and every
    /// `--param` against the node the bundle makes. The plates are not read
    /// here (a worker may see other mounts); each chunk checks them first.
    pub fn check_submission(&self, bundle_path: &Path) -> Result<(), HostError> {
        let Command { scene, params, .. } = self.command()?;
        let bundle = Bundle::load(bundle_path)?;
        let inst = bundle.instance(self.plugin, self.context)?;
        apply_params(&inst, scene.as_ref(), &params)
    }

    pub fn run(&self, bundle_path: &Path) -> Result<(), HostError> {
        let job = self.prepare()?;
        let bundle = Bundle::load(bundle_path)?;
        let inst = bundle.instance(self.plugin, self.context)?;
        self.set_up(&inst, &job)?;
        match &self.layers {
            Some(choice) => self.render_layers(&inst, &job, choice),
            None => self.render_frames(&inst, &job),
        }
    }

    /// `--layers`: every chosen layer through the same warp, frame by frame.
    fn render_layers(
        &self,
        inst: &Instance<'_>,
        job: &Prepared,
        choice: &LayerChoice,
    ) -> Result<(), HostError> {
        inst.set_choice("view", &self.view)?;
        let run = LayeredRun {
            input: &self.sources[0].1,
            output: &self.common.output,
            frames: &job.frames,
            format: self.common.output_format(&job.inputs)?,
            purge: job.animated(self.common.t.is_some()),
        };
        run.render(inst, choice)
    }

    /// The frames to render: `--frames`, else the one frame the scene or
    /// the keyed lines start at.
    pub fn frames(&self, scene: Option<&Scene>, lines: &[LineKey]) -> Result<Vec<i64>, HostError> {
        let c = &self.common;
        match &c.frames {
            Some(spec) => parse_frames(spec),
            None if self.sources.iter().any(|(_, p)| is_sequence(p)) || is_sequence(&c.output) => {
                Err(HostError::bad(
                    "sequences need --frames (e.g. --frames 1001-1048)",
                ))
            }
            None => Ok(vec![first_frame(scene, lines)]),
        }
    }

    /// The instance's params from the command line (`--param` last, so it
    /// has the final word), its project and clips.
    pub fn set_up(&self, inst: &Instance<'_>, job: &Prepared) -> Result<(), HostError> {
        let (lines, size) = (&job.lines, job.inputs.size);
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
        apply_params(inst, job.scene.as_ref(), &job.params)?;
        inst.set_project(size.0 as f64, size.1 as f64);
        for (clip, p) in job.plates.iter().chain(&job.mattes) {
            inst.connect(clip, p.clone())?;
        }
        // Hosts ask for clip preferences once the clips are connected.
        inst.clip_preferences()?;
        Ok(())
    }

    /// Renders every frame of every output as one sequence, and says where
    /// the time went.
    pub fn render_frames(&self, inst: &Instance<'_>, job: &Prepared) -> Result<(), HostError> {
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
        // A plate that fails to decode fails its frame, whatever the plugin
        // made of the missing image: a Morph node renders on without an
        // input it cannot fetch (B alone, or black), so the render's own
        // result cannot be trusted to say so.
        let read_failure = |f: i64| {
            plates.iter().chain(&job.mattes).find_map(|(clip, p)| {
                let e = p.error.locked().take()?;
                let frame = if is_sequence(&p.pattern) {
                    format!(" (frame {f})")
                } else {
                    String::new()
                };
                Some(HostError::bad(format!(
                    "{}{frame}: {}",
                    clip_option(clip),
                    e.message
                )))
            })
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
                for (_, p) in plates.iter().chain(&job.mattes) {
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
                if let Some(e) = read_failure(f) {
                    return Err(e);
                }
                let out = out?;
                rendering += started.elapsed();
                let plate = Plate {
                    image: out.into_image(),
                    size: inputs.size,
                    origin: inputs.windows.get(&f).map_or((0, 0), |w| w.origin),
                };
                writer.write(frame_path(pattern, f), plate, format_for(view, format))?;
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
        let reading: Duration = plates.iter().map(|(_, p)| *p.read_time.locked()).sum();
        progress.done(&format!(
            "render {:.2} s (waits for plates included); alongside it, read {:.2} s, write {:.2} s",
            rendering.as_secs_f64(),
            reading.as_secs_f64(),
            writing.as_secs_f64()
        ));
        Ok(())
    }
}

/// The frame a render of single plates is at: the first the scene keys
/// (features or progress), else the first keyed line's, else 0.
pub fn first_frame(scene: Option<&Scene>, lines: &[LineKey]) -> i64 {
    scene
        .and_then(|s| {
            s.keyframes
                .first()
                .map(|k| k.frame)
                .or(s.progress.first().map(|p| p.0))
        })
        .or(lines.iter().find_map(|l| l.frame))
        .unwrap_or(0.0) as i64
}

/// Every `--param` set on `inst` as a host would, and none that `scene`
/// would silently override.
pub fn apply_params(
    inst: &Instance<'_>,
    scene: Option<&Scene>,
    params: &[ParamSetting],
) -> Result<(), HostError> {
    for p in params {
        p.apply(inst)?;
    }
    match scene {
        Some(scene) => refuse_settings_the_scene_sets(inst, scene, params),
        None => Ok(()),
    }
}

/// The param groups whose values a scene's settings replace while
/// *Settings From Scene* is on (the node's default): the method's own.
const SCENE_GROUPS: [&str; 4] = ["field_group", "mesh_group", "auto_group", "scattered_group"];

/// `--param` has the last word, so one the scene would silently override
/// is refused rather than ignored: the method and its settings, and the
/// transition's when the scene has one (its spread still paces a timing
/// matte, so it is not among them).
fn refuse_settings_the_scene_sets(
    inst: &Instance<'_>,
    scene: &Scene,
    params: &[ParamSetting],
) -> Result<(), HostError> {
    let node_wins = params
        .iter()
        .any(|p| p.id == "settings_from_scene" && p.value.trim() == "false");
    if node_wins {
        return Ok(());
    }
    let scene_transition = scene.settings.transition != Default::default();
    for p in params {
        let group = inst
            .param_props(&p.id)
            .and_then(|props| props.str(openfx::sys::image_effect_v1::param::kOfxParamPropParent))
            .unwrap_or_default();
        let overridden = p.id == "method"
            || SCENE_GROUPS.contains(&group.as_str())
            || (group == "transition_group" && p.id != "transition_spread" && scene_transition);
        if overridden {
            return Err(HostError::bad(format!(
                "--param {}={}: the scene sets this (settings_from_scene is on, so its method \
                 settings win over the node's): add --param settings_from_scene=false to use \
                 the node's settings (the scene then gives its features, mesh and progress), or \
                 set it in the scene",
                p.id, p.value
            )));
        }
    }
    Ok(())
}

/// How `view` is written: ST maps always as 32-bit float (Nuke's STMap
/// convention, and half floats are 0.94 px off at 1920 px wide), the rest
/// as the run's format says.
fn format_for(view: &str, format: io::OutputFormat) -> io::OutputFormat {
    if view.starts_with("stmap") {
        io::OutputFormat {
            precision: ExrPrecision::Float,
            ..format
        }
    } else {
        format
    }
}

/// The run stopped by a signal before `missing` was written, once the
/// frames `done` are written whole: the error that says what is on disk.
pub fn interrupted(writer: WriteBehind, done: &[i64], missing: PathBuf) -> HostError {
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

/// The command-line option that feeds `clip`, as a user wrote it.
pub fn clip_option(clip: &str) -> &str {
    match clip {
        "SourceA" | "SourceFrom" => "--a",
        "SourceB" | "SourceTo" => "--b",
        "Source" => "--input",
        "Mask" => "--mask",
        "Timing" => "--timing",
        other => other,
    }
}

/// The scene file, parsed, if one is given.
pub fn read_scene(path: Option<&Path>) -> Result<Option<Scene>, HostError> {
    let Some(path) = path else {
        return Ok(None);
    };
    let bad = |e: &dyn std::fmt::Display| HostError::bad(format!("scene {}: {e}", path.display()));
    let text = std::fs::read_to_string(path).map_err(|e| bad(&e))?;
    Scene::parse(&text).map(Some).map_err(|e| bad(&e))
}

/// Checks that every matte can be read at every frame before anything is
/// rendered. Mattes may have any size and region: each lines up with the
/// sources by its own data window.
pub fn check_mattes(mattes: &[(String, Arc<Plates>)], frames: &[i64]) -> Result<(), HostError> {
    for (clip, p) in mattes {
        for &f in frames {
            let path = frame_path(&p.pattern, p.file_frame(f));
            io::probe(&path).map_err(|e| {
                HostError::bad(format!(
                    "--{} {}: {}",
                    clip.to_lowercase(),
                    p.pattern,
                    e.message
                ))
            })?;
        }
    }
    Ok(())
}

/// What the input files' headers say, for every frame.
pub struct Inputs {
    /// The display window size every input shares.
    pub size: (usize, usize),
    /// The first input is half float.
    pub half: bool,
    /// The first input's EXR compression.
    pub compression: Option<exr::prelude::Compression>,
    /// The first source's display window at each frame.
    pub windows: std::collections::BTreeMap<i64, io::DisplayWindow>,
}

/// Checks every input frame up front: a missing frame, or one whose display
/// window differs, is reported before anything is written. Data windows may
/// differ (overscan, bbox-cropped plates): each is its clip's region of
/// definition, and the Morph node's output covers their union. The output
/// keeps the first source's display window, frame by frame (its size is
/// every source's; its origin may move in a sequence).
pub fn check_inputs(plates: &[(String, Arc<Plates>)], frames: &[i64]) -> Result<Inputs, HostError> {
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
                        "size mismatch: the display window of {name} is {}x{} but \
                            that of {n0} is {}x{}",
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

impl Common {
    /// How outputs are written: precision and compression follow the first
    /// input unless the options say otherwise.
    pub fn output_format(&self, inputs: &Inputs) -> Result<io::OutputFormat, HostError> {
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
}
