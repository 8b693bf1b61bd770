//! Defaults of flag structs, taken from their clap declarations, so that the values an experiment file leaves
//! out are exactly those the command line leaves out (`#[serde(default)]` on a flag struct calls this).

/// `T` as clap builds it from no arguments: every field at its `default_value_t` (or None / empty / false).
pub fn clap_defaults<T: clap::Args + clap::FromArgMatches>() -> T {
    let cmd = T::augment_args(clap::Command::new("defaults").no_binary_name(true));
    // Cannot fail unless a flag is declared required without a default, which `cli_is_consistent` and the
    // defaults tests would catch first; the message names the struct if it ever does.
    let matches = cmd
        .try_get_matches_from(std::iter::empty::<&str>())
        .unwrap_or_else(|e| panic!("{} has a required flag: {e}", std::any::type_name::<T>()));
    T::from_arg_matches(&matches)
        .unwrap_or_else(|e| panic!("{} defaults: {e}", std::any::type_name::<T>()))
}
