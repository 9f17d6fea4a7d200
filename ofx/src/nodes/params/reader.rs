//! Param values read at a time, each by the table entry that defines it.

use std::cell::RefCell;

use morphfx::choice::Choice;
use morphfx::geom::Vec2;

use crate::nodes::kind::NodeKind;
use ofx_layer::params::Params;
use ofx_layer::spec::{
    Bool, Choose, Double, Id, Indexed, Int, IntValued, Kind, ParamSpec, Point, Text,
};
use ofx_layer::Outcome;

use super::table::spec;

/// Reads params at one time, each by the table entry that defines it: the
/// default it declares stands in for a value the host cannot give, and its
/// range bounds the value.
pub struct Reader<'a> {
    /// `None`: every param at its default.
    pub(super) params: Option<&'a Params>,
    pub(super) kind: &'static NodeKind,
    pub(super) time: f64,
    pub(super) missing: RefCell<Vec<String>>,
    pub(super) unreadable: RefCell<Vec<String>>,
}

impl<'a> Reader<'a> {
    pub fn new(params: &'a Params, kind: &'static NodeKind, time: f64) -> Self {
        Reader {
            params: Some(params),
            kind,
            time,
            missing: RefCell::new(Vec::new()),
            unreadable: RefCell::new(Vec::new()),
        }
    }

    pub(super) fn spec(&self, id: &str) -> &'static ParamSpec {
        spec(self.kind, id)
            .unwrap_or_else(|| panic!("param {id} is read but not in the node's table"))
    }

    /// The host's value, or `None` (and `id` noted missing or unreadable).
    pub(super) fn host<K, T>(
        &self,
        id: &Id<K>,
        read: impl FnOnce(&Params) -> Outcome<T>,
    ) -> Option<T> {
        let params = self.params?;
        match read(params) {
            Ok(v) => Some(v),
            Err(why) if params.has(id) => {
                self.unreadable.borrow_mut().push(why.message().to_owned());
                None
            }
            Err(_) => {
                self.missing.borrow_mut().push(id.name().to_owned());
                None
            }
        }
    }

    pub fn double(&self, id: &Id<Double>) -> f64 {
        let &Kind::Double {
            default, min, max, ..
        } = self.spec(id.name()).kind()
        else {
            panic!("param {} is not a double", id.name());
        };
        match self.host(id, |p| p.double(id, self.time)) {
            Some(v) if v.is_finite() => v.clamp(min, max),
            _ => default,
        }
    }

    pub fn int(&self, id: &Id<Int>) -> i32 {
        let &Kind::Int { default, min, max } = self.spec(id.name()).kind() else {
            panic!("param {} is not an integer", id.name());
        };
        self.host(id, |p| p.int(id, self.time))
            .map_or(default, |v| v.clamp(min, max))
    }

    pub fn bool(&self, id: &Id<Bool>) -> bool {
        let &Kind::Bool { default } = self.spec(id.name()).kind() else {
            panic!("param {} is not a boolean", id.name());
        };
        self.host(id, |p| p.int(id, self.time))
            .map_or(default, |v| v != 0)
    }

    /// The option of `options` the host's index picks (the list the table
    /// defined the param with), else the declared default.
    pub fn pick<C: Copy>(&self, id: &Id<Indexed>, options: &[C]) -> C {
        self.index(id, options)
    }

    fn index<K: IntValued, C: Copy>(&self, id: &Id<K>, options: &[C]) -> C {
        let Kind::Choice { default, .. } = self.spec(id.name()).kind() else {
            panic!("param {} is not a choice", id.name());
        };
        self.host(id, |p| p.int(id, self.time))
            .and_then(|i| usize::try_from(i).ok())
            .and_then(|i| options.get(i))
            .copied()
            .unwrap_or(options[*default])
    }

    /// A [`Choice`] param, defined with its options in [`Choice::ALL`] order.
    pub fn choice<C: Choice>(&self, id: &Id<Choose<C>>) -> C {
        self.index(id, C::ALL)
    }

    pub fn text(&self, id: &Id<Text>) -> String {
        let &Kind::Text { default, .. } = self.spec(id.name()).kind() else {
            panic!("param {} is not text", id.name());
        };
        self.host(id, |p| p.string(id, self.time))
            .unwrap_or_else(|| default.to_owned())
    }

    /// A position param, `None` when the host cannot give it.
    pub fn point(&self, id: &Id<Point>) -> Option<Vec2> {
        let Kind::Point { .. } = self.spec(id.name()).kind() else {
            panic!("param {} is not a position", id.name());
        };
        self.host(id, |p| p.point(id, self.time))
            .map(|(x, y)| Vec2::new(x, y))
    }
}
