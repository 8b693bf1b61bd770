//! Defaults of flag structs, taken from their clap declarations, so that the values an experiment file leaves
//! out are exactly those the command line leaves out (`#[serde(default)]` on a flag struct calls this); and the
//! two things every flag struct shares in `-h`: the headings its flags are grouped under and the value parser of
//! an enum flag.

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

/// The headings `lodbench <command> -h` groups the flags under (`help_heading = heading::...`); docs/flags.md
/// follows the same groups. A flag with none is listed first, under clap's "Options".
pub mod heading {
    /// What every scene takes: the viewport, the frames and the camera.
    pub const SCENE: &str = "Scene";
    /// The flags only the built-in scenes read.
    pub const BUILT_IN: &str = "Built-in scenes";
    /// The flags only a user's file (`--scene FILE.glb`, and `--mesh` for `--simplify`) reads.
    pub const FILE: &str = "Your file (--scene FILE.glb)";
    /// Where LODs switch and how a transition runs.
    pub const SWITCHES: &str = "Switches and transitions";
    /// TAA, shadows and extra shading work.
    pub const EFFECTS: &str = "Effects";
    /// The impostor that ends every chain (`--impostor`).
    pub const IMPOSTORS: &str = "Impostors";
    /// The methods' own flags.
    pub const METHODS: &str = "Methods";
    /// How the timing and the quality pass are made.
    pub const MEASUREMENT: &str = "Measurement";
    /// Where results go, and the frames dumped.
    pub const OUTPUT: &str = "Output";
}

/// The value parser of an enum flag, with the values' names only (`value_parser = names_only::<E>()`): a
/// variant's doc comment is for developers, and one value with a help text would make clap print `--help` as the
/// long listing, every value on a line of its own; the users' text of each value is in docs/flags.md.
pub fn names_only<E: clap::ValueEnum + Clone + Send + Sync + 'static>() -> NamesOnly<E> {
    NamesOnly(std::marker::PhantomData)
}

/// See [`names_only`].
#[derive(Clone)]
pub struct NamesOnly<E>(std::marker::PhantomData<fn() -> E>);

impl<E: clap::ValueEnum + Clone + Send + Sync + 'static> clap::builder::TypedValueParser
    for NamesOnly<E>
{
    type Value = E;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &std::ffi::OsStr,
    ) -> Result<E, clap::Error> {
        clap::builder::EnumValueParser::<E>::new().parse_ref(cmd, arg, value)
    }

    fn possible_values(
        &self,
    ) -> Option<Box<dyn Iterator<Item = clap::builder::PossibleValue> + '_>> {
        Some(Box::new(
            E::value_variants()
                .iter()
                .filter_map(clap::ValueEnum::to_possible_value)
                .map(|v| v.help(None::<&'static str>)),
        ))
    }
}
