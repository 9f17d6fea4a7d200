//! A grid's nodes followed through frames, as a grid tracker carries a
//! mesh warp's grid: each interior node whose patch fixes both directions
//! (a corner, some texture) is tracked as a point; a node on flat ground
//! or on a straight edge, or one lost in this frame, moves as its
//! neighbours do (its displacement the average of theirs, solved over the
//! whole grid at once: a discrete Laplace equation), so it follows the
//! picture rather than noise. The border stays where it is: a mesh's
//! border is the same on both sides and frozen (Wolberg).

use crate::geom::Vec2;

use super::grey::Pyramid;
use super::linear::solve;
use super::point::PointTracker;
use super::template::TrackSettings;

/// A node is followed by its own patch when the smaller eigenvalue of the
/// patch's information is at least this share of the larger (as a line's
/// end is, `track::feature`).
const CORNER_RATIO: f64 = 0.1;

/// The fill stops when no displacement changes by more than this (pixels).
const FILL_TOLERANCE: f64 = 1e-4;
const FILL_ITERATIONS: usize = 2000;

/// One side's grid followed away from its key frame.
pub struct GridTracker {
    rows: usize,
    cols: usize,
    key: Vec<Vec2>,
    /// Per node: its point tracker, for interior nodes with texture.
    trackers: Vec<Option<PointTracker>>,
}

/// The grid in one frame.
#[derive(Debug, Clone, PartialEq)]
pub struct GridEstimate {
    /// Every node, row-major from the bottom row, as the key's.
    pub nodes: Vec<Vec2>,
    /// Per node: found by its own patch in this frame (else it moved with
    /// its neighbours, or is on the border).
    pub followed: Vec<bool>,
}

impl GridEstimate {
    /// Whether any node was found by its own patch: a grid none of whose
    /// nodes was found is lost.
    pub fn is_lost(&self) -> bool {
        !self.followed.iter().any(|f| *f)
    }
}

impl GridTracker {
    /// Starts from `nodes` (`rows` × `cols`, row-major, this level's pixel
    /// coordinates) in the key frame.
    pub fn new(
        rows: usize,
        cols: usize,
        nodes: &[Vec2],
        key: &Pyramid,
        settings: &TrackSettings,
    ) -> GridTracker {
        let border = |i: usize| {
            let (r, c) = (i / cols, i % cols);
            r == 0 || c == 0 || r + 1 == rows || c + 1 == cols
        };
        let trackers = nodes
            .iter()
            .enumerate()
            .map(|(i, p)| {
                if border(i) {
                    return None;
                }
                let t = PointTracker::new(key, *p, settings);
                let [xx, xy, yy] = t.information();
                let (mean, spread) = (0.5 * (xx + yy), (0.25 * (xx - yy).powi(2) + xy * xy).sqrt());
                let (small, large) = (mean - spread, mean + spread);
                (large > 0.0 && small >= CORNER_RATIO * large).then_some(t)
            })
            .collect();
        GridTracker {
            rows,
            cols,
            key: nodes.to_vec(),
            trackers,
        }
    }

    /// How many nodes are followed by their own patch.
    pub fn tracked(&self) -> usize {
        self.trackers.iter().filter(|t| t.is_some()).count()
    }

    /// The grid in the next frame of the sweep.
    pub fn step(&mut self, frame: &Pyramid, settings: &TrackSettings) -> GridEstimate {
        let n = self.key.len();
        let mut known: Vec<Option<Vec2>> = vec![None; n];
        let mut followed = vec![false; n];
        for (i, t) in self.trackers.iter_mut().enumerate() {
            if let Some(t) = t {
                let e = t.step(frame, settings);
                if !e.lost {
                    known[i] = Some(e.at - self.key[i]);
                    followed[i] = true;
                }
            }
        }
        for (i, k) in known.iter_mut().enumerate() {
            if self.is_border(i) {
                *k = Some(Vec2::ZERO);
            }
        }
        let moved = fill(self.rows, self.cols, &self.key, &known);
        GridEstimate {
            nodes: self.key.iter().zip(moved).map(|(p, d)| *p + d).collect(),
            followed,
        }
    }

    fn is_border(&self, i: usize) -> bool {
        let (r, c) = (i / self.cols, i % self.cols);
        r == 0 || c == 0 || r + 1 == self.rows || c + 1 == self.cols
    }
}

/// Every node's displacement: the known ones as they are, each other the
/// value at its own position of the affine motion that best fits its (up
/// to four) neighbours' displacements (their mean where they lie in a
/// line), by Gauss-Seidel sweeps started from the known ones' mean. An
/// affine motion of the picture is so reproduced exactly, however uneven
/// the grid.
fn fill(rows: usize, cols: usize, at: &[Vec2], known: &[Option<Vec2>]) -> Vec<Vec2> {
    let given: Vec<Vec2> = known.iter().flatten().copied().collect();
    let start = given.iter().fold(Vec2::ZERO, |s, d| s + *d) * (1.0 / given.len().max(1) as f64);
    let mut d: Vec<Vec2> = known.iter().map(|k| k.unwrap_or(start)).collect();
    for _ in 0..FILL_ITERATIONS {
        let mut change: f64 = 0.0;
        for i in 0..d.len() {
            if known[i].is_some() {
                continue;
            }
            let (r, c) = (i / cols, i % cols);
            let mut near = Vec::with_capacity(4);
            if r > 0 {
                near.push(i - cols);
            }
            if r + 1 < rows {
                near.push(i + cols);
            }
            if c > 0 {
                near.push(i - 1);
            }
            if c + 1 < cols {
                near.push(i + 1);
            }
            let next = affine_at(at[i], near.iter().map(|&j| (at[j], d[j])));
            change = change.max(next.distance(d[i]));
            d[i] = next;
        }
        if change < FILL_TOLERANCE {
            break;
        }
    }
    d
}

/// The least-squares affine fit `t + G (p - centre)` of displacements
/// `(p, d)`, at `centre`: `t`. Their mean where the positions lie in a line
/// (the fit is then not fixed).
fn affine_at(centre: Vec2, samples: impl Iterator<Item = (Vec2, Vec2)>) -> Vec2 {
    let mut m = [[0.0f64; 3]; 3];
    let (mut bx, mut by) = ([0.0f64; 3], [0.0f64; 3]);
    let (mut sum, mut n) = (Vec2::ZERO, 0.0f64);
    for (p, d) in samples {
        let q = p - centre;
        let row = [1.0, q.x, q.y];
        for i in 0..3 {
            for j in 0..3 {
                m[i][j] += row[i] * row[j];
            }
            bx[i] += row[i] * d.x;
            by[i] += row[i] * d.y;
        }
        sum += d;
        n += 1.0;
    }
    match (solve(m, bx), solve(m, by)) {
        (Some(x), Some(y)) => Vec2::new(x[0], y[0]),
        _ => sum * (1.0 / n.max(1.0)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::RectI;
    use crate::track::Grey;

    /// Under an affine motion of the picture, a node off its neighbours'
    /// middle (an uneven grid) still moves exactly as the picture does
    /// there, not as their mean.
    #[test]
    fn an_affine_motion_is_filled_exactly_on_an_uneven_grid() {
        let (rows, cols) = (3, 3);
        let mut at: Vec<Vec2> = (0..9)
            .map(|i| Vec2::new(50.0 * (i % 3) as f64, 40.0 * (i / 3) as f64))
            .collect();
        at[4] = Vec2::new(62.0, 33.0);
        let motion = |p: Vec2| {
            Vec2::new(
                2.0 + 0.05 * p.x - 0.03 * p.y,
                -1.0 + 0.02 * p.x + 0.04 * p.y,
            )
        };
        let known: Vec<Option<Vec2>> = (0..9).map(|i| (i != 4).then(|| motion(at[i]))).collect();
        let d = fill(rows, cols, &at, &known);
        assert!(d[4].distance(motion(at[4])) < 1e-9, "{:?}", d[4]);
    }

    /// Texture whose middle moves by `d` (a bump of motion fading to 0 at
    /// the plate's edges), and flat grey in the top-left quarter.
    fn frame(d: Vec2) -> Pyramid {
        let grey = Grey::from_fn(RectI::from_size(192, 192), |i, j| {
            let p = Vec2::new(i as f64 + 0.5, j as f64 + 0.5);
            if p.x < 80.0 && p.y > 112.0 {
                return 0.5;
            }
            crate::testing::texture(p - d * bump(p))[0]
        });
        Pyramid::new(grey, 3, 16)
    }

    /// 1 in the middle of the plate, 0 at its edges.
    fn bump(p: Vec2) -> f64 {
        let s = |v: f64| (std::f64::consts::PI * v / 192.0).sin();
        s(p.x) * s(p.y)
    }

    /// A 5 × 5 grid over the plate, its middle moving by up to (3, -2) px:
    /// each node tracked by its own patch lands where the picture under it
    /// went, within 0.1 px; the nodes over the flat corner have no patch to
    /// follow and move with their neighbours; the border stays.
    #[test]
    fn textured_nodes_follow_the_picture_and_flat_ones_their_neighbours() {
        let (rows, cols) = (5, 5);
        let nodes: Vec<Vec2> = (0..rows * cols)
            .map(|i| Vec2::new(48.0 * (i % cols) as f64, 48.0 * (i / cols) as f64))
            .collect();
        let settings = TrackSettings::default();
        let mut tracker = GridTracker::new(rows, cols, &nodes, &frame(Vec2::ZERO), &settings);
        // Node (row 3, col 1) at (48, 144) is on the flat corner.
        let flat = 3 * cols + 1;
        assert_eq!(
            tracker.tracked(),
            8,
            "the nine interior nodes less the flat one"
        );
        for k in 1..=3 {
            let d = Vec2::new(1.0, -2.0 / 3.0) * k as f64;
            let e = tracker.step(&frame(d), &settings);
            assert!(!e.is_lost());
            for (i, p) in e.nodes.iter().enumerate() {
                let (r, c) = (i / cols, i % cols);
                if r == 0 || c == 0 || r + 1 == rows || c + 1 == cols {
                    assert_eq!(*p, nodes[i]);
                } else if i != flat {
                    assert!(e.followed[i]);
                    // The picture at q came from q - d·bump(q): the node
                    // at p went to q with q - d·bump(q) = p.
                    let q = *p;
                    let back = q - d * bump(q);
                    assert!(back.distance(nodes[i]) < 0.1, "node {i}: {q:?}");
                }
            }
            assert!(!e.followed[flat]);
            let neighbours = [flat - cols, flat + cols, flat - 1, flat + 1];
            let mean = neighbours
                .iter()
                .fold(Vec2::ZERO, |s, j| s + (e.nodes[*j] - nodes[*j]))
                * 0.25;
            assert!((e.nodes[flat] - nodes[flat]).distance(mean) < 1e-3);
        }
    }

    /// A node between two followed ones (and the frozen border) moves as
    /// its neighbours do, on a regular grid by their average: on a 3 × 5
    /// grid with the border fixed, the middle row's nodes 1 and 3 moved by
    /// (4, 0) and (8, 0), node 2 between them by (4 + 8 + 0 + 0) / 4 = 3.
    #[test]
    fn a_node_without_its_own_match_moves_as_its_neighbours_do() {
        let (rows, cols) = (3, 5);
        let mut known = vec![None; rows * cols];
        for (i, k) in known.iter_mut().enumerate() {
            let (r, c) = (i / cols, i % cols);
            if r == 0 || c == 0 || r + 1 == rows || c + 1 == cols {
                *k = Some(Vec2::ZERO);
            }
        }
        known[cols + 1] = Some(Vec2::new(4.0, 0.0));
        known[cols + 3] = Some(Vec2::new(8.0, 0.0));
        let at: Vec<Vec2> = (0..rows * cols)
            .map(|i| Vec2::new((i % cols) as f64, (i / cols) as f64))
            .collect();
        let d = fill(rows, cols, &at, &known);
        assert!(
            d[cols + 2].distance(Vec2::new(3.0, 0.0)) < 1e-3,
            "{:?}",
            d[cols + 2]
        );
        assert_eq!(d[cols + 1], Vec2::new(4.0, 0.0));
        assert_eq!(d[0], Vec2::ZERO);
    }
}
