//! Subcommands whose flags are defined only when they are used.

use std::ops::{Deref, DerefMut};

use clap::{ArgMatches, Args, Command, FromArgMatches};

/// A subcommand's arguments `T`, added to the parser only when that subcommand is the one
/// invoked (clap's [`Command::defer`]).
///
/// The derive API defines every flag of every subcommand before it parses anything: for the
/// `toonkit` command tree that was ~0.7 ms of a 16 ms `toonkit smear offsets` run. Wrapping a
/// subcommand variant's arguments in `Deferred` keeps the variant's name and summary in
/// `--help` and defines its flags when clap descends into it; parsing, help and errors are
/// unchanged (`deferred_subcommands_parse_like_eager_ones` below).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub(crate) struct Deferred<T>(pub(crate) T);

/// `command` with every deferred subcommand's flags defined ([`Command::build`]), for code
/// that reads the parser rather than parsing with it (e.g. looking up a subcommand's
/// arguments).
pub(crate) fn built(mut command: Command) -> Command {
    command.build();
    command
}

impl<T> Deref for Deferred<T> {
    type Target = T;
    fn deref(&self) -> &T {
        &self.0
    }
}

impl<T> DerefMut for Deferred<T> {
    fn deref_mut(&mut self) -> &mut T {
        &mut self.0
    }
}

impl<T: FromArgMatches> FromArgMatches for Deferred<T> {
    fn from_arg_matches(matches: &ArgMatches) -> Result<Self, clap::Error> {
        T::from_arg_matches(matches).map(Deferred)
    }

    fn from_arg_matches_mut(matches: &mut ArgMatches) -> Result<Self, clap::Error> {
        T::from_arg_matches_mut(matches).map(Deferred)
    }

    fn update_from_arg_matches(&mut self, matches: &ArgMatches) -> Result<(), clap::Error> {
        self.0.update_from_arg_matches(matches)
    }

    fn update_from_arg_matches_mut(&mut self, matches: &mut ArgMatches) -> Result<(), clap::Error> {
        self.0.update_from_arg_matches_mut(matches)
    }
}

impl<T: Args> Args for Deferred<T> {
    fn group_id() -> Option<clap::Id> {
        T::group_id()
    }

    fn augment_args(cmd: Command) -> Command {
        cmd.defer(T::augment_args)
    }

    fn augment_args_for_update(cmd: Command) -> Command {
        cmd.defer(T::augment_args_for_update)
    }
}

#[cfg(test)]
mod tests {
    use clap::{Parser, Subcommand};

    use super::*;

    #[derive(Debug, Parser)]
    #[command(name = "tool", version, propagate_version = true)]
    struct Cli {
        #[arg(long, global = true)]
        json: bool,
        #[command(subcommand)]
        command: Tool,
    }

    #[derive(Debug, Subcommand)]
    enum Tool {
        /// Scales things.
        Scale(Deferred<ScaleArgs>),
        /// Nested tools.
        Nest(Deferred<NestArgs>),
    }

    #[derive(Debug, Args)]
    struct ScaleArgs {
        /// The input.
        input: String,
        /// Factor.
        #[arg(long, default_value_t = 2.0)]
        factor: f32,
    }

    #[derive(Debug, Args)]
    #[command(args_conflicts_with_subcommands = true)]
    struct NestArgs {
        #[command(subcommand)]
        inner: Option<Inner>,
        #[arg(long)]
        style: Option<String>,
    }

    #[derive(Debug, Subcommand)]
    enum Inner {
        /// Inner tool.
        Deep(Deferred<ScaleArgs>),
    }

    /// Flags, defaults, globals after the subcommand and nested deferred subcommands parse as
    /// without the wrapper; errors and help name the deferred flags.
    #[test]
    fn deferred_subcommands_parse_like_eager_ones() {
        let cli = Cli::try_parse_from(["tool", "scale", "in.glb", "--json"]).unwrap();
        let Tool::Scale(a) = cli.command else {
            panic!("scale")
        };
        assert!(cli.json);
        assert_eq!((a.input.as_str(), a.factor), ("in.glb", 2.0));

        let cli = Cli::try_parse_from(["tool", "nest", "deep", "x", "--factor", "3"]).unwrap();
        let Tool::Nest(n) = cli.command else {
            panic!("nest")
        };
        let Some(Inner::Deep(d)) = &n.inner else {
            panic!("deep")
        };
        assert_eq!(d.factor, 3.0);
        let cli = Cli::try_parse_from(["tool", "nest", "--style", "s"]).unwrap();
        let Tool::Nest(n) = cli.command else {
            panic!("nest")
        };
        assert_eq!(n.style.as_deref(), Some("s"));

        let err = Cli::try_parse_from(["tool", "scale", "x", "--factr", "3"]).unwrap_err();
        assert!(err.to_string().contains("--factr"), "{err}");
        let err = Cli::try_parse_from(["tool", "scale"]).unwrap_err();
        assert!(err.to_string().contains("<INPUT>"), "{err}");
        let help = Cli::try_parse_from(["tool", "scale", "--help"])
            .unwrap_err()
            .to_string();
        assert!(
            help.contains("--factor") && help.contains("--json"),
            "{help}"
        );
        let top = Cli::try_parse_from(["tool", "--help"])
            .unwrap_err()
            .to_string();
        assert!(top.contains("scale  Scales things"), "{top}");
        let version = Cli::try_parse_from(["tool", "scale", "--version"]).unwrap_err();
        assert_eq!(version.kind(), clap::error::ErrorKind::DisplayVersion);
    }
}
