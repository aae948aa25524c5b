//! `--help` describes every positional argument and every flag of every subcommand.

use clap::CommandFactory;

#[test]
fn every_argument_of_every_subcommand_has_a_description() {
    let cli = vehsim::cli::Cli::command();
    let mut missing = Vec::new();
    let mut seen = 0;
    for sub in cli.get_subcommands() {
        assert!(sub.get_about().is_some(), "{} has no description", sub.get_name());
        for arg in sub.get_arguments().filter(|a| !["help", "version"].contains(&a.get_id().as_str())) {
            seen += 1;
            if arg.get_help().is_none_or(|h| h.to_string().trim().is_empty()) {
                missing.push(format!("{} {}", sub.get_name(), arg.get_id()));
            }
        }
    }
    assert!(seen > 30, "only {seen} arguments found");
    assert!(missing.is_empty(), "arguments without a description: {missing:?}");
}
