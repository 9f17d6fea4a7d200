//! Params as data: stable ids, labels, hints, defaults, ranges,
//! groups. The layer turns a table of these into OFX param definitions.
//!
//! A param's [`Id`] carries the kind of value it holds, and only an id of
//! that kind can build its row ([`Id::spec`] takes the kind's own
//! definition) or read and write its value (`Params`' accessors take
//! typed ids): a double's id with an integer's range does not compile.

use std::borrow::Cow;
use std::marker::PhantomData;

use morphfx::choice::Choice;

#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TextMode {
    SingleLine,
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

/// One param's row: what the host is told to make. Built only through a
/// typed [`Id`] (its fields are read, never written, outside this layer).
#[derive(Debug, Clone, PartialEq)]
pub struct ParamSpec {
    /// Stable id: never changes when the label does.
    id: String,
    label: String,
    hint: String,
    kind: Kind,
    group: Option<String>,
    animates: bool,
}

impl ParamSpec {
    fn new(id: String, label: String, hint: String, kind: Kind) -> Self {
        let animates = !matches!(
            kind,
            Kind::Choice { .. }
                | Kind::Text { .. }
                | Kind::Group { .. }
                | Kind::Bool { .. }
                | Kind::HostDriven { .. }
        );
        ParamSpec {
            id,
            label,
            hint,
            kind,
            group: None,
            animates,
        }
    }

    /// In group `group` (hosts show it inside).
    pub fn in_group(mut self, group: &Id<Group>) -> Self {
        self.group = Some(group.name().to_owned());
        self
    }

    /// Whether the host may key it (numbers and positions do by default).
    pub fn animated(mut self, animates: bool) -> Self {
        self.animates = animates;
        self
    }

    pub fn id(&self) -> &str {
        &self.id
    }
    pub fn label(&self) -> &str {
        &self.label
    }
    pub fn hint(&self) -> &str {
        &self.hint
    }
    pub fn kind(&self) -> &Kind {
        &self.kind
    }
    pub fn group(&self) -> Option<&str> {
        self.group.as_deref()
    }
    pub fn animates(&self) -> bool {
        self.animates
    }
}

/// A param's id, typed with the kind of value it holds ([`Double`],
/// [`Int`], [`Bool`], [`Text`], [`Point`], [`Choose`], [`Indexed`],
/// [`Button`], [`Group`]). Its row takes that kind's definition only:
///
/// ```
/// use ofx_layer::spec::{Double, Doubles, Id, Kind};
/// const MIX: Id<Double> = Id::new("mix");
/// let d = Doubles { default: 1.0, min: 0.0, max: 1.0, display: (0.0, 1.0) };
/// let row = MIX.spec("Mix", "How much of the effect", d);
/// assert!(matches!(row.kind(), Kind::Double { default: 1.0, .. }));
/// ```
///
/// ```compile_fail
/// use ofx_layer::spec::{Double, Id, Ints};
/// const MIX: Id<Double> = Id::new("mix");
/// // An integer's range for a double's id: refused by the compiler.
/// let row = MIX.spec("Mix", "", Ints { default: 1, min: 0, max: 1 });
/// ```
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Id<K> {
    name: Cow<'static, str>,
    kind: PhantomData<fn() -> K>,
}

impl<K> Id<K> {
    pub const fn new(name: &'static str) -> Self {
        Id {
            name: Cow::Borrowed(name),
            kind: PhantomData,
        }
    }

    /// An id made at run time (numbered slots).
    pub fn named(name: String) -> Self {
        Id {
            name: Cow::Owned(name),
            kind: PhantomData,
        }
    }

    /// The id as hosts know it.
    pub fn name(&self) -> &str {
        &self.name
    }
}

impl<K: ParamKind> Id<K> {
    /// The param's row: its label, its hint (the tooltip) and its kind's
    /// definition (range and default, options, ...).
    pub fn spec(
        &self,
        label: impl Into<String>,
        hint: impl Into<String>,
        def: K::Def,
    ) -> ParamSpec {
        let id = self.name().to_owned();
        ParamSpec::new(id, label.into(), hint.into(), K::kind(def))
    }
}

impl Id<Double> {
    /// A double the host drives and shows however it likes (the
    /// transition context's mandated `Transition`): the spec forbids
    /// labelling or placing it, so only its name and default are set.
    pub fn host_driven(&self, default: f64) -> ParamSpec {
        let id = self.name().to_owned();
        ParamSpec::new(
            id,
            String::new(),
            String::new(),
            Kind::HostDriven { default },
        )
    }
}

/// The kind of value a param holds, and what defines one.
pub trait ParamKind {
    /// What a row of this kind is defined by.
    type Def;
    fn kind(def: Self::Def) -> Kind;
}

/// A floating-point param.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Double;
/// An integer param.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Int;
/// A boolean param.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Bool;
/// A string param.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Text;
/// A canonical position (Double2D).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Point;
/// A push button: it has no value, only presses.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Button;
/// A group of params, shown folded or open.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Group;
/// A choice whose options are `C`'s, in `Choice::ALL` order.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Choose<C>(PhantomData<C>);
/// A choice whose options depend on the effect: read by index into the
/// list its row was defined with.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Indexed;

/// A double's default, bounds and the slider's range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Doubles {
    pub default: f64,
    pub min: f64,
    pub max: f64,
    pub display: (f64, f64),
}

/// An integer's default and bounds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ints {
    pub default: i32,
    pub min: i32,
    pub max: i32,
}

/// A string's default and how hosts edit it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Texts {
    pub default: &'static str,
    pub mode: TextMode,
}

/// An [`Indexed`] choice's option labels and default.
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    pub labels: Vec<&'static str>,
    pub default: usize,
}

impl Options {
    /// `options` labelled by `label`, `default` first unless not among them.
    pub fn of<C: Copy + PartialEq>(
        options: &[C],
        label: impl Fn(C) -> &'static str,
        default: C,
    ) -> Self {
        Options {
            labels: options.iter().map(|o| label(*o)).collect(),
            default: options.iter().position(|o| *o == default).unwrap_or(0),
        }
    }
}

impl ParamKind for Double {
    type Def = Doubles;
    fn kind(d: Doubles) -> Kind {
        let Doubles {
            default,
            min,
            max,
            display,
        } = d;
        Kind::Double {
            default,
            min,
            max,
            display,
        }
    }
}

impl ParamKind for Int {
    type Def = Ints;
    fn kind(d: Ints) -> Kind {
        let Ints { default, min, max } = d;
        Kind::Int { default, min, max }
    }
}

impl ParamKind for Bool {
    /// The default.
    type Def = bool;
    fn kind(default: bool) -> Kind {
        Kind::Bool { default }
    }
}

impl ParamKind for Text {
    type Def = Texts;
    fn kind(d: Texts) -> Kind {
        Kind::Text {
            default: d.default,
            mode: d.mode,
        }
    }
}

impl ParamKind for Point {
    /// The default position.
    type Def = (f64, f64);
    fn kind(default: (f64, f64)) -> Kind {
        Kind::Point { default }
    }
}

impl ParamKind for Button {
    type Def = ();
    fn kind((): ()) -> Kind {
        Kind::Button
    }
}

impl ParamKind for Group {
    /// Shown open.
    type Def = bool;
    fn kind(open: bool) -> Kind {
        Kind::Group { open }
    }
}

impl<C: Choice> ParamKind for Choose<C> {
    /// The default option.
    type Def = C;
    fn kind(default: C) -> Kind {
        let Options { labels, default } = Options::of(C::ALL, C::name, default);
        Kind::Choice {
            options: labels,
            default,
        }
    }
}

impl ParamKind for Indexed {
    type Def = Options;
    fn kind(o: Options) -> Kind {
        Kind::Choice {
            options: o.labels,
            default: o.default,
        }
    }
}

/// Kinds whose value the host passes as one `int`: integers, booleans and
/// choices (by option index).
pub trait IntValued {}
impl IntValued for Int {}
impl IntValued for Bool {}
impl IntValued for Indexed {}
impl<C> IntValued for Choose<C> {}
