//! The scene's mesh edited in place, as a grid tool in a viewer edits it:
//! an even grid made over a region, nodes dragged (one or a group) no
//! further than the grid stays unfolded, nodes put back where the other
//! side has them. Only the moved numbers change; a mesh listed top row
//! first stays so.

use serde_json::{Map, Value};

use super::{mesh_key_at, number, point_json, points_json, Document, Editor};
use crate::features::Side;
use crate::geom::{RectD, Vec2};
use crate::warp::mesh::{Line, Mesh, MeshPair, Node};
use crate::{Error, Result};

/// How finely a drag's path is walked for the first fold before the
/// fold's edge is found by halving.
const PATH_STEPS: usize = 16;

impl Document {
    /// An even `rows` × `cols` grid over `region` on both sides (A = B:
    /// nothing moves yet), and method `mesh`; the features stay, mesh keys
    /// and any earlier grid go (its `pass` stays).
    pub fn make_grid(&mut self, rows: usize, cols: usize, region: RectD) -> Result<()> {
        let grid = Mesh::regular(rows, cols, region.x1, region.y1, region.x2, region.y2)?;
        self.edit(|doc| {
            let mut mesh = match doc.root.remove("mesh") {
                Some(Value::Object(old)) => old,
                _ => Map::new(),
            };
            mesh.retain(|k, _| k == "pass");
            mesh.insert("rows".into(), Value::from(rows));
            mesh.insert("cols".into(), Value::from(cols));
            mesh.insert("a".into(), points_json(grid.nodes()));
            mesh.insert("b".into(), points_json(grid.nodes()));
            doc.root.insert("method".into(), Value::from("mesh"));
            doc.root.insert("mesh".into(), Value::Object(mesh));
            Ok(())
        })
    }

    /// Moves `nodes` of the mesh on `side` at `frame` by as much of `delta`
    /// as keeps every cell of both meshes unfolded, and returns that share
    /// of `delta` (1 when all of it; a drag edits the document as it was
    /// when the pen went down, afresh at each event). Border nodes move on both sides: a
    /// mesh's border stays the same on A and B (Wolberg). A keyed mesh is
    /// edited in its key at `frame`, made when there is none.
    pub fn drag_nodes(
        &mut self,
        frame: f64,
        side: Side,
        nodes: &[Node],
        delta: Vec2,
    ) -> Result<f64> {
        let pair = self
            .scene
            .mesh_at(frame)
            .ok_or_else(|| Error::scene("mesh", "the scene has no mesh to edit"))?;
        let moved = |share: f64| moved(&pair, side, nodes, delta * share);
        let unfolded = |share: f64| moved(share).is_ok_and(|p| MeshPair::new(p.a, p.b).is_ok());
        let share = last_unfolded(unfolded);
        let to = moved(share)?;
        self.edit(|doc| doc.set_mesh(frame, &to, nodes))?;
        Ok(share)
    }

    /// Puts `nodes` of the mesh on `side` at `frame` where the other side
    /// has them (border nodes are there already).
    pub fn reset_nodes(&mut self, frame: f64, side: Side, nodes: &[Node]) -> Result<()> {
        let pair = self
            .scene
            .mesh_at(frame)
            .ok_or_else(|| Error::scene("mesh", "the scene has no mesh to edit"))?;
        let (mut a, mut b) = (pair.a.clone(), pair.b.clone());
        let (to, from) = match side {
            Side::A => (&mut a, &pair.b),
            Side::B => (&mut b, &pair.a),
        };
        *to = to.map_nodes(|r, c, p| {
            let chosen = nodes.contains(&Node { row: r, col: c });
            if chosen {
                from.node(r, c)
            } else {
                p
            }
        });
        let to = MeshPair { a, b };
        self.edit(|doc| doc.set_mesh(frame, &to, nodes))
    }
}

impl Document {
    /// Sets the mesh on `side` at `frame` to `nodes` (row-major from the
    /// bottom row, as many as the mesh has): in a keyed mesh its key there,
    /// made when there is none; else the static mesh. What a tracker found.
    pub fn set_mesh_side(&mut self, frame: f64, side: Side, nodes: &[Vec2]) -> Result<()> {
        let mut pair = self
            .scene
            .mesh_at(frame)
            .ok_or_else(|| Error::scene("mesh", "the scene has no mesh to edit"))?;
        let (rows, cols) = (pair.a.rows(), pair.a.cols());
        let mesh = Mesh::new(rows, cols, nodes.to_vec())?;
        match side {
            Side::A => pair.a = mesh,
            Side::B => pair.b = mesh,
        }
        let all: Vec<Node> = (0..rows * cols)
            .map(|i| Node {
                row: i / cols,
                col: i % cols,
            })
            .collect();
        self.edit(|doc| doc.set_mesh(frame, &pair, &all))
    }

    /// A row (or column) added to the mesh through `through` on `side` at
    /// `frame`, in every key at the same place of the surfaces, so each
    /// key's mesh gains it where its own surfaces pass
    /// ([`MeshPair::with_line`]).
    pub fn add_grid_line(
        &mut self,
        frame: f64,
        side: Side,
        through: Vec2,
        line: Line,
    ) -> Result<()> {
        let pair = self
            .scene
            .mesh_at(frame)
            .ok_or_else(|| Error::scene("mesh", "the scene has no mesh to edit"))?;
        let (s, r) = pair.locate(side, through).ok_or_else(|| {
            Error::scene(
                "mesh",
                format!(
                    "({:.1}, {:.1}) is not on the mesh: a {} is added through a point inside it",
                    through.x,
                    through.y,
                    line.name()
                ),
            )
        })?;
        let at = match line {
            Line::Row => r,
            Line::Column => s,
        };
        self.reshape_mesh(|p| p.with_line(line, at))
    }

    /// Row (or column) `index` taken out of the mesh in every key.
    pub fn remove_grid_line(&mut self, line: Line, index: usize) -> Result<()> {
        self.reshape_mesh(|p| p.without_line(line, index))
    }

    /// Every key of the mesh (or the static one) replaced by `change` of it:
    /// its size and nodes rewritten, bottom row first; its other keys kept.
    fn reshape_mesh(&mut self, change: impl Fn(&MeshPair) -> Result<MeshPair>) -> Result<()> {
        let keyed = !self.mesh_keyed_frames().is_empty();
        let changed = self
            .scene
            .meshes
            .iter()
            .map(|(frame, pair)| Ok((*frame, change(pair)?)))
            .collect::<Result<Vec<_>>>()?;
        let Some((_, first)) = changed.first() else {
            return Err(Error::scene("mesh", "the scene has no mesh to edit"));
        };
        let (rows, cols) = (first.a.rows(), first.a.cols());
        self.edit(|doc| {
            let mesh = doc
                .root
                .get_mut("mesh")
                .and_then(Value::as_object_mut)
                .ok_or_else(|| Error::scene("mesh", "the scene has no mesh to edit"))?;
            mesh.insert("rows".into(), Value::from(rows));
            mesh.insert("cols".into(), Value::from(cols));
            let sides = |pair: &MeshPair, into: &mut Map<String, Value>| {
                into.insert("a".into(), points_json(pair.a.nodes()));
                into.insert("b".into(), points_json(pair.b.nodes()));
            };
            if keyed {
                let keys = changed
                    .iter()
                    .map(|(frame, pair)| {
                        let mut key = Map::new();
                        key.insert("frame".into(), number(*frame));
                        sides(pair, &mut key);
                        Value::Object(key)
                    })
                    .collect();
                mesh.insert("keyframes".into(), Value::Array(keys));
            } else {
                sides(&changed[0].1, mesh);
            }
            Ok(())
        })
    }

    /// The frames the mesh is keyed at, in order (none for a static mesh).
    pub fn mesh_keyed_frames(&self) -> Vec<f64> {
        let keys = self
            .root
            .get("mesh")
            .and_then(|m| m.get("keyframes"))
            .and_then(Value::as_array);
        keys.into_iter()
            .flatten()
            .filter_map(|k| k.get("frame").and_then(Value::as_f64))
            .collect()
    }
}

/// `pair` with `nodes` on `side` moved by `delta` (border nodes on both
/// sides); sizes only are checked.
fn moved(pair: &MeshPair, side: Side, nodes: &[Node], delta: Vec2) -> Result<MeshPair> {
    let (rows, cols) = (pair.a.rows(), pair.a.cols());
    if let Some(n) = nodes.iter().find(|n| n.row >= rows || n.col >= cols) {
        return Err(Error::scene(
            "mesh",
            format!(
                "node (row {}, col {}) is not in the {rows} × {cols} mesh",
                n.row, n.col
            ),
        ));
    }
    let border = |r: usize, c: usize| r == 0 || c == 0 || r + 1 == rows || c + 1 == cols;
    let shift = |on: Side| {
        move |r: usize, c: usize, p: Vec2| {
            let chosen = nodes.contains(&Node { row: r, col: c });
            if chosen && (on == side || border(r, c)) {
                p + delta
            } else {
                p
            }
        }
    };
    Ok(MeshPair {
        a: pair.a.map_nodes(shift(Side::A)),
        b: pair.b.map_nodes(shift(Side::B)),
    })
}

/// The largest share in `[0, 1]` of a drag's path up to which `unfolded`
/// holds all the way: the path walked in [`PATH_STEPS`] steps, then the
/// first step that folds halved down to a thousandth of a step.
fn last_unfolded(unfolded: impl Fn(f64) -> bool) -> f64 {
    let mut good = 0.0;
    for k in 1..=PATH_STEPS {
        let s = k as f64 / PATH_STEPS as f64;
        if !unfolded(s) {
            let mut bad = s;
            while bad - good > 1e-3 / PATH_STEPS as f64 {
                let mid = 0.5 * (good + bad);
                if unfolded(mid) {
                    good = mid;
                } else {
                    bad = mid;
                }
            }
            return good;
        }
        good = s;
    }
    1.0
}

impl Editor<'_> {
    /// Writes `nodes` of `pair` into the mesh at `frame`: into its key there
    /// (made from the pair when there is none) in a keyed mesh, else the
    /// static one. Border nodes are written on both sides.
    fn set_mesh(&mut self, frame: f64, pair: &MeshPair, nodes: &[Node]) -> Result<()> {
        let mesh = self
            .root
            .get_mut("mesh")
            .and_then(Value::as_object_mut)
            .ok_or_else(|| Error::scene("mesh", "the scene has no mesh to edit"))?;
        let target = match mesh.get_mut("keyframes").and_then(Value::as_array_mut) {
            Some(keys) if !keys.is_empty() => {
                let i = mesh_key_at(keys, frame, pair);
                keys[i]
                    .as_object_mut()
                    .ok_or_else(|| Error::scene(format!("mesh.keyframes[{i}]"), "not an object"))?
            }
            _ => mesh,
        };
        for (key, side) in [("a", &pair.a), ("b", &pair.b)] {
            let list = target
                .get_mut(key)
                .and_then(Value::as_array_mut)
                .ok_or_else(|| Error::scene(format!("mesh.{key}"), "not a list of nodes"))?;
            let top_first = is_top_first(list, side.cols());
            for n in nodes {
                let row = if top_first {
                    side.rows() - 1 - n.row
                } else {
                    n.row
                };
                let slot = list.get_mut(row * side.cols() + n.col).ok_or_else(|| {
                    Error::scene(format!("mesh.{key}"), "has fewer nodes than rows × cols")
                })?;
                *slot = point_json(side.node(n.row, n.col));
            }
        }
        Ok(())
    }
}

/// Whether a mesh's node list runs top row first (its second row lies
/// below its first, as an image is stored).
fn is_top_first(list: &[Value], cols: usize) -> bool {
    let y = |i: usize| list.get(i).and_then(|p| p.get(1)).and_then(Value::as_f64);
    matches!((y(0), y(cols)), (Some(first), Some(second)) if second < first)
}
