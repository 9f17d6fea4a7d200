//! The params both nodes share, as one table, and their values read at a time.

use morphfx::features::Feature;
use morphfx::geom::Vec2;
use morphfx::image::{EdgeMode, Filter};
use morphfx::scene::Method;
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

/// Line-pair slots every node offers.
pub const LINE_SLOTS: usize = 16;

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

/// The procedural transitions the node offers (curves come from the scene).
const TRANSITIONS: [&str; 5] = ["uniform", "ramp", "sine-rows", "sine-columns", "radial"];

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
fn method_options(kind: NodeKind) -> Vec<&'static str> {
    Method::ALL
        .iter()
        .filter(|m| kind == NodeKind::Morph || **m != Method::Auto)
        .map(|m| match m {
            Method::Field => "field",
            Method::Mesh => "mesh",
            Method::Triangles => "triangles",
            Method::ThinPlate => "thin-plate",
            Method::Mffd => "mffd",
            Method::Hybrid => "hybrid",
            Method::Auto => "auto",
        })
        .collect()
}

/// The views a node offers, in the order of its View choice.
pub fn views(kind: NodeKind) -> Vec<View> {
    match kind {
        NodeKind::Morph => View::ALL.to_vec(),
        NodeKind::Warp => vec![View::WarpedA, View::StmapA, View::Grid],
    }
}

fn view_label(kind: NodeKind, v: View) -> &'static str {
    match (kind, v) {
        (NodeKind::Warp, View::WarpedA) => "warped",
        (NodeKind::Warp, View::StmapA) => "stmap",
        _ => v.name(),
    }
}

pub fn table(kind: NodeKind) -> Vec<ParamSpec> {
    let d = FieldSettings::default();
    let c = Coefficients::default();
    let tp = ThinPlateSettings::default();
    let mut t = vec![
        ParamSpec::new(METHOD, "Method", "Warp generator. field: line pairs (Beier-Neely); mesh: the scene's mesh (two-pass Catmull-Rom); triangles: every feature point, Delaunay-triangulated, piecewise affine; thin-plate: every feature point pulls two thin plates (x and y displacement) by springs; mffd: multilevel B-spline free-form deformation, one-to-one whatever the features ask; hybrid: a coarse thin plate, then MFFD; auto (Morph node): the least-work warp of A onto B found from the pictures themselves, features acting as anchors.", Kind::Choice { options: method_options(kind), default: 0 }),
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
        ParamSpec::new(INTERPOLATION, "Line Interpolation", "endpoints: endpoints move straight; center-angle: centre, angle and length interpolate (rotating lines keep their length).", Kind::Choice { options: vec!["endpoints", "center-angle"], default: 0 }).in_group("field_group"),
        ParamSpec::new(EVALUATION, "Evaluation", "adaptive: coarse grid refined where needed, within Tolerance of exact; exact: every pixel.", Kind::Choice { options: vec!["adaptive", "exact"], default: 0 }).in_group("field_group"),
        ParamSpec::new(TOLERANCE, "Tolerance", "Largest error of the adaptive evaluation, in pixels.", Kind::Double { default: Evaluation::DEFAULT_TOLERANCE, min: 0.001, max: 5.0, display: (0.01, 1.0) }).in_group("field_group").animated(false),
        ParamSpec::new("mesh_group", "Mesh", "Mesh warp (the mesh comes from the scene's \"mesh\" key)", Kind::Group { open: false }),
        ParamSpec::new(MESH_PASS, "Mesh Pass", "two-pass: rows then columns with Fant filtering (the classic algorithm, anti-aliased when squeezing); one-pass: bicubic patches inverted per pixel (no bottleneck under strong rotation, uses the Filter param).", Kind::Choice { options: vec!["two-pass", "one-pass"], default: 0 }).in_group("mesh_group").animated(false),
        ParamSpec::new("auto_group", "Auto", "Automatic correspondence by work minimisation (method auto)", Kind::Group { open: false }),
        ParamSpec::new(AUTO_LEVELS, "Levels", "Depth of the search: 2^levels quads per side. 0: quads of about 4 pixels (6 at 256, 8 at HD). Fewer levels are faster and coarser.", Kind::Int { default: 0, min: 0, max: MAX_LEVEL as i32 }).in_group("auto_group").animated(false),
        ParamSpec::new(AUTO_COLOUR, "Colour Work", "Weight of re-colouring work (c_c): how hard the warp tries to match B's colours.", Kind::Double { default: c.colour, min: 0.0, max: 1000.0, display: (0.0, 10.0) }).in_group("auto_group").animated(false),
        ParamSpec::new(AUTO_STRETCH, "Stretch Work", "Weight of stretching work (c_s). 0 with Angle Work 0 gives a more fluid warp.", Kind::Double { default: c.stretch, min: 0.0, max: 1000.0, display: (0.0, 10.0) }).in_group("auto_group").animated(false),
        ParamSpec::new(AUTO_ANGLE, "Angle Work", "Weight of angle-change work (c_a).", Kind::Double { default: c.angle, min: 0.0, max: 1000.0, display: (0.0, 10.0) }).in_group("auto_group").animated(false),
        ParamSpec::new(AUTO_ANCHORS, "Anchor Weight", "How strongly features (line slots, scene features) hold as anchor points.", Kind::Double { default: c.anchor, min: 0.0, max: 1000.0, display: (0.0, 100.0) }).in_group("auto_group").animated(false),
        ParamSpec::new(AUTO_WARM_START, "Warm Start", "Start each frame from the previous frame's warp when this instance has it: faster, steadier over a sequence; off makes every frame independent of render order.", Kind::Bool { default: true }).in_group("auto_group").animated(false),
        ParamSpec::new("scattered_group", "Thin Plate / MFFD", "Settings of the scattered-feature methods (thin-plate, mffd, hybrid)", Kind::Group { open: false }),
        ParamSpec::new(PLATE_ALPHA, "Spring α", "How tightly the thin plate meets the feature points (px⁻²). Larger is tighter and slower to solve.", Kind::Double { default: tp.alpha, min: 0.01, max: 1e6, display: (1.0, 1000.0) }).in_group("scattered_group").animated(false),
        ParamSpec::new(PLATE_BETA, "Glue β", "How soon a feature's pull dies away in the thin plate (px⁻⁴): it reaches about β^(-1/4) px. 0: no glue, the pull spreads over the frame.", Kind::Double { default: tp.beta, min: 0.0, max: 1.0, display: (0.0, 1e-4) }).in_group("scattered_group").animated(false),
        ParamSpec::new(MFFD_ALPHA, "Refine α", "MFFD moves to a finer lattice when a step gains less than α (0.48 h)²: small values keep the deformation coarse and smooth.", Kind::Double { default: MffdSettings::default().alpha, min: 0.0, max: 1.0, display: (0.0, 1.0) }).in_group("scattered_group").animated(false),
        ParamSpec::new("transition_group", "Transition", "How fast each part changes (transition curves come from the scene's \"transition\" key)", Kind::Group { open: false }),
        ParamSpec::new(TRANSITION, "Transition", "uniform: every pixel at Progress; ramp, sine-rows, sine-columns, radial: each pixel's turn comes from where it is on A, every pixel still exactly A at 0 and B at 1.", Kind::Choice { options: TRANSITIONS.to_vec(), default: 0 }).in_group("transition_group"),
        ParamSpec::new(TRANSITION_AFFECTS, "Affects", "What the transition paces: the geometry (where features are) and the colour (the dissolve), or one of them (the other stays uniform).", Kind::Choice { options: vec!["geometry and colour", "geometry", "colour"], default: 0 }).in_group("transition_group").animated(false),
        ParamSpec::new(TRANSITION_SPREAD, "Spread", "Share of the progress over which the pattern sweeps: 0 is uniform; near 1 each pixel changes almost at once, at its turn.", Kind::Double { default: 0.5, min: 0.0, max: 0.99, display: (0.0, 0.99) }).in_group("transition_group"),
        ParamSpec::new(TRANSITION_ANGLE, "Angle", "Direction of the ramp in degrees: 0 left to right, 90 bottom to top.", Kind::Double { default: 0.0, min: -360.0, max: 360.0, display: (-180.0, 180.0) }).in_group("transition_group"),
        ParamSpec::new(TRANSITION_CYCLES, "Cycles", "Sinusoid periods across the frame (sine patterns), or rings (radial; 0: the centre first, then outward).", Kind::Double { default: 2.0, min: 0.0, max: 100.0, display: (0.0, 8.0) }).in_group("transition_group"),
        ParamSpec::new("lines_group", "Lines", "Line pairs keyframed in the host", Kind::Group { open: true }),
        ParamSpec::new(LINE_COUNT, "Line Count", "How many of the line slots below are used.", Kind::Int { default: 0, min: 0, max: LINE_SLOTS as i32 }).in_group("lines_group").animated(false),
        ParamSpec::new(SNAP_LINES, "Snap Lines", "Slides every enabled line onto the nearest strong edge of its source at the current frame (A positions on Source A, B positions on Source B) and keys the moved endpoints there. Place lines roughly, then press.", Kind::Button).in_group("lines_group"),
        ParamSpec::new(SNAP_SIGMA, "Snap Reach", "Edge smoothing for Snap Lines, in pixels: edges pull lines from about twice this far.", Kind::Double { default: 3.0, min: 0.5, max: 50.0, display: (1.0, 10.0) }).in_group("lines_group").animated(false),
    ];
    for k in 1..=LINE_SLOTS {
        let [enable, a0, a1, b0, b1] = slot_ids(k);
        let y = 100.0 + 40.0 * (k as f64 - 1.0);
        t.push(
            ParamSpec::new(
                enable,
                format!("Line {k}"),
                format!("Use line pair {k}."),
                Kind::Bool { default: true },
            )
            .in_group("lines_group"),
        );
        for (id, label, x) in [
            (a0, "A Start", 100.0),
            (a1, "A End", 300.0),
            (b0, "B Start", 100.0),
            (b1, "B End", 300.0),
        ] {
            t.push(
                ParamSpec::new(
                    id,
                    format!("Line {k} {label}"),
                    format!("Line {k}: {label} (canonical pixels, y up)."),
                    Kind::Point { default: (x, y) },
                )
                .in_group("lines_group"),
            );
        }
    }
    t.extend([
        ParamSpec::new(
            "scene_group",
            "Scene",
            "A MorphFX scene (CONTRACT §2) with keyframed features",
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
            Kind::Choice {
                options: vec!["bilinear", "bicubic"],
                default: 0,
            },
        ),
        ParamSpec::new(
            EDGE,
            "Edge",
            "Outside the source: clamp to the edge pixels, black (transparent), or mirror.",
            Kind::Choice {
                options: vec!["clamp", "black", "mirror"],
                default: 0,
            },
        ),
        ParamSpec::new(
            VIEW,
            "View",
            "What the node outputs.",
            Kind::Choice {
                options: views(kind)
                    .into_iter()
                    .map(|v| view_label(kind, v))
                    .collect(),
                default: 0,
            },
        ),
    ]);
    t
}

/// The params a node defines in `context`: its table, and in the
/// transition context the mandated `Transition` param (Parameters Mandated
/// In A Context: the plugin defines it, the host drives it).
pub fn table_in_context(kind: NodeKind, context: &str) -> Vec<ParamSpec> {
    let mut table = table(kind);
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

/// Param values at one time. A param the host cannot read keeps its default
/// (minimal hosts), and is named in `missing` so it can be reported once.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    pub method: Method,
    pub progress: f64,
    pub use_scene_progress: bool,
    pub settings_from_scene: bool,
    pub field: FieldSettings,
    pub mesh: MeshSettings,
    pub auto: AutoSettings,
    pub thin_plate: ThinPlateSettings,
    pub mffd: MffdSettings,
    pub transition: TransitionSettings,
    pub lines: Vec<Feature>,
    pub scene_file: String,
    pub scene_text: String,
    pub offset_a: i32,
    pub offset_b: i32,
    pub filter: Filter,
    pub edge: EdgeMode,
    pub view: View,
    pub missing: Vec<String>,
}

impl Settings {
    pub fn read(params: &Params, time: f64, kind: NodeKind) -> Settings {
        let missing = std::cell::RefCell::new(Vec::new());
        let f64_or = |id: &str, default: f64| {
            params.double(id, time).unwrap_or_else(|_| {
                missing.borrow_mut().push(id.to_owned());
                default
            })
        };
        let d = FieldSettings::default();
        let progress = f64_or(PROGRESS, 0.5).clamp(0.0, 1.0);
        let (a, b, p) = (
            f64_or(FIELD_A, d.a).max(1e-9),
            f64_or(FIELD_B, d.b).max(0.0),
            f64_or(FIELD_P, d.p).max(0.0),
        );
        let tolerance = f64_or(TOLERANCE, Evaluation::DEFAULT_TOLERANCE).max(1e-4);
        let int_or = |id: &str, default: i32| {
            params.int(id, time).unwrap_or_else(|_| {
                missing.borrow_mut().push(id.to_owned());
                default
            })
        };
        let method = Method::ALL[int_or(METHOD, 0).clamp(0, Method::ALL.len() as i32 - 1) as usize];
        let use_scene_progress = int_or(USE_SCENE_PROGRESS, 1) != 0;
        let settings_from_scene = int_or(SETTINGS_FROM_SCENE, 1) != 0;
        let interpolation = if int_or(INTERPOLATION, 0) == 1 {
            LineInterpolation::CenterAngle
        } else {
            LineInterpolation::Endpoints
        };
        let evaluation = if int_or(EVALUATION, 0) == 1 {
            Evaluation::Exact
        } else {
            Evaluation::Adaptive { tolerance }
        };
        let pass = if int_or(MESH_PASS, 0) == 1 {
            Pass::OnePass
        } else {
            Pass::TwoPass
        };
        let c = Coefficients::default();
        let weight = |id: &str, d: f64| f64_or(id, d).clamp(0.0, 1000.0);
        let auto = AutoSettings {
            levels: match int_or(AUTO_LEVELS, 0) {
                l if l <= 0 => None,
                l => Some((l as u32).min(MAX_LEVEL)),
            },
            coefficients: Coefficients {
                colour: weight(AUTO_COLOUR, c.colour),
                stretch: weight(AUTO_STRETCH, c.stretch),
                angle: weight(AUTO_ANGLE, c.angle),
                anchor: weight(AUTO_ANCHORS, c.anchor),
            },
            warm_start: int_or(AUTO_WARM_START, 1) != 0,
            ..AutoSettings::default()
        };
        let tp = ThinPlateSettings::default();
        let thin_plate = ThinPlateSettings {
            alpha: f64_or(PLATE_ALPHA, tp.alpha).clamp(0.01, 1e6),
            beta: f64_or(PLATE_BETA, tp.beta).clamp(0.0, 1.0),
            ..tp
        };
        let mffd = MffdSettings {
            alpha: f64_or(MFFD_ALPHA, MffdSettings::default().alpha).clamp(0.0, 1.0),
            ..MffdSettings::default()
        };
        let spread = f64_or(TRANSITION_SPREAD, 0.5).clamp(0.0, 0.99);
        let cycles = f64_or(TRANSITION_CYCLES, 2.0).clamp(0.0, 100.0);
        let pattern = match int_or(TRANSITION, 0) {
            1 => Some(Pattern::Ramp {
                angle: f64_or(TRANSITION_ANGLE, 0.0),
            }),
            2 => Some(Pattern::SineRows { cycles }),
            3 => Some(Pattern::SineColumns { cycles }),
            4 => Some(Pattern::Radial {
                cycles,
                centre: None,
            }),
            _ => None,
        };
        let transition = match pattern {
            None => TransitionSettings::default(),
            Some(pattern) => {
                let t = Transition::Procedural(Procedural { pattern, spread });
                match int_or(TRANSITION_AFFECTS, 0) {
                    1 => TransitionSettings {
                        geometry: t,
                        colour: Some(Transition::Uniform),
                    },
                    2 => TransitionSettings {
                        geometry: Transition::Uniform,
                        colour: Some(t),
                    },
                    _ => TransitionSettings {
                        geometry: t,
                        colour: None,
                    },
                }
            }
        };
        let count = int_or(LINE_COUNT, 0).clamp(0, LINE_SLOTS as i32) as usize;
        let offset_a = int_or(OFFSET_A, 0);
        let offset_b = if kind == NodeKind::Morph {
            int_or(OFFSET_B, 0)
        } else {
            0
        };
        let filter = if int_or(FILTER, 0) == 1 {
            Filter::Bicubic
        } else {
            Filter::Bilinear
        };
        let edge = [EdgeMode::Clamp, EdgeMode::Black, EdgeMode::Mirror]
            [int_or(EDGE, 0).clamp(0, 2) as usize];
        let views = views(kind);
        let view = views[int_or(VIEW, 0).clamp(0, views.len() as i32 - 1) as usize];
        let mut lines = Vec::new();
        for k in 1..=count {
            let [enable, a0, a1, b0, b1] = slot_ids(k);
            if int_or(&enable, 1) == 0 {
                continue;
            }
            let pt = |id: &str| params.point(id, time).ok().map(|(x, y)| Vec2::new(x, y));
            if let (Some(a0), Some(a1), Some(b0), Some(b1)) = (pt(&a0), pt(&a1), pt(&b0), pt(&b1)) {
                // A zero-length line has no direction: the slot is skipped, not an error,
                // so a half-placed line never breaks a render.
                if a0 != a1 && b0 != b1 && [a0, a1, b0, b1].iter().all(|p| p.is_finite()) {
                    lines.push(Feature::line([a0, a1], [b0, b1]).named(format!("line {k}")));
                }
            } else {
                missing.borrow_mut().push(format!("line{k}"));
            }
        }
        let text_or = |id: &str| {
            params.string(id, time).unwrap_or_else(|_| {
                missing.borrow_mut().push(id.to_owned());
                String::new()
            })
        };
        let scene_file = text_or(SCENE_FILE);
        let scene_text = text_or(SCENE_TEXT);
        Settings {
            method,
            progress,
            use_scene_progress,
            settings_from_scene,
            field: FieldSettings {
                a,
                b,
                p,
                interpolation,
                evaluation,
                curve_samples: d.curve_samples,
            },
            mesh: MeshSettings { pass },
            auto,
            thin_plate,
            mffd,
            transition,
            lines,
            scene_file,
            scene_text,
            offset_a,
            offset_b,
            filter,
            edge,
            view,
            missing: missing.into_inner(),
        }
    }
}
