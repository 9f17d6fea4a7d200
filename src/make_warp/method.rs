//! Which warp generator a morph uses.

use crate::choice::Choice;

/// The warp generator (scene key `method`, the nodes' Method param).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Method {
    /// Beier-Neely line-pair field warping.
    #[default]
    Field,
    /// Smythe and Wolberg's two-pass Catmull-Rom mesh warp.
    Mesh,
    /// Piecewise-affine warping over a Delaunay triangulation.
    Triangles,
    /// Lee et al.'s thin-plate deformable surfaces, solved by multigrid.
    ThinPlate,
    /// Lee, Wolberg et al.'s multilevel free-form deformation.
    Mffd,
    /// The hybrid of MFFD and thin plate (Lee, Wolberg et al.).
    Hybrid,
    /// Gao and Sederberg's automatic warp by work minimisation.
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
