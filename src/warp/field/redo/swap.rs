//! The moved lines' terms swapped in a row of pixels, eight at a time.
//!
//! A pixel's new position is `X + (S − s_old + s_new) / (W − w_old + w_new)`
//! with `S = (X′ − X)·W` read back from its position and `W` kept beside
//! it (Beier-Neely eq. 4 divides two sums over lines, so each line's term
//! comes and goes on its own).

use super::super::grid::Between;

/// The change at each pixel of a row, `[Δ Σ w·Δx, Δ Σ w·Δy, Δ Σ w]`.
pub(super) type RowChange<'a> = Between<'a, 3>;

/// Swaps the terms in the pixels of a row `y` at `xs`, their positions
/// `pos` and `Σ w` `ws` edited in place; false when the old terms carried
/// a tenth of some pixel's weight or more (taking them away would cancel
/// digits of its sums), or its weight changes by a tenth or more. One pass
/// with no early exit and no branch, which the compiler vectorises
/// (positions come in pairs, which it deinterleaves better than lanes
/// loaded one by one).
pub(super) fn swap_terms(
    xs: &[f32],
    y: f32,
    change: &RowChange,
    (pos, ws): (&mut [[f32; 2]], &mut [f32]),
) -> bool {
    let n = pos.len();
    let (xs, ws) = (&xs[..n], &mut ws[..n]);
    let [lx, ly, lw] = change.lo.map(|s| &s[..n]);
    let [hx, hy, hw] = change.hi.map(|s| &s[..n]);
    let f = change.f;
    let mut good = true;
    for k in 0..n {
        let (dx, dy) = (lx[k] + (hx[k] - lx[k]) * f, ly[k] + (hy[k] - ly[k]) * f);
        let dw = lw[k] + (hw[k] - lw[k]) * f;
        let (w, p) = (ws[k], pos[k]);
        let w1 = w + dw;
        let tenth = 0.1 * w;
        // NaNs compare false: they fail here too.
        good &= (w > 0.0) & (w < f32::INFINITY) & (dw.abs() <= tenth);
        let sx = (p[0] - xs[k]) * w + dx;
        let sy = (p[1] - y) * w + dy;
        pos[k] = [xs[k] + sx / w1, y + sy / w1];
        ws[k] = w1;
    }
    good
}
