//! The `pada` binary: bad input gives one line on stderr, exit code 2 and
//! no files; good input gives the documented outputs.

mod common;
use common::{assert_bad_input, ok, pada};

use std::path::Path;

#[test]
fn unknown_names_list_the_valid_values() {
    assert_bad_input(
        &["run", "--algo", "qlearning"],
        &["qlearning", "sarsa", "markov-integrator", "pada"],
    );
    assert_bad_input(
        &["run", "--task", "walker", "--algo", "sarsa"],
        &["walker", "pendulum", "physical-pendulum", "leo"],
    );
    assert_bad_input(&["paper", "cartpole"], &["cartpole", "pendulum"]);
    assert_bad_input(&["frobnicate"], &["frobnicate"]);
    assert_bad_input(&[], &["run, demo, paper, mtbf"]);
}

/// A fault that cannot apply to the robot's bus is bad input, refused
/// before anything is built or booted.
#[test]
fn sil_faults_that_cannot_apply_are_refused() {
    assert_bad_input(
        &["sil", "--task", "leo", "--fault", "drop:servo=9"],
        &["no servo 9 on leo's bus", "1, 3, 2, 5, 4, 7, 6"],
    );
    assert_bad_input(
        &["sil", "--fault", "past-limit:at=2"],
        &["servo 1's joint has no soft limit on physical-pendulum"],
    );
    assert_bad_input(&["sil", "--fault", "wobble"], &["wobble", "past-limit"]);
}

/// Each value out of its range: the command line, and what the one line of
/// stderr must name.
const OUT_OF_RANGE: &[(&str, &[&str])] = &[
    ("run --algo lowpass --alpha 1.5", &["--alpha 1.5", "0 < alpha <= 1"]),
    ("run --algo lowpass --alpha -0.2", &["0 < alpha <= 1"]),
    ("run --algo pada --delta 0", &["--delta 0", "0 < delta <= 1"]),
    ("run --algo integrator --delta NaN", &["0 < delta <= 1"]),
    ("run --algo sarsa --delta 0.5", &["--delta applies only"]),
    ("run --algo pada --alpha 0.5", &["--alpha applies only"]),
    ("run --algo sarsa --trials 0", &["--trials", "1..=10000"]),
    ("run --algo sarsa --trials many", &["--trials", "many"]),
    ("run --algo sarsa --seconds -5", &["--seconds -5", "0 < seconds"]),
    ("run --algo sarsa --seconds inf", &["0 < seconds"]),
    ("run --algo sarsa --switch-at 10", &["--switch-at applies only"]),
    ("run --algo pada --seconds 100 --switch-at 200", &["0 <= switch-at <= seconds"]),
    ("run --algo sarsa --threads 0", &["--threads"]),
    ("demo --seconds 0", &["0 < seconds"]),
    ("paper pendulum --physical-seconds -1", &["--physical-seconds"]),
    ("mtbf --torques x.csv --rate 0", &["--rate 0", "0 < rate"]),
    ("mtbf --torques x.csv --window 0", &["--window"]),
];

#[test]
fn parameters_out_of_range_name_the_range() {
    for (line, needles) in OUT_OF_RANGE {
        let args: Vec<&str> = line.split(' ').collect();
        assert_bad_input(&args, needles);
    }
}

#[test]
fn an_unwritable_output_directory_is_refused_before_running() {
    let root = tempfile::tempdir().unwrap();
    let file = root.path().join("plain-file");
    std::fs::write(&file, b"x").unwrap();
    let out = file.join("results");
    assert_bad_input(
        &[
            "run",
            "--algo",
            "sarsa",
            "--seconds",
            "1",
            "--trials",
            "1",
            "--out",
            out.to_str().unwrap(),
        ],
        &["cannot write output directory", "is not a directory"],
    );
    assert_bad_input(
        &[
            "paper",
            "pendulum",
            "--trials",
            "1",
            "--seconds",
            "1",
            "--out",
            out.to_str().unwrap(),
        ],
        &["cannot write output directory"],
    );
    // Nothing was created next to the file.
    let entries: Vec<_> = std::fs::read_dir(root.path()).unwrap().collect();
    assert_eq!(entries.len(), 1);
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.to_str().unwrap().to_string()
}

#[test]
fn malformed_torque_logs_are_reported_by_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let missing = write(dir.path(), "missing.csv", "hip,knee\n1.5,0\n-1.5\n");
    assert_bad_input(
        &["mtbf", "--torques", &missing],
        &["line 3", "1 columns, expected 2"],
    );
    let text = write(dir.path(), "text.csv", "hip,knee\n1.5,0\n-1.5,lots\n");
    assert_bad_input(
        &["mtbf", "--torques", &text],
        &["line 3, column 2 (knee)", "'lots' is not a number"],
    );
    let empty = write(dir.path(), "empty.csv", "");
    assert_bad_input(&["mtbf", "--torques", &empty], &["no torque rows"]);
    let nowhere = dir.path().join("nowhere.csv");
    assert_bad_input(
        &["mtbf", "--torques", nowhere.to_str().unwrap()],
        &["cannot read torque log"],
    );
}

#[test]
fn mtbf_of_a_known_log() {
    let dir = tempfile::tempdir().unwrap();
    // Joint a: +1.5, −1.5, +1.5, … (1 re-engagement per step after the
    // first); joint b: constant (none). 10 steps at 20 Hz, window 4.
    let mut csv = String::from("a,b\n");
    for k in 0..10 {
        csv += &format!("{},0.7\n", if k % 2 == 0 { 1.5 } else { -1.5 });
    }
    let path = write(dir.path(), "log.csv", &csv);
    let out = pada(&[
        "mtbf",
        "--torques",
        &path,
        "--rate",
        "20",
        "--window",
        "4",
        "--json",
    ]);
    ok(&out);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let a = &v["joints"][0]["report"];
    assert_eq!(a["reengagements"], 9);
    assert_eq!(a["window"]["reengagements"], 3);
    let per_event = pada_core::fatigue::GearboxParams::TABLE_I.damage_per_reengagement(1.5);
    let mtbf = a["mtbf_s"].as_f64().unwrap();
    assert!(
        (mtbf / (0.5 / (9.0 * per_event)) - 1.0).abs() < 1e-9,
        "{mtbf}"
    );
    let window = a["window"]["mtbf_s"].as_f64().unwrap();
    assert!(
        (window / (0.2 / (3.0 * per_event)) - 1.0).abs() < 1e-9,
        "{window}"
    );
    // The constant joint never re-engages: infinite MTBF, written as null.
    assert_eq!(v["joints"][1]["report"]["reengagements"], 0);
    assert!(v["joints"][1]["report"]["mtbf_s"].is_null());
    // Human-readable output names both joints.
    let text = pada(&["mtbf", "--torques", &path]);
    let s = String::from_utf8_lossy(&text.stdout);
    assert!(
        s.contains("a ") && s.contains("b ") && s.contains("inf"),
        "{s}"
    );
}

/// A bang-bang joint `a` (±1.5 N·m, 9 re-engagements in 10 steps) and a
/// constant joint `b`, as in `mtbf_of_a_known_log`.
fn bang_bang_log(dir: &Path) -> String {
    let mut csv = String::from("a,b\n");
    for k in 0..10 {
        csv += &format!("{},0.7\n", if k % 2 == 0 { 1.5 } else { -1.5 });
    }
    write(dir, "log.csv", &csv)
}

fn mtbf_json(args: &[&str]) -> serde_json::Value {
    let out = pada(args);
    ok(&out);
    serde_json::from_slice(&out.stdout).unwrap()
}

/// The MTBF of joint `a` of [`bang_bang_log`] at 20 Hz with `p`.
fn expected_mtbf(p: &pada_core::fatigue::GearboxParams) -> f64 {
    0.5 / (9.0 * p.damage_per_reengagement(1.5))
}

const TABLE_I_FIELDS: &str = "theta_bl_rad = 0.01\nk_nm_per_rad = 106.0\nd = -0.262\nsigma_f_mpa = 4402.0\nb_mm = 4.0\nm_n_mm = 0.4\nd_w_mm = 18.5\ny_fa = 2.15\ny_sa = 2.0\ny_epsilon = 1.22\ny_beta = 1.0\nteeth = 45\n";

#[test]
fn mtbf_default_gearbox_is_table_i_and_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let log = bang_bang_log(dir.path());
    let v = mtbf_json(&["mtbf", "--torques", &log, "--rate", "20", "--json"]);
    let g = &v["joints"][0]["gearbox"];
    assert_eq!(g["name"], "RX-28");
    assert_eq!(g["estimate"], false);
    assert_eq!(v["gearbox_estimate"], false);
    let mtbf = v["joints"][0]["report"]["mtbf_s"].as_f64().unwrap();
    let want = expected_mtbf(&pada_core::fatigue::GearboxParams::TABLE_I);
    assert!((mtbf / want - 1.0).abs() < 1e-9, "{mtbf} vs {want}");
    let text = String::from_utf8_lossy(&pada(&["mtbf", "--torques", &log]).stdout).into_owned();
    assert!(text.contains("gearbox: RX-28 (Table I of the paper, measured)"), "{text}");
    assert!(!text.contains("estimate"), "{text}");
}

#[test]
fn mtbf_named_gearbox_is_used_and_marked_an_estimate() {
    let dir = tempfile::tempdir().unwrap();
    let log = bang_bang_log(dir.path());
    let v = mtbf_json(&["mtbf", "--torques", &log, "--rate", "20", "--gearbox", "xm430-w350", "--json"]);
    for j in 0..2 {
        assert_eq!(v["joints"][j]["gearbox"]["name"], "XM430-W350");
        assert_eq!(v["joints"][j]["gearbox"]["estimate"], true);
    }
    assert_eq!(v["gearbox_estimate"], true);
    let xm = pada_core::servo::gearbox("XM430-W350").unwrap().params;
    let mtbf = v["joints"][0]["report"]["mtbf_s"].as_f64().unwrap();
    assert!((mtbf / expected_mtbf(&xm) - 1.0).abs() < 1e-9, "{mtbf}");
    assert!(mtbf < expected_mtbf(&pada_core::fatigue::GearboxParams::TABLE_I), "a smaller gear wears faster");
    let text = String::from_utf8_lossy(&pada(&["mtbf", "--torques", &log, "--gearbox", "XM430-W350"]).stdout).into_owned();
    assert!(text.contains("XM430-W350 (its last gear's geometry is an estimate"), "{text}");
    assert!(text.contains("XM430-W350 (estimate)"), "{text}");
    // One per joint, in the log's order.
    let v = mtbf_json(&["mtbf", "--torques", &log, "--gearbox", "RX-28,XL330-M288", "--json"]);
    assert_eq!(v["joints"][0]["gearbox"]["name"], "RX-28");
    assert_eq!(v["joints"][1]["gearbox"]["name"], "XL330-M288");
    assert_eq!(v["gearbox_estimate"], true);
}

#[test]
fn mtbf_gearbox_file_is_read_and_named() {
    let dir = tempfile::tempdir().unwrap();
    let log = bang_bang_log(dir.path());
    let fields = TABLE_I_FIELDS.replace("b_mm = 4.0", "b_mm = 3.0");
    let file = write(dir.path(), "mine.toml", &format!("name = \"my servo\"\n{fields}"));
    let v = mtbf_json(&["mtbf", "--torques", &log, "--rate", "20", "--gearbox", &file, "--json"]);
    assert_eq!(v["joints"][0]["gearbox"]["name"], "my servo");
    assert_eq!(v["joints"][0]["gearbox"]["estimate"], false);
    assert_eq!(v["joints"][0]["gearbox"]["source"], file.as_str());
    let p = pada_core::fatigue::GearboxParams { b_mm: 3.0, ..pada_core::fatigue::GearboxParams::TABLE_I };
    let mtbf = v["joints"][0]["report"]["mtbf_s"].as_f64().unwrap();
    assert!((mtbf / expected_mtbf(&p) - 1.0).abs() < 1e-9, "{mtbf}");
}

#[test]
fn mtbf_gearbox_errors_name_the_problem_and_the_valid_values() {
    let dir = tempfile::tempdir().unwrap();
    let log = bang_bang_log(dir.path());
    assert_bad_input(
        &["mtbf", "--torques", &log, "--gearbox", "XM430-W999"],
        &["unknown gearbox \"XM430-W999\"", "RX-28", "MX-28", "XM430-W350", "XL430-W250", "XL330-M288", "TOML"],
    );
    let bad = write(dir.path(), "bad.toml", &TABLE_I_FIELDS.replace("b_mm = 4.0", "b_mm = -4.0"));
    assert_bad_input(&["mtbf", "--torques", &log, "--gearbox", &bad], &[&bad, "b_mm = -4", "0 < b_mm < inf (mm)"]);
    let zero = write(dir.path(), "zero.toml", &TABLE_I_FIELDS.replace("teeth = 45", "teeth = 0"));
    assert_bad_input(&["mtbf", "--torques", &log, "--gearbox", &zero], &[&zero, "teeth", "teeth >= 1"]);
    let typo = write(dir.path(), "typo.toml", &format!("{TABLE_I_FIELDS}teeht = 4\n"));
    assert_bad_input(&["mtbf", "--torques", &log, "--gearbox", &typo], &[&typo, "line 13", "teeht"]);
    let missing = write(dir.path(), "missing.toml", &TABLE_I_FIELDS.replace("d_w_mm = 18.5\n", ""));
    assert_bad_input(&["mtbf", "--torques", &log, "--gearbox", &missing], &[&missing, "d_w_mm"]);
    let nowhere = dir.path().join("nowhere.toml");
    assert_bad_input(
        &["mtbf", "--torques", &log, "--gearbox", nowhere.to_str().unwrap()],
        &["cannot read gearbox file", "nowhere.toml"],
    );
    assert_bad_input(
        &["mtbf", "--torques", &log, "--gearbox", "RX-28,RX-28,RX-28"],
        &["--gearbox has 3 entries for 2 joints", "one per joint"],
    );
}

#[test]
fn run_json_prints_the_summary_and_writes_the_files() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("run");
    let args = [
        "run",
        "--task",
        "pendulum",
        "--algo",
        "pada",
        "--delta",
        "0.5",
        "--trials",
        "2",
        "--seconds",
        "60",
        "--seed",
        "9",
        "--json",
        "--out",
        out_dir.to_str().unwrap(),
    ];
    let out = pada(&args);
    ok(&out);
    let v: serde_json::Value =
        serde_json::from_slice(&out.stdout).expect("stdout is the JSON summary");
    assert_eq!(v["task"], "pendulum");
    assert_eq!(v["algo"], "pada");
    assert_eq!(v["trials"], 2);
    assert_eq!(v["parameters"]["delta"], 0.5);
    assert!(v["parameters"]["alpha"].is_null());
    for key in ["end_performance", "rise_time_s", "mtbf_s"] {
        assert!(v[key]["mean"].is_f64(), "{key}: {}", v[key]);
        assert!(v[key]["ci95"].is_f64(), "{key}: {}", v[key]);
    }
    assert!(v["mtbf_s"]["mean"].as_f64().unwrap() > 100.0);
    assert!(v["wall_s"].as_f64().unwrap() > 0.0);
    assert!(v["env_steps_per_s"].as_f64().unwrap() > 0.0);
    // 2 trials × (1200 learning steps + 3 test runs of 60 steps).
    assert_eq!(v["env_steps"], 2 * (1200 + 3 * 60));
    // The files: summary.json equal to stdout, trials.csv, two curves.
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out_dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary, v);
    let curve = std::fs::read_to_string(out_dir.join("trial-001.csv")).unwrap();
    assert!(
        curve.starts_with("test_run,learning_time_s,learning_episodes,return\n"),
        "{curve}"
    );
    assert_eq!(curve.lines().count(), 1 + 3);
    assert_eq!(
        std::fs::read_to_string(out_dir.join("trials.csv"))
            .unwrap()
            .lines()
            .count(),
        3
    );
    let names: Vec<String> = std::fs::read_dir(&out_dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names.len(), 4, "no temporary files left: {names:?}");

    // The same seed reproduces the numbers.
    let again = pada(&args);
    let w: serde_json::Value = serde_json::from_slice(&again.stdout).unwrap();
    assert_eq!(v["per_trial"], w["per_trial"]);
    assert_eq!(v["end_performance"], w["end_performance"]);
}

#[test]
fn paper_pendulum_writes_the_report_and_the_figures() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("paper");
    let mut args: Vec<&str> = "paper pendulum --trials 2 --seconds 30 --physical-seconds 30 --out".split(' ').collect();
    args.push(out_dir.to_str().unwrap());
    let out = pada(&args);
    ok(&out);
    let report = std::fs::read_to_string(out_dir.join("report.md")).unwrap();
    for needle in [
        "SARSA(λ) on the simulated pendulum",
        "-851 ± 39",
        "-1093",
        "839",
        "6.920e7",
        "pada Δ=0.5",
        "lowpass α=0.834",
    ] {
        assert!(report.contains(needle), "report lacks {needle}");
    }
    for stem in [
        "fig3-mtbf",
        "fig4-end-performance",
        "fig5-rise-time",
        "fig6-physical-curves",
        "fig6-simulated-curves",
    ] {
        let png = std::fs::read(out_dir.join(format!("{stem}.png"))).unwrap();
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n", "{stem}.png is a PNG");
        let svg = std::fs::read_to_string(out_dir.join(format!("{stem}.svg"))).unwrap();
        assert!(
            svg.starts_with("<svg") && (svg.contains("MTBF") || svg.contains("learning")),
            "{stem}.svg"
        );
    }
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out_dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["simulated"].as_array().unwrap().len(), 24);
    assert_eq!(summary["physical"].as_array().unwrap().len(), 3);
}

#[test]
fn mtbf_budget_errors_name_the_flag_and_the_range() {
    assert_bad_input(&["run", "--algo", "sarsa", "--mtbf-budget", "2600"], &["--mtbf-budget", "pada and lowpass"]);
    assert_bad_input(&["run", "--algo", "ou", "--mtbf-budget", "2600"], &["--mtbf-budget", "not to ou"]);
    assert_bad_input(&["run", "--algo", "pada", "--delta", "0.5", "--mtbf-budget", "2600"], &["--delta", "--mtbf-budget"]);
    assert_bad_input(&["run", "--algo", "lowpass", "--alpha", "0.5", "--mtbf-budget", "2600"], &["--alpha", "--mtbf-budget"]);
    for bad in ["0", "-5", "NaN", "inf", "2e10"] {
        assert_bad_input(&["run", "--algo", "pada", "--mtbf-budget", bad, "--seconds", "10"], &["--mtbf-budget", "0 < budget <= 1e10"]);
    }
    assert_bad_input(
        &["run", "--algo", "pada", "--mtbf-budget", "2600", "--switch-at", "10"],
        &["--switch-at", "--mtbf-budget"],
    );
    // pada sil checks the same flags before it builds or boots anything.
    assert_bad_input(&["sil", "--algo", "sarsa", "--mtbf-budget", "1e7"], &["--mtbf-budget", "pada and lowpass"]);
    assert_bad_input(&["sil", "--algo", "pada", "--delta", "0.5", "--mtbf-budget", "1e7"], &["--delta", "--mtbf-budget"]);
    assert_bad_input(&["sil", "--algo", "pada", "--mtbf-budget", "NaN"], &["--mtbf-budget", "0 < budget <= 1e10"]);
    assert_bad_input(&["paper", "pendulum", "--task", "leo"], &["--task", "pada paper wear"]);
    assert_bad_input(&["paper", "wear", "--task", "moon"], &["moon", "pendulum", "leo"]);
}

#[test]
fn paper_wear_writes_the_report_the_figures_and_a_plan() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("wear");
    let args = ["paper", "wear", "--trials", "2", "--seconds", "60", "--out", out_dir.to_str().unwrap()];
    let out = pada(&args);
    ok(&out);
    let report = std::fs::read_to_string(out_dir.join("report.md")).unwrap();
    for needle in [
        "# Learning on a wear budget (pendulum)",
        "| strategy | parameters | MTBF [s] | physical MTBF [s] | end performance | rise time [s]",
        "| pada + governor | budget 2594 s; mean Δ",
        "| lowpass + governor | budget 3891 s; mean α",
        "| ou | theta 0.150, sigma 0.400 |",
        "| action-penalty | weight 3.000 |",
        "## Pareto front, end performance against the paper's MTBF",
        "## Pareto front, end performance against the physical MTBF",
        "pada at a budget of 2594 s (2× SARSA(λ))",
        "held in ",
    ] {
        assert!(report.contains(needle), "report.md lacks {needle:?}:\n{report}");
    }
    for f in ["summary.json", "configurations.csv", "timing.json", "wear-pareto.png", "wear-pareto.svg", "wear-curves.png"] {
        assert!(out_dir.join(f).is_file(), "{f}");
    }
    let csv = std::fs::read_to_string(out_dir.join("configurations.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 23, "a header and 23 configurations");
    // The same report from the same command.
    let again = dir.path().join("again");
    let mut args2 = args;
    args2[7] = again.to_str().unwrap();
    assert_eq!(pada(&args2).status.code(), Some(0));
    assert_eq!(std::fs::read_to_string(again.join("report.md")).unwrap(), report);
    // As a plan for a cluster: one trial file per trial.
    let plan = dir.path().join("plan");
    let out = pada(&["paper", "wear", "--trials", "2", "--seconds", "60", "--plan", plan.to_str().unwrap()]);
    ok(&out);
    let plan_json = std::fs::read_to_string(plan.join("plan.json")).unwrap();
    assert!(plan_json.contains("\"paper-wear\"") && plan_json.contains("\"mtbf_budget_s\""), "{plan_json}");
    assert_eq!(std::fs::read_dir(plan.join("trials")).unwrap().count(), 46);
    for i in 0..46 {
        let out = pada(&["trial", "--plan", plan.to_str().unwrap(), "--index", &i.to_string()]);
        assert_eq!(out.status.code(), Some(0), "trial {i}: {}", String::from_utf8_lossy(&out.stderr));
    }
    // The merge reports exactly what the local run reported.
    let merged = dir.path().join("merged");
    let out = pada(&[
        "paper", "wear", "--trials", "2", "--seconds", "60", "--merge", plan.to_str().unwrap(), "--out", merged.to_str().unwrap(),
    ]);
    ok(&out);
    assert_eq!(std::fs::read_to_string(merged.join("report.md")).unwrap(), report);
}

#[test]
fn pada_run_on_a_board_learns_on_a_wear_budget() {
    let dir = tempfile::tempdir().unwrap();
    let run = |name: &str| {
        let out = pada(&[
            "run", "--board", "f405", "--task", "physical-pendulum", "--algo", "pada", "--mtbf-budget", "1.1e8", "--trials", "2",
            "--seconds", "120", "--json", "--out", dir.path().join(name).to_str().unwrap(),
        ]);
        ok(&out);
        serde_json::from_slice::<serde_json::Value>(&out.stdout).unwrap()
    };
    let a = run("a");
    let g = &a["governor"];
    assert_eq!(g["budget_s"], 1.1e8);
    assert!(g["moves"]["mean"].as_f64().unwrap() > 0.0, "{g}");
    assert_eq!(a["parameters"]["mtbf_budget_s"], 1.1e8);
    for t in a["per_trial"].as_array().unwrap() {
        assert_eq!(t["governor"]["held"], t["mtbf_s"].as_f64().unwrap() >= 1.1e8, "{t}");
    }
    // The board's run reproduces bit for bit.
    let b = run("b");
    assert_eq!(a["per_trial"], b["per_trial"]);
    assert_bad_input(
        &["run", "--board", "f405", "--task", "physical-pendulum", "--algo", "ou", "--mtbf-budget", "1e8"],
        &["--mtbf-budget", "pada and lowpass"],
    );
}

#[test]
fn the_gentle_explorations_parameters_name_their_range() {
    assert_bad_input(&["run", "--algo", "ou", "--theta", "0"], &["theta", "0 < theta <= 1"]);
    assert_bad_input(&["run", "--algo", "ou", "--sigma", "5"], &["sigma", "0 < sigma <= 4"]);
    assert_bad_input(&["run", "--algo", "pink", "--sigma", "NaN"], &["sigma"]);
    assert_bad_input(&["run", "--algo", "action-penalty", "--weight", "-1"], &["weight", "10000"]);
    assert_bad_input(&["run", "--algo", "epsilon-pada", "--delta", "1.5"], &["--delta", "0 < delta <= 1"]);
    assert_bad_input(&["run", "--algo", "pink", "--theta", "0.2"], &["--theta applies only to ou", "not to pink"]);
    assert_bad_input(&["run", "--algo", "sarsa", "--weight", "1"], &["--weight applies only to action-penalty"]);
}

/// `pada sil --robot FILE`: a path that is no file, a file with a bad
/// field, a robot.toml whose URDF is missing, `--robot` with `--task`,
/// and a calibration the board cannot read are each one line and exit
/// code 2, before anything is built or booted; `--help` says what the
/// path is.
#[test]
fn sil_robot_file_errors_are_one_line_and_the_help_says_what_the_path_is() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("nothing/robot.toml");
    let missing = missing.to_str().unwrap();
    assert_bad_input(&["sil", "--robot", missing], &["--robot", missing, "cannot read it"]);
    // The example arm with a servo pada does not know.
    let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/robots/arm2");
    let toml = std::fs::read_to_string(example.join("robot.toml")).unwrap();
    assert!(toml.contains("servo = \"XM430-W350\""));
    std::fs::copy(example.join("arm2.urdf"), dir.path().join("arm2.urdf")).unwrap();
    let bad = write(dir.path(), "robot.toml", &toml.replacen("servo = \"XM430-W350\"", "servo = \"XM999\"", 1));
    assert_bad_input(&["sil", "--robot", &bad], &[&bad, "joint[0].servo", "XM999", "valid are", "XM430-W350"]);
    // Its URDF missing.
    let lost = write(dir.path(), "lost.toml", &toml.replacen("urdf = \"arm2.urdf\"", "urdf = \"nowhere.urdf\"", 1));
    assert_bad_input(&["sil", "--robot", &lost], &["nowhere.urdf"]);
    assert_bad_input(&["sil", "--robot", &bad, "--task", "leo"], &["--robot", "--task"]);
    // (The example arm as written runs: tests/tests/sil.rs's arm test.)
    let help = String::from_utf8_lossy(&pada(&["sil", "--help"]).stdout).into_owned();
    for needle in ["--robot <robot.toml>", "the path of its robot.toml", "relative to the current directory", "cargo xtask qemu --robot FILE"] {
        assert!(help.contains(needle), "pada sil --help lacks {needle:?}:\n{help}");
    }
}
