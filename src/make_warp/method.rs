//! Which warp generator a morph uses.

use crate::choice::Choice;

/// The warp generator (scene key `method`, the nodes' Method param).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Method {
    #[default]
    Field,
    Mesh,
    Triangles,
    ThinPlate,
    Mffd,
    Hybrid,
    Auto,
}

impl Choice for Method {
    const ALL: &'static [Method] = &[
        Method::Field,
        Method::Mesh,
        Method::Triangles,
        Method::ThinPlate,
        Method::Mffd,
        Method::Hybrid,
        Method::Auto,
    ];

    fn name(self) -> &'static str {
        match self {
            Method::Field => "field",
            Method::Mesh => "mesh",
            Method::Triangles => "triangles",
            Method::ThinPlate => "thin-plate",
            Method::Mffd => "mffd",
            Method::Hybrid => "hybrid",
            Method::Auto => "auto",
        }
    }
}

impl Method {
    /// Methods that cannot do anything without features (`auto` finds its own
    /// correspondence, `mesh` takes its own mesh).
    pub fn needs_features(self) -> bool {
        !matches!(self, Method::Auto | Method::Mesh)
    }
}
