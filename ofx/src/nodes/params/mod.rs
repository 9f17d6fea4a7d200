//! The params both nodes share: their ids, choice options and table (each
//! param declared once), and their values read at a time.

mod choices;
mod ids;
mod reader;
mod settings;
mod table;
#[cfg(test)]
mod tests;

pub use choices::*;
pub use ids::*;
pub use reader::*;
pub use settings::*;
pub use table::*;
