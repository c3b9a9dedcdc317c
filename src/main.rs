//! The `blutrace` binary: the command line lives in the library ([`blutrace::cli`]).

fn main() -> std::process::ExitCode {
    blutrace::cli::main()
}
