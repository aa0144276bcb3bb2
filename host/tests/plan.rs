//! Plans without a cluster: `--plan`, `pada trial` and `--merge` give the
//! local run's outputs byte for byte; missing, corrupt and foreign results
//! are listed and stop the merge; a changed plan is refused; a killed trial
//! leaves no result; the index comes from the environment.

mod common;
use common::{ok, pada, pada_env, without_timing};

use std::collections::BTreeMap;
use std::path::Path;
use std::process::{Command, Output, Stdio};

fn fails(out: &Output, code: i32, needles: &[&str]) -> String {
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(code), "stderr: {err}");
    for n in needles {
        assert!(err.contains(n), "stderr lacks {n:?}: {err}");
    }
    err
}

/// Every file of a directory (not its subdirectories), by name.
fn files(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap())
        .filter(|e| e.file_type().unwrap().is_file())
        .map(|e| {
            (
                e.file_name().to_string_lossy().into_owned(),
                std::fs::read(e.path()).unwrap(),
            )
        })
        .collect()
}

/// Runs every trial of the plan in `dir` with `pada trial`, two at a time.
fn run_all_trials(dir: &Path, n: usize) {
    let d = dir.to_str().unwrap();
    std::thread::scope(|s| {
        for worker in 0..2 {
            s.spawn(move || {
                for i in (worker..n).step_by(2) {
                    ok(&pada(&["trial", "--plan", d, "--index", &i.to_string()]));
                }
            });
        }
    });
}

/// Asserts that two output directories hold the same files with the same
/// bytes, except timing.json (wall time; its own field "how" differs).
fn assert_same_outputs(local: &Path, merged: &Path) {
    let (mut a, mut b) = (files(local), files(merged));
    assert!(a.remove("timing.json").is_some() && b.remove("timing.json").is_some());
    assert_eq!(
        a.keys().collect::<Vec<_>>(),
        b.keys().collect::<Vec<_>>(),
        "the same files"
    );
    for (name, bytes) in &a {
        assert!(
            bytes == &b[name],
            "{name} differs between the local and the merged run"
        );
    }
}

#[test]
fn a_merged_paper_pendulum_equals_the_local_run_byte_for_byte() {
    let root = tempfile::tempdir().unwrap();
    let (local, plan, merged) = (
        root.path().join("local"),
        root.path().join("plan"),
        root.path().join("merged"),
    );
    let with = |extra: &[&str]| {
        let mut v: Vec<&str> = "paper pendulum --trials 2 --seconds 30 --physical-seconds 30 --seed 3".split(' ').collect();
        v.extend(extra);
        v.iter().map(|s| s.to_string()).collect::<Vec<_>>()
    };
    ok(&pada_s(&with(&["--out", local.to_str().unwrap()])));
    let text = ok(&pada_s(&with(&["--plan", plan.to_str().unwrap()])));
    assert!(text.contains("54 trials"), "{text}");
    assert_eq!(std::fs::read_dir(plan.join("trials")).unwrap().count(), 54);
    run_all_trials(&plan, 54);
    ok(&pada_s(&with(&[
        "--merge",
        plan.to_str().unwrap(),
        "--out",
        merged.to_str().unwrap(),
    ])));
    assert_same_outputs(&local, &merged);
    let report = std::fs::read_to_string(merged.join("report.md")).unwrap();
    assert!(
        report.contains("timing.json"),
        "the report says where the wall time went"
    );
    let timing: serde_json::Value =
        serde_json::from_slice(&std::fs::read(merged.join("timing.json")).unwrap()).unwrap();
    assert_eq!(timing["how"], "merge");
    assert_eq!(timing["trials"]["count"], 54);
    assert!(timing["trials"]["mean_s"].as_f64().unwrap() > 0.0);
}

#[test]
fn a_merged_paper_leo_equals_the_local_run_with_its_best_learner() {
    let root = tempfile::tempdir().unwrap();
    let (local, plan, merged) = (
        root.path().join("local"),
        root.path().join("plan"),
        root.path().join("merged"),
    );
    let base = ["paper", "leo", "--trials", "1", "--seconds", "30"];
    let run = |extra: &[&str]| {
        let mut v = base.to_vec();
        v.extend(extra);
        pada(&v)
    };
    ok(&run(&["--out", local.to_str().unwrap()]));
    ok(&run(&["--plan", plan.to_str().unwrap()]));
    run_all_trials(&plan, 9);
    // Of the nine trials' weights, only the best trial's are left.
    let kept: Vec<_> = std::fs::read_dir(plan.join("best")).unwrap().collect();
    assert_eq!(kept.len(), 1, "{kept:?}");
    let merge = |to: &Path| {
        run(&[
            "--merge",
            plan.to_str().unwrap(),
            "--out",
            to.to_str().unwrap(),
        ])
    };
    let out = merge(&merged);
    ok(&out);
    let rerun = |out: &Output| {
        String::from_utf8_lossy(&out.stderr).contains("running the best trial again")
    };
    assert!(!rerun(&out), "the merge takes the kept weights");
    // best.weights, the gait strip and animation are the local run's too.
    assert!(files(&merged).contains_key("best.weights"));
    assert_same_outputs(&local, &merged);

    // Without the kept weights, the merge runs the best trial again.
    for e in std::fs::read_dir(plan.join("best")).unwrap() {
        std::fs::remove_file(e.unwrap().path()).unwrap();
    }
    let again = root.path().join("again");
    let out = merge(&again);
    ok(&out);
    assert!(rerun(&out), "the best trial is run again");
    assert_same_outputs(&local, &again);
}

/// `pada run` of low-pass on the pendulum, 60 s trials, seed 11, JSON.
fn run_args(trials: &str, extra: &[&str]) -> Vec<String> {
    let mut v = vec![
        "run",
        "--task",
        "pendulum",
        "--algo",
        "lowpass",
        "--trials",
        trials,
        "--seconds",
        "60",
        "--seed",
        "11",
        "--json",
    ];
    v.extend(extra);
    v.iter().map(|s| s.to_string()).collect()
}

fn pada_s(args: &[String]) -> Output {
    pada(&args.iter().map(String::as_str).collect::<Vec<_>>())
}

#[test]
fn a_merged_run_prints_the_local_summary_with_identical_trials() {
    let root = tempfile::tempdir().unwrap();
    let p = |n: &str| root.path().join(n).to_str().unwrap().to_string();
    let local: serde_json::Value =
        serde_json::from_str(&ok(&pada_s(&run_args("3", &["--out", &p("local")])))).unwrap();
    let planned: serde_json::Value =
        serde_json::from_str(&ok(&pada_s(&run_args("3", &["--plan", &p("plan")])))).unwrap();
    assert_eq!(planned["trials"], 3);
    assert!(planned["merge"].as_str().unwrap().contains("--merge"));
    run_all_trials(Path::new(&p("plan")), 3);
    let merge = run_args("3", &["--merge", &p("plan"), "--out", &p("merged")]);
    let merged: serde_json::Value = serde_json::from_str(&ok(&pada_s(&merge))).unwrap();
    assert_eq!(without_timing(&merged), without_timing(&local));
    assert_eq!(merged["per_trial"], local["per_trial"]);
    assert!(merged["wall_s"].as_f64().unwrap() > 0.0);
    for name in ["trials.csv", "trial-000.csv", "trial-002.csv"] {
        assert_eq!(
            std::fs::read(root.path().join("local").join(name)).unwrap(),
            std::fs::read(root.path().join("merged").join(name)).unwrap(),
            "{name}"
        );
    }
}

#[test]
fn missing_corrupt_and_foreign_results_are_listed_and_nothing_is_reported() {
    let root = tempfile::tempdir().unwrap();
    let p = |n: &str| root.path().join(n).to_str().unwrap().to_string();
    ok(&pada_s(&run_args("4", &["--plan", &p("plan")])));
    run_all_trials(Path::new(&p("plan")), 4);
    // A second plan (another seed) lends its result file for trial 3.
    let mut other = run_args("4", &["--plan", &p("other")]);
    other[10] = "12".into();
    ok(&pada_s(&other));
    ok(&pada(&["trial", "--plan", &p("other"), "--index", "3"]));
    let results = root.path().join("plan/results");
    std::fs::copy(
        root.path().join("other/results/000003.json"),
        results.join("000003.json"),
    )
    .unwrap();
    // Trial 1: one digit of its end performance changed.
    let path = results.join("000001.json");
    let text = std::fs::read_to_string(&path).unwrap();
    let at = text.find("\"end_performance\": -").unwrap() + "\"end_performance\": -".len();
    let mut bytes = text.into_bytes();
    bytes[at] = if bytes[at] == b'1' { b'2' } else { b'1' };
    std::fs::write(&path, bytes).unwrap();
    // Trial 2: cut short.
    let path = results.join("000002.json");
    let len = std::fs::metadata(&path).unwrap().len();
    std::fs::OpenOptions::new()
        .write(true)
        .open(&path)
        .unwrap()
        .set_len(len / 2)
        .unwrap();
    // Trial 0 stays intact. Merge:
    let merge = run_args("4", &["--merge", &p("plan"), "--out", &p("merged")]);
    let out = pada_s(&merge);
    let err = fails(
        &out,
        1,
        &[
            "trial 1 (pendulum lowpass α=0.834, trial 1): corrupt",
            "checksum does not match",
            "trial 2 (pendulum lowpass α=0.834, trial 2): corrupt",
            "trial 3 (pendulum lowpass α=0.834, trial 3): corrupt",
            "another plan",
            "3 of 4 trials have no verified result",
            "no report written",
        ],
    );
    assert!(!err.contains("trial 0 ("), "trial 0 verifies: {err}");
    assert!(!root.path().join("merged").exists(), "no report written");
    // The last line is the one-line error.
    assert!(
        err.trim_end()
            .lines()
            .last()
            .unwrap()
            .starts_with("error: "),
        "{err}"
    );

    // Removing trial 3 makes it "missing"; `pada trial` replaces a corrupt
    // result and skips a verified one.
    std::fs::remove_file(results.join("000003.json")).unwrap();
    let out = pada_s(&merge);
    fails(
        &out,
        1,
        &["trial 3 (pendulum lowpass α=0.834, trial 3): missing"],
    );
    let out = pada(&["trial", "--plan", &p("plan"), "--index", "1"]);
    ok(&out);
    assert!(String::from_utf8_lossy(&out.stderr).contains("replaced a result that did not verify"));
    let out = ok(&pada(&["trial", "--plan", &p("plan"), "--index", "0"]));
    assert!(out.contains("already done"), "{out}");
    for i in ["2", "3"] {
        ok(&pada(&["trial", "--plan", &p("plan"), "--index", i]));
    }
    ok(&pada_s(&merge));
    assert!(root.path().join("merged/summary.json").exists());
}

#[test]
fn a_changed_or_another_plan_is_refused() {
    let root = tempfile::tempdir().unwrap();
    let p = |n: &str| root.path().join(n).to_str().unwrap().to_string();
    ok(&pada_s(&run_args("2", &["--plan", &p("plan")])));
    // The same plan again is found, with its results kept.
    let again = ok(&pada_s(&run_args("2", &["--plan", &p("plan")])));
    assert!(again.contains("\"already_written\":true"), "{again}");
    // Other options into the same directory, or merged from it, are refused.
    let err = fails(
        &pada_s(&run_args("3", &["--plan", &p("plan")])),
        2,
        &["holds the plan of `pada run --task pendulum --algo lowpass --alpha 0.834 --trials 2 --seconds 60 --seed 11`"],
    );
    assert!(
        err.contains("give the options the plan was written with"),
        "{err}"
    );
    fails(
        &pada_s(&run_args("3", &["--merge", &p("plan")])),
        2,
        &["holds the plan of"],
    );
    // An edited trial file: that trial refuses to run, and so does the
    // merge (which reads them all).
    let path = root.path().join("plan/trials/000001.json");
    let text = std::fs::read_to_string(&path).unwrap();
    std::fs::write(
        &path,
        text.replace("\"seconds\": 60.0", "\"seconds\": 600.0"),
    )
    .unwrap();
    let changed = "a file of the plan was changed after it was written";
    fails(
        &pada(&["trial", "--plan", &p("plan"), "--index", "1"]),
        2,
        &["000001.json is not the plan's trial 1", changed],
    );
    fails(
        &pada_s(&run_args("2", &["--merge", &p("plan")])),
        2,
        &[changed],
    );
    std::fs::write(&path, text).unwrap();
    ok(&pada(&["trial", "--plan", &p("plan"), "--index", "1"]));
    // An edited plan.json: every trial refuses it.
    let path = root.path().join("plan/plan.json");
    let text = std::fs::read_to_string(&path).unwrap();
    std::fs::write(&path, text.replace("\"seed\": 11", "\"seed\": 12")).unwrap();
    fails(
        &pada(&["trial", "--plan", &p("plan"), "--index", "0"]),
        2,
        &["plan.json hashes to", changed],
    );
    fails(
        &pada(&["trial", "--plan", &p("nowhere"), "--index", "0"]),
        2,
        &["plan.json", "--plan DIR"],
    );
}

#[test]
fn the_trial_index_comes_from_slurm_or_kubernetes() {
    let root = tempfile::tempdir().unwrap();
    let p = |n: &str| root.path().join(n).to_str().unwrap().to_string();
    ok(&pada_s(&run_args("3", &["--plan", &p("plan")])));
    ok(&pada_env(
        &["trial", "--plan", &p("plan")],
        &[("SLURM_ARRAY_TASK_ID", "1")],
    ));
    ok(&pada_env(
        &["trial", "--plan", &p("plan")],
        &[("JOB_COMPLETION_INDEX", "0")],
    ));
    // A plan submitted as several arrays: the script adds its offset.
    ok(&pada_env(
        &["trial", "--plan", &p("plan"), "--index-offset", "2"],
        &[("SLURM_ARRAY_TASK_ID", "0")],
    ));
    let mut names: Vec<String> = std::fs::read_dir(root.path().join("plan/results"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["000000.json", "000001.json", "000002.json"]);
    fails(
        &pada_env(
            &["trial", "--plan", &p("plan")],
            &[("SLURM_ARRAY_TASK_ID", "-2")],
        ),
        2,
        &["SLURM_ARRAY_TASK_ID is \"-2\", not a trial index"],
    );
    fails(
        &pada(&["trial", "--plan", &p("plan")]),
        2,
        &[
            "no trial index",
            "SLURM_ARRAY_TASK_ID",
            "JOB_COMPLETION_INDEX",
            "valid is 0..=2",
        ],
    );
    fails(
        &pada_env(
            &["trial", "--plan", &p("plan")],
            &[("SLURM_ARRAY_TASK_ID", "7")],
        ),
        2,
        &[
            "trial index 7 (from SLURM_ARRAY_TASK_ID",
            "out of range: valid is 0..=2",
        ],
    );
}

#[test]
fn a_trial_killed_midway_leaves_no_result() {
    let root = tempfile::tempdir().unwrap();
    let dir = root.path().join("plan");
    let d = dir.to_str().unwrap();
    // 100,000 s of learning: much longer than the 0.7 s before the kill, even
    // in an optimised build on a fast machine.
    ok(&pada(&[
        "run",
        "--task",
        "pendulum",
        "--algo",
        "sarsa",
        "--trials",
        "1",
        "--seconds",
        "100000",
        "--plan",
        d,
    ]));
    for signal in ["KILL", "TERM"] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_pada"))
            .args(["trial", "--plan", d, "--index", "0"])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(std::time::Duration::from_millis(700));
        let killed = Command::new("kill")
            .args([&format!("-{signal}"), &child.id().to_string()])
            .status()
            .unwrap();
        assert!(killed.success());
        let status = child.wait().unwrap();
        assert!(
            status.code().is_none(),
            "the trial was still running when killed ({signal})"
        );
        let left: Vec<String> = std::fs::read_dir(dir.join("results"))
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        assert!(
            left.is_empty(),
            "nothing left behind by SIG{signal}: {left:?}"
        );
    }
}

#[test]
fn cluster_options_are_checked_before_anything_runs() {
    let root = tempfile::tempdir().unwrap();
    let d = root.path().join("x");
    let d = d.to_str().unwrap();
    let base = ["run", "--algo", "sarsa", "--trials", "1", "--seconds", "60"];
    let with = |extra: &[&str]| {
        let mut v = base.to_vec();
        v.extend(extra);
        pada(&v)
    };
    fails(&with(&["--partition", "debug"]), 2, &["--slurm"]);
    fails(
        &with(&["--merge", d, "--plan", d]),
        2,
        &["cannot be used with"],
    );
    fails(
        &with(&["--slurm", "--time", "1h"]),
        2,
        &["--time \"1h\"", "valid forms are"],
    );
    fails(
        &with(&["--slurm", "--partition", "a b"]),
        2,
        &["not a partition name"],
    );
    fails(
        &with(&["--slurm", "--sbatch-arg=--array=0-3"]),
        2,
        &["pada sets --array itself"],
    );
    fails(&with(&["--slurm", "--retries", "99"]), 2, &["99"]);
    fails(
        &with(&["--plan", d, "--telemetry", "t.bin"]),
        2,
        &["do not combine with --plan"],
    );
    assert!(!root.path().join("x").exists());
}
