//! Uniform cubic B-spline lattices over the plane (Lee, Wolberg et al. §5.1, §6.1): the
//! free-form deformations of MFFD and the surfaces of multilevel B-spline
//! interpolation are both sums `Σ B_k(s) B_l(t) φ`. One lattice type serves
//! both; a deformation is a pair of them (x and y displacements).

mod approximate;
mod lattice;
pub mod mba;

pub use approximate::Approximation;
pub use lattice::Lattice;

/// The uniform cubic B-spline basis `B_0..B_3` at `s ∈ [0, 1)`.
#[inline]
pub fn basis(s: f64) -> [f64; 4] {
    let s2 = s * s;
    let s3 = s2 * s;
    let m = 1.0 - s;
    [
        m * m * m / 6.0,
        (3.0 * s3 - 6.0 * s2 + 4.0) / 6.0,
        (-3.0 * s3 + 3.0 * s2 + 3.0 * s + 1.0) / 6.0,
        s3 / 6.0,
    ]
}

/// The derivatives `B_k'(s)`.
#[inline]
pub fn basis_derivative(s: f64) -> [f64; 4] {
    let s2 = s * s;
    let m = 1.0 - s;
    [
        -m * m / 2.0,
        (3.0 * s2 - 4.0 * s) / 2.0,
        (-3.0 * s2 + 2.0 * s + 1.0) / 2.0,
        s2 / 2.0,
    ]
}

#[cfg(test)]
mod tests;
