//! The params both nodes share, as one table, and their values read at a time.

use std::cell::RefCell;
use std::collections::HashMap;
use std::sync::OnceLock;

use morphfx::choice::Choice;
use morphfx::features::Feature;
use morphfx::geom::Vec2;
use morphfx::image::{EdgeMode, Filter};
use morphfx::make_warp::{Method, MethodSettings};
use morphfx::transition::procedural::PatternKind;
use morphfx::transition::{Pattern, Procedural, Transition, TransitionSettings};
use morphfx::views::View;
use morphfx::warp::auto::grid::MAX_LEVEL;
use morphfx::warp::auto::{AutoSettings, Coefficients};
use morphfx::warp::field::{Evaluation, FieldSettings, LineInterpolation};
use morphfx::warp::mesh::{MeshSettings, Pass};
use morphfx::warp::mffd::MffdSettings;
use morphfx::warp::thin_plate::ThinPlateSettings;

use super::spec::{Kind, ParamSpec, TextMode};
use super::NodeKind;
use crate::wrapper::params::Params;
use crate::wrapper::Outcome;

/// Line-pair slots every node offers (a face takes 30 to 60 lines).
pub const LINE_SLOTS: usize = 64;

pub const METHOD: &str = "method";
pub const PROGRESS: &str = "progress";
pub const USE_SCENE_PROGRESS: &str = "use_scene_progress";
pub const SETTINGS_FROM_SCENE: &str = "settings_from_scene";
pub const FIELD_A: &str = "field_a";
pub const FIELD_B: &str = "field_b";
pub const FIELD_P: &str = "field_p";
pub const INTERPOLATION: &str = "line_interpolation";
pub const EVALUATION: &str = "evaluation";
pub const TOLERANCE: &str = "tolerance";
pub const LINE_COUNT: &str = "line_count";
pub const SCENE_FILE: &str = "scene_file";
pub const SCENE_TEXT: &str = "scene_text";
pub const OFFSET_A: &str = "frame_offset_a";
pub const OFFSET_B: &str = "frame_offset_b";
pub const FILTER: &str = "filter";
pub const EDGE: &str = "edge";
pub const VIEW: &str = "view";
pub const MESH_PASS: &str = "mesh_pass";
pub const SNAP_LINES: &str = "snap_lines";
pub const SNAP_SIGMA: &str = "snap_sigma";
pub const TRACK_FORWARD: &str = "track_forward";
pub const TRACK_BACKWARD: &str = "track_backward";
pub const OVERLAY_SHOW: &str = "overlay_show";
pub const OVERLAY_EDIT: &str = "overlay_edit";
pub const AUTO_LEVELS: &str = "auto_levels";
pub const AUTO_COLOUR: &str = "auto_colour";
pub const AUTO_STRETCH: &str = "auto_stretch";
pub const AUTO_ANGLE: &str = "auto_angle";
pub const AUTO_ANCHORS: &str = "auto_anchors";
pub const AUTO_WARM_START: &str = "auto_warm_start";
pub const PLATE_ALPHA: &str = "plate_alpha";
pub const PLATE_BETA: &str = "plate_beta";
pub const MFFD_ALPHA: &str = "mffd_alpha";
pub const TRANSITION: &str = "transition";
pub const TRANSITION_AFFECTS: &str = "transition_affects";
pub const TRANSITION_SPREAD: &str = "transition_spread";
pub const TRANSITION_ANGLE: &str = "transition_angle";
pub const TRANSITION_CYCLES: &str = "transition_cycles";

/// The group holding line slot `k`'s params.
pub fn slot_group(k: usize) -> String {
    format!("line{k}_group")
}

/// Line slot `k`'s Clear Line button.
pub fn slot_clear(k: usize) -> String {
    format!("line{k}_clear")
}

/// The slot whose Clear Line button `id` is.
pub fn clear_button_slot(id: &str) -> Option<usize> {
    let k: usize = id
        .strip_prefix("line")?
        .strip_suffix("_clear")?
        .parse()
        .ok()?;
    (1..=LINE_SLOTS).contains(&k).then_some(k)
}

/// What the viewer overlay shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Show {
    /// A's and B's lines, their connectors and the in-between lines.
    Both,
    /// A's lines only.
    A,
    /// B's lines only.
    B,
    /// The in-between lines at the current progress only.
    Between,
    /// Nothing.
    Off,
}

impl Choice for Show {
    const ALL: &'static [Self] = &[Show::Both, Show::A, Show::B, Show::Between, Show::Off];
    fn name(self) -> &'static str {
        match self {
            Show::Both => "A and B",
            Show::A => "A only",
            Show::B => "B only",
            Show::Between => "in-between",
            Show::Off => "off",
        }
    }
}

/// Which lines the overlay lets the pen move.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EditSides {
    /// A's and B's.
    Both,
    /// A's only (B's are drawn, locked).
    A,
    /// B's only.
    B,
}

impl Choice for EditSides {
    const ALL: &'static [Self] = &[EditSides::Both, EditSides::A, EditSides::B];
    fn name(self) -> &'static str {
        match self {
            EditSides::Both => "A and B",
            EditSides::A => "A only",
            EditSides::B => "B only",
        }
    }
}

/// Ids of line slot `k` (1-based): enable, A start, A end, B start, B end.
pub fn slot_ids(k: usize) -> [String; 5] {
    [
        format!("line{k}_enable"),
        format!("line{k}_a_start"),
        format!("line{k}_a_end"),
        format!("line{k}_b_start"),
        format!("line{k}_b_end"),
    ]
}

/// The methods a node offers, in choice order (hosts save the index: only
/// ever append). Auto finds its warp from both pictures, so the Warp node,
/// which has one, stops before it; auto is last, so no index moves.
fn methods(kind: NodeKind) -> &'static [Method] {
    match kind {
        NodeKind::Morph => Method::ALL,
        NodeKind::Warp => &Method::ALL[..Method::ALL.len() - 1],
    }
}

/// The views a node offers, in the order of its View choice.
pub fn views(kind: NodeKind) -> &'static [View] {
    match kind {
        NodeKind::Morph => View::ALL,
        NodeKind::Warp => &[View::WarpedA, View::StmapA, View::Grid],
    }
}

fn view_label(kind: NodeKind, v: View) -> &'static str {
    match (kind, v) {
        (NodeKind::Warp, View::WarpedA) => "warped",
        (NodeKind::Warp, View::StmapA) => "stmap",
        _ => v.name(),
    }
}

/// The Transition param's options: uniform, then each procedural pattern
/// (curves come from the scene).
const PATTERNS: [Option<PatternKind>; 5] = [
    None,
    Some(PatternKind::Ramp),
    Some(PatternKind::SineRows),
    Some(PatternKind::SineColumns),
    Some(PatternKind::Radial),
];

fn pattern_label(p: Option<PatternKind>) -> &'static str {
    p.map_or("uniform", PatternKind::name)
}

/// How the field is evaluated (the tolerance is its own param).
#[derive(Debug, Clone, Copy, PartialEq)]
enum EvaluationMode {
    Adaptive,
    Exact,
}

impl Choice for EvaluationMode {
    const ALL: &'static [Self] = &[EvaluationMode::Adaptive, EvaluationMode::Exact];
    fn name(self) -> &'static str {
        match self {
            EvaluationMode::Adaptive => "adaptive",
            EvaluationMode::Exact => "exact",
        }
    }
}

/// What a procedural transition paces.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Affects {
    Both,
    Geometry,
    Colour,
}

impl Choice for Affects {
    const ALL: &'static [Self] = &[Affects::Both, Affects::Geometry, Affects::Colour];
    fn name(self) -> &'static str {
        match self {
            Affects::Both => "geometry and colour",
            Affects::Geometry => "geometry",
            Affects::Colour => "colour",
        }
    }
}

/// A choice param's kind: `options` labelled by `label`, `default` first
/// unless said otherwise.
fn choice_of<C: Copy + PartialEq>(
    options: &[C],
    label: impl Fn(C) -> &'static str,
    default: C,
) -> Kind {
    Kind::Choice {
        options: options.iter().map(|o| label(*o)).collect(),
        default: options.iter().position(|o| *o == default).unwrap_or(0),
    }
}

/// A [`Choice`] param's kind, options in [`Choice::ALL`] order.
fn choice<C: Choice>(default: C) -> Kind {
    choice_of(C::ALL, C::name, default)
}

/// The node's params, built once per kind.
pub fn table(kind: NodeKind) -> &'static [ParamSpec] {
    static MORPH: OnceLock<Vec<ParamSpec>> = OnceLock::new();
    static WARP: OnceLock<Vec<ParamSpec>> = OnceLock::new();
    match kind {
        NodeKind::Morph => MORPH.get_or_init(|| build_table(kind)),
        NodeKind::Warp => WARP.get_or_init(|| build_table(kind)),
    }
}

fn build_table(kind: NodeKind) -> Vec<ParamSpec> {
    let d = FieldSettings::default();
    let c = Coefficients::default();
    let tp = ThinPlateSettings::default();
    let mut t = vec![
        ParamSpec::new(METHOD, "Method", "Warp generator. field: line pairs (Beier-Neely); mesh: the scene's mesh (two-pass Catmull-Rom); triangles: every feature point, Delaunay-triangulated, piecewise affine; thin-plate: every feature point pulls two thin plates (x and y displacement) by springs; mffd: multilevel B-spline free-form deformation, one-to-one whatever the features ask; hybrid: a coarse thin plate, then MFFD; auto (Morph node): the least-work warp of A onto B found from the pictures themselves, features acting as anchors.", choice_of(methods(kind), Method::name, Method::Field)),
        ParamSpec::new(
            PROGRESS,
            "Progress",
            "t in [0, 1]: 0 shows A unchanged, 1 shows B (Morph) or A warped fully onto B's features (Warp). Ignored in the transition context, where the host's Transition param drives it.",
            Kind::Double { default: 0.5, min: 0.0, max: 1.0, display: (0.0, 1.0) },
        ),
        ParamSpec::new(USE_SCENE_PROGRESS, "Use Scene Progress", "When the scene keys progress, follow it instead of the Progress param.", Kind::Bool { default: true }),
        ParamSpec::new(SETTINGS_FROM_SCENE, "Settings From Scene", "When a scene is loaded, its method and field settings win over this node's.", Kind::Bool { default: true }),
        ParamSpec::new("field_group", "Field", "Beier-Neely field constants", Kind::Group { open: true }),
        ParamSpec::new(FIELD_A, "a", "weight = (length^p / (a + dist))^b. Barely above 0 pins pixels on a line to it; larger is smoother.", Kind::Double { default: d.a, min: 1e-6, max: 1000.0, display: (0.0001, 10.0) }).in_group("field_group"),
        ParamSpec::new(FIELD_B, "b", "How fast a line's influence falls off with distance (0.5 to 2 is most useful).", Kind::Double { default: d.b, min: 0.0, max: 10.0, display: (0.0, 4.0) }).in_group("field_group"),
        ParamSpec::new(FIELD_P, "p", "How much longer lines outweigh shorter ones (0: all equal, 1: by length).", Kind::Double { default: d.p, min: 0.0, max: 4.0, display: (0.0, 1.0) }).in_group("field_group"),
        ParamSpec::new(INTERPOLATION, "Line Interpolation", "endpoints: endpoints move straight; center-angle: centre, angle and length interpolate (rotating lines keep their length).", choice(LineInterpolation::Endpoints)).in_group("field_group"),
        ParamSpec::new(EVALUATION, "Evaluation", "adaptive: coarse grid refined where needed, within Tolerance of exact; exact: every pixel.", choice(EvaluationMode::Adaptive)).in_group("field_group"),
        ParamSpec::new(TOLERANCE, "Tolerance", "Largest error of the adaptive evaluation, in pixels.", Kind::Double { default: Evaluation::DEFAULT_TOLERANCE, min: 0.001, max: 5.0, display: (0.01, 1.0) }).in_group("field_group").animated(false),
        ParamSpec::new("mesh_group", "Mesh", "Mesh warp (the mesh comes from the scene's \"mesh\" key)", Kind::Group { open: false }),
        ParamSpec::new(MESH_PASS, "Mesh Pass", "two-pass: rows then columns with Fant filtering (the classic algorithm, anti-aliased when squeezing); one-pass: bicubic patches inverted per pixel (no bottleneck under strong rotation, uses the Filter param).", choice(Pass::TwoPass)).in_group("mesh_group").animated(false),
        ParamSpec::new("auto_group", "Auto", "Automatic correspondence by work minimisation (method auto)", Kind::Group { open: false }),
        ParamSpec::new(AUTO_LEVELS, "Levels", "Depth of the search: 2^levels quads per side. 0: quads of about 4 pixels (6 at 256, 8 at HD). Fewer levels are faster and coarser.", Kind::Int { default: 0, min: 0, max: MAX_LEVEL as i32 }).in_group("auto_group").animated(false),
        ParamSpec::new(AUTO_COLOUR, "Colour Work", "How hard the warp tries to match B's colours (the weight of re-colouring work).", Kind::Double { default: c.colour, min: 0.0, max: 1000.0, display: (0.0, 10.0) }).in_group("auto_group").animated(false),
        ParamSpec::new(AUTO_STRETCH, "Stretch Work", "How much the warp resists stretching. 0 with Angle Work 0 gives a more fluid warp.", Kind::Double { default: c.stretch, min: 0.0, max: 1000.0, display: (0.0, 10.0) }).in_group("auto_group").animated(false),
        ParamSpec::new(AUTO_ANGLE, "Angle Work", "How much the warp resists changing angles (shearing).", Kind::Double { default: c.angle, min: 0.0, max: 1000.0, display: (0.0, 10.0) }).in_group("auto_group").animated(false),
        ParamSpec::new(AUTO_ANCHORS, "Anchor Weight", "How strongly features (line slots, scene features) hold as anchor points.", Kind::Double { default: c.anchor, min: 0.0, max: 1000.0, display: (0.0, 100.0) }).in_group("auto_group").animated(false),
        ParamSpec::new(AUTO_WARM_START, "Warm Start", "Start each frame from the previous frame's warp when this instance has it: faster, steadier over a sequence; off makes every frame independent of render order.", Kind::Bool { default: true }).in_group("auto_group").animated(false),
        ParamSpec::new("scattered_group", "Thin Plate / MFFD", "Settings of the scattered-feature methods (thin-plate, mffd, hybrid)", Kind::Group { open: false }),
        ParamSpec::new(PLATE_ALPHA, "Spring α", "How tightly the thin plate meets the feature points (px⁻²). Larger is tighter and slower to solve.", Kind::Double { default: tp.alpha, min: 0.01, max: 1e6, display: (1.0, 1000.0) }).in_group("scattered_group").animated(false),
        ParamSpec::new(PLATE_BETA, "Glue β", "How soon a feature's pull dies away in the thin plate (px⁻⁴): it reaches about β^(-1/4) px. 0: no glue, the pull spreads over the frame.", Kind::Double { default: tp.beta, min: 0.0, max: 1.0, display: (0.0, 1e-4) }).in_group("scattered_group").animated(false),
        ParamSpec::new(MFFD_ALPHA, "Refine α", "MFFD moves to a finer lattice when a step gains less than α (0.48 h)²: small values keep the deformation coarse and smooth.", Kind::Double { default: MffdSettings::default().alpha, min: 0.0, max: 1.0, display: (0.0, 1.0) }).in_group("scattered_group").animated(false),
        ParamSpec::new("transition_group", "Transition", "How fast each part changes (transition curves come from the scene's \"transition\" key)", Kind::Group { open: false }),
        ParamSpec::new(TRANSITION, "Transition", "uniform: every pixel at Progress; ramp, sine-rows, sine-columns, radial: each pixel's turn comes from where it is on A, every pixel still exactly A at 0 and B at 1.", choice_of(&PATTERNS, pattern_label, None)).in_group("transition_group"),
        ParamSpec::new(TRANSITION_AFFECTS, "Affects", "What the transition paces: the geometry (where features are) and the colour (the dissolve), or one of them (the other stays uniform).", choice(Affects::Both)).in_group("transition_group").animated(false),
        ParamSpec::new(TRANSITION_SPREAD, "Spread", "Share of the progress over which the pattern sweeps: 0 is uniform; near 1 each pixel changes almost at once, at its turn.", Kind::Double { default: 0.5, min: 0.0, max: 0.99, display: (0.0, 0.99) }).in_group("transition_group"),
        ParamSpec::new(TRANSITION_ANGLE, "Angle", "Direction of the ramp in degrees: 0 left to right, 90 bottom to top.", Kind::Double { default: 0.0, min: -360.0, max: 360.0, display: (-180.0, 180.0) }).in_group("transition_group"),
        ParamSpec::new(TRANSITION_CYCLES, "Cycles", "Sinusoid periods across the frame (sine patterns), or rings (radial; 0: the centre first, then outward).", Kind::Double { default: 2.0, min: 0.0, max: 100.0, display: (0.0, 8.0) }).in_group("transition_group"),
        ParamSpec::new("lines_group", "Lines", "Line pairs keyframed in the host", Kind::Group { open: true }),
        ParamSpec::new(LINE_COUNT, "Line Count", "How many of the line slots below are used.", Kind::Int { default: 0, min: 0, max: LINE_SLOTS as i32 }).in_group("lines_group").animated(false),
        ParamSpec::new(SNAP_LINES, "Snap Lines", "Slides every enabled line onto the nearest strong edge of its source at the current frame (A positions on Source A, B positions on Source B) and keys the moved endpoints there. Place lines roughly, then press.", Kind::Button).in_group("lines_group"),
        ParamSpec::new(SNAP_SIGMA, "Snap Reach", "Edge smoothing for Snap Lines, in pixels: edges pull lines from about twice this far.", Kind::Double { default: 3.0, min: 0.5, max: 50.0, display: (1.0, 10.0) }).in_group("lines_group").animated(false),
        ParamSpec::new(TRACK_FORWARD, "Track Forward", "Follows every enabled line through its source from the current frame to the line's next key (or the end of the clip) and keys it at each frame: A on Source A, B on Source B. Each frame is matched against the current frame's picture, so it does not drift; a line that loses track is left unkeyed from there and named. Cancel keeps the keys made so far.", Kind::Button).in_group("lines_group"),
        ParamSpec::new(TRACK_BACKWARD, "Track Backward", "As Track Forward, towards the start: to the previous key, or the first frame of the clip.", Kind::Button).in_group("lines_group"),
        ParamSpec::new(OVERLAY_SHOW, "Show Lines", "What the viewer draws: A's lines (one colour) and B's (another) with arrowheads, numbers and connectors, and the in-between lines dashed; or one of them; or nothing.", choice(Show::Both)).in_group("lines_group").animated(false),
        ParamSpec::new(OVERLAY_EDIT, "Edit Lines", "Which lines the pen moves in the viewer. Drag an end, or a line by its middle; drag in empty space to draw a new line. Hold Shift to grab only A's lines, Ctrl only B's.", choice(EditSides::Both)).in_group("lines_group").animated(false),
    ];
    for k in 1..=LINE_SLOTS {
        t.extend(slot_specs(k));
    }
    t.extend([
        ParamSpec::new(
            "scene_group",
            "Scene",
            "A MorphFX scene (.morph.json) with keyframed features, mesh and settings",
            Kind::Group { open: false },
        ),
        ParamSpec::new(
            SCENE_FILE,
            "Scene File",
            "Path of a .morph.json scene; its features add to the line slots.",
            Kind::Text {
                default: "",
                mode: TextMode::FilePath,
            },
        )
        .in_group("scene_group"),
        ParamSpec::new(
            SCENE_TEXT,
            "Scene Text",
            "A scene as JSON text (used when Scene File is empty).",
            Kind::Text {
                default: "",
                mode: TextMode::MultiLine,
            },
        )
        .in_group("scene_group"),
        ParamSpec::new(
            OFFSET_A,
            if kind == NodeKind::Morph {
                "Frame Offset A"
            } else {
                "Frame Offset"
            },
            "Frames added to the time at which the source is read (sequence morphs).",
            Kind::Int {
                default: 0,
                min: -100000,
                max: 100000,
            },
        )
        .animated(false),
    ]);
    if kind == NodeKind::Morph {
        t.push(
            ParamSpec::new(
                OFFSET_B,
                "Frame Offset B",
                "Frames added to the time at which Source B is read.",
                Kind::Int {
                    default: 0,
                    min: -100000,
                    max: 100000,
                },
            )
            .animated(false),
        );
    }
    t.extend([
        ParamSpec::new(
            FILTER,
            "Filter",
            "bilinear, or bicubic (Catmull-Rom: sharper, may overshoot).",
            choice(Filter::Bilinear),
        ),
        ParamSpec::new(
            EDGE,
            "Edge",
            "Outside the source: clamp to the edge pixels, black (transparent), or mirror.",
            choice(EdgeMode::Clamp),
        ),
        ParamSpec::new(
            VIEW,
            "View",
            "What the node outputs.",
            choice_of(views(kind), |v| view_label(kind, v), views(kind)[0]),
        ),
    ]);
    t
}

/// Line slot `k`'s params, in their own group: enable, the four ends, Clear.
fn slot_specs(k: usize) -> Vec<ParamSpec> {
    let [enable, a0, a1, b0, b1] = slot_ids(k);
    let group = slot_group(k);
    // Default lines stacked down the frame, so slots added one by one in a
    // host without the overlay do not all start on top of each other.
    let y = 100.0 + 40.0 * ((k - 1) % 16) as f64;
    let mut specs = vec![
        ParamSpec::new(
            group.clone(),
            format!("Line {k}"),
            format!("Line pair {k}"),
            Kind::Group { open: false },
        )
        .in_group("lines_group"),
        ParamSpec::new(
            enable,
            "Enabled",
            format!("Use line pair {k}."),
            Kind::Bool { default: true },
        )
        .in_group(group.clone()),
    ];
    for (id, label, x) in [
        (a0, "A Start", 100.0),
        (a1, "A End", 300.0),
        (b0, "B Start", 100.0),
        (b1, "B End", 300.0),
    ] {
        specs.push(
            ParamSpec::new(
                id,
                format!("Line {k} {label}"),
                format!("Line {k}: {label} (canonical pixels, y up)."),
                Kind::Point { default: (x, y) },
            )
            .in_group(group.clone()),
        );
    }
    specs.push(
        ParamSpec::new(
            slot_clear(k),
            "Clear Line",
            format!("Removes line {k}'s keys, puts it back where it started and turns it off."),
            Kind::Button,
        )
        .in_group(group),
    );
    specs
}

/// The table entry of param `id`, through an index built once per node: a
/// render reads a few hundred params from a table of several hundred.
pub fn spec(kind: NodeKind, id: &str) -> Option<&'static ParamSpec> {
    type Index = HashMap<&'static str, &'static ParamSpec>;
    static MORPH: OnceLock<Index> = OnceLock::new();
    static WARP: OnceLock<Index> = OnceLock::new();
    let build = || table(kind).iter().map(|p| (p.id.as_str(), p)).collect();
    let index = match kind {
        NodeKind::Morph => MORPH.get_or_init(build),
        NodeKind::Warp => WARP.get_or_init(build),
    };
    index.get(id).copied()
}

/// The params a node defines in `context`: its table, and in the
/// transition context the mandated `Transition` param (Parameters Mandated
/// In A Context: the plugin defines it, the host drives it).
pub fn table_in_context(kind: NodeKind, context: &str) -> Vec<ParamSpec> {
    let mut table = table(kind).to_vec();
    if context == super::render::TRANSITION {
        table.push(ParamSpec::new(
            TRANSITION_PARAM,
            "",
            "",
            Kind::HostDriven { default: 0.0 },
        ));
    }
    table
}

/// The transition context's mandated param (`kOfxImageEffectTransitionParamName`).
pub const TRANSITION_PARAM: &str = "Transition";

/// Param values at one time. A param the host did not make keeps its
/// default (minimal hosts), and is named in `missing` so it can be reported
/// once; one the host made but cannot read is in `unreadable`, which fails
/// the render (its value is the user's, and no default stands in for it).
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    pub warp: MethodSettings,
    pub progress: f64,
    pub use_scene_progress: bool,
    pub settings_from_scene: bool,
    pub lines: Vec<Feature>,
    pub scene_file: String,
    pub scene_text: String,
    pub offset_a: i32,
    pub offset_b: i32,
    pub filter: Filter,
    pub edge: EdgeMode,
    pub view: View,
    pub missing: Vec<String>,
    /// Why each param the host has could not be read.
    pub unreadable: Vec<String>,
}

/// Reads params at one time, each by the table entry that defines it: the
/// default it declares stands in for a value the host cannot give, and its
/// range bounds the value.
pub struct Reader<'a> {
    /// `None`: every param at its default.
    params: Option<&'a Params>,
    kind: NodeKind,
    time: f64,
    missing: RefCell<Vec<String>>,
    unreadable: RefCell<Vec<String>>,
}

impl<'a> Reader<'a> {
    pub fn new(params: &'a Params, kind: NodeKind, time: f64) -> Self {
        Reader {
            params: Some(params),
            kind,
            time,
            missing: RefCell::new(Vec::new()),
            unreadable: RefCell::new(Vec::new()),
        }
    }

    fn spec(&self, id: &str) -> &'static ParamSpec {
        spec(self.kind, id)
            .unwrap_or_else(|| panic!("param {id} is read but not in the node's table"))
    }

    /// The host's value, or `None` (and `id` noted missing or unreadable).
    fn host<T>(&self, id: &str, read: impl FnOnce(&Params) -> Outcome<T>) -> Option<T> {
        let params = self.params?;
        match read(params) {
            Ok(v) => Some(v),
            Err(why) if params.has(id) => {
                self.unreadable.borrow_mut().push(why.message().to_owned());
                None
            }
            Err(_) => {
                self.missing.borrow_mut().push(id.to_owned());
                None
            }
        }
    }

    pub fn double(&self, id: &str) -> f64 {
        let Kind::Double {
            default, min, max, ..
        } = self.spec(id).kind
        else {
            panic!("param {id} is not a double");
        };
        match self.host(id, |p| p.double(id, self.time)) {
            Some(v) if v.is_finite() => v.clamp(min, max),
            _ => default,
        }
    }

    pub fn int(&self, id: &str) -> i32 {
        let Kind::Int { default, min, max } = self.spec(id).kind else {
            panic!("param {id} is not an integer");
        };
        self.host(id, |p| p.int(id, self.time))
            .map_or(default, |v| v.clamp(min, max))
    }

    pub fn bool(&self, id: &str) -> bool {
        let Kind::Bool { default } = self.spec(id).kind else {
            panic!("param {id} is not a boolean");
        };
        self.host(id, |p| p.int(id, self.time))
            .map_or(default, |v| v != 0)
    }

    /// The option of `options` the host's index picks (the list the table
    /// defined the param with), else the declared default.
    fn pick<C: Copy>(&self, id: &str, options: &[C]) -> C {
        let Kind::Choice { default, .. } = &self.spec(id).kind else {
            panic!("param {id} is not a choice");
        };
        self.host(id, |p| p.int(id, self.time))
            .and_then(|i| usize::try_from(i).ok())
            .and_then(|i| options.get(i))
            .copied()
            .unwrap_or(options[*default])
    }

    /// A [`Choice`] param defined with [`choice`].
    pub fn choice<C: Choice>(&self, id: &str) -> C {
        self.pick(id, C::ALL)
    }

    pub fn text(&self, id: &str) -> String {
        let Kind::Text { default, .. } = self.spec(id).kind else {
            panic!("param {id} is not text");
        };
        self.host(id, |p| p.string(id, self.time))
            .unwrap_or_else(|| default.to_owned())
    }

    /// A position param, `None` when the host cannot give it.
    pub fn point(&self, id: &str) -> Option<Vec2> {
        let Kind::Point { .. } = self.spec(id).kind else {
            panic!("param {id} is not a position");
        };
        self.host(id, |p| p.point(id, self.time))
            .map(|(x, y)| Vec2::new(x, y))
    }
}

impl Settings {
    pub fn read(params: &Params, time: f64, kind: NodeKind) -> Settings {
        Settings::read_with(Reader::new(params, kind, time), kind)
    }

    /// Every param at the default its table entry declares.
    #[cfg(test)]
    pub fn defaults(kind: NodeKind) -> Settings {
        let reader = Reader {
            params: None,
            kind,
            time: 0.0,
            missing: RefCell::new(Vec::new()),
            unreadable: RefCell::new(Vec::new()),
        };
        Settings::read_with(reader, kind)
    }

    fn read_with(r: Reader<'_>, kind: NodeKind) -> Settings {
        let warp = MethodSettings {
            method: r.pick(METHOD, methods(kind)),
            field: field_settings(&r),
            mesh: MeshSettings {
                pass: r.choice(MESH_PASS),
            },
            auto: auto_settings(&r),
            thin_plate: ThinPlateSettings {
                alpha: r.double(PLATE_ALPHA),
                beta: r.double(PLATE_BETA),
                ..ThinPlateSettings::default()
            },
            mffd: MffdSettings {
                alpha: r.double(MFFD_ALPHA),
                ..MffdSettings::default()
            },
            transition: transition_settings(&r),
            ..MethodSettings::default()
        };
        let settings = Settings {
            warp,
            progress: r.double(PROGRESS),
            use_scene_progress: r.bool(USE_SCENE_PROGRESS),
            settings_from_scene: r.bool(SETTINGS_FROM_SCENE),
            lines: lines(&r),
            scene_file: r.text(SCENE_FILE),
            scene_text: r.text(SCENE_TEXT),
            offset_a: r.int(OFFSET_A),
            offset_b: if kind == NodeKind::Morph {
                r.int(OFFSET_B)
            } else {
                0
            },
            filter: r.choice(FILTER),
            edge: r.choice(EDGE),
            view: r.pick(VIEW, views(kind)),
            missing: Vec::new(),
            unreadable: Vec::new(),
        };
        Settings {
            missing: r.missing.into_inner(),
            unreadable: r.unreadable.into_inner(),
            ..settings
        }
    }
}

fn field_settings(r: &Reader<'_>) -> FieldSettings {
    let evaluation = match r.choice(EVALUATION) {
        EvaluationMode::Exact => Evaluation::Exact,
        EvaluationMode::Adaptive => Evaluation::Adaptive {
            tolerance: r.double(TOLERANCE),
        },
    };
    FieldSettings {
        a: r.double(FIELD_A),
        b: r.double(FIELD_B),
        p: r.double(FIELD_P),
        interpolation: r.choice(INTERPOLATION),
        evaluation,
        ..FieldSettings::default()
    }
}

fn auto_settings(r: &Reader<'_>) -> AutoSettings {
    AutoSettings {
        // 0: the level that gives quads of about 4 pixels.
        levels: match r.int(AUTO_LEVELS) {
            0 => None,
            l => Some(l as u32),
        },
        coefficients: Coefficients {
            colour: r.double(AUTO_COLOUR),
            stretch: r.double(AUTO_STRETCH),
            angle: r.double(AUTO_ANGLE),
            anchor: r.double(AUTO_ANCHORS),
        },
        warm_start: r.bool(AUTO_WARM_START),
        ..AutoSettings::default()
    }
}

fn transition_settings(r: &Reader<'_>) -> TransitionSettings {
    let Some(kind) = r.pick(TRANSITION, &PATTERNS) else {
        return TransitionSettings::default();
    };
    let cycles = r.double(TRANSITION_CYCLES);
    let pattern = match kind {
        PatternKind::Ramp => Pattern::Ramp {
            angle: r.double(TRANSITION_ANGLE),
        },
        PatternKind::SineRows => Pattern::SineRows { cycles },
        PatternKind::SineColumns => Pattern::SineColumns { cycles },
        PatternKind::Radial => Pattern::Radial {
            cycles,
            centre: None,
        },
    };
    let t = Transition::Procedural(Procedural {
        pattern,
        spread: r.double(TRANSITION_SPREAD),
    });
    match r.choice(TRANSITION_AFFECTS) {
        Affects::Both => TransitionSettings {
            geometry: t,
            colour: None,
        },
        Affects::Geometry => TransitionSettings {
            geometry: t,
            colour: Some(Transition::Uniform),
        },
        Affects::Colour => TransitionSettings {
            geometry: Transition::Uniform,
            colour: Some(t),
        },
    }
}

/// The enabled line slots with both lines placed, as features.
fn lines(r: &Reader<'_>) -> Vec<Feature> {
    // A zero-length line has no direction: the slot is skipped, not an
    // error, so a half-placed line never breaks a render.
    super::lines::slot_lines(r)
        .into_iter()
        .filter(|l| l.a[0] != l.a[1] && l.b[0] != l.b[1])
        .map(|l| Feature::line(l.a, l.b).named(format!("line {}", l.slot)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every choice param's options as MorphFX 1.0 shipped them. Hosts save
    /// a choice by its index, so a saved project reads these back by
    /// position: they may be followed by new options, never reordered,
    /// renamed or removed.
    const RELEASED: &[(NodeKind, &str, &[&str])] = &[
        (
            NodeKind::Morph,
            METHOD,
            &[
                "field",
                "mesh",
                "triangles",
                "thin-plate",
                "mffd",
                "hybrid",
                "auto",
            ],
        ),
        (
            NodeKind::Warp,
            METHOD,
            &["field", "mesh", "triangles", "thin-plate", "mffd", "hybrid"],
        ),
        (
            NodeKind::Morph,
            VIEW,
            &[
                "morph",
                "warped-a",
                "warped-b",
                "stmap-a",
                "stmap-b",
                "transition",
                "grid",
            ],
        ),
        (NodeKind::Warp, VIEW, &["warped", "stmap", "grid"]),
    ];

    /// Choice params both nodes share, with their released options.
    const RELEASED_BOTH: &[(&str, &[&str])] = &[
        (INTERPOLATION, &["endpoints", "center-angle"]),
        (EVALUATION, &["adaptive", "exact"]),
        (MESH_PASS, &["two-pass", "one-pass"]),
        (
            TRANSITION,
            &["uniform", "ramp", "sine-rows", "sine-columns", "radial"],
        ),
        (
            TRANSITION_AFFECTS,
            &["geometry and colour", "geometry", "colour"],
        ),
        (FILTER, &["bilinear", "bicubic"]),
        (EDGE, &["clamp", "black", "mirror"]),
        (
            OVERLAY_SHOW,
            &["A and B", "A only", "B only", "in-between", "off"],
        ),
        (OVERLAY_EDIT, &["A and B", "A only", "B only"]),
    ];

    fn released() -> Vec<(NodeKind, &'static str, &'static [&'static str])> {
        let mut all = RELEASED.to_vec();
        for kind in NodeKind::ALL {
            all.extend(RELEASED_BOTH.iter().map(|(id, o)| (kind, *id, *o)));
        }
        all
    }

    fn options(kind: NodeKind, id: &str) -> Option<(Vec<&'static str>, usize)> {
        table(kind)
            .iter()
            .find(|p| p.id == id)
            .map(|p| match &p.kind {
                Kind::Choice { options, default } => (options.clone(), *default),
                other => panic!("{id} is not a choice: {other:?}"),
            })
    }

    #[test]
    fn choice_options_only_ever_grow_at_the_end() {
        for (kind, id, was) in released() {
            let (now, _) = options(kind, id).unwrap_or_else(|| panic!("{kind:?} lost {id}"));
            assert!(
                now.starts_with(was),
                "{kind:?} {id}: released {was:?}, now {now:?}"
            );
        }
    }

    #[test]
    fn every_choice_param_is_recorded_with_a_default_among_its_options() {
        let recorded = released();
        for kind in NodeKind::ALL {
            for p in table(kind) {
                if let Kind::Choice { options, default } = &p.kind {
                    assert!(
                        recorded.iter().any(|(k, id, _)| *k == kind && *id == p.id),
                        "{kind:?} {}: record its options in RELEASED",
                        p.id
                    );
                    assert!(*default < options.len(), "{kind:?} {}", p.id);
                }
            }
        }
    }

    /// The option lists the reader picks from are the ones the table
    /// defined, so index k reads back the option labelled k.
    #[test]
    fn choices_read_back_the_option_they_label() {
        for kind in NodeKind::ALL {
            let (labels, _) = options(kind, METHOD).expect("method");
            let names: Vec<_> = methods(kind).iter().map(|m| m.name()).collect();
            assert_eq!(labels, names);
            let (labels, _) = options(kind, VIEW).expect("view");
            let names: Vec<_> = views(kind).iter().map(|v| view_label(kind, *v)).collect();
            assert_eq!(labels, names);
        }
        assert_eq!(
            options(NodeKind::Morph, EDGE).expect("edge").0,
            EdgeMode::names()
        );
    }

    /// The defaults a fresh node renders with: what the table declares.
    #[test]
    fn defaults_are_the_tables() {
        let s = Settings::defaults(NodeKind::Morph);
        assert_eq!(s.warp.method, Method::Field);
        assert_eq!(s.progress, 0.5);
        assert_eq!(s.view, View::Morph);
        assert_eq!(s.edge, EdgeMode::Clamp);
        assert!(s.lines.is_empty() && s.missing.is_empty());
        assert_eq!(s.warp.field, FieldSettings::default());
        assert_eq!(Settings::defaults(NodeKind::Warp).view, View::WarpedA);
    }

    #[test]
    fn ids_are_unique_and_hints_speak_to_compositors() {
        for kind in NodeKind::ALL {
            let t = table(kind);
            for (i, p) in t.iter().enumerate() {
                assert!(t[i + 1..].iter().all(|q| q.id != p.id), "{} twice", p.id);
                for stale in ["not yet", "seed", "CONTRACT", "§"] {
                    assert!(
                        !p.label.contains(stale) && !p.hint.contains(stale),
                        "{}: {stale:?} in {:?} / {:?}",
                        p.id,
                        p.label,
                        p.hint
                    );
                }
            }
        }
    }
}
