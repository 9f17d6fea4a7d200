//! The mesh edited as a grid tool edits it, checked against positions
//! worked out by hand.

use super::edit::Document;
use crate::features::Side;
use crate::geom::{RectD, Vec2};
use crate::testing::changed_numbers;
use crate::warp::mesh::Node;

/// A 3 × 3 mesh over `[0, 200]²`, B's middle node moved, listed top row
/// first, with one line feature and a two-pass setting.
const GRID: &str = r#"{
  "format": "morphfx-scene", "version": 1, "method": "mesh",
  "features": [
    { "type": "line", "a": [[10, 10], [50, 50]], "b": [[12, 10], [52, 50]] }
  ],
  "mesh": { "rows": 3, "cols": 3, "pass": "one-pass",
    "a": [[0, 200], [100, 200], [200, 200], [0, 100], [100, 100], [200, 100], [0, 0], [100, 0], [200, 0]],
    "b": [[0, 200], [100, 200], [200, 200], [0, 100], [110, 95], [200, 100], [0, 0], [100, 0], [200, 0]]
  }
}"#;

const MIDDLE: Node = Node { row: 1, col: 1 };

fn doc() -> Document {
    Document::parse(GRID).unwrap()
}

/// An even grid: method mesh, A = B, nodes evenly over the region bottom
/// row first; the features and the pass stay.
#[test]
fn a_new_grid_is_even_over_the_region_and_keeps_the_features() {
    let mut d = Document::parse(
        r#"{"format": "morphfx-scene", "version": 1, "method": "field",
            "features": [{ "type": "point", "a": [[5, 5]], "b": [[6, 6]] }]}"#,
    )
    .unwrap();
    d.make_grid(3, 4, RectD::new(0.0, 0.0, 300.0, 100.0))
        .unwrap();
    let pair = d.scene().mesh_at(0.0).unwrap();
    assert_eq!((pair.a.rows(), pair.a.cols()), (3, 4));
    assert_eq!(pair.a, pair.b);
    assert_eq!(pair.a.node(0, 0), Vec2::new(0.0, 0.0));
    assert_eq!(pair.a.node(1, 2), Vec2::new(200.0, 50.0));
    assert_eq!(pair.a.node(2, 3), Vec2::new(300.0, 100.0));
    assert_eq!(d.scene().features_at(0.0).len(), 1);
    assert!(d.text().contains("\"method\": \"mesh\""));
    let mut again = doc();
    again
        .make_grid(2, 2, RectD::new(0.0, 0.0, 50.0, 50.0))
        .unwrap();
    assert!(again.text().contains("one-pass"), "{}", again.text());
}

/// A drag of B's middle node: only its two numbers change (the list stays
/// top row first), all of the motion is made.
#[test]
fn a_node_drag_changes_only_its_numbers() {
    let mut d = doc();
    let share = d
        .drag_nodes(0.0, Side::B, &[MIDDLE], Vec2::new(-20.0, 15.0))
        .unwrap();
    assert_eq!(share, 1.0);
    let changed = changed_numbers(GRID, &d.text());
    let paths: Vec<&str> = changed.iter().map(|c| c.0.as_str()).collect();
    assert_eq!(paths, [".mesh.b[4][0]", ".mesh.b[4][1]"]);
    assert_eq!(
        d.scene().mesh_at(0.0).unwrap().b.node(1, 1),
        Vec2::new(90.0, 110.0)
    );
}

/// The fold guard: dragging A's middle node 150 px right would carry it
/// past the right column at x = 200 (its row would run back left, and
/// the cells beside it turn inside out); it stops there, at two thirds of
/// the drag, within a hundredth of a pixel.
#[test]
fn a_drag_across_a_neighbour_stops_before_the_fold() {
    let mut d = doc();
    let share = d
        .drag_nodes(0.0, Side::A, &[MIDDLE], Vec2::new(150.0, 0.0))
        .unwrap();
    assert!((share - 100.0 / 150.0).abs() < 1e-4, "{share}");
    let x = d.scene().mesh_at(0.0).unwrap().a.node(1, 1).x;
    assert!(x < 200.0 && x > 199.99, "{x}");
}

/// A group moved together: a whole interior row and column of a 4 × 4.
/// Border nodes move on both sides, so the border stays frozen.
#[test]
fn groups_move_together_and_a_border_node_moves_on_both_sides() {
    let mut d = doc();
    d.make_grid(4, 4, RectD::new(0.0, 0.0, 300.0, 300.0))
        .unwrap();
    let group = [Node { row: 1, col: 1 }, Node { row: 1, col: 2 }];
    let share = d
        .drag_nodes(0.0, Side::B, &group, Vec2::new(0.0, 30.0))
        .unwrap();
    assert_eq!(share, 1.0);
    let pair = d.scene().mesh_at(0.0).unwrap();
    assert_eq!(pair.b.node(1, 1), Vec2::new(100.0, 130.0));
    assert_eq!(pair.b.node(1, 2), Vec2::new(200.0, 130.0));
    assert_eq!(pair.a.node(1, 1), Vec2::new(100.0, 100.0));
    let edge = [Node { row: 0, col: 1 }];
    d.drag_nodes(0.0, Side::A, &edge, Vec2::new(10.0, 0.0))
        .unwrap();
    let pair = d.scene().mesh_at(0.0).unwrap();
    assert_eq!(pair.a.node(0, 1), Vec2::new(110.0, 0.0));
    assert_eq!(pair.b.node(0, 1), Vec2::new(110.0, 0.0));
}

/// Reset puts the chosen nodes of one side where the other side has them.
#[test]
fn reset_puts_nodes_where_the_other_side_has_them() {
    let mut d = doc();
    d.reset_nodes(0.0, Side::B, &[MIDDLE]).unwrap();
    let pair = d.scene().mesh_at(0.0).unwrap();
    assert_eq!(pair.b.node(1, 1), Vec2::new(100.0, 100.0));
    let changed = changed_numbers(GRID, &d.text());
    assert_eq!(changed.len(), 2, "{changed:?}");
}

/// Keys: Key Shapes Here keys the mesh; a drag at another frame adds its
/// key there, in frame order, and frames between interpolate.
#[test]
fn keys_are_made_where_the_mesh_is_edited() {
    let mut d = doc();
    d.key_here(10.0).unwrap();
    assert!(d.text().contains("\"keyframes\""), "{}", d.text());
    d.drag_nodes(20.0, Side::B, &[MIDDLE], Vec2::new(10.0, 0.0))
        .unwrap();
    d.drag_nodes(5.0, Side::B, &[MIDDLE], Vec2::new(-10.0, 0.0))
        .unwrap();
    let x = |frame: f64| d.scene().mesh_at(frame).unwrap().b.node(1, 1).x;
    assert_eq!((x(5.0), x(10.0), x(20.0)), (100.0, 110.0, 120.0));
    assert_eq!(x(15.0), 115.0);
    let frames: Vec<f64> = d.scene().meshes.iter().map(|(f, _)| *f).collect();
    assert_eq!(frames, [5.0, 10.0, 20.0]);
}

/// A column added through a point of B lands in every key, through that
/// point on B, where each key's surfaces pass; taken out again, every key
/// is as it was. A border column stays.
#[test]
fn a_column_added_lands_in_every_key_and_comes_out_again() {
    use crate::warp::mesh::Line;
    let mut d = doc();
    d.key_here(0.0).unwrap();
    d.drag_nodes(10.0, Side::B, &[MIDDLE], Vec2::new(0.0, 10.0))
        .unwrap();
    let before = d.scene().meshes.clone();
    let through = Vec2::new(60.0, 120.0);
    d.add_grid_line(10.0, Side::B, through, Line::Column)
        .unwrap();
    let keys = &d.scene().meshes;
    assert_eq!(keys.len(), 2);
    for (_, pair) in keys {
        assert_eq!((pair.a.rows(), pair.a.cols()), (3, 4));
    }
    // On B at frame 10 the new column passes through the point.
    let b10 = &keys[1].1.b;
    let column: Vec<Vec2> = (0..3).map(|r| b10.node(r, 1)).collect();
    let (s, _) = keys[1].1.locate(Side::B, through).unwrap();
    assert!(
        (s - 1.0).abs() < 1e-4,
        "the point is on the new column: {s}"
    );
    assert_eq!(column[0], Vec2::new(column[0].x, 0.0));
    d.remove_grid_line(Line::Column, 1).unwrap();
    assert_eq!(d.scene().meshes, before);
    assert!(d.remove_grid_line(Line::Column, 0).is_err());
}
