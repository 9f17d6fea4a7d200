use serde_json::Value;

use super::edit::Document;
use crate::features::{Feature, FeatureKind, Side};
use crate::geom::Vec2;
use crate::testing::changed_numbers;

const STATIC: &str = r#"{
  "format": "morphfx-scene", "version": 1, "method": "field",
  "field": { "a": 0.001, "b": 2.0, "p": 0.5 },
  "features": [
    { "name": "nose", "type": "line", "a": [[410.1, 300], [412, 220]], "b": [[400, 310.7], [405, 215]] },
    { "name": "lip", "type": "curve", "a": [[300, 200], [340, 180], [380, 200]], "b": [[300, 210], [340, 190], [380, 210]] }
  ],
  "progress": [[1001, 0.0], [1024, 1.0]],
  "my_tool": { "zeta": 1, "alpha": 0.1 }
}"#;

const KEYED: &str = r#"{"keyframes": [
  {"frame": 10, "features": [{"name": "eye", "type": "polyline", "a": [[0,0],[10,0],[10,10]], "b": [[0,0],[10,0],[10,10]],
     "track": {"a": {"confidence": [1, 1, 1], "lost": [false, false, false]}}}]},
  {"frame": 20, "features": [{"name": "eye", "type": "polyline", "a": [[10,0],[20,0],[20,10]], "b": [[0,0],[10,0],[10,10]]}]}
]}"#;

#[test]
fn moving_one_point_changes_exactly_that_number_pair_and_keeps_key_order() {
    let mut d = Document::parse(STATIC).unwrap();
    d.set_point(5.0, 1, Side::B, 1, Vec2::new(345.25, 187.0))
        .unwrap();
    let text = d.text();
    assert_eq!(
        changed_numbers(STATIC, &text),
        [
            (".features[1].b[1][0]".into(), 340.0, 345.25),
            (".features[1].b[1][1]".into(), 190.0, 187.0)
        ]
    );
    // Keys keep the user's order (my_tool's zeta before alpha), and the
    // text reads: one point per line, not one number.
    assert!(text.find("zeta").unwrap() < text.find("alpha").unwrap());
    assert!(
        text.contains(r#""a": [[410.1, 300], [412, 220]]"#),
        "{text}"
    );
    assert_eq!(d.scene().features[1].b[1], Vec2::new(345.25, 187.0));
}

#[test]
fn an_edit_at_a_frame_between_keys_makes_a_key_there_from_the_interpolated_shape() {
    let mut d = Document::parse(KEYED).unwrap();
    d.set_point(15.0, 0, Side::A, 2, Vec2::new(30.0, 30.0))
        .unwrap();
    assert_eq!(d.keyed_frames(), [10.0, 15.0, 20.0]);
    let k = &d.scene().keyframes[1].features[0];
    assert_eq!(
        k.a,
        [
            Vec2::new(5.0, 0.0),
            Vec2::new(15.0, 0.0),
            Vec2::new(30.0, 30.0)
        ]
    );
    assert_eq!(k.b[2], Vec2::new(10.0, 10.0));
    // The keys around it are untouched; the new key keeps the name and
    // drops the tracker's flags (they were about frame 10's points).
    assert_eq!(
        d.scene().keyframes[0].features[0].a[2],
        Vec2::new(10.0, 10.0)
    );
    let v: Value = serde_json::from_str(&d.text()).unwrap();
    assert_eq!(v["keyframes"][1]["features"][0]["name"], "eye");
    assert!(v["keyframes"][1]["features"][0].get("track").is_none());
    assert!(v["keyframes"][0]["features"][0].get("track").is_some());
    // An edit at an existing key edits that key.
    d.set_point(20.0, 0, Side::B, 0, Vec2::new(1.0, 1.0))
        .unwrap();
    assert_eq!(d.keyed_frames(), [10.0, 15.0, 20.0]);
    assert_eq!(d.scene().keyframes[2].features[0].b[0], Vec2::new(1.0, 1.0));
}

#[test]
fn key_here_turns_a_static_scene_into_one_key_and_nothing_moves() {
    let mut d = Document::parse(STATIC).unwrap();
    let before = d.scene().features.clone();
    d.key_here(1012.0).unwrap();
    assert_eq!(d.keyed_frames(), [1012.0]);
    assert_eq!(d.scene().features_at(0.0), before);
    assert_eq!(d.scene().features_at(2000.0), before);
    let v: Value = serde_json::from_str(&d.text()).unwrap();
    assert!(v.get("features").is_none());
}

#[test]
fn shapes_are_added_drawn_point_by_point_closed_and_deleted() {
    let mut d = Document::parse("").unwrap();
    let p = |x, y| Vec2::new(x, y);
    let first = Feature::new(
        FeatureKind::Polyline,
        vec![p(0.0, 0.0), p(10.0, 0.0)],
        vec![p(0.0, 0.0), p(10.0, 0.0)],
    );
    assert_eq!(d.add_feature(&first).unwrap(), 0);
    d.append_point(0, p(10.0, 10.0)).unwrap();
    d.set_closed(0, true).unwrap();
    let f = &d.scene().features[0];
    assert!(f.closed);
    assert_eq!(f.a.len(), 3);
    assert_eq!(f.b[2], p(10.0, 10.0));
    let dot = Feature::point(p(50.0, 50.0), p(50.0, 50.0));
    assert_eq!(d.add_feature(&dot).unwrap(), 1);
    // A closed shape at its 3-point minimum goes whole with its point.
    assert!(d.delete_point(0, 1).unwrap());
    assert_eq!(d.scene().features.len(), 1);
    assert_eq!(d.scene().features[0].kind, FeatureKind::Point);
    d.delete_feature(0).unwrap();
    assert!(d.scene().features.is_empty());
    // A new document's text is itself a valid scene.
    Document::parse(&d.text()).unwrap();
}

#[test]
fn inserting_a_point_keeps_every_keys_shape() {
    let mut d = Document::parse(KEYED).unwrap();
    d.insert_point(0, 0, 0.25).unwrap();
    let keys = &d.scene().keyframes;
    assert_eq!(keys[0].features[0].a[1], Vec2::new(2.5, 0.0));
    assert_eq!(keys[1].features[0].a[1], Vec2::new(12.5, 0.0));
    assert_eq!(keys[1].features[0].b[1], Vec2::new(2.5, 0.0));
    assert!(keys.iter().all(|k| k.features[0].a.len() == 4));
    // A curve's new point lies on the curve: the span's parameter there.
    let mut d = Document::parse(STATIC).unwrap();
    let before = d.scene().features[1].sampled(Side::A, 4);
    d.insert_point(1, 1, 0.5).unwrap();
    assert_eq!(d.scene().features[1].a[2], before[6]);
}

#[test]
fn an_edit_that_breaks_the_scene_is_refused_and_leaves_the_document() {
    let mut d = Document::parse(STATIC).unwrap();
    let text = d.text();
    // Nose's end onto its start: a zero-length line.
    let err = d
        .set_point(0.0, 0, Side::A, 1, Vec2::new(410.1, 300.0))
        .unwrap_err();
    assert!(err.to_string().contains("zero length"), "{err}");
    assert_eq!(d.text(), text);
    assert!(Document::parse("{ not json").is_err());
    assert!(d.set_point(0.0, 7, Side::A, 0, Vec2::ZERO).is_err());
}

#[test]
fn many_keys_in_one_edit_key_a_static_scene_at_each_frame() {
    let mut d = Document::parse(STATIC).unwrap();
    let nose = |dx: f64| vec![Vec2::new(410.0 + dx, 300.0), Vec2::new(412.0 + dx, 220.0)];
    d.key_here(1001.0).unwrap();
    d.set_points(&[
        (1002.0, 0, Side::A, nose(1.0)),
        (1003.0, 0, Side::A, nose(2.0)),
    ])
    .unwrap();
    assert_eq!(d.keyed_frames(), [1001.0, 1002.0, 1003.0]);
    let s = d.scene();
    assert_eq!(s.keyframes[0].features[0].a[0], Vec2::new(410.1, 300.0));
    assert_eq!(s.keyframes[2].features[0].a, nose(2.0));
    // The other feature, not set, is held at every new key.
    assert_eq!(s.keyframes[2].features[1], s.keyframes[0].features[1]);
    // A point list of the wrong length is refused whole.
    assert!(d
        .set_points(&[(1004.0, 0, Side::A, vec![Vec2::ZERO])])
        .is_err());
    assert_eq!(d.keyed_frames(), [1001.0, 1002.0, 1003.0]);
}

#[test]
fn deleting_a_feature_keeps_transition_curves_on_theirs() {
    let text = r#"{"features": [
        {"type": "point", "a": [[1, 1]], "b": [[1, 1]]},
        {"type": "point", "a": [[5, 5]], "b": [[6, 6]]},
        {"type": "point", "a": [[9, 9]], "b": [[9, 8]]}],
      "transition": {"geometry": {"type": "curves", "curves": [
        {"feature": 2, "keys": [[0.5, 0.2]]}, {"feature": 1, "keys": [[0.5, 0.8]]}]}}}"#;
    let mut d = Document::parse(text).unwrap();
    // Feature 1 carries a curve: refused, nothing changes.
    let err = d.delete_feature(1).unwrap_err().to_string();
    assert!(err.contains("transition.geometry.curves[1]"), "{err}");
    assert_eq!(d.scene().features.len(), 3);
    // Feature 0 goes; the curves now name features 1 and 0, the same points.
    d.delete_feature(0).unwrap();
    let v: Value = serde_json::from_str(&d.text()).unwrap();
    let curves = &v["transition"]["geometry"]["curves"];
    assert_eq!(
        (curves[0]["feature"].as_u64(), curves[1]["feature"].as_u64()),
        (Some(1), Some(0))
    );
}

/// After every kind of edit, the scene a document holds is the scene its
/// text reads as: a node hands the edited scene on with the text it
/// writes, so nothing reads the text again.
#[test]
fn a_documents_scene_is_what_its_text_reads_as_after_every_edit() {
    let same = |d: &Document| {
        let read = super::Scene::read(&d.text()).expect("the text reads");
        assert_eq!(*d.scene(), read);
    };
    for text in [STATIC, KEYED, ""] {
        let mut d = Document::parse(text).unwrap();
        same(&d);
        let f = d
            .add_feature(&Feature::point(Vec2::new(1.5, 2.0), Vec2::new(3.0, 4.25)))
            .unwrap();
        same(&d);
        d.set_point(15.0, f, Side::B, 0, Vec2::new(7.125, 8.0))
            .unwrap();
        same(&d);
        let from = [Vec2::new(1.5, 2.0)];
        d.move_feature(15.0, f, Side::A, &from, Vec2::new(0.5, -1.0))
            .unwrap();
        same(&d);
        d.key_here(12.0).unwrap();
        same(&d);
        d.delete_feature(f).unwrap();
        same(&d);
    }
}

/// A suggestion's confidence stays through edits of other features and
/// goes when the artist moves one of its points; out of [0, 1] it is
/// refused.
#[test]
fn a_suggestions_confidence_goes_when_the_artist_moves_it() {
    let text = r#"{"format": "morphfx-scene", "version": 1, "features": [
        {"type": "point", "a": [[1, 2]], "b": [[3, 4]], "confidence": 0.9},
        {"type": "point", "a": [[5, 6]], "b": [[7, 8]], "confidence": 0.6}]}"#;
    let mut d = Document::parse(text).unwrap();
    d.set_point(0.0, 1, Side::B, 0, Vec2::new(7.5, 8.0))
        .unwrap();
    let v: Value = serde_json::from_str(&d.text()).unwrap();
    assert_eq!(v["features"][0]["confidence"], 0.9);
    assert!(v["features"][1].get("confidence").is_none());
    let from = [Vec2::new(1.0, 2.0)];
    d.move_feature(0.0, 0, Side::A, &from, Vec2::new(1.0, 0.0))
        .unwrap();
    let v: Value = serde_json::from_str(&d.text()).unwrap();
    assert!(v["features"][0].get("confidence").is_none());
    let wrong = text.replace("0.9", "1.5");
    let e = Document::parse(&wrong).unwrap_err().to_string();
    assert!(e.contains("confidence 1.5 must be between 0 and 1"), "{e}");
}

/// Between two keys a suggestion is as sure as its less sure end, and a
/// key made between them keeps that; a key the artist made has none.
#[test]
fn confidence_between_keys_is_the_less_sure_ends() {
    let text = r#"{"keyframes": [
      {"frame": 0, "features": [{"type": "point", "a": [[0, 0]], "b": [[1, 1]], "confidence": 0.9}]},
      {"frame": 10, "features": [{"type": "point", "a": [[10, 0]], "b": [[11, 1]], "confidence": 0.6}]},
      {"frame": 20, "features": [{"type": "point", "a": [[20, 0]], "b": [[21, 1]]}]}]}"#;
    let mut d = Document::parse(text).unwrap();
    let at = |d: &Document, t: f64| d.scene().features_at(t)[0].confidence;
    assert_eq!(at(&d, 5.0), Some(0.6));
    assert_eq!(at(&d, 15.0), None);
    d.key_here(5.0).unwrap();
    let v: Value = serde_json::from_str(&d.text()).unwrap();
    let key = v["keyframes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|k| k["frame"] == 5)
        .unwrap();
    assert_eq!(key["features"][0]["confidence"], 0.6);
}
