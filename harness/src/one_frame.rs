//! One frame rendered from pictures held in memory, through the bundle's
//! nodes as `morphfx morph` and `morphfx warp` render them: the same
//! params set the same way, the same action sequence. The Python module
//! renders with this, so its pixels are the command line's.
//!
//! Pictures travel as rows, top row first, as files and numpy store them.
//! The sources are lent to the host, which hands the caller's rows to the
//! plugin in place, top-down (negative row bytes, as the spec allows):
//! nothing is copied or flipped on the way in, nor on the way out.

use std::sync::Arc;
use std::time::{Duration, Instant};

use morphfx::geom::RectI;
use morphfx::scene::Scene;

use crate::args::param_value::ParamSetting;
use crate::commands::job::{apply_params, first_frame, MORPH_ID, WARP_ID};
use crate::host::frame::lend;
pub use crate::host::frame::LentRows;
use crate::host::{Bundle, Frame, HostError, Instance, OutputSpec};
use crate::plates::Still;
pub use crate::rows::Rows;

/// Which node renders, in the context the command line uses for it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Node {
    /// `morphfx morph`: the Morph node, general context, Source A and B.
    Morph,
    /// `morphfx warp`: the Warp node, filter context, one Source.
    Warp,
}

impl Node {
    fn plugin(self) -> &'static str {
        match self {
            Node::Morph => MORPH_ID,
            Node::Warp => WARP_ID,
        }
    }

    fn context(self) -> &'static str {
        match self {
            Node::Morph => "OfxImageEffectContextGeneral",
            Node::Warp => "OfxImageEffectContextFilter",
        }
    }

    /// How many of the matte inputs (Mask, then Timing) the node has.
    fn mattes(self) -> usize {
        match self {
            Node::Morph => 2,
            Node::Warp => 1,
        }
    }

    fn clips(self) -> &'static [&'static str] {
        match self {
            Node::Morph => &["SourceA", "SourceB"],
            Node::Warp => &["Source"],
        }
    }
}

/// What to render: the command line's options, with pictures for files.
#[derive(Debug, Clone)]
pub struct OneFrame<'a> {
    pub node: Node,
    /// The node's sources in clip order (A then B for a morph).
    pub sources: Vec<LentRows<'a>>,
    /// The Mask and Timing inputs, where given.
    pub mask: Option<LentRows<'a>>,
    pub timing: Option<LentRows<'a>>,
    /// The scene document (its text, as a scene file holds it).
    pub scene: Option<String>,
    /// `--t`: the progress, over the scene's keys.
    pub t: Option<f64>,
    /// The frame; by default the one the command line renders alone.
    pub frame: Option<f64>,
    /// The node's view by option name (`--view`).
    pub view: String,
    /// `--param`s, applied last as the command line applies them.
    pub params: Vec<ParamSetting>,
}

/// A frame as single plates make it: every source the same size.
fn size_of(sources: &[LentRows<'_>]) -> Result<(usize, usize), HostError> {
    let first = sources
        .first()
        .ok_or_else(|| HostError::bad("no source picture"))?;
    let size = (first.width, first.height);
    for (k, s) in sources.iter().enumerate() {
        if (s.width, s.height) != size {
            return Err(HostError::bad(format!(
                "size mismatch: source {} is {}x{} but source 1 is {}x{}",
                k + 1,
                s.width,
                s.height,
                size.0,
                size.1
            )));
        }
    }
    Ok(size)
}

/// What a render failed at: the request's scene, its params (an
/// unknown id or view, a wrong value, one the scene sets), or the render.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// The pictures: their sizes disagree.
    Inputs,
    Scene,
    Params,
    Render,
}

/// A rendered picture, and how long the host's render call took (the
/// plugin's own time, without setting up or handing pictures over).
pub struct Rendered {
    pub rows: Rows,
    pub render: Duration,
}

/// A failed render: where, and the command line's message.
pub type Failed = (Stage, HostError);

/// The node instance a request renders on.
pub fn instance(bundle: &Bundle, node: Node) -> Result<Instance<'_>, HostError> {
    bundle.instance(node.plugin(), node.context())
}

impl OneFrame<'_> {
    /// Renders through `bundle` on a fresh instance of the node, as the
    /// command line would render the same request with single plates: the
    /// picture the size of the sources, top row first, four channels.
    pub fn render(self, bundle: &Bundle) -> Result<Rendered, Failed> {
        let inst = instance(bundle, self.node).map_err(|e| (Stage::Render, e))?;
        self.render_on(&inst)
    }

    /// [`OneFrame::render`] on `inst`, an instance of this request's node
    /// that may have rendered other requests: its params go back to their
    /// defaults and its inputs are cut first, so nothing of those shows.
    pub fn render_on(self, inst: &Instance<'_>) -> Result<Rendered, Failed> {
        let at = |stage: Stage| move |e: HostError| (stage, e);
        let size = size_of(&self.sources).map_err(at(Stage::Inputs))?;
        let scene = self
            .scene
            .as_deref()
            .map(|text| Scene::parse(text).map_err(|e| HostError::bad(format!("scene: {e}"))))
            .transpose()
            .map_err(at(Stage::Scene))?;
        let frame = self
            .frame
            .unwrap_or_else(|| first_frame(scene.as_ref(), &[]) as f64);
        let clips = self
            .node
            .clips()
            .iter()
            .chain(&["Mask", "Timing"][..self.node.mattes()]);
        for clip in clips.clone() {
            inst.disconnect(clip).map_err(at(Stage::Render))?;
        }
        inst.reset_params();
        set_params(inst, &self, scene.as_ref()).map_err(at(Stage::Params))?;
        inst.set_project(size.0 as f64, size.1 as f64);
        // Nothing of an earlier render: cached warps and warm starts go too.
        inst.purge_caches().map_err(at(Stage::Render))?;
        let given = self
            .sources
            .into_iter()
            .map(Some)
            .chain([self.mask, self.timing]);
        let (clips, pictures): (Vec<&str>, Vec<LentRows<'_>>) = clips
            .zip(given)
            .filter_map(|(clip, rows)| Some((*clip, rows?)))
            .unzip();
        let rendered = |frames: Vec<Arc<Frame>>| {
            let connected = clips
                .iter()
                .zip(frames)
                .try_for_each(|(clip, frame)| inst.connect(clip, Arc::new(Still(frame))));
            let spec = OutputSpec {
                sequential: true,
                top_down: true,
                ..OutputSpec::default()
            };
            let rendered = connected.and_then(|()| render_connected(inst, frame, spec, size));
            // The inputs let go, whatever happened: the lent rows are the
            // caller's again (a clip this node has always disconnects).
            for clip in &clips {
                let _ = inst.disconnect(clip);
            }
            rendered
        };
        let lent = lend(&pictures, rendered).map_err(|e| (Stage::Inputs, HostError::bad(e)))?;
        // An instance kept idle for the next request holds no maps meanwhile.
        let purged = inst.purge_caches();
        let rendered = lent.map_err(at(Stage::Render))?;
        purged.map_err(at(Stage::Render))?;
        Ok(rendered)
    }
}

/// The render of connected `inst` at `frame`, as the command line's.
fn render_connected(
    inst: &Instance<'_>,
    frame: f64,
    spec: OutputSpec,
    size: (usize, usize),
) -> Result<Rendered, HostError> {
    inst.clip_preferences()?;
    inst.begin_sequence(frame, frame)?;
    let started = Instant::now();
    let out = inst.render(frame, spec)?;
    let render = started.elapsed();
    inst.end_sequence(frame, frame)?;
    Ok(Rendered {
        rows: displayed(out, size),
        render,
    })
}

/// The request's params on `inst` in the command line's order: the scene,
/// the progress, the view, then every `--param`.
fn set_params(inst: &Instance<'_>, req: &OneFrame, scene: Option<&Scene>) -> Result<(), HostError> {
    if let Some(text) = &req.scene {
        inst.set_string("scene_text", text)?;
    }
    if let Some(t) = req.t {
        if !(0.0..=1.0).contains(&t) {
            return Err(HostError::bad(format!("--t {t}: must be in [0, 1]")));
        }
        inst.set_double("progress", &[t], None)?;
        inst.set_int("use_scene_progress", 0)?;
    }
    inst.set_choice("view", &req.view)?;
    apply_params(inst, scene, &req.params)
}

/// The display window `size` of a rendered frame, top row first: the
/// frame's own rows when it covers exactly that (moved, not copied),
/// else its pixels within the window and black beyond.
fn displayed(out: Arc<Frame>, (width, height): (usize, usize)) -> Rows {
    let window = RectI::new(0, 0, width as i32, height as i32);
    let out = match Arc::try_unwrap(out) {
        Ok(f) if f.top_down && f.channels == 4 && f.bounds == window => match f.into_floats() {
            Ok(data) => {
                return Rows {
                    width,
                    height,
                    channels: 4,
                    data,
                }
            }
            Err(f) => Arc::new(f),
        },
        Ok(f) => Arc::new(f),
        Err(shared) => shared,
    };
    Rows::of_window(&out.to_image(), (width, height))
}
