use super::*;
use crate::geom::{PixelScale, RectI};
use crate::image::{EdgeMode, Filter, Image, Plane, Sampler};
use crate::warp::Warp;

const W: usize = 160;
const H: usize = 120;

/// A regular 9 × 9 mesh on the frame, and the same mesh with the interior
/// nodes moved by `f` (the border stays frozen).
fn meshes(f: impl Fn(Vec2) -> Vec2) -> (Mesh, Mesh) {
    let src = Mesh::regular(9, 9, 0.0, 0.0, W as f64, H as f64).unwrap();
    let dst = src.map_nodes(|r, c, p| {
        if r == 0 || c == 0 || r == 8 || c == 8 {
            p
        } else {
            f(p)
        }
    });
    (src, dst)
}

/// A ramp image whose red and green hold the canonical pixel centre, so a
/// warp of it shows where each output pixel was read from.
fn ramp() -> Image {
    Image::from_fn(RectI::from_size(W, H), 4, |i, j, c| match c {
        0 => i as f32 + 0.5,
        1 => j as f32 + 0.5,
        2 => 0.25,
        _ => 1.0,
    })
}

fn sampler(img: &Image) -> Sampler<'_, f32> {
    Sampler::new(
        img.view(),
        PixelScale::UNIT,
        Filter::Bilinear,
        EdgeMode::Clamp,
        true,
    )
}

fn at(plane: &Plane, i: i32, j: i32) -> [f32; 4] {
    plane.row(j)[(i - plane.window.x1) as usize]
}

/// The affine motion of the interior nodes, and its inverse. Both passes
/// magnify under it, so linear data is reproduced exactly.
const CENTRE: Vec2 = Vec2 { x: 80.0, y: 60.0 };
fn affine(p: Vec2) -> Vec2 {
    let d = p - CENTRE;
    CENTRE
        + Vec2::new(
            1.06 * d.x + 0.08 * d.y + 1.5,
            -0.05 * d.x + 1.04 * d.y - 2.0,
        )
}
fn affine_inverse(q: Vec2) -> Vec2 {
    let e = q - CENTRE - Vec2::new(1.5, -2.0);
    let det = 1.06 * 1.04 + 0.08 * 0.05;
    CENTRE
        + Vec2::new(
            (1.04 * e.x - 0.08 * e.y) / det,
            (0.05 * e.x + 1.06 * e.y) / det,
        )
}

/// Output pixels whose whole spline support is affinely moved: inside the
/// image of the source cells two or more cells away from the border, with a
/// tenth of a cell to spare for the filter's reach.
fn interior() -> Vec<(i32, i32)> {
    let (cw, ch) = (W as f64 / 8.0, H as f64 / 8.0);
    let mut px = Vec::new();
    for j in 0..H as i32 {
        for i in 0..W as i32 {
            let p = affine_inverse(Vec2::new(i as f64 + 0.5, j as f64 + 0.5));
            let (s, r) = (p.x / cw, p.y / ch);
            if (2.1..5.9).contains(&s) && (2.1..5.9).contains(&r) {
                px.push((i, j));
            }
        }
    }
    px
}

#[test]
fn identity_meshes_give_the_identity() {
    let (src, _) = meshes(|p| p);
    let w = MeshWarp::new(&src, &src);
    assert!(w.is_identity());
    let img = ramp();
    let out = two_pass(&sampler(&img), &src, &src, img.bounds, PixelScale::UNIT);
    for j in 0..H as i32 {
        for i in 0..W as i32 {
            let want = img.pixel(i, j);
            let got = at(&out, i, j);
            for c in 0..4 {
                assert!(
                    (got[c] - want[c]).abs() < 1e-5,
                    "({i}, {j}): {got:?} vs {want:?}"
                );
            }
        }
    }
}

#[test]
fn an_affinely_moved_interior_warps_affinely_one_pass() {
    let (src, dst) = meshes(affine);
    let w = MeshWarp::new(&src, &dst);
    let px = interior();
    assert!(px.len() > 2000, "{} interior pixels", px.len());
    for (i, j) in px {
        let p = Vec2::new(i as f64 + 0.5, j as f64 + 0.5);
        let got = w.map(p);
        assert!(got.distance(affine_inverse(p)) < 1e-6, "{p:?}: {got:?}");
    }
}

#[test]
fn an_affinely_moved_interior_warps_affinely_two_pass() {
    let (src, dst) = meshes(affine);
    let img = ramp();
    let out = two_pass(&sampler(&img), &src, &dst, img.bounds, PixelScale::UNIT);
    for (i, j) in interior() {
        let want = affine_inverse(Vec2::new(i as f64 + 0.5, j as f64 + 0.5));
        let got = at(&out, i, j);
        assert!(
            (got[0] as f64 - want.x).abs() < 2e-3 && (got[1] as f64 - want.y).abs() < 2e-3,
            "({i}, {j}): {got:?} vs {want:?}"
        );
        assert_eq!(got[2], 0.25);
    }
}

#[test]
fn nodes_land_on_their_destinations() {
    let (src, dst) = meshes(|p| p + Vec2::new((p.y * 0.1).sin() * 4.0, (p.x * 0.07).cos() * 3.0));
    let w = MeshWarp::new(&src, &dst);
    for r in 0..9 {
        for c in 0..9 {
            let got = w.map(dst.node(r, c));
            assert!(
                got.distance(src.node(r, c)) < 1e-6,
                "node ({r}, {c}): {got:?}"
            );
        }
    }
}

/// Where the two evaluations may differ on a smooth mesh: the two-pass
/// splines run through the nodes' actual coordinates, the patches through
/// their indices, and the second pass filters columns of the first. Measured
/// worst case for this mesh (displacements up to 5 px): 0.14 px.
const TWO_VS_ONE_PASS_PX: f64 = 0.2;

#[test]
fn two_pass_and_one_pass_agree_on_smooth_meshes() {
    let (src, dst) = meshes(|p| {
        p + Vec2::new(
            5.0 * (p.y * 0.03).sin() * (p.x * 0.02).cos(),
            4.0 * (p.x * 0.025).sin(),
        )
    });
    let img = ramp();
    let two = two_pass(&sampler(&img), &src, &dst, img.bounds, PixelScale::UNIT);
    let one = MeshWarp::new(&src, &dst).map_window(img.bounds, PixelScale::UNIT);
    let mut worst: f64 = 0.0;
    for j in 1..H as i32 - 1 {
        for i in 1..W as i32 - 1 {
            let q = one.get(i, j);
            let got = at(&two, i, j);
            worst = worst.max((got[0] as f64 - q.x).abs().max((got[1] as f64 - q.y).abs()));
        }
    }
    assert!(worst < TWO_VS_ONE_PASS_PX, "largest difference {worst} px");
}

#[test]
fn render_scale_and_straight_alpha_keep_the_warp() {
    // Half resolution: the same canonical warp at half the pixels.
    let (src, dst) = meshes(affine);
    let img = Image::from_fn(RectI::from_size(W / 2, H / 2), 4, |i, j, c| match c {
        0 => (i as f32 + 0.5) * 2.0,
        1 => (j as f32 + 0.5) * 2.0,
        2 => 0.5,
        _ => 0.5,
    });
    let half = PixelScale::new(0.5, 0.5, 1.0);
    let s = Sampler::new(img.view(), half, Filter::Bilinear, EdgeMode::Clamp, false);
    let out = two_pass(&s, &src, &dst, img.bounds, half);
    let p = Vec2::new(80.0, 60.0); // centre of half-res pixel (40, 30) is (81, 61)
    let got = at(&out, 40, 30);
    let want = affine_inverse(p + Vec2::new(1.0, 1.0));
    assert!(
        (got[0] as f64 - want.x).abs() < 1e-2 && (got[1] as f64 - want.y).abs() < 1e-2,
        "{got:?} vs {want:?}"
    );
    // Straight alpha comes back straight (colour not darkened by alpha).
    assert!(
        (got[2] - 0.5).abs() < 1e-6 && (got[3] - 0.5).abs() < 1e-6,
        "{got:?}"
    );
}

#[test]
fn bad_meshes_are_refused_naming_mesh_and_cell() {
    let (src, _) = meshes(|p| p);
    let err = |a: Mesh, b: Mesh| MeshPair::new(a, b).unwrap_err().to_string();

    // A node pushed past its right neighbour: the row is not monotone.
    let crossed = src.map_nodes(|r, c, p| {
        if (r, c) == (4, 4) {
            p + Vec2::new(25.0, 0.0)
        } else {
            p
        }
    });
    let e = err(src.clone(), crossed);
    assert!(
        e.contains("mesh b") && e.contains("row 4") && e.contains("monotonically"),
        "{e}"
    );

    // A node pushed below its lower neighbour: the column is not monotone.
    let sunk = src.map_nodes(|r, c, p| {
        if (r, c) == (3, 2) {
            p - Vec2::new(0.0, 20.0)
        } else {
            p
        }
    });
    let e = err(sunk, src.clone());
    assert!(e.contains("mesh a") && e.contains("column 2"), "{e}");

    // Monotone rows and columns but a cell turned inside out.
    let folded = src.map_nodes(|r, c, p| match (r, c) {
        (4, 4) => p + Vec2::new(15.0, -10.0),
        _ => p,
    });
    let e = err(src.clone(), folded);
    assert!(
        e.contains("mesh b") && e.contains("cell (row") && e.contains("folded"),
        "{e}"
    );

    // A border node that moves.
    let moved = src.map_nodes(|r, c, p| {
        if (r, c) == (0, 3) {
            p + Vec2::new(2.0, 0.0)
        } else {
            p
        }
    });
    let e = err(src.clone(), moved);
    assert!(
        e.contains("border node (row 0, col 3)") && e.contains("frozen"),
        "{e}"
    );

    // Sizes.
    let e = Mesh::new(3, 3, vec![Vec2::default(); 8])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("3 × 3") && e.contains("9 nodes") && e.contains("found 8"),
        "{e}"
    );
    let small = Mesh::regular(3, 3, 0.0, 0.0, 10.0, 10.0).unwrap();
    let e = err(src, small);
    assert!(e.contains("9 × 9") && e.contains("3 × 3"), "{e}");
}

#[test]
fn meshes_listed_top_row_first_are_accepted() {
    let (src, dst) = meshes(affine);
    let flip = |m: &Mesh| m.map_nodes(|r, c, _| m.node(m.rows() - 1 - r, c));
    let pair = MeshPair::new(flip(&src), flip(&dst)).unwrap();
    assert_eq!(pair.a, src);
    assert_eq!(pair.b, dst);
}

#[test]
fn the_in_between_mesh_interpolates_nodes() {
    let (src, dst) = meshes(affine);
    let pair = MeshPair::new(src.clone(), dst.clone()).unwrap();
    let mid = pair.at(0.25);
    assert_eq!(mid.node(4, 4), src.node(4, 4).lerp(dst.node(4, 4), 0.25));
    // Warping A toward t = 1 is the full warp; toward t = 0 the identity.
    assert!(MeshWarp::toward(&pair, crate::features::Side::A, 0.0).is_identity());
    let full = MeshWarp::toward(&pair, crate::features::Side::A, 1.0);
    let p = dst.node(3, 5);
    assert!(full.map(p).distance(src.node(3, 5)) < 1e-6);
}
