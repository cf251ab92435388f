//! The `main` shared by the tool binaries that write files through this crate's
//! [`crate::output`] (`tumble-bench`, `tumble-report`): one place for their command line,
//! `--version` and the `error: …` exit.

/// The `main` of a tool binary (`tumble-bench`, `tumble-report`): parses the command line into
/// `$options` (a `clap::Args`, with `--version`, and the doc comments given as the tool's
/// about), runs `$run(&options)`, and exits with success, or prints `error: …` and fails. The
/// calling crate needs `clap` with its `derive` feature.
#[macro_export]
macro_rules! tool_main {
    ($(#[$about:meta])* $options:ty, $run:expr) => {
        $(#[$about])*
        #[derive(clap::Parser)]
        #[command(version)]
        struct Args {
            #[command(flatten)]
            options: $options,
        }

        fn main() -> std::process::ExitCode {
            match ($run)(&<Args as clap::Parser>::parse().options) {
                Ok(()) => std::process::ExitCode::SUCCESS,
                Err(e) => {
                    eprintln!("error: {e}");
                    std::process::ExitCode::FAILURE
                }
            }
        }
    };
}
