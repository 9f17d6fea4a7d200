//! Every setting a render needs, read from the params at one time.

use morphfx::features::Feature;
use morphfx::image::{EdgeMode, Filter};
use morphfx::make_warp::MethodSettings;
use morphfx::shutter::Shutter;
use morphfx::transition::procedural::PatternKind;
use morphfx::transition::{Pattern, Procedural, Transition, TransitionSettings};
use morphfx::views::View;
use morphfx::warp::auto::{AutoSettings, Coefficients};
use morphfx::warp::field::{Evaluation, FieldSettings};
use morphfx::warp::mesh::MeshSettings;
use morphfx::warp::mffd::MffdSettings;
use morphfx::warp::thin_plate::ThinPlateSettings;

use crate::nodes::kind::NodeKind;
use ofx_layer::params::Params;

use super::choices::{Affects, EvaluationMode, PATTERNS};
use super::ids::*;
use super::reader::Reader;

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
    /// Layers sampled nearest besides those whose names say IDs.
    pub id_layers: Vec<String>,
    pub edge: EdgeMode,
    pub view: View,
    /// What a timing matte paces (the Transition group's Affects).
    pub affects: Affects,
    /// The share of the progress a timing matte's turns spread over.
    pub spread: f64,
    /// Share of the effect in the output, `[0, 1]`.
    pub mix: f64,
    /// The Mask input's alpha is read inverted.
    pub mask_invert: bool,
    /// Motion blur: samples, shutter length and offset.
    pub shutter: Shutter,
    pub missing: Vec<String>,
    /// Why each param the host has could not be read.
    pub unreadable: Vec<String>,
}

impl Settings {
    pub fn read(params: &Params, time: f64, kind: &'static NodeKind) -> Settings {
        Settings::read_with(Reader::new(params, kind, time), kind)
    }

    /// Every param at the default its table entry declares.
    #[cfg(test)]
    pub fn defaults(kind: &'static NodeKind) -> Settings {
        let reader = Reader {
            params: None,
            kind,
            time: 0.0,
            missing: std::cell::RefCell::new(Vec::new()),
            unreadable: std::cell::RefCell::new(Vec::new()),
        };
        Settings::read_with(reader, kind)
    }

    fn read_with(r: Reader<'_>, kind: &'static NodeKind) -> Settings {
        let warp = MethodSettings {
            method: r.pick(&METHOD, kind.methods),
            field: field_settings(&r),
            mesh: MeshSettings {
                pass: r.choice(&MESH_PASS),
            },
            auto: if kind.has_auto() {
                auto_settings(&r)
            } else {
                AutoSettings::default()
            },
            thin_plate: ThinPlateSettings {
                alpha: r.double(&PLATE_ALPHA),
                beta: r.double(&PLATE_BETA),
                ..ThinPlateSettings::default()
            },
            mffd: MffdSettings {
                alpha: r.double(&MFFD_ALPHA),
                ..MffdSettings::default()
            },
            transition: transition_settings(&r),
            ..MethodSettings::default()
        };
        let settings = Settings {
            warp,
            progress: r.double(&PROGRESS),
            use_scene_progress: r.bool(&USE_SCENE_PROGRESS),
            settings_from_scene: r.bool(&SETTINGS_FROM_SCENE),
            lines: lines(&r),
            scene_file: r.text(&SCENE_FILE),
            scene_text: r.text(&SCENE_TEXT),
            offset_a: r.int(&OFFSET_A),
            offset_b: if kind.has_b() { r.int(&OFFSET_B) } else { 0 },
            filter: r.choice(&FILTER),
            id_layers: r
                .text(&ID_LAYERS)
                .split(',')
                .map(str::trim)
                .filter(|n| !n.is_empty())
                .map(str::to_owned)
                .collect(),
            edge: r.choice(&EDGE),
            view: r.pick(&VIEW, kind.views),
            affects: r.choice(&TRANSITION_AFFECTS),
            spread: r.double(&TRANSITION_SPREAD),
            mix: r.double(&MIX),
            shutter: Shutter {
                // A host that does not clamp to the declared range gets it here.
                samples: r.int(&MOTION_BLUR).clamp(0, MAX_BLUR_SAMPLES) as usize,
                length: r.double(&SHUTTER),
                offset: r.choice(&SHUTTER_OFFSET),
            },
            mask_invert: r.bool(&MASK_INVERT),
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

pub fn field_settings(r: &Reader<'_>) -> FieldSettings {
    let evaluation = match r.choice(&EVALUATION) {
        EvaluationMode::Exact => Evaluation::Exact,
        EvaluationMode::Adaptive => Evaluation::Adaptive {
            tolerance: r.double(&TOLERANCE),
        },
    };
    FieldSettings {
        a: r.double(&FIELD_A),
        b: r.double(&FIELD_B),
        p: r.double(&FIELD_P),
        interpolation: r.choice(&INTERPOLATION),
        evaluation,
        ..FieldSettings::default()
    }
}

pub(super) fn auto_settings(r: &Reader<'_>) -> AutoSettings {
    AutoSettings {
        // 0: the level that gives quads of about 4 pixels.
        levels: match r.int(&AUTO_LEVELS) {
            0 => None,
            l => Some(l as u32),
        },
        coefficients: Coefficients {
            colour: r.double(&AUTO_COLOUR),
            stretch: r.double(&AUTO_STRETCH),
            angle: r.double(&AUTO_ANGLE),
            anchor: r.double(&AUTO_ANCHORS),
        },
        warm_start: r.bool(&AUTO_WARM_START),
        ..AutoSettings::default()
    }
}

pub(super) fn transition_settings(r: &Reader<'_>) -> TransitionSettings {
    let Some(kind) = r.pick(&TRANSITION, &PATTERNS) else {
        return TransitionSettings::default();
    };
    let cycles = r.double(&TRANSITION_CYCLES);
    let pattern = match kind {
        PatternKind::Ramp => Pattern::Ramp {
            angle: r.double(&TRANSITION_ANGLE),
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
        spread: r.double(&TRANSITION_SPREAD),
    });
    pacing(t, r.choice(&TRANSITION_AFFECTS))
}

/// `t` on what `affects` names, the rest uniform.
pub fn pacing(t: Transition, affects: Affects) -> TransitionSettings {
    match affects {
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
pub(super) fn lines(r: &Reader<'_>) -> Vec<Feature> {
    // A zero-length line has no direction: the slot is skipped, not an
    // error, so a half-placed line never breaks a render.
    crate::nodes::lines::slot_lines(r)
        .into_iter()
        .filter(|l| l.a[0] != l.a[1] && l.b[0] != l.b[1])
        .map(|l| Feature::line(l.a, l.b).named(format!("line {}", l.slot)))
        .collect()
}
