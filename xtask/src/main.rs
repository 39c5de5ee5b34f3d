//! `cargo run -p xtask -- bindings [--check]`: regenerates the committed FMI 2.0 and FMI 3.0
//! bindings from third_party/fmi2/ and third_party/fmi3/, or with `--check` only verifies
//! them (exit status 1 when a committed file is out of date).

use std::fs;
use std::process::ExitCode;

const USAGE: &str = "\
usage: cargo run -p xtask -- bindings [--check]

bindings          regenerate the FMI 2.0 and 3.0 bindings from third_party/fmi2/ and fmi3/ with bindgen
                  (needs libclang; Debian: libclang-dev) and write the files that changed
bindings --check  regenerate in memory only; fail if a committed file differs";

fn bindings(check: bool) -> Result<ExitCode, String> {
    let root = xtask::workspace_root();
    let outputs = xtask::generate().map_err(|e| e.to_string())?;
    let mut stale = 0;
    for output in &outputs {
        let Some(drift) = xtask::drift(&root, output) else {
            println!("{}: up to date", output.path);
            continue;
        };
        if check {
            eprintln!("{} {drift}", output.path);
            stale += 1;
        } else {
            let path = root.join(output.path);
            fs::write(&path, &output.contents)
                .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
            println!("{}: written", output.path);
        }
    }
    if stale > 0 {
        eprintln!(
            "the committed FMI bindings are out of date: run `cargo run -p xtask -- bindings` \
             and commit the result"
        );
        return Ok(ExitCode::FAILURE);
    }
    Ok(ExitCode::SUCCESS)
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let result = match args.as_slice() {
        ["bindings"] => bindings(false),
        ["bindings", "--check"] => bindings(true),
        ["-h" | "--help" | "help"] => {
            println!("{USAGE}");
            return ExitCode::SUCCESS;
        }
        _ => {
            eprintln!("{USAGE}");
            return ExitCode::from(2);
        }
    };
    result.unwrap_or_else(|message| {
        eprintln!("xtask: {message}");
        ExitCode::from(2)
    })
}
