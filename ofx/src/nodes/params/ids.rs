//! The params' ids: stable names hosts save projects by, each typed with
//! the kind of value the param holds, so every row, read and write through
//! an id is checked when the plugin is compiled.

use morphfx::image::{EdgeMode, Filter};
use morphfx::shutter::ShutterOffset;
use morphfx::warp::field::LineInterpolation;
use morphfx::warp::mesh::Pass;

use ofx_layer::spec::{Bool, Button, Choose, Double, Group, Id, Indexed, Int, Point, Text};

use super::choices::{Affects, DrawTool, EditSides, EvaluationMode, Show};

/// Line-pair slots every node offers (a face takes 30 to 60 lines).
pub const LINE_SLOTS: usize = 64;

pub const METHOD: Id<Indexed> = Id::new("method");
pub const PROGRESS: Id<Double> = Id::new("progress");
pub const USE_SCENE_PROGRESS: Id<Bool> = Id::new("use_scene_progress");
pub const SETTINGS_FROM_SCENE: Id<Bool> = Id::new("settings_from_scene");
pub const FIELD_A: Id<Double> = Id::new("field_a");
pub const FIELD_B: Id<Double> = Id::new("field_b");
pub const FIELD_P: Id<Double> = Id::new("field_p");
pub const INTERPOLATION: Id<Choose<LineInterpolation>> = Id::new("line_interpolation");
pub const EVALUATION: Id<Choose<EvaluationMode>> = Id::new("evaluation");
pub const TOLERANCE: Id<Double> = Id::new("tolerance");
pub const LINE_COUNT: Id<Int> = Id::new("line_count");
pub const SCENE_FILE: Id<Text> = Id::new("scene_file");
pub const SCENE_TEXT: Id<Text> = Id::new("scene_text");
pub const OFFSET_A: Id<Int> = Id::new("frame_offset_a");
pub const OFFSET_B: Id<Int> = Id::new("frame_offset_b");
pub const FILTER: Id<Choose<Filter>> = Id::new("filter");
pub const ID_LAYERS: Id<Text> = Id::new("id_layers");
pub const EDGE: Id<Choose<EdgeMode>> = Id::new("edge");
pub const VIEW: Id<Indexed> = Id::new("view");
pub const MESH_PASS: Id<Choose<Pass>> = Id::new("mesh_pass");
pub const GRID_ROWS: Id<Int> = Id::new("grid_rows");
pub const GRID_COLS: Id<Int> = Id::new("grid_cols");
pub const RESET_GRID: Id<Button> = Id::new("reset_grid");
pub const ADD_ROW: Id<Button> = Id::new("grid_add_row");
pub const ADD_COLUMN: Id<Button> = Id::new("grid_add_column");
pub const REMOVE_ROW: Id<Button> = Id::new("grid_remove_row");
pub const REMOVE_COLUMN: Id<Button> = Id::new("grid_remove_column");
pub const SNAP_LINES: Id<Button> = Id::new("snap_lines");
pub const SNAP_SIGMA: Id<Double> = Id::new("snap_sigma");
pub const TRACK_FORWARD: Id<Button> = Id::new("track_forward");
pub const TRACK_BACKWARD: Id<Button> = Id::new("track_backward");
pub const OVERLAY_SHOW: Id<Choose<Show>> = Id::new("overlay_show");
pub const OVERLAY_EDIT: Id<Choose<EditSides>> = Id::new("overlay_edit");
pub const DRAW_TOOL: Id<Choose<DrawTool>> = Id::new("draw_tool");
pub const FINISH_SHAPE: Id<Button> = Id::new("finish_shape");
pub const DELETE_SHAPE: Id<Button> = Id::new("delete_shape");
pub const KEY_SHAPES: Id<Button> = Id::new("key_shapes");
pub const COPY_SCENE: Id<Button> = Id::new("copy_scene");
pub const SUGGEST_FEATURES: Id<Button> = Id::new("suggest_features");
pub const SUGGEST_COUNT: Id<Int> = Id::new("suggest_count");
pub const MIN_CONFIDENCE: Id<Double> = Id::new("suggest_min_confidence");
pub const AUTO_LEVELS: Id<Int> = Id::new("auto_levels");
pub const AUTO_COLOUR: Id<Double> = Id::new("auto_colour");
pub const AUTO_STRETCH: Id<Double> = Id::new("auto_stretch");
pub const AUTO_ANGLE: Id<Double> = Id::new("auto_angle");
pub const AUTO_ANCHORS: Id<Double> = Id::new("auto_anchors");
pub const AUTO_WARM_START: Id<Bool> = Id::new("auto_warm_start");
pub const PLATE_ALPHA: Id<Double> = Id::new("plate_alpha");
pub const PLATE_BETA: Id<Double> = Id::new("plate_beta");
pub const MFFD_ALPHA: Id<Double> = Id::new("mffd_alpha");
pub const TRANSITION: Id<Indexed> = Id::new("transition");
pub const TRANSITION_AFFECTS: Id<Choose<Affects>> = Id::new("transition_affects");
pub const TRANSITION_SPREAD: Id<Double> = Id::new("transition_spread");
pub const TRANSITION_ANGLE: Id<Double> = Id::new("transition_angle");
pub const TRANSITION_CYCLES: Id<Double> = Id::new("transition_cycles");
pub const MASK_INVERT: Id<Bool> = Id::new("mask_invert");
pub const MIX: Id<Double> = Id::new("mix");
pub const MOTION_BLUR: Id<Int> = Id::new("motion_blur");
pub const SHUTTER: Id<Double> = Id::new("shutter");
/// The most motion blur samples a render takes (the param's maximum).
pub const MAX_BLUR_SAMPLES: i32 = 64;
pub const SHUTTER_OFFSET: Id<Choose<ShutterOffset>> = Id::new("shutter_offset");

/// The groups, as hosts fold them.
pub const FIELD_GROUP: Id<Group> = Id::new("field_group");
pub const MESH_GROUP: Id<Group> = Id::new("mesh_group");
pub const AUTO_GROUP: Id<Group> = Id::new("auto_group");
pub const SCATTERED_GROUP: Id<Group> = Id::new("scattered_group");
pub const TRANSITION_GROUP: Id<Group> = Id::new("transition_group");
pub const LINES_GROUP: Id<Group> = Id::new("lines_group");
pub const SCENE_GROUP: Id<Group> = Id::new("scene_group");
pub const MOTION_BLUR_GROUP: Id<Group> = Id::new("motion_blur_group");

/// The group holding line slot `k`'s params.
pub fn slot_group(k: usize) -> Id<Group> {
    Id::named(format!("line{k}_group"))
}

/// Line slot `k`'s Clear Line button.
pub fn slot_clear(k: usize) -> Id<Button> {
    Id::named(format!("line{k}_clear"))
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

/// Line slot `k`'s params (1-based): its switch and the ends of its lines.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SlotIds {
    pub enable: Id<Bool>,
    /// A's start and end.
    pub a: [Id<Point>; 2],
    /// B's start and end.
    pub b: [Id<Point>; 2],
}

impl SlotIds {
    /// Every position of the slot: A's start and end, then B's.
    pub fn ends(&self) -> [&Id<Point>; 4] {
        [&self.a[0], &self.a[1], &self.b[0], &self.b[1]]
    }

    /// The slot's ids as hosts know them, switch first.
    pub fn names(&self) -> [String; 5] {
        let [a0, a1, b0, b1] = self.ends().map(|id| id.name().to_owned());
        [self.enable.name().to_owned(), a0, a1, b0, b1]
    }
}

/// Line slot `k`'s ids.
pub fn slot_ids(k: usize) -> SlotIds {
    let point = |which: &str| Id::named(format!("line{k}_{which}"));
    SlotIds {
        enable: Id::named(format!("line{k}_enable")),
        a: [point("a_start"), point("a_end")],
        b: [point("b_start"), point("b_end")],
    }
}

/// The transition context's mandated param (`kOfxImageEffectTransitionParamName`).
pub const TRANSITION_PARAM: Id<Double> = Id::new("Transition");
