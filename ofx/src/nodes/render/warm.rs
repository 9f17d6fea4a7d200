//! Solves that start from this instance's earlier ones: thin plates in a
//! viewer's interactive renders, and `auto` correspondences in sequential
//! renders when *Warm Start* asks for it. Every other render solves cold,
//! so a frame's pixels depend on that frame alone: a farm's chunks render
//! what one call over the whole range renders, bit for bit.

use std::sync::Arc;

use morphfx::features::Side;
use morphfx::geom::RectD;
use morphfx::make_warp;
use morphfx::warp::auto::{self, Correspondence, WorkImage};
use morphfx::warp::thin_plate::multigrid::Report;
use morphfx::warp::thin_plate::ThinPlateWarp;

use crate::cache::Key;
use crate::nodes::inputs::WarpInputs;
use crate::nodes::state::{NodeState, GRIDS_KEPT, PLATES_KEPT};
use ofx_layer::sync::Locked;
use ofx_layer::{Failure, Outcome};

/// The frame's `auto` correspondence: solved once per content of the two
/// images and settings (tiles and repeated renders share it), warm-started
/// from the previous frame's grid when this instance solved it.
pub(super) fn correspondence(
    instance: &NodeState,
    inputs: &WarpInputs,
    (time, sequential): (f64, bool),
    (a, a_frame): (&WorkImage, RectD),
    (b, b_frame): (&WorkImage, RectD),
) -> Outcome<Arc<Correspondence>> {
    let settings = &inputs.warp.settings.auto;
    let per_segment = inputs.warp.settings.samples_per_segment;
    let same_setup = Key::of(&(
        settings,
        per_segment,
        a_frame,
        b_frame,
        a.width,
        a.height,
        b.width,
        b.height,
    ));
    let key = Key::of(&(&same_setup, a.digest(), b.digest(), &inputs.features));
    instance.correspondences.get_or_compute(key, || {
        // Warm starts only in a sequential render, and only when asked for
        // (off by default): the result then depends on where the sequence
        // started, so a farm's chunks differ from one call at their starts.
        let warm = sequential
            .then(|| {
                let grids = instance.grids.locked();
                grids
                    .iter()
                    .find(|(t, k, _)| *t == time - 1.0 && *k == same_setup)
                    .map(|(_, _, g)| g.clone())
            })
            .flatten();
        let started = std::time::Instant::now();
        let (c, table) = auto::correspond(
            a,
            a_frame,
            b,
            b_frame,
            &inputs.features,
            per_segment,
            settings,
            warm.as_ref(),
        )
        .map_err(|e| Failure::BadInput(e.to_string()))?;
        if ofx_layer::verbose() {
            eprintln!(
                "auto: frame {time}: {}x{} to {}x{}, {} start, {:.2} s\n{}",
                a.width,
                a.height,
                b.width,
                b.height,
                if warm.is_some() && settings.warm_start {
                    "warm"
                } else {
                    "cold"
                },
                started.elapsed().as_secs_f64(),
                auto::table_text(&table)
            );
        }
        let mut grids = instance.grids.locked();
        grids.retain(|(t, k, _)| !(*t == time && *k == same_setup));
        if grids.len() >= GRIDS_KEPT {
            grids.remove(0);
        }
        grids.push((time, same_setup, c.grid.clone()));
        Ok(c)
    })
}

/// The frame's thin plates on `side`. In a viewer's interactive render,
/// solved from the plates this instance solved nearest in time (this frame
/// at another scale, or a neighbouring frame) with the same settings: Lee
/// et al.'s warm start, since features move little from frame to frame. A
/// warm start lands within the solver's tolerance of the cold solution, not
/// on its bits, so final renders (sequential or not) always start cold.
pub(super) fn thin_plate(
    instance: &NodeState,
    inputs: &WarpInputs,
    side: Side,
    (time, interactive): (f64, bool),
) -> Outcome<ThinPlateWarp> {
    let setup = Key::of(&(side, &inputs.warp.settings.thin_plate, inputs.warp.region));
    let warm = interactive
        .then(|| {
            let plates = instance.plates.locked();
            plates
                .iter()
                .filter(|(t, k, _)| *k == setup && (t - time).abs() <= 1.0)
                .min_by(|a, b| (a.0 - time).abs().total_cmp(&(b.0 - time).abs()))
                .map(|(_, _, p)| p.clone())
        })
        .flatten();
    let w = make_warp::thin_plate_toward(
        &inputs.features,
        side,
        inputs.t,
        &inputs.warp,
        warm.as_deref(),
    )
    .map_err(|e| Failure::BadInput(e.to_string()))?;
    if ofx_layer::verbose() {
        let cycles = |r: &Report| r.residuals.len() - 1;
        eprintln!(
            "thin-plate: frame {time} side {side:?}: {} start, {} + {} cycles",
            if warm.is_some() { "warm" } else { "cold" },
            cycles(&w.plate.report_x),
            cycles(&w.plate.report_y),
        );
    }
    let mut plates = instance.plates.locked();
    plates.retain(|(t, k, _)| !(*t == time && *k == setup));
    if plates.len() >= PLATES_KEPT {
        plates.remove(0);
    }
    plates.push((time, setup, Arc::new(w.plate.clone())));
    Ok(w)
}
