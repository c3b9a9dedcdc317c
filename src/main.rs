//! The `blutrace` binary: the command line ([`cli`]), one file a subcommand, over the
//! `blutrace` library.

mod cli;

fn main() -> std::process::ExitCode {
    cli::main()
}
