//! What the command line's values mean beyond their syntax: `--param`
//! settings of any node param and `--line` keys of the line slots, each
//! read against the node it will be set on.

pub mod line_key;
pub mod param_value;
