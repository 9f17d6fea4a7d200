//! What an image layer's (plane's) name says it holds.

/// Whether a layer's name says it holds IDs or mattes, whose values must
/// not be blended: `id` (`id`, `objectId`, `id2`), `crypto...`, and any
/// name holding `mask` or `matte`.
pub fn holds_ids(layer: &str) -> bool {
    let n = layer.to_ascii_lowercase();
    n.starts_with("id")
        || n.ends_with("id")
        || n.starts_with("crypto")
        || n.contains("mask")
        || n.contains("matte")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn id_and_matte_layers_are_known_by_name() {
        for id in [
            "id",
            "objectId",
            "ID2",
            "cryptomatte00",
            "crypto_object",
            "mask",
            "holdout_matte",
        ] {
            assert!(holds_ids(id), "{id}");
        }
        for other in ["rgba", "N", "P", "diffuse", "Z", "motion", "forward"] {
            assert!(!holds_ids(other), "{other}");
        }
    }
}
