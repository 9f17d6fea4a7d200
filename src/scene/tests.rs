use super::*;
use crate::make_warp::Method;
use crate::Error;

const GOOD: &str = r#"{
  "format": "morphfx-scene", "version": 1, "method": "field",
  "field": { "a": 0.001, "b": 2.0, "p": 0.5, "interpolation": "endpoints" },
  "features": [
    { "name": "nose",  "type": "line",     "a": [[410, 300], [412, 220]], "b": [[400, 310], [405, 215]] },
    { "name": "pupil", "type": "point",    "a": [[350, 380]],             "b": [[344, 390]] },
    { "name": "jaw",   "type": "polyline", "a": [[300, 200], [380, 120], [460, 200]], "b": [[290, 210], [385, 110], [470, 205]] },
    { "name": "brow",  "type": "curve",    "a": [[320, 420], [350, 440], [380, 430]], "b": [[315, 425], [350, 450], [385, 432]] }
  ],
  "progress": [[1001, 0.0], [1024, 1.0]]
}"#;

fn err(text: &str) -> (String, String) {
    match Scene::parse(text) {
        Err(Error::Scene { at, message }) => (at, message),
        other => panic!("expected a scene error, got {other:?}"),
    }
}

/// `text` is refused at a place starting with `at`, with a message holding `message`.
fn assert_refused(text: &str, at: &str, message: &str) {
    let (got_at, got_message) = err(text);
    assert!(
        got_at.starts_with(at),
        "{text}: at = {got_at:?}, wanted {at:?}"
    );
    assert!(
        got_message.contains(message),
        "{text}: message = {got_message:?}, wanted {message:?}"
    );
}

#[test]
fn parses_the_contract_example() {
    let s = Scene::parse(GOOD).unwrap();
    assert_eq!(s.settings.method, Method::Field);
    assert_eq!(s.features.len(), 4);
    assert_eq!(s.features[2].a.len(), 3);
    assert_eq!(s.features[0].name.as_deref(), Some("nose"));
    assert_eq!(s.progress_at(1001.0), Some(0.0));
    assert_eq!(s.progress_at(900.0), Some(0.0));
    assert_eq!(s.progress_at(2000.0), Some(1.0));
    assert!((s.progress_at(1012.5).unwrap() - 0.5).abs() < 1e-12);
}

#[test]
fn keyframes_interpolate_linearly_and_hold_outside() {
    let s = Scene::parse(
        r#"{"keyframes": [
            {"frame": 10, "features": [{"type": "line", "a": [[0,0],[10,0]], "b": [[0,0],[0,10]]}]},
            {"frame": 20, "features": [{"type": "line", "a": [[10,0],[20,0]], "b": [[4,0],[0,30]]}]}
        ]}"#,
    )
    .unwrap();
    let f = &s.features_at(12.5)[0];
    assert_eq!(f.a[0], crate::Vec2::new(2.5, 0.0));
    assert_eq!(f.b[1], crate::Vec2::new(0.0, 15.0));
    assert_eq!(s.features_at(0.0)[0].a[0], crate::Vec2::new(0.0, 0.0));
    assert_eq!(s.features_at(99.0)[0].a[1], crate::Vec2::new(20.0, 0.0));
}

#[test]
fn refuses_each_kind_of_bad_scene_naming_the_culprit() {
    let cases: &[(&str, &str, &str)] = &[
        (
            r#"{"features": [{"name": "eye", "type": "blob", "a": [[0,0]], "b": [[0,0]]}]}"#,
            "features[0] \"eye\"",
            "unknown type",
        ),
        (
            r#"{"features": [{"type": "line", "a": [[0,0],[1,1]], "b": [[0,0]]}]}"#,
            "features[0]",
            "a has 2 points but b has 1",
        ),
        (
            r#"{"features": [{"type": "line", "a": [[0,0],[1,1],[2,2]], "b": [[0,0],[1,1],[2,2]]}]}"#,
            "features[0]",
            "exactly 2",
        ),
        (
            r#"{"features": [{"type": "line", "a": [[5,5],[5,5]], "b": [[0,0],[1,1]]}]}"#,
            "features[0]",
            "zero length",
        ),
        (
            r#"{"features": [{"type": "point", "a": [[1e999, 0]], "b": [[0,0]]}]}"#,
            "line 1",
            "",
        ),
        (
            r#"{"method": "warpy", "features": []}"#,
            "method",
            "unknown method",
        ),
        (
            r#"{"features": []}"#,
            "features",
            "needs at least one feature",
        ),
        (r#"{"format": "other"}"#, "format", "expected"),
        (
            r#"{"field": {"a": 0}, "features": [{"type": "point", "a": [[0,0]], "b": [[1,1]]}]}"#,
            "field.a",
            "must be > 0",
        ),
        (
            r#"{"progress": [[1, 1.5]], "features": [{"type": "point", "a": [[0,0]], "b": [[1,1]]}]}"#,
            "progress[0]",
            "outside [0, 1]",
        ),
        (
            r#"{"keyframes": [
                {"frame": 1, "features": [{"name": "n", "type": "line", "a": [[0,0],[1,0]], "b": [[0,0],[1,0]]}]},
                {"frame": 5, "features": [{"name": "n", "type": "point", "a": [[0,0]], "b": [[0,0]]}]}]}"#,
            "keyframes[1] (frame 5) features[0] \"n\"",
            "every keyframe must hold the same features",
        ),
        (
            r#"{"keyframes": [
                {"frame": 1, "features": [{"type": "point", "a": [[0,0]], "b": [[0,0]]}]},
                {"frame": 5, "features": []}]}"#,
            "keyframes[1] (frame 5)",
            "has 0 features",
        ),
        (
            r#"{"keyframes": [
                {"frame": 1, "features": [{"type": "point", "a": [[0,0]], "b": [[0,0]]}]},
                {"frame": 1, "features": [{"type": "point", "a": [[0,0]], "b": [[0,0]]}]}]}"#,
            "keyframes",
            "keyed twice",
        ),
    ];
    for (text, at, message) in cases {
        assert_refused(text, at, message);
    }
}

#[test]
fn keys_of_other_tools_are_kept() {
    let text = r#"{"method": "field", "features": [{"type": "point", "a": [[1, 2]], "b": [[3, 4]]}], "x-studio": {"shot": 12}}"#;
    let s = Scene::parse(text).unwrap();
    assert!(s.extra.contains_key("x-studio"));
}

const TWO_FEATURES: &str = r#""features": [
    {"name": "nose", "type": "line", "a": [[10, 10], [20, 20]], "b": [[12, 10], [22, 20]]},
    {"type": "point", "a": [[40, 40]], "b": [[44, 41]]}]"#;

#[test]
fn scattered_method_and_transition_settings_are_read() {
    use crate::transition::{Attach, Pattern, Propagation, Transition};
    let text = format!(
        r#"{{"method": "hybrid", {TWO_FEATURES},
        "thin-plate": {{"alpha": 40, "beta": 0.001, "cell": 8}},
        "mffd": {{"coarsest": 3, "alpha": 0.25, "tolerance": 0.02}},
        "hybrid": {{"cell": 32}},
        "transition": {{
            "geometry": {{"type": "curves", "curves": [
                {{"feature": "nose", "keys": [[0.5, 0.9]]}},
                {{"feature": 1, "keys": [[0.2, 0.0], [0.8, 0.1]]}},
                {{"at": [100, 50], "keys": []}}], "threshold": 0.01}},
            "colour": {{"type": "procedural", "pattern": "radial", "spread": 0.4, "centre": [5, 6]}}}}}}"#
    );
    let s = Scene::parse(&text).unwrap();
    assert_eq!(s.settings.method, Method::Hybrid);
    assert_eq!(
        (
            s.settings.thin_plate.alpha,
            s.settings.thin_plate.beta,
            s.settings.thin_plate.cell
        ),
        (40.0, 0.001, 8.0)
    );
    assert_eq!(
        (
            s.settings.mffd.coarsest,
            s.settings.mffd.alpha,
            s.settings.mffd.tolerance
        ),
        (3, 0.25, 0.02)
    );
    assert_eq!(s.settings.hybrid.cell, 32.0);
    let Transition::Curves {
        curves,
        propagation,
    } = &s.settings.transition.geometry
    else {
        panic!("{:?}", s.settings.transition.geometry)
    };
    assert_eq!(curves[0].attach, Attach::Name("nose".into()));
    assert_eq!(curves[1].attach, Attach::Index(1));
    assert_eq!(curves[2].attach, Attach::At(crate::Vec2::new(100.0, 50.0)));
    assert!((curves[0].curve.at(0.5) - 0.9).abs() < 1e-12);
    assert!((curves[0].curve.at(0.75) - 0.95).abs() < 1e-12);
    assert_eq!(curves[2].curve.at(0.3), 0.3, "no keys: the uniform rate");
    assert!(matches!(propagation, Propagation::BSpline(m) if m.threshold == 0.01));
    let Some(Transition::Procedural(p)) = &s.settings.transition.colour else {
        panic!("{:?}", s.settings.transition.colour)
    };
    assert_eq!(p.spread, 0.4);
    assert_eq!(
        p.pattern,
        Pattern::Radial {
            cycles: 0.0,
            centre: Some(crate::Vec2::new(5.0, 6.0))
        }
    );
    assert!(!s.extra.contains_key("transition"));
}

#[test]
fn bad_scattered_and_transition_settings_are_refused() {
    let scene = |extra: &str| format!(r#"{{"method": "mffd", {TWO_FEATURES}, {extra}}}"#);
    let cases = [
        (
            r#""thin-plate": {"alpha": 0}"#,
            "thin-plate.alpha",
            "greater than 0",
        ),
        (
            r#""thin-plate": {"beta": -1}"#,
            "thin-plate.beta",
            "out of range",
        ),
        (
            r#""thin-plate": {"stiffness": 1}"#,
            "thin-plate",
            "unknown field",
        ),
        (r#""mffd": {"alpha": 2}"#, "mffd.alpha", "out of range"),
        (r#""mffd": {"finest": 0}"#, "mffd.finest", "out of range"),
        (r#""hybrid": {"cell": 1}"#, "hybrid.cell", "out of range"),
        (
            r#""transition": {"geometry": {"type": "wipe"}}"#,
            "transition.geometry.type",
            "unknown transition type",
        ),
        (
            r#""transition": {"geometry": {"type": "curves"}}"#,
            "transition.geometry.curves",
            "needs a list",
        ),
        (
            r#""transition": {"geometry": {"type": "curves", "curves": [{"feature": "ear", "keys": []}]}}"#,
            "transition.geometry.curves[0].feature",
            "no feature is named \"ear\"",
        ),
        (
            r#""transition": {"geometry": {"type": "curves", "curves": [{"feature": 2, "keys": []}]}}"#,
            "transition.geometry.curves[0].feature",
            "not the index",
        ),
        (
            r#""transition": {"geometry": {"type": "curves", "curves": [{"keys": []}]}}"#,
            "transition.geometry.curves[0]",
            "attach the curve",
        ),
        (
            r#""transition": {"geometry": {"type": "curves", "curves": [{"at": [1, 2], "keys": [[0.5, 1.2]]}]}}"#,
            "transition.geometry.curves[0].keys[0]",
            "in [0, 1]",
        ),
        (
            r#""transition": {"geometry": {"type": "curves", "curves": [{"at": [1, 2], "keys": [[0.6, 0.5], [0.4, 0.6]]}]}}"#,
            "transition.geometry.curves[0].keys[1]",
            "does not come after",
        ),
        (
            r#""transition": {"geometry": {"type": "curves", "curves": [{"at": [1, 2], "keys": [[0, 0.3]]}]}}"#,
            "transition.geometry.curves[0].keys[0]",
            "rate 0 at t = 0",
        ),
        (
            r#""transition": {"geometry": {"type": "curves", "curves": [], "surface": "soap"}}"#,
            "transition.geometry.surface",
            "unknown surface",
        ),
        (
            r#""transition": {"colour": {"type": "procedural", "pattern": "spiral"}}"#,
            "transition.colour.pattern",
            "unknown pattern",
        ),
        (
            r#""transition": {"colour": {"type": "procedural", "spread": 1}}"#,
            "transition.colour.spread",
            "out of range",
        ),
        (
            r#""transition": {"colour": {"type": "procedural", "centre": [1, 2]}}"#,
            "transition.colour.centre",
            "only the radial",
        ),
        (
            r#""transition": {"colour": {"type": "uniform", "spread": 0.5}}"#,
            "transition.colour.spread",
            "does not apply",
        ),
        (
            r#""transition": {"colour": {"type": "procedural", "curves": []}}"#,
            "transition.colour.curves",
            "does not apply",
        ),
    ];
    for (extra, at, message) in cases {
        assert_refused(&scene(extra), at, message);
    }
}

#[test]
fn auto_settings_are_read_and_checked() {
    let s = Scene::parse(
        r#"{"method": "auto", "auto": {"levels": 4, "colour": 2, "stretch": 0, "angle": 0.5, "anchors": 30,
            "warm_start": false, "initial": [[0,0],[50,0],[100,0],[0,50],[60,45],[100,50],[0,100],[50,100],[100,100]]}}"#,
    )
    .unwrap();
    assert_eq!(s.settings.method, Method::Auto);
    let a = &s.settings.auto;
    assert_eq!(a.levels, Some(4));
    assert_eq!(
        (
            a.coefficients.colour,
            a.coefficients.stretch,
            a.coefficients.angle,
            a.coefficients.anchor
        ),
        (2.0, 0.0, 0.5, 30.0)
    );
    assert!(!a.warm_start);
    assert_eq!(
        a.initial.as_ref().map(|p| p[4]),
        Some(crate::geom::Vec2::new(60.0, 45.0))
    );
    // No features needed: auto finds its own correspondence.
    assert!(Scene::parse(r#"{"method": "auto"}"#).is_ok());
    let cases = [
        (
            r#"{"method": "auto", "auto": {"levels": 0}}"#,
            "auto.levels",
            "out of range",
        ),
        (
            r#"{"method": "auto", "auto": {"stretch": -1}}"#,
            "auto.stretch",
            "out of range",
        ),
        (
            r#"{"method": "auto", "auto": {"warm_iterations": 50}}"#,
            "auto.warm_iterations",
            "out of range",
        ),
        (
            r#"{"method": "auto", "auto": {"initial": [[0,0],[1,0]]}}"#,
            "auto.initial",
            "(2^i + 1)",
        ),
        (
            r#"{"method": "auto", "auto": {"initial": [[0,0],[50,0],[100,0],[0,50],[150,45],[100,50],[0,100],[50,100],[100,100]]}}"#,
            "auto.initial",
            "not convex",
        ),
        (
            r#"{"method": "auto", "auto": {"speed": 3}}"#,
            "line",
            "unknown field",
        ),
    ];
    for (text, at, message) in cases {
        assert_refused(text, at, message);
    }
}

/// A 3 × 3 mesh over 0..20 whose centre node moves from (10, 10) to `centre`.
fn mesh_json(centre: [f64; 2]) -> String {
    let a = "[[0,0],[10,0],[20,0],[0,10],[10,10],[20,10],[0,20],[10,20],[20,20]]";
    let b = format!(
        "[[0,0],[10,0],[20,0],[0,10],[{},{}],[20,10],[0,20],[10,20],[20,20]]",
        centre[0], centre[1]
    );
    format!(r#""rows": 3, "cols": 3, "a": {a}, "b": {b}"#)
}

#[test]
fn mesh_scenes_parse_with_pass_and_keyframes() {
    let s = Scene::parse(&format!(
        r#"{{"method": "mesh", "mesh": {{ {}, "pass": "one-pass" }} }}"#,
        mesh_json([12.0, 9.0])
    ))
    .unwrap();
    assert_eq!(s.settings.method, Method::Mesh);
    assert_eq!(s.settings.mesh.pass, crate::warp::mesh::Pass::OnePass);
    let pair = s.mesh_at(5.0).unwrap();
    assert_eq!(pair.b.node(1, 1), crate::Vec2::new(12.0, 9.0));

    let a = "[[0,0],[10,0],[20,0],[0,10],[10,10],[20,10],[0,20],[10,20],[20,20]]";
    let keyed = Scene::parse(&format!(
        r#"{{"method": "mesh", "mesh": {{"rows": 3, "cols": 3, "keyframes": [
            {{"frame": 10, "a": {a}, "b": {a}}},
            {{"frame": 20, "a": {a}, "b": [[0,0],[10,0],[20,0],[0,10],[14,12],[20,10],[0,20],[10,20],[20,20]]}}
        ]}}}}"#
    ))
    .unwrap();
    assert_eq!(
        keyed.mesh_at(15.0).unwrap().b.node(1, 1),
        crate::Vec2::new(12.0, 11.0)
    );
    assert_eq!(
        keyed.mesh_at(0.0).unwrap().b.node(1, 1),
        crate::Vec2::new(10.0, 10.0)
    );
}

#[test]
fn bad_meshes_name_the_mesh_and_the_place() {
    // Method mesh without a mesh.
    let (at, msg) = err(r#"{"method": "mesh"}"#);
    assert_eq!(at, "mesh");
    assert!(msg.contains("needs a mesh"), "{msg}");
    // The centre node dragged across its right neighbour column.
    let (at, msg) = err(&format!(
        r#"{{"method": "mesh", "mesh": {{ {} }} }}"#,
        mesh_json([25.0, 10.0])
    ));
    assert_eq!(at, "mesh");
    assert!(msg.contains("mesh b") && msg.contains("row 1"), "{msg}");
    // Wrong node count, with the side named.
    let (at, msg) = err(
        r#"{"method": "mesh", "mesh": {"rows": 2, "cols": 2, "a": [[0,0],[1,0],[0,1]], "b": [[0,0],[1,0],[0,1],[1,1]]}}"#,
    );
    assert_eq!(at, "mesh.a");
    assert!(msg.contains("4 nodes, found 3"), "{msg}");
    // Unknown pass and unknown keys.
    let (at, _) = err(&format!(
        r#"{{"mesh": {{ {}, "pass": "three-pass" }} }}"#,
        mesh_json([10.0, 10.0])
    ));
    assert_eq!(at, "mesh.pass");
    let (at, msg) = err(&format!(
        r#"{{"mesh": {{ {}, "passes": 2 }} }}"#,
        mesh_json([10.0, 10.0])
    ));
    assert!(
        at.starts_with("line") && msg.contains("passes"),
        "{at}: {msg}"
    );
}

#[test]
fn closed_polylines_and_curves_parse_and_bad_ones_are_refused() {
    let one = |f: &str| format!(r#"{{"features": [{f}]}}"#);
    let s = Scene::parse(&one(
        r#"{"type": "curve", "closed": true, "a": [[0,0],[10,0],[5,8]], "b": [[0,0],[10,0],[5,9]]}"#,
    ))
    .unwrap();
    assert!(s.features[0].closed);
    // Old scenes, and "closed": false, read open.
    let s = Scene::parse(GOOD).unwrap();
    assert!(s.features.iter().all(|f| !f.closed));
    let s = Scene::parse(&one(
        r#"{"type": "line", "closed": false, "a": [[0,0],[1,0]], "b": [[0,0],[1,0]]}"#,
    ))
    .unwrap();
    assert!(!s.features[0].closed);
    assert_refused(
        &one(r#"{"type": "line", "closed": true, "a": [[0,0],[1,0]], "b": [[0,0],[1,0]]}"#),
        "features[0]",
        "a line cannot be closed",
    );
    assert_refused(
        &one(r#"{"type": "polyline", "closed": true, "a": [[0,0],[1,0]], "b": [[0,0],[1,0]]}"#),
        "features[0]",
        "a closed polyline needs at least 3 points",
    );
    assert_refused(
        &one(
            r#"{"type": "polyline", "closed": true, "a": [[0,0],[1,0],[1,1],[0,0]], "b": [[0,0],[1,0],[1,1],[0,1]]}"#,
        ),
        "features[0]",
        "a[3] repeats a[0]",
    );
    // Keyframes must agree on closure.
    assert_refused(
        r#"{"keyframes": [
            {"frame": 1, "features": [{"type": "polyline", "closed": true, "a": [[0,0],[1,0],[1,1]], "b": [[0,0],[1,0],[1,1]]}]},
            {"frame": 2, "features": [{"type": "polyline", "a": [[0,0],[1,0],[1,1]], "b": [[0,0],[1,0],[1,1]]}]}
        ]}"#,
        "keyframes[1]",
        "every keyframe must hold the same features",
    );
}
