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

    /// The option at `index` of [`Choice::ALL`], if there is one.
    fn from_index(index: i64) -> Option<Self> {
        usize::try_from(index)
            .ok()
            .and_then(|i| Self::ALL.get(i))
            .copied()
    }

    /// The option's index in [`Choice::ALL`].
    fn index(self) -> usize {
        Self::ALL
            .iter()
            .position(|o| *o == self)
            .expect("every option is in ALL")
    }

    /// Every option's name, in order.
    fn names() -> Vec<&'static str> {
        Self::ALL.iter().map(|o| o.name()).collect()
    }
}
