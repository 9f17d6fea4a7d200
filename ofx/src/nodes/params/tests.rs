use morphfx::choice::Choice;
use morphfx::image::EdgeMode;
use morphfx::make_warp::Method;
use morphfx::views::View;
use morphfx::warp::field::FieldSettings;

use ofx_layer::spec::Kind;

use super::ids::*;
use super::settings::*;
use super::table::*;
use crate::nodes::kind::NodeKind;
use crate::nodes::node::Node;
use crate::nodes::{Morph, Warp};

const MORPH: &NodeKind = Morph::KIND;
const WARP: &NodeKind = Warp::KIND;

/// Every choice param's options as MorphFX 1.0 shipped them. Hosts save
/// a choice by its index, so a saved project reads these back by
/// position: they may be followed by new options, never reordered,
/// renamed or removed.
const RELEASED: &[(&NodeKind, &str, &[&str])] = &[
    (
        MORPH,
        "method",
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
        WARP,
        "method",
        &["field", "mesh", "triangles", "thin-plate", "mffd", "hybrid"],
    ),
    (
        MORPH,
        "view",
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
    (WARP, "view", &["warped", "stmap", "grid"]),
];

/// Choice params both nodes share, with their released options.
const RELEASED_BOTH: &[(&str, &[&str])] = &[
    ("line_interpolation", &["endpoints", "center-angle"]),
    ("evaluation", &["adaptive", "exact"]),
    ("mesh_pass", &["two-pass", "one-pass"]),
    (
        "transition",
        &["uniform", "ramp", "sine-rows", "sine-columns", "radial"],
    ),
    (
        "transition_affects",
        &["geometry and colour", "geometry", "colour"],
    ),
    ("filter", &["bilinear", "bicubic", "nearest"]),
    ("edge", &["clamp", "black", "mirror"]),
    (
        "overlay_show",
        &["A and B", "A only", "B only", "in-between", "off"],
    ),
    ("overlay_edit", &["A and B", "A only", "B only"]),
    ("draw_tool", &["line", "point", "polyline", "curve"]),
    ("shutter_offset", &["centred", "start", "end"]),
];

fn released() -> Vec<(&'static NodeKind, &'static str, &'static [&'static str])> {
    let mut all = RELEASED.to_vec();
    for kind in [MORPH, WARP] {
        all.extend(RELEASED_BOTH.iter().map(|(id, o)| (kind, *id, *o)));
    }
    all
}

fn options(kind: &'static NodeKind, id: &str) -> Option<(Vec<&'static str>, usize)> {
    table(kind)
        .iter()
        .find(|p| p.id() == id)
        .map(|p| match p.kind() {
            Kind::Choice { options, default } => (options.clone(), *default),
            other => panic!("{id} is not a choice: {other:?}"),
        })
}

#[test]
fn choice_options_only_ever_grow_at_the_end() {
    for (kind, id, was) in released() {
        let (now, _) = options(kind, id).unwrap_or_else(|| panic!("{} lost {id}", kind.label));
        assert!(
            now.starts_with(was),
            "{} {id}: released {was:?}, now {now:?}",
            kind.label
        );
    }
}

#[test]
fn every_choice_param_is_recorded_with_a_default_among_its_options() {
    let recorded = released();
    for kind in [MORPH, WARP] {
        for p in table(kind) {
            if let Kind::Choice { options, default } = p.kind() {
                assert!(
                    recorded
                        .iter()
                        .any(|(k, id, _)| *k == kind && *id == p.id()),
                    "{} {}: record its options in RELEASED",
                    kind.label,
                    p.id()
                );
                assert!(*default < options.len(), "{} {}", kind.label, p.id());
            }
        }
    }
}

/// The option lists the reader picks from are the ones the table
/// defined, so index k reads back the option labelled k.
#[test]
fn choices_read_back_the_option_they_label() {
    for kind in [MORPH, WARP] {
        let (labels, _) = options(kind, METHOD.name()).expect("method");
        let names: Vec<_> = kind.methods.iter().map(|m| m.name()).collect();
        assert_eq!(labels, names);
        let (labels, _) = options(kind, VIEW.name()).expect("view");
        let names: Vec<_> = kind.views.iter().map(|v| kind.view_label(*v)).collect();
        assert_eq!(labels, names);
    }
    assert_eq!(
        options(MORPH, EDGE.name()).expect("edge").0,
        EdgeMode::names()
    );
}

/// The defaults a fresh node renders with: what the table declares.
#[test]
fn defaults_are_the_tables() {
    let s = Settings::defaults(MORPH);
    assert_eq!(s.warp.method, Method::Field);
    assert_eq!(s.progress, 0.5);
    assert_eq!(s.view, View::Morph);
    assert_eq!(s.edge, EdgeMode::Clamp);
    assert!(s.lines.is_empty() && s.missing.is_empty());
    assert_eq!(s.warp.field, FieldSettings::default());
    assert_eq!(Settings::defaults(WARP).view, View::WarpedA);
}

#[test]
fn ids_are_unique_and_hints_speak_to_compositors() {
    for kind in [MORPH, WARP] {
        let t = table(kind);
        for (i, p) in t.iter().enumerate() {
            assert!(
                t[i + 1..].iter().all(|q| q.id() != p.id()),
                "{} twice",
                p.id()
            );
            for stale in ["not yet", "seed", "CONTRACT", "§"] {
                assert!(
                    !p.label().contains(stale) && !p.hint().contains(stale),
                    "{}: {stale:?} in {:?} / {:?}",
                    p.id(),
                    p.label(),
                    p.hint()
                );
            }
        }
    }
}
