//! Params as data: stable ids, labels, hints, defaults, ranges,
//! groups. The layer turns a table of these into OFX param definitions.

#[derive(Debug, Clone, PartialEq)]
pub enum TextMode {
    MultiLine,
    FilePath,
}

#[derive(Debug, Clone, PartialEq)]
pub enum Kind {
    Double {
        default: f64,
        min: f64,
        max: f64,
        display: (f64, f64),
    },
    Int {
        default: i32,
        min: i32,
        max: i32,
    },
    Bool {
        default: bool,
    },
    /// The value is the option's index.
    Choice {
        options: Vec<&'static str>,
        default: usize,
    },
    /// A canonical position (Double2D, XY absolute): what hosts draw and keyframe as a point.
    Point {
        default: (f64, f64),
    },
    Text {
        default: &'static str,
        mode: TextMode,
    },
    Group {
        open: bool,
    },
    /// A push-button: no value, it sends instanceChanged when pressed.
    Button,
    /// A double the host drives and shows however it likes (the transition
    /// context's mandated `Transition`): the spec forbids labelling or
    /// placing it, so only its name, default and range are set.
    HostDriven {
        default: f64,
    },
}

#[derive(Debug, Clone, PartialEq)]
pub struct ParamSpec {
    /// Stable id: never changes when the label does.
    pub id: String,
    pub label: String,
    pub hint: String,
    pub kind: Kind,
    pub group: Option<String>,
    pub animates: bool,
}

impl ParamSpec {
    pub fn new(
        id: impl Into<String>,
        label: impl Into<String>,
        hint: impl Into<String>,
        kind: Kind,
    ) -> Self {
        let animates = !matches!(
            kind,
            Kind::Choice { .. }
                | Kind::Text { .. }
                | Kind::Group { .. }
                | Kind::Bool { .. }
                | Kind::HostDriven { .. }
        );
        ParamSpec {
            id: id.into(),
            label: label.into(),
            hint: hint.into(),
            kind,
            group: None,
            animates,
        }
    }
    pub fn in_group(mut self, group: impl Into<String>) -> Self {
        self.group = Some(group.into());
        self
    }
    pub fn animated(mut self, animates: bool) -> Self {
        self.animates = animates;
        self
    }
}
