//! `wobblog completions` and `wobblog man`: generated from the clap
//! definitions, so they never drift from the commands.

use std::path::Path;

use clap::CommandFactory;
use clap_complete::Shell;

use crate::cli::Cli;
use crate::output::Output;
use crate::CliError;

/// Arguments of `wobblog completions`.
#[derive(clap::Args)]
pub struct Args {
    /// The shell to complete for.
    #[arg(value_enum)]
    pub shell: Shell,
}

/// Prints the completion script for `args.shell`.
pub fn run(args: &Args) -> Result<(), CliError> {
    let mut script = Vec::new();
    clap_complete::generate(args.shell, &mut Cli::command(), "wobblog", &mut script);
    crate::cmd::logs::print(Output::stdout(&[])?, &String::from_utf8_lossy(&script))
}

/// Prints the man page, with one section per subcommand.
pub fn man() -> Result<(), CliError> {
    let page = man_page().map_err(|e| CliError::file(Path::new("<stdout>"), e))?;
    crate::cmd::logs::print(Output::stdout(&[])?, &page)
}

/// The man page as roff text.
pub fn man_page() -> std::io::Result<String> {
    let command = Cli::command();
    let mut roff = Vec::new();
    clap_mangen::Man::new(command.clone()).render(&mut roff)?;
    for sub in command.get_subcommands() {
        let name = format!("wobblog-{}", sub.get_name());
        clap_mangen::Man::new(sub.clone())
            .title(name)
            .render(&mut roff)?;
    }
    Ok(String::from_utf8_lossy(&roff).into_owned())
}
