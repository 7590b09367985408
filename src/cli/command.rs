//! One definition per subcommand: its name, help, clap arguments and how it runs, and — where it
//! has them — the settings its part files hold, how it runs as a batch job, the part it traces
//! without meshing and what the browser editor offers to change. [`super::COMMANDS`] lists them;
//! `main.rs`, `latvox batch`, part files and the editor all read them from there, so a new
//! command is its own module and one line in that list.

use super::clap_message;
use super::part::Part;
use clap::{ArgMatches, FromArgMatches};
use latvox::batch::Task;
use latvox::{Error, Result};

/// Arguments as a batch job.
pub(crate) type JobOf = fn(&ArgMatches) -> Result<Box<dyn Task>>;

/// Arguments as the part they describe, to trace.
pub(crate) type TraceOf = fn(&ArgMatches, latvox::render::Fidelity) -> Result<Part>;

/// A subcommand.
pub(crate) struct Command {
    /// Its name on the command line, in part files and in job files.
    pub name: &'static str,
    /// Former names, still understood (hidden from the help).
    pub aliases: &'static [&'static str],
    /// What it does, one sentence (the help's summary).
    pub about: &'static str,
    /// The help's examples, after the options.
    pub examples: &'static str,
    /// Its arguments, added to a clap command.
    pub args: fn(clap::Command) -> clap::Command,
    /// Runs it on parsed arguments (`quiet`: no progress); the exit code.
    pub run: fn(&ArgMatches, bool) -> Result<i32>,
    /// The settings that define its part, where it makes one that part files hold.
    pub part: Option<PartKeys>,
    /// Its arguments as a batch job, where it can be one.
    pub job: Option<JobOf>,
    /// Its part as an implicit solid to trace (render, slice, view), where it has one.
    pub trace: Option<TraceOf>,
    /// The choices the browser editor offers for its part: option name → values.
    pub choices: Option<fn() -> serde_json::Value>,
}

/// The settings that define a part, saved by `--save-part` and read back by `--part`: every
/// option but where the files go.
#[derive(Clone, Copy)]
pub(crate) struct PartKeys {
    /// The command's own options.
    pub own: &'static [&'static str],
    /// Options it shares with other commands: a lattice's box and meshing
    /// ([`super::part::LATTICE_BOX`]), or the meshing alone ([`super::part::MESHING`]).
    pub shared: &'static [&'static str],
}

impl Command {
    /// A command with a name, help, arguments and a run, and nothing else yet.
    pub(crate) const fn new(
        name: &'static str,
        about: &'static str,
        examples: &'static str,
        args: fn(clap::Command) -> clap::Command,
        run: fn(&ArgMatches, bool) -> Result<i32>,
    ) -> Self {
        Command {
            name,
            aliases: &[],
            about,
            examples,
            args,
            run,
            part: None,
            job: None,
            trace: None,
            choices: None,
        }
    }

    /// The clap command: name, help, arguments, hidden aliases.
    pub(crate) fn clap(&self) -> clap::Command {
        // The summary set after the arguments: a flattened group's doc comment sets one too.
        (self.args)(clap::Command::new(self.name))
            .about(self.about)
            .long_about(None)
            .after_help(self.examples)
            .aliases(self.aliases.iter().copied())
    }

    /// The clap command parsing a job's or a part file's options (no binary name, no --help).
    pub(crate) fn parser(&self) -> clap::Command {
        let mut cmd = (self.args)(clap::Command::new(self.name))
            .no_binary_name(true)
            .disable_help_flag(true);
        cmd.build();
        cmd
    }

    /// Whether `name` names this command (its name or a former one).
    pub(crate) fn is(&self, name: &str) -> bool {
        self.name == name || self.aliases.contains(&name)
    }
}

/// The command `name` names (by its name or a former one).
pub(crate) fn find(name: &str) -> Option<&'static Command> {
    super::COMMANDS.iter().copied().find(|c| c.is(name))
}

/// The names of the commands that have `what`, for messages: "tpms, strut or fill".
pub(crate) fn names_with(what: impl Fn(&Command) -> bool) -> String {
    let names: Vec<String> = super::COMMANDS
        .iter()
        .filter(|c| what(c))
        .map(|c| format!("\"{}\"", c.name))
        .collect();
    match names.split_last() {
        Some((last, [])) => last.clone(),
        Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
        None => String::new(),
    }
}

/// Arguments of type `A` from parsed matches.
pub(crate) fn parsed<A: FromArgMatches>(m: &ArgMatches) -> Result<A> {
    A::from_arg_matches(m).map_err(|e| Error::invalid(clap_message(e)))
}

/// Arguments of type `A` as a batch job.
pub(crate) fn job<A: FromArgMatches + Task + 'static>(m: &ArgMatches) -> Result<Box<dyn Task>> {
    Ok(Box::new(parsed::<A>(m)?))
}

#[cfg(test)]
mod tests {
    use super::super::COMMANDS;

    #[test]
    fn every_command_is_named_once_and_builds() {
        let mut names: Vec<&str> = COMMANDS
            .iter()
            .flat_map(|c| std::iter::once(c.name).chain(c.aliases.iter().copied()))
            .collect();
        let all = names.len();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), all, "a name or alias given twice: {names:?}");
        let cli = COMMANDS
            .iter()
            .fold(clap::Command::new("latvox"), |cmd, c| {
                cmd.subcommand(c.clap())
            });
        cli.debug_assert();
        for c in COMMANDS {
            assert!(
                !c.about.ends_with('.'),
                "{}: the summary ends without a period",
                c.name
            );
            assert!(
                c.examples.contains(&format!("latvox {}", c.name)),
                "{}: its help shows it",
                c.name
            );
        }
    }

    #[test]
    fn part_settings_are_options_of_their_command() {
        for c in COMMANDS {
            let cmd = c.parser();
            let missing: Vec<&str> = super::super::part::keys(c)
                .into_iter()
                .filter(|key| {
                    !cmd.get_arguments()
                        .any(|a| a.get_long() == Some(key) || a.get_id().as_str() == *key)
                })
                .collect();
            assert!(
                missing.is_empty(),
                "{}: part settings that are not its options: {missing:?}",
                c.name
            );
            // A command whose part is traced or edited has part files to read it from.
            if c.trace.is_some() || c.choices.is_some() {
                assert!(c.part.is_some(), "{}", c.name);
            }
        }
    }
}
