//! The `pada` command; see `pada --help`.

use std::io::Write;

fn main() {
    // The last of standard output is flushed here, so that a full disk or a
    // closed pipe is still an error and not dropped at exit.
    let result = pada::cli::run(std::env::args_os()).and_then(|()| pada::console::flush());
    let code = match result {
        Ok(()) => 0,
        Err(e) => {
            // Not eprintln!: with standard error closed too there is nothing
            // left to tell, but the exit code still says it.
            let _ = writeln!(std::io::stderr(), "error: {}", e.one_line());
            e.exit_code()
        }
    };
    std::process::exit(code);
}
