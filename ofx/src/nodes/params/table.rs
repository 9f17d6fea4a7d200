//! The params both nodes define, as one table per node: each param's
//! id, label, hint, default and range stated once.

use std::collections::HashMap;
use std::ffi::CStr;
use std::sync::{Mutex, OnceLock};

use morphfx::choice::Choice;
use morphfx::image::{EdgeMode, Filter};
use morphfx::make_warp::Method;
use morphfx::shutter::ShutterOffset;
use morphfx::suggest::SuggestSettings;
use morphfx::warp::auto::grid::MAX_LEVEL;
use morphfx::warp::auto::Coefficients;
use morphfx::warp::field::{Evaluation, FieldSettings, LineInterpolation};
use morphfx::warp::mesh::{Pass, MAX_SIZE};
use morphfx::warp::mffd::MffdSettings;
use morphfx::warp::thin_plate::ThinPlateSettings;

use crate::nodes::kind::NodeKind;
use ofx_layer::plugin::Context;
use ofx_layer::spec::{Doubles, Id, Int, Ints, Options, ParamSpec, TextMode, Texts};
use ofx_layer::sync::Locked;

use super::choices::{pattern_label, Affects, DrawTool, EditSides, EvaluationMode, Show, PATTERNS};
use super::ids::*;

/// A node kind's params and their index by id, built once per kind.
struct Catalogue {
    table: Vec<ParamSpec>,
    index: HashMap<String, usize>,
}

/// `kind`'s catalogue, built the first time it is asked for and kept for
/// the life of the process (a few hundred rows per node type).
fn catalogue(kind: &'static NodeKind) -> &'static Catalogue {
    type Catalogues = Mutex<HashMap<&'static CStr, &'static Catalogue>>;
    static BUILT: OnceLock<Catalogues> = OnceLock::new();
    let mut built = BUILT.get_or_init(Default::default).locked();
    built.entry(kind.id).or_insert_with(|| {
        let table = build_table(kind);
        let index = table
            .iter()
            .enumerate()
            .map(|(i, p)| (p.id().to_owned(), i));
        let index = index.collect();
        Box::leak(Box::new(Catalogue { table, index }))
    })
}

/// The node's params.
pub fn table(kind: &'static NodeKind) -> &'static [ParamSpec] {
    &catalogue(kind).table
}

pub(super) fn build_table(kind: &'static NodeKind) -> Vec<ParamSpec> {
    let d = FieldSettings::default();
    let c = Coefficients::default();
    let tp = ThinPlateSettings::default();
    let mut t = vec![
        METHOD.spec(
            "Method",
            "Warp generator. field: line pairs (Beier-Neely); mesh: the scene's \
            mesh (two-pass Catmull-Rom); triangles: every feature point, \
            Delaunay-triangulated, piecewise affine; thin-plate: every feature \
            point pulls two thin plates (x and y displacement) by springs; mffd: \
            multilevel B-spline free-form deformation, one-to-one whatever the \
            features ask; hybrid: a coarse thin plate, then MFFD; auto (Morph \
            node): the least-work warp of A onto B found from the pictures \
            themselves, features acting as anchors.",
            Options::of(kind.methods, Method::name, Method::Field),
        ),
        PROGRESS.spec(
            "Progress",
            "t in [0, 1]: 0 shows A unchanged, 1 shows B (Morph) or A warped \
            fully onto B's features (Warp). Ignored in the transition context, \
            where the host's Transition param drives it.",
            Doubles {
                default: 0.5,
                min: 0.0,
                max: 1.0,
                display: (0.0, 1.0),
            },
        ),
        USE_SCENE_PROGRESS.spec(
            "Use Scene Progress",
            "When the scene keys progress, follow it instead of the Progress \
            param.",
            true,
        ),
        SETTINGS_FROM_SCENE.spec(
            "Settings From Scene",
            "When a scene is loaded, its method and that method's settings \
            (field, mesh, auto, thin plate, MFFD, and its transition when it has \
            one) win over this node's.",
            true,
        ),
        FIELD_GROUP.spec("Field", "Beier-Neely field constants", true),
        FIELD_A
            .spec(
                "a",
                "weight = (length^p / (a + dist))^b. Barely above 0 pins pixels on a \
            line to it; larger is smoother.",
                Doubles {
                    default: d.a,
                    min: 1e-6,
                    max: 1000.0,
                    display: (0.0001, 10.0),
                },
            )
            .in_group(&FIELD_GROUP),
        FIELD_B
            .spec(
                "b",
                "How fast a line's influence falls off with distance (0.5 to 2 is \
            most useful).",
                Doubles {
                    default: d.b,
                    min: 0.0,
                    max: 10.0,
                    display: (0.0, 4.0),
                },
            )
            .in_group(&FIELD_GROUP),
        FIELD_P
            .spec(
                "p",
                "How much longer lines outweigh shorter ones (0: all equal, 1: by \
            length).",
                Doubles {
                    default: d.p,
                    min: 0.0,
                    max: 4.0,
                    display: (0.0, 1.0),
                },
            )
            .in_group(&FIELD_GROUP),
        INTERPOLATION
            .spec(
                "Line Interpolation",
                "endpoints: endpoints move straight; center-angle: centre, angle and \
            length interpolate (rotating lines keep their length).",
                LineInterpolation::Endpoints,
            )
            .in_group(&FIELD_GROUP),
        EVALUATION
            .spec(
                "Evaluation",
                "adaptive: coarse grid refined where needed, within Tolerance of \
            exact; exact: every pixel.",
                EvaluationMode::Adaptive,
            )
            .in_group(&FIELD_GROUP),
        TOLERANCE
            .spec(
                "Tolerance",
                "Largest error of the adaptive evaluation, in pixels.",
                Doubles {
                    default: Evaluation::DEFAULT_TOLERANCE,
                    min: 0.001,
                    max: 5.0,
                    display: (0.01, 1.0),
                },
            )
            .in_group(&FIELD_GROUP)
            .animated(false),
        MESH_GROUP.spec(
            "Mesh",
            "Mesh warp (the mesh comes from the scene's \"mesh\" key)",
            false,
        ),
        MESH_PASS
            .spec(
                "Mesh Pass",
                "two-pass: rows then columns with Fant filtering (the classic \
            algorithm, anti-aliased when squeezing); one-pass: bicubic patches \
            inverted per pixel (no bottleneck under strong rotation, uses the \
            Filter param).",
                Pass::TwoPass,
            )
            .in_group(&MESH_GROUP)
            .animated(false),
        grid_size(
            &GRID_ROWS,
            "Grid Rows",
            "Rows of nodes Reset Grid makes (a row runs left to right).",
        ),
        grid_size(
            &GRID_COLS,
            "Grid Columns",
            "Columns of nodes Reset Grid makes.",
        ),
        RESET_GRID
            .spec(
                "Reset Grid",
                "Writes an even grid of Grid Rows × Grid Columns nodes over Source \
            A (the project when nothing is connected) into Scene Text, the same \
            on A and B, and sets the scene's method to mesh; your features stay. \
            Then drag its nodes in the viewer (Method: mesh shows the grid). One \
            undo step.",
                (),
            )
            .in_group(&MESH_GROUP),
        ADD_ROW
            .spec(
                "Add Row",
                "Adds a row of nodes through the point last clicked on the grid in \
            the viewer, on A and B where the grid's splines pass there (Shift+Ctrl-click \
            near a column line does the same at the pen).",
                (),
            )
            .in_group(&MESH_GROUP),
        ADD_COLUMN
            .spec(
                "Add Column",
                "Adds a column of nodes through the point last clicked on the grid \
            (Shift+Ctrl-click near a row line does the same at the pen).",
                (),
            )
            .in_group(&MESH_GROUP),
        REMOVE_ROW
            .spec(
                "Remove Row",
                "Removes the row of nodes nearest the point last clicked on the grid \
            (not a border row).",
                (),
            )
            .in_group(&MESH_GROUP),
        REMOVE_COLUMN
            .spec(
                "Remove Column",
                "Removes the column of nodes nearest the point last clicked on the \
            grid (not a border column).",
                (),
            )
            .in_group(&MESH_GROUP),
        AUTO_GROUP.spec(
            "Auto",
            "Automatic correspondence by work minimisation (method auto)",
            false,
        ),
        AUTO_LEVELS
            .spec(
                "Levels",
                "Depth of the search: 2^levels quads per side. 0: quads of about 4 \
            pixels (6 at 256, 8 at HD). Fewer levels are faster and coarser.",
                Ints {
                    default: 0,
                    min: 0,
                    max: MAX_LEVEL as i32,
                },
            )
            .in_group(&AUTO_GROUP)
            .animated(false),
        AUTO_COLOUR
            .spec(
                "Colour Work",
                "How hard the warp tries to match B's colours (the weight of \
            re-colouring work).",
                Doubles {
                    default: c.colour,
                    min: 0.0,
                    max: 1000.0,
                    display: (0.0, 10.0),
                },
            )
            .in_group(&AUTO_GROUP)
            .animated(false),
        AUTO_STRETCH
            .spec(
                "Stretch Work",
                "How much the warp resists stretching. 0 with Angle Work 0 gives a \
            more fluid warp.",
                Doubles {
                    default: c.stretch,
                    min: 0.0,
                    max: 1000.0,
                    display: (0.0, 10.0),
                },
            )
            .in_group(&AUTO_GROUP)
            .animated(false),
        AUTO_ANGLE
            .spec(
                "Angle Work",
                "How much the warp resists changing angles (shearing).",
                Doubles {
                    default: c.angle,
                    min: 0.0,
                    max: 1000.0,
                    display: (0.0, 10.0),
                },
            )
            .in_group(&AUTO_GROUP)
            .animated(false),
        AUTO_ANCHORS
            .spec(
                "Anchor Weight",
                "How strongly features (line slots, scene features) hold as anchor \
            points.",
                Doubles {
                    default: c.anchor,
                    min: 0.0,
                    max: 1000.0,
                    display: (0.0, 100.0),
                },
            )
            .in_group(&AUTO_GROUP)
            .animated(false),
        AUTO_WARM_START
            .spec(
                "Warm Start",
                "Start each frame from the previous frame's warp when the host \
            renders in order: faster, but a frame then depends on where the \
            sequence started, so a farm's chunks differ from one render at their \
            first frames. Off (default): every frame is solved on its own, the \
            same in any order and any chunking.",
                false,
            )
            .in_group(&AUTO_GROUP)
            .animated(false),
        SCATTERED_GROUP.spec(
            "Thin Plate / MFFD",
            "Settings of the scattered-feature methods (thin-plate, mffd, hybrid)",
            false,
        ),
        PLATE_ALPHA
            .spec(
                "Spring α",
                "How tightly the thin plate meets the feature points (px⁻²). Larger \
            is tighter and slower to solve.",
                Doubles {
                    default: tp.alpha,
                    min: 0.01,
                    max: 1e6,
                    display: (1.0, 1000.0),
                },
            )
            .in_group(&SCATTERED_GROUP)
            .animated(false),
        PLATE_BETA
            .spec(
                "Glue β",
                "How soon a feature's pull dies away in the thin plate (px⁻⁴): it \
            reaches about β^(-1/4) px. 0: no glue, the pull spreads over the \
            frame.",
                Doubles {
                    default: tp.beta,
                    min: 0.0,
                    max: 1.0,
                    display: (0.0, 1e-4),
                },
            )
            .in_group(&SCATTERED_GROUP)
            .animated(false),
        MFFD_ALPHA
            .spec(
                "Refine α",
                "MFFD moves to a finer lattice when a step gains less than α (0.48 \
            h)²: small values keep the deformation coarse and smooth.",
                Doubles {
                    default: MffdSettings::default().alpha,
                    min: 0.0,
                    max: 1.0,
                    display: (0.0, 1.0),
                },
            )
            .in_group(&SCATTERED_GROUP)
            .animated(false),
        TRANSITION_GROUP.spec(
            "Transition",
            "How fast each part changes (transition curves come from the scene's \
            \"transition\" key)",
            false,
        ),
        TRANSITION
            .spec(
                "Transition",
                "uniform: every pixel at Progress; ramp, sine-rows, sine-columns, \
            radial: each pixel's turn comes from where it is on A, every pixel \
            still exactly A at 0 and B at 1.",
                Options::of(&PATTERNS, pattern_label, None),
            )
            .in_group(&TRANSITION_GROUP),
        TRANSITION_AFFECTS
            .spec(
                "Affects",
                "What the transition paces: the geometry (where features are) and the \
            colour (the dissolve), or one of them (the other stays uniform).",
                Affects::Both,
            )
            .in_group(&TRANSITION_GROUP)
            .animated(false),
        TRANSITION_SPREAD
            .spec(
                "Spread",
                "Share of the progress over which the pattern sweeps: 0 is uniform; \
            near 1 each pixel changes almost at once, at its turn.",
                Doubles {
                    default: 0.5,
                    min: 0.0,
                    max: 0.99,
                    display: (0.0, 0.99),
                },
            )
            .in_group(&TRANSITION_GROUP),
        TRANSITION_ANGLE
            .spec(
                "Angle",
                "Direction of the ramp in degrees: 0 left to right, 90 bottom to top.",
                Doubles {
                    default: 0.0,
                    min: -360.0,
                    max: 360.0,
                    display: (-180.0, 180.0),
                },
            )
            .in_group(&TRANSITION_GROUP),
        TRANSITION_CYCLES
            .spec(
                "Cycles",
                "Sinusoid periods across the frame (sine patterns), or rings (radial; \
            0: the centre first, then outward).",
                Doubles {
                    default: 2.0,
                    min: 0.0,
                    max: 100.0,
                    display: (0.0, 8.0),
                },
            )
            .in_group(&TRANSITION_GROUP),
        LINES_GROUP.spec("Lines", "Line pairs keyframed in the host", true),
        LINE_COUNT
            .spec(
                "Line Count",
                "How many of the line slots below are used.",
                Ints {
                    default: 0,
                    min: 0,
                    max: LINE_SLOTS as i32,
                },
            )
            .in_group(&LINES_GROUP)
            .animated(false),
        SNAP_LINES
            .spec(
                "Snap Lines",
                "Slides every enabled line, and every line, polyline and curve of \
            Scene Text, onto the nearest strong edge of its source at the \
            current frame (A positions on Source A, B positions on Source B) and \
            keys the moved points there. Place features roughly, then press.",
                (),
            )
            .in_group(&LINES_GROUP),
        SNAP_SIGMA
            .spec(
                "Snap Reach",
                "Edge smoothing for Snap Lines, in pixels: edges pull lines from \
            about twice this far.",
                Doubles {
                    default: 3.0,
                    min: 0.5,
                    max: 50.0,
                    display: (1.0, 10.0),
                },
            )
            .in_group(&LINES_GROUP)
            .animated(false),
        TRACK_FORWARD
            .spec(
                "Track Forward",
                "Follows every enabled line, and every control point of Scene Text's \
            shapes, through its source from the current frame to the line's next \
            key (or the end of the clip) and keys it at each frame: A on Source \
            A, B on Source B. Each frame is matched against the current frame's \
            picture, so it does not drift; a line that loses track is left \
            unkeyed from there and named. Cancel keeps the keys made so far.",
                (),
            )
            .in_group(&LINES_GROUP),
        TRACK_BACKWARD
            .spec(
                "Track Backward",
                "As Track Forward, towards the start: to the previous key, or the \
            first frame of the clip.",
                (),
            )
            .in_group(&LINES_GROUP),
        OVERLAY_SHOW
            .spec(
                "Show Lines",
                "What the viewer draws: A's lines (one colour) and B's (another) with \
            arrowheads, numbers and connectors, and the in-between lines dashed; \
            or one of them; or nothing.",
                Show::Both,
            )
            .in_group(&LINES_GROUP)
            .animated(false),
        OVERLAY_EDIT
            .spec(
                "Edit Lines",
                "Which features the pen moves in the viewer (line slots and the \
            shapes of Scene Text). Drag a point, or a feature by its body. Hold \
            Shift to grab only A's, Ctrl only B's.",
                EditSides::Both,
            )
            .in_group(&LINES_GROUP)
            .animated(false),
        DRAW_TOOL
            .spec(
                "Draw",
                "What the pen draws in empty space. line: drag a line into the next \
            slot. point: click to add a point to Scene Text. polyline, curve: \
            click to add control points (click the first point to close the \
            shape; click the last again, press Return or Finish Shape to end it \
            open); with these tools a click on a shape's segment inserts a \
            point. New shapes start with B on A: then move B's points.",
                DrawTool::Line,
            )
            .in_group(&LINES_GROUP)
            .animated(false),
        FINISH_SHAPE
            .spec(
                "Finish Shape",
                "Ends the polyline or curve being drawn, open.",
                (),
            )
            .in_group(&LINES_GROUP),
        DELETE_SHAPE
            .spec(
                "Delete Shape",
                "Deletes the shape last drawn or grabbed in the viewer from Scene \
            Text (Delete or Backspace over a point deletes that point).",
                (),
            )
            .in_group(&LINES_GROUP),
        KEY_SHAPES
            .spec(
                "Key Shapes Here",
                "Keys Scene Text's shapes at the current frame (a static scene \
            becomes keyed); from then on an edit at a frame keys that frame.",
                (),
            )
            .in_group(&LINES_GROUP),
        COPY_SCENE
            .spec(
                "Copy Scene Into Node",
                "Copies Scene File's scene into Scene Text and empties Scene File, so \
            its shapes can be edited in the viewer.",
                (),
            )
            .in_group(&LINES_GROUP),
    ];
    if !kind.has_auto() {
        t.retain(|p| p.id() != AUTO_GROUP.name() && p.group() != Some(AUTO_GROUP.name()));
    }
    if kind.has_b() {
        // Pairs between two sources: the Morph node's.
        t.extend([
            SUGGEST_FEATURES
                .spec(
                    "Suggest Features",
                    "Proposes feature pairs between Source A and Source B at the \
                    current frame (lines along A's straight edges and points at its \
                    corners, found on B and checked both ways) and adds them to Scene Text, clear of your own features, each \
                    drawn in its confidence's colour until you move it. One undo step; \
                    Cancel leaves Scene Text as it was.",
                    (),
                )
                .in_group(&LINES_GROUP),
            SUGGEST_COUNT
                .spec(
                    "Suggest Count",
                    "Pairs Suggest Features proposes at most.",
                    Ints {
                        default: 40,
                        min: 1,
                        max: 1000,
                    },
                )
                .in_group(&LINES_GROUP)
                .animated(false),
            MIN_CONFIDENCE
                .spec(
                    "Min Confidence",
                    "Pairs Suggest Features is less sure of than this are left out \
                    (0: every pair that matched; 1: only the surest).",
                    Doubles {
                        default: SuggestSettings::default().min_confidence,
                        min: 0.0,
                        max: 1.0,
                        display: (0.0, 1.0),
                    },
                )
                .in_group(&LINES_GROUP)
                .animated(false),
        ]);
    }
    for k in 1..=LINE_SLOTS {
        t.extend(slot_specs(k));
    }
    t.extend([
        SCENE_GROUP.spec(
            "Scene",
            "A MorphFX scene (.morph.json) with keyframed features, mesh and \
            settings",
            false,
        ),
        SCENE_FILE
            .spec(
                "Scene File",
                "Path of a .morph.json scene; its features add to the line slots.",
                Texts {
                    default: "",
                    mode: TextMode::FilePath,
                },
            )
            .in_group(&SCENE_GROUP),
        SCENE_TEXT
            .spec(
                "Scene Text",
                "A scene as JSON text (used when Scene File is empty). The viewer \
            draws its shapes and edits them in place.",
                Texts {
                    default: "",
                    mode: TextMode::MultiLine,
                },
            )
            .in_group(&SCENE_GROUP),
        OFFSET_A
            .spec(
                if kind.has_b() {
                    "Frame Offset A"
                } else {
                    "Frame Offset"
                },
                "Frames added to the time at which the source is read (sequence \
            morphs).",
                Ints {
                    default: 0,
                    min: -100000,
                    max: 100000,
                },
            )
            .animated(false),
    ]);
    if kind.has_b() {
        t.push(
            OFFSET_B
                .spec(
                    "Frame Offset B",
                    "Frames added to the time at which Source B is read.",
                    Ints {
                        default: 0,
                        min: -100000,
                        max: 100000,
                    },
                )
                .animated(false),
        );
    }
    t.extend([
        FILTER.spec(
            "Filter",
            "bilinear, bicubic (Catmull-Rom: sharper, may overshoot), or nearest (the \
            source pixel itself, unblended: for IDs and mattes).",
            Filter::Bilinear,
        ),
        ID_LAYERS
            .spec(
                "ID Layers",
                "In hosts that hand every layer to the node (Natron's multi-plane \
                extension), the layers besides the colour go through the same warp; \
                those whose names say IDs or mattes (id, objectId, crypto*, any name \
                with mask or matte), and those listed here (comma-separated), are \
                sampled nearest and never blended.",
                Texts {
                    default: "",
                    mode: TextMode::SingleLine,
                },
            )
            .animated(false),
        EDGE.spec(
            "Edge",
            "Outside the source: clamp to the edge pixels, black (transparent), \
            or mirror.",
            EdgeMode::Clamp,
        ),
        VIEW.spec(
            "View",
            "What the node outputs. ghost: where the warped sources still \
            disagree (alpha the mean |A - B| over R, G, B; colour a heat ramp, \
            black where they agree): double edges to fix. folds: where a warp \
            folds the image over itself (alpha 1 there, the morph tinted magenta \
            beneath).",
            Options::of(kind.views, |v| kind.view_label(v), kind.views[0]),
        ),
        MASK_INVERT.spec(
            "Invert Mask",
            "Use 1 - the Mask input's alpha: the effect applies where the mask is \
            clear.",
            false,
        ),
        MIX.spec(
            "Mix",
            "How much of the effect reaches the output: 0 shows the source \
            unchanged (Source A on the Morph node), 1 the full effect. \
            Multiplies the Mask input's alpha where one is connected.",
            Doubles {
                default: 1.0,
                min: 0.0,
                max: 1.0,
                display: (0.0, 1.0),
            },
        ),
        MOTION_BLUR_GROUP.spec(
            "Motion Blur",
            "The warp's motion within the shutter, as the picture views show it",
            false,
        ),
        MOTION_BLUR
            .spec(
                "Motion Blur",
                "Renders averaged over the shutter (0: off). With N, the picture is \
            the mean of the node rendered at N times evenly spread over the \
            shutter (the features, mesh, progress and params at each time; the \
            sources held at the frame). A still scene renders once.",
                Ints {
                    default: 0,
                    min: 0,
                    max: MAX_BLUR_SAMPLES,
                },
            )
            .in_group(&MOTION_BLUR_GROUP)
            .animated(false),
        SHUTTER
            .spec(
                "Shutter",
                "How long the shutter is open, in frames.",
                Doubles {
                    default: 0.5,
                    min: 0.0,
                    max: 10.0,
                    display: (0.0, 2.0),
                },
            )
            .in_group(&MOTION_BLUR_GROUP),
        SHUTTER_OFFSET
            .spec(
                "Shutter Offset",
                "Where the shutter opens: centred on the frame, starting at it, or \
            ending at it.",
                ShutterOffset::Centred,
            )
            .in_group(&MOTION_BLUR_GROUP)
            .animated(false),
    ]);
    t
}

/// Grid Rows or Grid Columns: 2 to the largest mesh, 5 by default.
fn grid_size(id: &Id<Int>, label: &'static str, hint: &'static str) -> ParamSpec {
    let size = Ints {
        default: 5,
        min: 2,
        max: MAX_SIZE as i32,
    };
    id.spec(label, hint, size)
        .in_group(&MESH_GROUP)
        .animated(false)
}

/// Line slot `k`'s params, in their own group: enable, the four ends, Clear.
pub(super) fn slot_specs(k: usize) -> Vec<ParamSpec> {
    let SlotIds {
        enable,
        a: [a0, a1],
        b: [b0, b1],
    } = slot_ids(k);
    let group = slot_group(k);
    // Default lines stacked down the frame, so slots added one by one in a
    // host without the overlay do not all start on top of each other.
    let y = 100.0 + 40.0 * ((k - 1) % 16) as f64;
    let mut specs = vec![
        group
            .spec(format!("Line {k}"), format!("Line pair {k}"), false)
            .in_group(&LINES_GROUP),
        enable
            .spec("Enabled", format!("Use line pair {k}."), true)
            .in_group(&group),
    ];
    for (id, label, x) in [
        (a0, "A Start", 100.0),
        (a1, "A End", 300.0),
        (b0, "B Start", 100.0),
        (b1, "B End", 300.0),
    ] {
        let hint = format!("Line {k}: {label} (canonical pixels, y up).");
        let row = id.spec(format!("Line {k} {label}"), hint, (x, y));
        specs.push(row.in_group(&group));
    }
    let hint = format!(
        "Removes line {k}'s keys, puts it back where it started and turns it \
            off."
    );
    specs.push(slot_clear(k).spec("Clear Line", hint, ()).in_group(&group));
    specs
}

/// The table entry of param `id`, through an index built once per node: a
/// render reads a few hundred params from a table of several hundred.
pub fn spec(kind: &'static NodeKind, id: &str) -> Option<&'static ParamSpec> {
    let c = catalogue(kind);
    c.index.get(id).map(|&i| &c.table[i])
}

/// The params a node defines in `context`: its table, and in the
/// transition context the mandated `Transition` param (Parameters Mandated
/// In A Context: the plugin defines it, the host drives it).
pub fn table_in_context(kind: &'static NodeKind, context: Context) -> Vec<ParamSpec> {
    let mut table = table(kind).to_vec();
    if context == Context::Transition {
        table.push(TRANSITION_PARAM.host_driven(0.0));
    }
    table
}
