//! The params' ids: stable names hosts save projects by.

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

/// The transition context's mandated param (`kOfxImageEffectTransitionParamName`).
pub const TRANSITION_PARAM: &str = "Transition";
