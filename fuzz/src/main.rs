//! `pada-fuzz [--seconds S] [--seed K]` (or `pada-fuzz --replay FILE…` to
//! run saved failing inputs again, each through the target its name
//! starts with): drives every decoder that faces
//! untrusted bytes with random and mutated-valid inputs for about `S`
//! seconds in all (default 60, shared evenly between the targets) and
//! checks four invariants:
//!
//! 1. no input makes a decoder panic;
//! 2. a frame or packet that is accepted re-encodes to exactly the bytes
//!    received;
//! 3. every damaged frame or packet is counted exactly once (the decoders'
//!    counters agree with an independent count of the input);
//! 4. a save torn at any byte keeps the old or the new checkpoint.
//!
//! Run through `cargo xtask fuzz` (the `fuzz` profile: optimised, with
//! overflow checks and debug assertions on, so arithmetic overflow is a
//! panic here too). It prints the inputs per second of each target and
//! exits 1 if any invariant failed, after writing each failing input to
//! `target/fuzz-failures/`.
//!
//! Why not libFuzzer or AFL: both need a nightly compiler or a C++
//! toolchain with sanitizers, which CI does not have (stable Rust, host
//! target only), and their coverage guidance buys little on decoders this
//! small: the structure-aware generators here (valid frames and packets
//! from the message types themselves, then damaged) reach every branch
//! within seconds. The mutators are a few lines each and know the formats.

mod gen;
mod targets;

use rand_core::SeedableRng;
use std::time::{Duration, Instant};
use targets::{Outcome, Target};

fn main() -> std::process::ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().is_some_and(|a| a == "--replay") {
        return replay(&args[1..]);
    }
    let (seconds, seed) = match parse_args(args.into_iter()) {
        Ok(a) => a,
        Err(e) => {
            eprintln!("pada-fuzz: error: {e}\nusage: pada-fuzz [--seconds S] [--seed K]");
            return std::process::ExitCode::from(2);
        }
    };
    let corpus = gen::Corpus::load();
    let mut targets = targets::all(&corpus);
    let share = Duration::from_secs_f64(seconds / targets.len() as f64);
    println!(
        "pada-fuzz: {} targets, {:.0} s each, seed {seed}, {} recorded frames in the corpus",
        targets.len(),
        share.as_secs_f64(),
        corpus.frames.len()
    );
    let mut failed = 0usize;
    for (i, t) in targets.iter_mut().enumerate() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(seed.wrapping_add(i as u64));
        let report = run(t.as_mut(), &mut rng, share);
        println!(
            "{:<18} {:>10} inputs {:>9.0} inputs/s  {}",
            t.name(),
            report.inputs,
            report.inputs as f64 / report.elapsed.as_secs_f64(),
            if report.failures == 0 {
                "ok".to_string()
            } else {
                format!("{} FAILED", report.failures)
            }
        );
        failed += report.failures;
    }
    if failed > 0 {
        eprintln!(
            "pada-fuzz: {failed} inputs broke an invariant; the first ten of each target are in \
             target/fuzz-failures/ (again: cargo run --profile fuzz -p pada-fuzz -- --replay FILE...)"
        );
        return std::process::ExitCode::FAILURE;
    }
    std::process::ExitCode::SUCCESS
}

/// Runs each saved input (`<target>-<n>.bin`) through its target again.
fn replay(files: &[String]) -> std::process::ExitCode {
    let corpus = gen::Corpus::load();
    let targets = targets::all(&corpus);
    let mut failed = false;
    for f in files {
        let name = std::path::Path::new(f).file_name().and_then(|n| n.to_str()).unwrap_or("");
        let Some(t) = targets.iter().find(|t| name.starts_with(&format!("{}-", t.name()))) else {
            eprintln!("{f}: no target is named like it");
            failed = true;
            continue;
        };
        let input = match std::fs::read(f) {
            Ok(b) => b,
            Err(e) => {
                eprintln!("{f}: cannot read: {e}");
                failed = true;
                continue;
            }
        };
        let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| t.check(&input)));
        match outcome {
            Ok(Outcome::Ok) => println!("{f}: ok"),
            Ok(Outcome::Failed(why)) => {
                println!("{f}: FAILED: {why}");
                failed = true;
            }
            Err(_) => {
                println!("{f}: FAILED: panic");
                failed = true;
            }
        }
    }
    if failed {
        std::process::ExitCode::FAILURE
    } else {
        std::process::ExitCode::SUCCESS
    }
}

struct Report {
    inputs: u64,
    failures: usize,
    elapsed: Duration,
}

/// Runs one target until `share` has passed, catching panics; keeps at
/// most ten failing inputs.
fn run(target: &mut dyn Target, rng: &mut rand_pcg::Pcg64, share: Duration) -> Report {
    let start = Instant::now();
    let mut inputs = 0u64;
    let mut failures = 0usize;
    // Panics are reported with the input that caused them, not printed.
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    while start.elapsed() < share {
        for _ in 0..64 {
            let input = target.generate(rng);
            inputs += 1;
            let outcome =
                std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| target.check(&input)))
                    .unwrap_or_else(|p| {
                        let what = p
                            .downcast_ref::<String>()
                            .cloned()
                            .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                            .unwrap_or_default();
                        Outcome::Failed(format!("panic: {what}"))
                    });
            if let Outcome::Failed(why) = outcome {
                failures += 1;
                if failures <= 10 {
                    save_failure(target.name(), failures, &input, &why);
                }
            }
        }
    }
    std::panic::set_hook(hook);
    Report {
        inputs,
        failures,
        elapsed: start.elapsed(),
    }
}

fn save_failure(name: &str, n: usize, input: &[u8], why: &str) {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/fuzz-failures");
    let _ = std::fs::create_dir_all(&dir);
    let path = dir.join(format!("{name}-{n}.bin"));
    let _ = std::fs::write(&path, input);
    eprintln!(
        "{name}: {why} (input of {} bytes in {})",
        input.len(),
        path.display()
    );
}

fn parse_args(mut args: impl Iterator<Item = String>) -> Result<(f64, u64), String> {
    let (mut seconds, mut seed) = (60.0f64, 1u64);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--seconds" => {
                let v = args.next().ok_or("--seconds needs a value")?;
                seconds = v
                    .parse()
                    .map_err(|_| format!("--seconds {v}: not a number"))?;
                if !(seconds.is_finite() && seconds > 0.0 && seconds <= 86_400.0) {
                    return Err(format!(
                        "--seconds {v} is out of range: valid is 0 < S <= 86400"
                    ));
                }
            }
            "--seed" => {
                let v = args.next().ok_or("--seed needs a value")?;
                seed = v.parse().map_err(|_| {
                    format!("--seed {v}: valid is an integer 0..=18446744073709551615")
                })?;
            }
            other => return Err(format!("unknown argument `{other}`")),
        }
    }
    Ok((seconds, seed))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_target_passes_a_few_hundred_inputs_and_replays_them() {
        let corpus = gen::Corpus::load();
        assert!(!corpus.frames.is_empty(), "the recorded stream is the wire corpus");
        for (i, t) in targets::all(&corpus).iter_mut().enumerate() {
            let mut rng = rand_pcg::Pcg64::seed_from_u64(i as u64);
            for n in 0..300 {
                let input = t.generate(&mut rng);
                // The check is a function of the input alone, so a saved
                // failing input replays.
                for _ in 0..2 {
                    if let Outcome::Failed(why) = t.check(&input) {
                        panic!("{} input {n}: {why}", t.name());
                    }
                }
            }
        }
    }

    #[test]
    fn arguments_are_checked() {
        let a = |s: &str| parse_args(s.split_whitespace().map(String::from));
        assert_eq!(a(""), Ok((60.0, 1)));
        assert_eq!(a("--seconds 2.5 --seed 9"), Ok((2.5, 9)));
        assert!(a("--seconds 0").is_err() && a("--seconds x").is_err() && a("--bogus").is_err());
    }
}
