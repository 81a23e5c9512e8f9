//! `luau-check [--definitions FILE]... SCRIPT...`: type-checks Luau scripts in strict mode
//! with Luau's own Analysis library (the new solver), after loading the host's definition
//! files, and prints each problem as `path:line:column: error: message`.
//!
//! Every script must open with `--!strict`, so an editor checks it the same way. Exits 1
//! when any script has an error (or lacks the header), 2 on bad arguments or an unreadable
//! file, 0 otherwise.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use luau_analyze::{CheckOptions, Checker, Severity};

/// The longest a single script may take to check before it counts as an error.
const CHECK_TIMEOUT: Duration = Duration::from_secs(60);

fn main() -> ExitCode {
    let mut definitions: Vec<PathBuf> = Vec::new();
    let mut scripts: Vec<PathBuf> = Vec::new();
    let mut args = std::env::args_os().skip(1);
    while let Some(arg) = args.next() {
        if arg == "--definitions" {
            match args.next() {
                Some(path) => definitions.push(path.into()),
                None => return usage("--definitions needs a file"),
            }
        } else if arg == "--help" || arg == "-h" {
            println!("usage: luau-check [--definitions FILE]... SCRIPT...");
            return ExitCode::SUCCESS;
        } else {
            scripts.push(arg.into());
        }
    }
    if scripts.is_empty() {
        return usage("no script given");
    }

    let mut checker = match Checker::new() {
        Ok(checker) => checker,
        Err(e) => {
            eprintln!("luau-check: cannot create the checker: {e}");
            return ExitCode::from(2);
        }
    };
    for path in &definitions {
        let source = match std::fs::read_to_string(path) {
            Ok(source) => source,
            Err(e) => return unreadable(path, &e),
        };
        let name = format!("@{}", path.display());
        if let Err(e) = checker.add_definitions_with_name(&source, &name) {
            eprintln!(
                "{}: error: the definitions do not load: {e}",
                path.display()
            );
            return ExitCode::from(1);
        }
    }

    let mut errors = 0usize;
    let mut failed_files = 0usize;
    for path in &scripts {
        let source = match std::fs::read_to_string(path) {
            Ok(source) => source,
            Err(e) => return unreadable(path, &e),
        };
        let before = errors;
        if source.lines().next().map(str::trim_end) != Some("--!strict") {
            println!(
                "{}:1:1: error: the first line must be --!strict",
                path.display()
            );
            errors += 1;
        }
        let name = path.display().to_string();
        let options = CheckOptions {
            timeout: Some(CHECK_TIMEOUT),
            module_name: Some(&name),
            ..CheckOptions::default()
        };
        match checker.check_with_options(&source, options) {
            Ok(result) => {
                if result.timed_out || result.cancelled {
                    println!(
                        "{}:1:1: error: the check did not finish within {} s",
                        path.display(),
                        CHECK_TIMEOUT.as_secs()
                    );
                    errors += 1;
                }
                for d in &result.diagnostics {
                    let kind = match d.severity {
                        Severity::Error => {
                            errors += 1;
                            "error"
                        }
                        Severity::Warning => "warning",
                    };
                    println!(
                        "{}:{}:{}: {kind}: {}",
                        path.display(),
                        d.line + 1,
                        d.col + 1,
                        d.message
                    );
                }
            }
            Err(e) => {
                println!("{}:1:1: error: the checker failed: {e}", path.display());
                errors += 1;
            }
        }
        if errors > before {
            failed_files += 1;
        }
    }
    println!(
        "luau-check: {} scripts, {} with errors, {errors} errors (strict mode)",
        scripts.len(),
        failed_files
    );
    if errors > 0 {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}

/// Reports a usage error.
fn usage(why: &str) -> ExitCode {
    eprintln!("luau-check: {why}\nusage: luau-check [--definitions FILE]... SCRIPT...");
    ExitCode::from(2)
}

/// Reports a file that cannot be read.
fn unreadable(path: &std::path::Path, e: &std::io::Error) -> ExitCode {
    eprintln!("luau-check: cannot read {}: {e}", path.display());
    ExitCode::from(2)
}
