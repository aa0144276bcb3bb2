//! `--slurm` against a real Slurm cluster (in CI: the one-node cluster of
//! `.ci/slurm up`): a small pendulum sweep gives the local run's summary
//! and files; a re-run with the same directory runs only the trials whose
//! results are missing or corrupt; an array task cancelled with scancel
//! while it runs is submitted again and the summary is still the same.
//!
//! The cluster is found through SLURM_CONF, else `.ci/slurm`'s
//! `$PADA_SLURM_DIR/slurm.conf` (default /tmp/pada-slurm). Without one the
//! tests fail under CI=true (`cargo xtask test` sets it, and starts the
//! cluster) and are skipped, with the reason, elsewhere.

mod common;
use common::{ok, without_timing};

use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// A cluster that answers.
struct Cluster {
    /// SLURM_CONF for every Slurm command (None: Slurm's own default).
    conf: Option<PathBuf>,
    /// The default partition.
    partition: String,
}

impl Cluster {
    fn command(&self, program: &str) -> Command {
        let mut c = Command::new(program);
        if let Some(conf) = &self.conf {
            c.env("SLURM_CONF", conf);
        }
        c.env_remove("SLURM_ARRAY_TASK_ID");
        c
    }

    fn pada(&self) -> Command {
        self.command(env!("CARGO_BIN_EXE_pada"))
    }
}

fn find_cluster() -> Result<Cluster, String> {
    let conf = std::env::var_os("SLURM_CONF")
        .map(PathBuf::from)
        .or_else(|| {
            let dir = std::env::var_os("PADA_SLURM_DIR")
                .map(PathBuf::from)
                .unwrap_or_else(|| PathBuf::from("/tmp/pada-slurm"));
            Some(dir.join("slurm.conf")).filter(|p| p.exists())
        });
    // Slurm's clients retry a missing configuration for a minute: look first.
    let file = conf
        .clone()
        .unwrap_or_else(|| PathBuf::from("/etc/slurm/slurm.conf"));
    if !file.exists() {
        return Err(format!("no Slurm configuration at {}", file.display()));
    }
    let mut sinfo = Command::new("sinfo");
    sinfo
        .args(["--noheader", "--format=%P %a"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    if let Some(c) = &conf {
        sinfo.env("SLURM_CONF", c);
    }
    let mut child = sinfo
        .spawn()
        .map_err(|e| format!("cannot run sinfo ({e})"))?;
    let started = Instant::now();
    while child.try_wait().map_err(|e| e.to_string())?.is_none() {
        if started.elapsed() > Duration::from_secs(30) {
            let _ = child.kill();
            return Err("sinfo did not answer within 30 s".into());
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let out = child.wait_with_output().map_err(|e| e.to_string())?;
    if !out.status.success() {
        return Err(format!(
            "sinfo failed: {}",
            String::from_utf8_lossy(&out.stderr).trim()
        ));
    }
    let text = String::from_utf8_lossy(&out.stdout);
    let partition = text
        .lines()
        .find_map(|l| {
            let (p, avail) = l.split_once(' ')?;
            (p.ends_with('*') && avail.trim() == "up").then(|| p.trim_end_matches('*').to_string())
        })
        .ok_or_else(|| format!("no default partition that is up: {text:?}"))?;
    Ok(Cluster { conf, partition })
}

/// The cluster, or `None` (skip) outside CI; under CI=true no cluster is a
/// failure.
fn cluster() -> Option<Cluster> {
    match find_cluster() {
        Ok(c) => Some(c),
        Err(why) if std::env::var("CI").as_deref() == Ok("true") => {
            panic!("CI=true but no Slurm cluster answers ({why}); `cargo xtask test` starts one (.ci/slurm up)")
        }
        Err(why) => {
            // Straight to stderr, past the test harness's capture, so the
            // reason shows in a passing run.
            let _ = writeln!(
                std::io::stderr(),
                "skipping: no Slurm cluster answers ({why}); `cargo xtask test` starts one (or `.ci/slurm up`)"
            );
            None
        }
    }
}

/// `pada run` of PADA on the pendulum with `trials` trials of `seconds`.
fn run_args(trials: &str, seconds: &str, seed: &str, out: &Path) -> Vec<String> {
    [
        "run",
        "--task",
        "pendulum",
        "--algo",
        "pada",
        "--trials",
        trials,
        "--seconds",
        seconds,
        "--seed",
        seed,
        "--json",
        "--out",
    ]
    .iter()
    .map(|s| s.to_string())
    .chain([out.to_str().unwrap().to_string()])
    .collect()
}

fn json(text: &str) -> serde_json::Value {
    serde_json::from_str(text).unwrap_or_else(|e| panic!("not JSON ({e}): {text}"))
}

fn assert_same_trial_files(a: &Path, b: &Path, trials: usize) {
    let mut names = vec!["trials.csv".to_string()];
    names.extend((0..trials).map(|i| format!("trial-{i:03}.csv")));
    for n in names {
        assert_eq!(
            std::fs::read(a.join(&n)).unwrap(),
            std::fs::read(b.join(&n)).unwrap(),
            "{n}"
        );
    }
}

#[test]
fn a_sweep_on_slurm_reports_what_the_local_run_reports_and_resumes() {
    let Some(c) = cluster() else { return };
    let root = tempfile::tempdir().unwrap();
    let (local_dir, slurm_dir) = (root.path().join("local"), root.path().join("slurm"));
    let local = json(&ok(&c
        .pada()
        .args(run_args("6", "60", "5", &local_dir))
        .output()
        .unwrap()));
    let slurm_run = |extra: &[&str]| {
        c.pada()
            .args(run_args("6", "60", "5", &slurm_dir))
            .args(["--slurm", "--partition", &c.partition, "--time", "10"])
            .args(["--max-parallel", "2", "--sbatch-arg=--comment=pada-test"])
            .args(extra)
            .output()
            .unwrap()
    };
    let out = slurm_run(&[]);
    let slurm = json(&ok(&out));
    assert_eq!(without_timing(&slurm), without_timing(&local));
    assert_eq!(slurm["per_trial"], local["per_trial"]);
    assert_same_trial_files(&local_dir, &slurm_dir, 6);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("slurm: submitted job") && err.contains("6 trials (indices 0-5)"),
        "{err}"
    );
    let timing = json(&std::fs::read_to_string(slurm_dir.join("timing.json")).unwrap());
    assert_eq!(timing["how"], "slurm");
    assert_eq!(timing["trials"]["count"], 6);
    assert!(
        timing["threads"].as_u64().unwrap() <= 2,
        "--max-parallel 2 held: {timing}"
    );
    // Every array task ran in Slurm (its result names its task).
    let result = std::fs::read_to_string(slurm_dir.join("plan/results/000004.json")).unwrap();
    assert!(result.contains("\"slurm_task\": \""), "{result}");

    // A corrupt and a missing result: the re-run runs only those two.
    let results = slurm_dir.join("plan/results");
    let path = results.join("000002.json");
    let text = std::fs::read_to_string(&path).unwrap();
    std::fs::write(
        &path,
        text.replacen("\"learning_steps\": 1200", "\"learning_steps\": 1201", 1),
    )
    .unwrap();
    std::fs::remove_file(results.join("000004.json")).unwrap();
    let out = slurm_run(&[]);
    let again = json(&ok(&out));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("4 of 6 trials already have verified results"),
        "{err}"
    );
    assert!(err.contains("2 trials (indices 2,4)"), "{err}");
    assert_eq!(without_timing(&again), without_timing(&local));
    // All verified: nothing is submitted.
    let out = slurm_run(&[]);
    ok(&out);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("submitted job"), "{err}");
}

/// Reads a child's stderr into lines as they come.
fn collect_lines(stream: impl std::io::Read + Send + 'static) -> Arc<Mutex<Vec<String>>> {
    let lines = Arc::new(Mutex::new(Vec::new()));
    let sink = lines.clone();
    std::thread::spawn(move || {
        for l in BufReader::new(stream).lines().map_while(Result::ok) {
            sink.lock().unwrap().push(l);
        }
    });
    lines
}

#[test]
fn an_array_task_cancelled_while_it_runs_is_submitted_again() {
    let Some(c) = cluster() else { return };
    let root = tempfile::tempdir().unwrap();
    let (local_dir, slurm_dir) = (root.path().join("local"), root.path().join("slurm"));
    // 2400 s trials: a second or more each in a debug build, so that one is
    // caught running; one at a time, so the others wait in the queue.
    let mut child = c
        .pada()
        .args(run_args("4", "2400", "8", &slurm_dir))
        .args(["--slurm", "--max-parallel", "1"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let stdout = child.stdout.take().unwrap();
    let stdout = std::thread::spawn(move || {
        let mut s = String::new();
        std::io::Read::read_to_string(&mut { stdout }, &mut s).unwrap();
        s
    });
    let lines = collect_lines(child.stderr.take().unwrap());
    let deadline = Instant::now() + Duration::from_secs(600);
    let job = loop {
        assert!(
            Instant::now() < deadline,
            "no submission: {:?}",
            lines.lock().unwrap()
        );
        let found = lines.lock().unwrap().iter().find_map(|l| {
            l.strip_prefix("slurm: submitted job ")
                .and_then(|r| r.split(':').next())
                .map(str::to_string)
        });
        if let Some(j) = found {
            break j;
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    // Cancel a running task; if it finished before the signal landed (its
    // result is there), cancel the next one: with one task at a time, one of
    // the four is caught midway on any machine.
    let results = slurm_dir.join("plan/results");
    let running = || {
        let out = c
            .command("squeue")
            .args(["--noheader", "--array", "--states=RUNNING", "--format=%i"])
            .arg(format!("--jobs={job}"))
            .output()
            .unwrap();
        String::from_utf8_lossy(&out.stdout)
            .lines()
            .next()
            .map(|t| t.trim().to_string())
    };
    let (task, index) = loop {
        assert!(
            Instant::now() < deadline,
            "no task of job {job} was caught running"
        );
        let Some(task) = running() else {
            std::thread::sleep(Duration::from_millis(20));
            continue;
        };
        let cancelled = c.command("scancel").arg(&task).status().unwrap();
        assert!(cancelled.success(), "scancel {task}");
        // Wait until the task has left the queue in every state, not only
        // RUNNING: a task leaves RUNNING for COMPLETING while its process
        // may still be writing its result.
        let queued = || {
            let out = c
                .command("squeue")
                .args(["--noheader", "--array", "--format=%i"])
                .arg(format!("--jobs={task}"))
                .output()
                .unwrap();
            String::from_utf8_lossy(&out.stdout)
                .lines()
                .any(|l| l.trim() == task)
        };
        while queued() {
            std::thread::sleep(Duration::from_millis(20));
        }
        let index: u32 = task.split('_').nth(1).unwrap().parse().unwrap();
        if !results.join(format!("{index:06}.json")).exists() {
            break (task, index);
        }
    };

    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            panic!(
                "pada run --slurm did not finish: {:?}",
                lines.lock().unwrap()
            );
        }
        std::thread::sleep(Duration::from_millis(100));
    };
    let stdout = stdout.join().unwrap();
    let err = lines.lock().unwrap().join("\n");
    assert!(status.success(), "{err}");
    assert!(
        err.contains(&format!(
            "trial {index} (pendulum pada Δ=0.5, trial {index}) left no verified result"
        )) && err.contains("submitting it again (attempt 2 of 3)"),
        "task {task} was cancelled: {err}"
    );
    let timing = json(&std::fs::read_to_string(slurm_dir.join("timing.json")).unwrap());
    assert_eq!(
        timing["slurm"]["resubmitted"],
        serde_json::json!([index]),
        "{timing}"
    );

    let local = json(&ok(&c
        .pada()
        .args(run_args("4", "2400", "8", &local_dir))
        .output()
        .unwrap()));
    let slurm = json(&stdout);
    assert_eq!(without_timing(&slurm), without_timing(&local));
    assert_same_trial_files(&local_dir, &slurm_dir, 4);
}
