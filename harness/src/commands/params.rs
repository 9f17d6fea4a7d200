//! `morphfx params`: every param of the nodes, as `--param` takes them.

use std::path::Path;

use super::job::{MORPH_ID, WARP_ID};
use crate::args::param_value::param_lines;
use crate::host::{Bundle, HostError};

/// Lists the params of `node` (`morph`, `warp`, or both when `None`), in
/// the order the node defines them.
pub fn list_params(bundle_path: &Path, node: Option<&str>) -> Result<(), HostError> {
    let nodes: &[(&str, &str, &str)] = &[
        ("morph", MORPH_ID, "OfxImageEffectContextGeneral"),
        ("warp", WARP_ID, "OfxImageEffectContextFilter"),
    ];
    let chosen: Vec<_> = match node {
        None => nodes.iter().collect(),
        Some(n) => {
            let found: Vec<_> = nodes.iter().filter(|(name, _, _)| *name == n).collect();
            if found.is_empty() {
                return Err(HostError::bad(format!(
                    "--node {n}: expected morph or warp"
                )));
            }
            found
        }
    };
    let bundle = Bundle::load(bundle_path)?;
    for (name, id, context) in chosen {
        let inst = bundle.instance(id, context)?;
        println!("# {name} ({id}): --param ID=VALUE or ID@FRAME=VALUE");
        for line in param_lines(&inst) {
            println!("{line}");
        }
    }
    Ok(())
}
