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
/// `pos` and `Σ w` `ws` edited in place; `refused[k]` is set for a pixel
/// whose weight changes by a tenth or more (the moved lines dominate it,
/// and the division would magnify the map's rounding by `W / W'`), or
/// was not a finite positive sum, and the result says whether none was.
/// One pass with no early exit and no branch, which the compiler
/// vectorises (positions come in pairs, which it deinterleaves better
/// than lanes loaded one by one).
///
/// `pos` and `ws` are arguments of their own, not a pair: only a reference
/// passed as itself tells the compiler nothing else aliases it. Passed as
/// a tuple, where the function was not inlined, the loop checked at run
/// time, at every call (one 48-pixel block row), that they overlap none of
/// the six change rows, and those checks drew about a third of its
/// profile samples.
pub(super) fn swap_terms(
    xs: &[f32],
    y: f32,
    change: &RowChange,
    pos: &mut [[f32; 2]],
    ws: &mut [f32],
    refused: &mut [bool],
) -> bool {
    let n = pos.len();
    let (xs, ws, refused) = (&xs[..n], &mut ws[..n], &mut refused[..n]);
    let [lx, ly, lw] = change.lo.map(|s| &s[..n]);
    let [hx, hy, hw] = change.hi.map(|s| &s[..n]);
    let f = change.f;
    let mut good = true;
    for k in 0..n {
        let (dx, dy) = (lx[k] + (hx[k] - lx[k]) * f, ly[k] + (hy[k] - ly[k]) * f);
        let dw = lw[k] + (hw[k] - lw[k]) * f;
        let (w, p) = (ws[k], pos[k]);
        let w1 = w + dw;
        // NaNs compare false: they fail here too.
        let ok = (w > 0.0) & (w < f32::INFINITY) & (dw.abs() <= 0.1 * w);
        refused[k] = !ok;
        good &= ok;
        let sx = (p[0] - xs[k]) * w + dx;
        let sy = (p[1] - y) * w + dy;
        pos[k] = [xs[k] + sx / w1, y + sy / w1];
        ws[k] = w1;
    }
    good
}
