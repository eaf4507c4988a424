//! `wobblog`: the wobble logger's host tool.

fn main() -> std::process::ExitCode {
    wobblog::cli::main()
}
