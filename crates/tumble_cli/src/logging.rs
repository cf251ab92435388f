//! Log output: `tracing` events (stability predictions, quarantined bodies, …) on stderr.

use std::io::IsTerminal;

use tracing_subscriber::EnvFilter;
use tracing_subscriber::filter::LevelFilter;
use tumble_scene::text::terminal_safe;

use crate::exit::{self, Failure};

/// The level `-v`/`-q` ask for: warnings by default, `-v` info, `-vv` debug, `-vvv` trace,
/// `-q` errors only.
pub(crate) fn level(verbose: u8, quiet: bool) -> LevelFilter {
    match (quiet, verbose) {
        (true, _) => LevelFilter::ERROR,
        (false, 0) => LevelFilter::WARN,
        (false, 1) => LevelFilter::INFO,
        (false, 2) => LevelFilter::DEBUG,
        (false, _) => LevelFilter::TRACE,
    }
}

/// Installs a `fmt` subscriber on stderr: `RUST_LOG` directives over the default level from
/// the flags; colour only on a terminal. A malformed `RUST_LOG` is an error naming it (escaped
/// for the terminal): the parser's own "ignoring …" message would echo its bytes raw, and a
/// setting that silently does nothing is no setting.
pub(crate) fn init(verbose: u8, quiet: bool) -> Result<(), Failure> {
    let level = level(verbose, quiet);
    let filter = match std::env::var("RUST_LOG") {
        Ok(directives) if !directives.trim().is_empty() => EnvFilter::builder()
            .with_default_directive(level.into())
            .parse(&directives)
            .map_err(|e| {
                Failure::new(
                    exit::ERROR,
                    format!(
                        "RUST_LOG `{}` is not a log filter: {}",
                        terminal_safe(&directives),
                        terminal_safe(&e.to_string())
                    ),
                )
            })?,
        Err(std::env::VarError::NotUnicode(directives)) => {
            return Err(Failure::new(
                exit::ERROR,
                format!(
                    "RUST_LOG `{}` is not a log filter: not valid Unicode",
                    terminal_safe(&directives.to_string_lossy())
                ),
            ));
        }
        // The CLI names bodies and springs as the scene does when it reports predictions and
        // quarantines (target `tumble`); the engine's own events say the same with entity ids,
        // so by default they are kept to errors. `RUST_LOG` shows them.
        _ => EnvFilter::builder().parse_lossy(format!(
            "{level},tumble_ecs::schedule=error,tumble_ecs::components=error"
        )),
    };
    // `try_init`: a second subscriber (none today) must not make the CLI panic.
    let _ = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .with_ansi(std::io::stderr().is_terminal())
        .without_time()
        .try_init();
    Ok(())
}
