//! The `roam` binary: parse arguments, set up tracing, call the library.

mod cli;

use clap::Parser;

fn main() -> std::process::ExitCode {
    // Before any thread starts: it sets the environment Zenoh reads its pool sizes from.
    let zenoh_threads = roam_runtime::zenoh_threads::provision();
    let cli = cli::Cli::parse();
    roam_runtime::telemetry::init();
    tracing::debug!(?zenoh_threads, "Zenoh's runtimes");
    // Zenoh needs tokio's multi-thread runtime.
    let runtime = match tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .build()
    {
        Ok(runtime) => runtime,
        Err(e) => {
            eprintln!("error: cannot start the async runtime: {e}");
            return std::process::ExitCode::FAILURE;
        }
    };
    match runtime.block_on(cli::run(cli)) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}
