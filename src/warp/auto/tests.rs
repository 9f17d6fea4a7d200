use super::grid::{inverse_bilinear, is_convex_ccw, lattice, Grid};
use super::*;
use crate::geom::Vec2;
use crate::testing::texture;
use crate::warp::Warp;

const SIZE: usize = 128;

/// The known warp: B(y) = A(H(y)), a smooth displacement of up to 5 px that
/// vanishes at the frame's border.
fn h(p: Vec2) -> Vec2 {
    let (u, v) = (p.x / SIZE as f64, p.y / SIZE as f64);
    let bump = (std::f64::consts::PI * u).sin() * (std::f64::consts::PI * v).sin();
    p + Vec2::new(
        5.0 * bump * (2.0 * v - 0.5).cos(),
        -4.0 * bump * (3.0 * u).sin(),
    )
}

/// F = H⁻¹ (where a point of A lands on B), by fixed-point iteration.
fn h_inverse(x: Vec2) -> Vec2 {
    let mut y = x;
    for _ in 0..60 {
        y = y - (h(y) - x);
    }
    y
}

fn centre(i: usize, j: usize) -> Vec2 {
    Vec2::new(i as f64 + 0.5, j as f64 + 0.5)
}

fn plate_a() -> WorkImage {
    WorkImage::from_fn(SIZE, SIZE, |i, j| texture(centre(i, j)))
}

fn plate_b(gain: f32, offset: f32) -> WorkImage {
    WorkImage::from_fn(SIZE, SIZE, |i, j| {
        texture(h(centre(i, j))).map(|c| c * gain + offset)
    })
}

fn frame() -> RectD {
    RectD::new(0.0, 0.0, SIZE as f64, SIZE as f64)
}

fn colour_work(a: &WorkImage, b: &WorkImage, grid: &Grid) -> f64 {
    let p = Pricer::new(a, b, grid.level(), &[], &Coefficients::default());
    p.all(grid).iter().map(|w| w.colour).sum()
}

/// The true correspondence as a grid of `level`.
fn true_grid(level: u32) -> Grid {
    let n = 1 << level;
    let s = SIZE as f64;
    let pts = (0..=n)
        .flat_map(|k| (0..=n).map(move |j| (j, k)))
        .map(|(j, k)| {
            let l = lattice(n, j, k);
            let y = h_inverse(l * s);
            Vec2::new(y.x / s, y.y / s)
        })
        .collect();
    Grid::from_points(pts).unwrap()
}

/// Distance (pixels) from the solved to the true correspondence at every
/// control point, sorted.
fn errors(grid: &Grid) -> Vec<f64> {
    let s = SIZE as f64;
    let n = grid.n();
    let mut e: Vec<f64> = (0..=n)
        .flat_map(|k| (0..=n).map(move |j| (j, k)))
        .map(|(j, k)| {
            let found = grid.at(j, k) * s;
            h(found).distance(lattice(n, j, k) * s)
        })
        .collect();
    e.sort_by(f64::total_cmp);
    e
}

fn all_legal(grid: &Grid) -> bool {
    grid.first_folded_quad().is_none()
}

#[test]
fn refining_keeps_the_warp() {
    let g = true_grid(2);
    let r = g.refined();
    assert_eq!(r.level(), 3);
    for i in 0..50 {
        let u = Vec2::new((i as f64 * 0.377) % 1.0, (i as f64 * 0.611) % 1.0);
        assert!(g.eval(u).distance(r.eval(u)) < 1e-12, "at {u:?}");
    }
}

#[test]
fn inverse_bilinear_round_trips() {
    let q = [
        Vec2::new(0.0, 0.0),
        Vec2::new(10.0, 1.0),
        Vec2::new(12.0, 9.0),
        Vec2::new(-1.0, 7.0),
    ];
    assert!(is_convex_ccw(&q));
    for i in 0..=10 {
        for k in 0..=10 {
            let (s, t) = (i as f64 / 10.0, k as f64 / 10.0);
            let p = grid::bilinear(&q, s, t);
            let (s2, t2) = inverse_bilinear(&q, p, 1e-9).expect("inside");
            assert!((s - s2).abs() < 1e-12 && (t - t2).abs() < 1e-12, "{s} {t}");
        }
    }
    assert!(inverse_bilinear(&q, Vec2::new(20.0, 20.0), 1e-9).is_none());
    // A bow-tie is not a legal quad.
    let folded = [q[0], q[1], q[3], q[2]];
    assert!(!is_convex_ccw(&folded));
}

#[test]
fn identical_plates_keep_the_identity() {
    let a = plate_a();
    let s = solve(&a, &a, &[], &AutoSettings::default(), Start::Identity).unwrap();
    assert_eq!(s.grid, Grid::identity(default_levels(SIZE, SIZE)));
    assert!(s.table.iter().all(|r| r.work.total() == 0.0));
}

#[test]
fn finds_a_known_smooth_warp() {
    let (a, b) = (plate_a(), plate_b(1.0, 0.0));
    let s = solve(&a, &b, &[], &AutoSettings::default(), Start::Identity).unwrap();
    let identity = colour_work(&a, &b, &Grid::identity(s.grid.level()));
    let found = colour_work(&a, &b, &s.grid);
    assert!(
        found <= 0.2 * identity,
        "colour work {found:.1} of identity {identity:.1}\n{}",
        table_text(&s.table)
    );
    let e = errors(&s.grid);
    let (median, p90) = (e[e.len() / 2], e[e.len() * 9 / 10]);
    assert!(
        median < 0.5 && p90 < 1.0,
        "median {median:.2} px, 90% {p90:.2} px"
    );
    assert!(all_legal(&s.grid) && s.grid.is_onto());
    // The paper's table falls level by level.
    for w in s.table.windows(2) {
        assert!(
            w[1].work.total() <= w[0].work.total(),
            "{}",
            table_text(&s.table)
        );
    }
}

#[test]
fn finds_a_known_warp_under_a_colour_shift() {
    let (a, b) = (plate_a(), plate_b(0.92, 0.04));
    let s = solve(&a, &b, &[], &AutoSettings::default(), Start::Identity).unwrap();
    let level = s.grid.level();
    let identity = colour_work(&a, &b, &Grid::identity(level));
    let truth = colour_work(&a, &b, &true_grid(level));
    let found = colour_work(&a, &b, &s.grid);
    // At least 80% of the work a warp can remove is removed.
    assert!(
        identity - found >= 0.8 * (identity - truth),
        "identity {identity:.1}, truth {truth:.1}, found {found:.1}"
    );
    let e = errors(&s.grid);
    assert!(e[e.len() / 2] < 0.75, "median {:.2} px", e[e.len() / 2]);
    assert!(all_legal(&s.grid));
}

#[test]
fn anchors_are_met_against_the_colour() {
    // Identical plates: colour says stay, the anchor says move 6 px.
    let a = plate_a();
    let s = SIZE as f64;
    let an = Anchor {
        a: Vec2::new(40.0 / s, 70.0 / s),
        b: Vec2::new(46.0 / s, 66.0 / s),
    };
    let sol = solve(&a, &a, &[an], &AutoSettings::default(), Start::Identity).unwrap();
    let got = sol.grid.eval(an.a) * s;
    let want = an.b * s;
    let tol = ANCHOR_FLOOR_PX / 2.0;
    assert!(
        got.distance(want) <= tol,
        "anchor at {got:?}, wanted {want:?}"
    );
    assert!(all_legal(&sol.grid));
}

#[test]
fn swapped_anchors_never_fold() {
    let a = plate_a();
    let anchors = [
        Anchor {
            a: Vec2::new(0.3, 0.5),
            b: Vec2::new(0.7, 0.5),
        },
        Anchor {
            a: Vec2::new(0.7, 0.5),
            b: Vec2::new(0.3, 0.5),
        },
        Anchor {
            a: Vec2::new(0.5, 0.3),
            b: Vec2::new(0.5, 0.8),
        },
        Anchor {
            a: Vec2::new(0.5, 0.8),
            b: Vec2::new(0.5, 0.2),
        },
    ];
    let s = solve(
        &a,
        &plate_b(1.0, 0.0),
        &anchors,
        &AutoSettings::default(),
        Start::Identity,
    )
    .unwrap();
    assert!(all_legal(&s.grid) && s.grid.is_onto());
}

#[test]
fn same_warp_whatever_the_thread_count() {
    let (a, b) = (plate_a(), plate_b(1.0, 0.0));
    let settings = AutoSettings {
        levels: Some(4),
        ..AutoSettings::default()
    };
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| solve(&a, &b, &[], &settings, Start::Identity).unwrap().grid)
    };
    assert_eq!(run(1), run(3));
}

#[test]
fn an_initial_warp_off_the_edges_is_pulled_onto_them() {
    let (a, b) = (plate_a(), plate_b(1.0, 0.0));
    // F_1 shrunk toward the centre: not onto.
    let pts = Grid::identity(1)
        .points()
        .iter()
        .map(|&p| Vec2::new(0.5, 0.5) + (p - Vec2::new(0.5, 0.5)) * 0.8)
        .collect();
    let start = Grid::from_points(pts).unwrap();
    assert!(!start.is_onto());
    let s = solve(
        &a,
        &b,
        &[],
        &AutoSettings::default(),
        Start::Initial(start.clone()),
    )
    .unwrap();
    assert!(s.grid.is_onto() && all_legal(&s.grid));
    // The search started from it: the table's first row is its work.
    let p = Pricer::new(&a, &b, 1, &[], &Coefficients::default());
    let w0: Work = p.all(&start).into_iter().sum();
    assert_eq!(s.table[0].work, w0);
}

#[test]
fn a_folded_initial_warp_is_refused() {
    let mut pts: Vec<Vec2> = Grid::identity(1).points().to_vec();
    pts.swap(3, 5);
    let err = Grid::from_points(pts).unwrap_err().to_string();
    assert!(err.contains("not convex"), "{err}");
    assert!(Grid::from_points(vec![Vec2::ZERO; 10]).is_err());
}

#[test]
fn a_warm_start_tracks_the_next_frame() {
    let (a, b) = (plate_a(), plate_b(1.0, 0.0));
    let first = solve(&a, &b, &[], &AutoSettings::default(), Start::Identity).unwrap();
    // The next frame: the same warp, B slightly brighter.
    let b2 = plate_b(1.02, 0.0);
    let warm = solve(
        &a,
        &b2,
        &[],
        &AutoSettings::default(),
        Start::Warm(&first.grid),
    )
    .unwrap();
    assert_eq!(
        warm.table.len(),
        2,
        "warm start refines the finest level only"
    );
    assert!(warm.table[1].work.total() <= warm.table[0].work.total());
    let e = errors(&warm.grid);
    assert!(e[e.len() / 2] < 0.5);
}

#[test]
fn the_morph_grid_maps_b_onto_a_at_t1() {
    let grid = true_grid(3);
    let corr = Correspondence::new(grid, frame(), frame());
    // At t = 1, A's warp finds for each B position the A point that lands there.
    let wa = corr.toward(Side::A, 1.0);
    for i in 1..20 {
        let x = Vec2::new(6.0 * i as f64 + 3.0, 5.0 * i as f64 + 10.0);
        let y = corr.map_a_to_b(x);
        assert!(wa.map(y).distance(x) < 1e-9, "{x:?}");
    }
    // At t = 0, A is not moved and B's warp is F itself.
    assert!(corr.toward(Side::A, 0.0).is_identity());
    let wb = corr.toward(Side::B, 0.0);
    let x = Vec2::new(50.3, 77.9);
    assert!(wb.map(x).distance(corr.map_a_to_b(x)) < 1e-9);
    // Outside the frame the warp is the identity.
    assert_eq!(wa.map(Vec2::new(-5.0, 3.0)), Vec2::new(-5.0, 3.0));
}
