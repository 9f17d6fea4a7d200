//! The Warp node: one source warped toward the features' positions at `t`
//! (t = 1 lands A's features on B's positions). Filter and general contexts.

use super::NodeInfo;

pub const INFO: NodeInfo = NodeInfo {
    id: "net.morphfx.Warp",
    label: "MorphFX Warp",
    description:
        "Warps one image so its features (A positions) move toward their B positions by progress t.",
    contexts: &[
        c"OfxImageEffectContextFilter",
        c"OfxImageEffectContextGeneral",
    ],
};

pub const SOURCE_CLIP: &str = "Source";
