//! The Warp node: one source warped toward the features' positions at `t`
//! (t = 1 lands A's features on B's positions). Filter and general contexts.

use morphfx::make_warp::Method;
use morphfx::views::View;

use super::kind::{NodeKind, Sources};
use super::node::Node;
use ofx_layer::plugin::Context;

pub struct Warp;

impl Node for Warp {
    const KIND: &'static NodeKind = &NodeKind {
        id: c"net.morphfx.Warp",
        label: "MorphFX Warp",
        description: "Warps one image so its features (A positions) move toward \
            their B positions by progress t.",
        contexts: &[Context::Filter, Context::General],
        sources: Sources::One("Source"),
        timing_matte: false,
        // Every method but auto, which finds its warp from two pictures.
        methods: &[
            Method::Field,
            Method::Mesh,
            Method::Triangles,
            Method::ThinPlate,
            Method::Mffd,
            Method::Hybrid,
        ],
        views: &[
            View::WarpedA,
            View::StmapA,
            View::Grid,
            View::Folds,
            View::Vectors,
        ],
        view_labels: &[(View::WarpedA, "warped"), (View::StmapA, "stmap")],
    };
}
