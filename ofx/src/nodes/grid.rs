//! The Reset Grid push-button: an even grid of Grid Rows × Grid Columns
//! nodes over Source A (the project when nothing is connected) written
//! into Scene Text, the same on A and B, with method mesh (the node's
//! Method too, where the node's own settings rule); the user's features
//! stay. One undo step; refused (Scene Text kept) when the text
//! cannot be edited.

use morphfx::geom::RectD;
use morphfx::make_warp::Method;

use super::overlay::shapes;
use super::params::{Reader, GRID_COLS, GRID_ROWS, METHOD, SETTINGS_FROM_SCENE};
use super::state::NodeState;
use ofx_layer::clips::EffectHandle;
use ofx_layer::{Failure, Outcome};

/// The Reset Grid button, pressed at `time`.
pub fn reset_grid(instance: &NodeState, effect: &EffectHandle, time: f64) -> Outcome {
    let r = Reader::new(instance.params(), instance.kind, time);
    let (rows, cols) = (r.int(&GRID_ROWS), r.int(&GRID_COLS));
    // Where the node's own settings rule, its Method follows, so the grid
    // just made is what renders and what the viewer shows.
    let node_method = match r.bool(&SETTINGS_FROM_SCENE) {
        true => None,
        false => instance
            .kind
            .methods
            .iter()
            .position(|m| *m == Method::Mesh),
    };
    let region = region(instance, effect, time);
    let result = region.and_then(|region| {
        let mut doc = shapes::document(instance, time)?;
        doc.make_grid(rows.max(2) as usize, cols.max(2) as usize, region)
            .map_err(shapes::refused)?;
        let params = instance.params();
        params.edit_block("Reset Grid", || {
            if let Some(mesh) = node_method {
                params.set_int(&METHOD, mesh as i32)?;
            }
            shapes::write(instance, &doc)
        })
    });
    shapes::settle(instance, effect, result)
}

/// Where the grid goes: Source A's region of definition, or the project
/// where A is not connected or its region is empty or unbounded.
fn region(instance: &NodeState, effect: &EffectHandle, time: f64) -> Outcome<RectD> {
    let (a, _) = instance.kind.source_clips(instance.context);
    let clip = effect.clip(a)?;
    if clip.is_connected() {
        let rod = clip.rod(time)?;
        let finite = [rod.x1, rod.y1, rod.x2, rod.y2]
            .iter()
            .all(|v| v.is_finite());
        if finite && rod.width() > 0.0 && rod.height() > 0.0 && rod.width() < 65536.0 {
            return Ok(rod);
        }
    }
    match effect.project() {
        Some((origin, size)) => Ok(RectD::new(
            origin.x,
            origin.y,
            origin.x + size.x,
            origin.y + size.y,
        )),
        None => Err(Failure::BadInput(
            "Reset Grid: connect Source A, or use a host that says its project size".into(),
        )),
    }
}
