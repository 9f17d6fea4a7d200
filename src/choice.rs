//! Closed sets of named options: methods, filters, edge modes, views, ...
//! A scene names them by [`Choice::name`]; a host stores a choice param by
//! its index in [`Choice::ALL`], so that order only ever grows at the end.

/// A closed set of named options.
pub trait Choice: Copy + PartialEq + Sized + 'static {
    /// Every option, in the order hosts index them.
    const ALL: &'static [Self];

    /// The option's name, as scenes and the command line spell it.
    fn name(self) -> &'static str;

    /// The option named `name`.
    fn parse(name: &str) -> Option<Self> {
        Self::ALL.iter().copied().find(|o| o.name() == name)
    }

    /// Every option's name, in order.
    fn names() -> Vec<&'static str> {
        Self::ALL.iter().map(|o| o.name()).collect()
    }
}
