//! The `pada` command; see `pada --help`.

fn main() {
    let code = match pada::cli::run(std::env::args_os()) {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("error: {}", e.one_line());
            e.exit_code()
        }
    };
    std::process::exit(code);
}
