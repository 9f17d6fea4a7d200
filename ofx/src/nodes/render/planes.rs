//! Layers besides colour, in hosts with the multi-plane extension (Natron):
//! every plane of the sources goes through the colour's warps (the same
//! scene, params and cached maps). Planes that hold IDs or mattes are
//! sampled nearest and never blended: the Morph node switches from A's to
//! B's at half way rather than dissolving, no motion blur averages them,
//! and Mix and the Mask act as switches at one half.

use morphfx::image::{holds_ids, Filter};
use morphfx::views::View;
use ofx_layer::clips::{EffectHandle, HostImage};
use ofx_layer::planes::{self, ClipPlanes};
use ofx_layer::{Failure, Outcome, Reply};

use crate::nodes::kind::{MASK_CLIP, OUTPUT_CLIP, TIMING_CLIP};
use crate::nodes::params::{Reader, Settings, OFFSET_A};
use crate::nodes::state::NodeState;

/// `GetClipComponents`: the output makes every plane Source A has, colour
/// first; Source B is asked for those of them it has; the mattes give
/// their colour. Planes the host asks for that A lacks pass through from A.
pub fn clip_planes(
    node: &NodeState,
    effect: &EffectHandle,
    time: f64,
    out: &mut ClipPlanes,
) -> Outcome<Reply> {
    // Hosts ask before every render: read the one param the answer needs.
    let offset_a = Reader::new(node.params(), node.kind, time).int(&OFFSET_A);
    let (a, b) = node.kind.source_clips(node.context);
    let present = |name: &str| -> Outcome<Vec<String>> {
        let clip = effect.clip(name)?;
        Ok(match clip.is_connected() {
            true => clip.planes_present(),
            false => Vec::new(),
        })
    };
    let mut made = vec![planes::COLOUR.to_owned()];
    made.extend(present(a)?.into_iter().filter(|p| !planes::is_colour(p)));
    out.set(a, made.clone());
    if let Some(b) = b {
        let has = present(b)?;
        let wanted = made
            .iter()
            .filter(|p| planes::is_colour(p) || has.contains(p));
        out.set(b, wanted.cloned().collect());
    }
    if node.kind.timing_matte {
        out.set(TIMING_CLIP, vec![planes::COLOUR.to_owned()]);
    }
    out.set(MASK_CLIP, vec![planes::COLOUR.to_owned()]);
    out.set(OUTPUT_CLIP, made);
    out.pass_through(a, time + offset_a as f64);
    Ok(Reply::Done)
}

/// Whether a render's planes include colour (a host that names none means it).
pub(super) fn colour_asked(asked: &[String]) -> bool {
    asked.is_empty() || asked.iter().any(|p| planes::is_colour(p))
}

/// How a plane besides colour is drawn: the view and filter it takes,
/// and whether it holds IDs (never blended: no dissolve, no blur, Mix
/// and the Mask as switches).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Treatment {
    pub view: View,
    pub filter: Filter,
    pub ids: bool,
}

/// The treatment of `plane` under `settings`, at progress `t`: the
/// colour's view when it is a picture (the source warped otherwise) and
/// filter; for IDs nearest, and on the Morph node (`has_b`) A's IDs
/// below half way, B's from there.
pub(super) fn treatment(plane: &str, settings: &Settings, has_b: bool, t: f64) -> Treatment {
    let name = planes::name_of(plane);
    let ids = holds_ids(name) || settings.id_layers.iter().any(|n| n == name);
    let mut view = match settings.view.is_picture() {
        true => settings.view,
        false => View::WarpedA,
    };
    if ids && view == View::Morph && has_b {
        view = if t < 0.5 {
            View::WarpedA
        } else {
            View::WarpedB
        };
    }
    let filter = if ids {
        Filter::Nearest
    } else {
        settings.filter
    };
    Treatment { view, filter, ids }
}

/// The image of `plane` a clip gives at `at`: `None` when the clip is not
/// connected or lacks the plane (transparent black, as the extension says
/// of a plane a clip cannot give).
pub(super) fn plane_image(
    effect: &EffectHandle,
    clip: &str,
    at: f64,
    plane: &str,
) -> Outcome<Option<HostImage>> {
    let c = effect.clip(clip)?;
    if !c.is_connected() || !c.planes_present().iter().any(|p| p == plane) {
        return Ok(None);
    }
    c.image_plane(at, plane)
}

/// The output's image of `plane`.
pub(super) fn output_image(effect: &EffectHandle, time: f64, plane: &str) -> Outcome<HostImage> {
    effect
        .clip(OUTPUT_CLIP)?
        .image_plane(time, plane)?
        .ok_or_else(|| {
            let name = planes::name_of(plane);
            Failure::Failed(format!("the host gave no output image of plane {name}"))
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nodes::node::Node;
    use crate::nodes::{Morph, Warp};

    #[test]
    fn id_planes_are_sampled_nearest_and_switch_sources_at_half_way() {
        let morph = <Morph as Node>::KIND;
        let mut settings = Settings::defaults(morph);
        let id = planes::natron_plane("objectId", &["id"]);
        let n = planes::natron_plane("N", &["X", "Y", "Z"]);
        let of = |plane: &str, s: &Settings, t| treatment(plane, s, true, t);
        assert_eq!(
            of(&id, &settings, 0.49),
            Treatment {
                view: View::WarpedA,
                filter: Filter::Nearest,
                ids: true
            }
        );
        assert_eq!(of(&id, &settings, 0.5).view, View::WarpedB);
        assert_eq!(
            of(&n, &settings, 0.3),
            Treatment {
                view: View::Morph,
                filter: Filter::Bilinear,
                ids: false
            }
        );
        settings.id_layers = vec!["N".into()];
        assert!(of(&n, &settings, 0.3).ids, "listed in ID Layers");
        // A diagnostic view leaves other planes as the warped source.
        let mut stmap = Settings::defaults(<Warp as Node>::KIND);
        stmap.view = View::StmapA;
        assert_eq!(treatment(&n, &stmap, false, 0.3).view, View::WarpedA);
    }
}
