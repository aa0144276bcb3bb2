//! `pada run --weights FILE`: trials continue from saved weights, and a
//! file for another task, table or learner is refused with one line.

mod common;
use common::{assert_bad_input, ok, pada};

/// The learning curve's returns of trial `t` in `dir`.
fn returns(dir: &std::path::Path, t: u32) -> Vec<String> {
    let csv = std::fs::read_to_string(dir.join(format!("trial-{t:03}.csv"))).unwrap();
    csv.lines().skip(1).map(|l| l.rsplit(',').next().unwrap().to_string()).collect()
}

/// A run from saved weights starts where the saving run ended: its first
/// test run (greedy, before learning) returns exactly what the saving
/// run's last test run returned, since both run the same weights from the
/// same start; and it then learns on (its curve is not the saving run's).
#[test]
fn a_run_continues_from_saved_weights_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let w = dir.path().join("a.wts").display().to_string();
    let (a, b, c) = (dir.path().join("a"), dir.path().join("b"), dir.path().join("c"));
    let base = ["run", "--task", "pendulum", "--algo", "pada", "--trials", "1", "--seconds", "120", "--threads", "1"];
    ok(&pada(&[&base[..], &["--out", a.to_str().unwrap(), "--save-weights", &w]].concat()));
    let out = ok(&pada(&[&base[..], &["--out", b.to_str().unwrap(), "--weights", &w]].concat()));
    assert!(out.contains("started from"), "{out}");
    let (ra, rb) = (returns(&a, 0), returns(&b, 0));
    assert_eq!(ra.last(), rb.first(), "the continuing run's first test run is not the saving run's last");
    assert_ne!(ra.first(), rb.first(), "the continuing run starts from the initial weights");
    // Without --weights the same command learns from nothing, as before.
    ok(&pada(&[&base[..], &["--out", c.to_str().unwrap()]].concat()));
    assert_eq!(returns(&c, 0), ra);
    // PADA's Δ restricts decisions, not the weights' meaning: another Δ
    // and SARSA(λ) continue from the same file.
    let d = dir.path().join("d");
    ok(&pada(&[
        "run", "--task", "pendulum", "--algo", "sarsa", "--trials", "1", "--seconds", "30", "--threads", "1",
        "--out", d.to_str().unwrap(), "--weights", &w,
    ]));
    // The greedy test run before learning: SARSA chooses among all
    // levels, PADA within Δ, so only the weights are shared; still a run.
    assert!(!returns(&d, 0).is_empty());
}

/// Weights for another task, learner or table, and no file, are refused
/// with one line naming the difference.
#[test]
fn weights_for_another_configuration_are_refused_with_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let w = dir.path().join("p.wts").display().to_string();
    let out = |n: &str| dir.path().join(n).display().to_string();
    ok(&pada(&[
        "run", "--task", "pendulum", "--algo", "pada", "--trials", "1", "--seconds", "10", "--threads", "1",
        "--out", &out("a"), "--save-weights", &w,
    ]));
    // Another task.
    assert_bad_input(
        &["run", "--task", "physical-pendulum", "--algo", "pada", "--trials", "1", "--seconds", "10", "--out", &out("b"), "--weights", &w],
        &["--weights", "p.wts", "written for another configuration", "task"],
    );
    // Another learner: a Markov filter adds a state dimension.
    assert_bad_input(
        &["run", "--task", "pendulum", "--algo", "markov-lowpass", "--trials", "1", "--seconds", "10", "--out", &out("c"), "--weights", &w],
        &["--weights", "p.wts", "another"],
    );
    // No such file.
    assert_bad_input(
        &["run", "--task", "pendulum", "--algo", "pada", "--trials", "1", "--seconds", "10", "--out", &out("d"), "--weights", &out("none.wts")],
        &["--weights", "cannot read", "none.wts"],
    );
    // Not a weights file.
    std::fs::write(dir.path().join("junk.wts"), b"not weights at all").unwrap();
    assert_bad_input(
        &["run", "--task", "pendulum", "--algo", "pada", "--trials", "1", "--seconds", "10", "--out", &out("e"), "--weights", &out("junk.wts")],
        &["--weights", "junk.wts", "bad magic"],
    );
}

/// `pada run --board B --weights`: a file for another robot, one whose
/// table cannot go into the board's, and one for another learner are each
/// refused with one line naming the difference.
#[test]
fn board_runs_refuse_weights_of_another_robot_board_or_learner_with_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let out = |n: &str| dir.path().join(n).display().to_string();
    let (leo, pp) = (out("leo.wts"), out("pp.wts"));
    ok(&pada(&["run", "--task", "leo", "--algo", "pada", "--trials", "1", "--seconds", "5", "--out", &out("a"), "--save-weights", &leo]));
    ok(&pada(&[
        "run", "--task", "physical-pendulum", "--algo", "pada", "--trials", "1", "--seconds", "10", "--out", &out("b"), "--save-weights", &pp,
    ]));
    let board = |extra: &[&str], o: &str| -> Vec<String> {
        [&["run", "--task", "physical-pendulum", "--board", "f405", "--algo", "pada", "--trials", "1", "--seconds", "5", "--out"][..], &[o], extra]
            .concat()
            .iter()
            .map(|s| s.to_string())
            .collect()
    };
    let refused = |args: Vec<String>, needles: &[&str]| {
        let a: Vec<&str> = args.iter().map(String::as_str).collect();
        assert_bad_input(&a, needles);
    };
    // Another robot: LEO's weights for the pendulum.
    refused(board(&["--weights", &leo], &out("c")), &["--weights", "leo.wts", "task is \"leo\" in the file but \"physical-pendulum\" here"]);
    // Another board: the pendulum's exact table into a hashed one.
    refused(
        board(&["--weights", &pp, "--table-log2", "12"], &out("d")),
        &["--weights", "pp.wts", "does not go into board f405's hashed 2^12"],
    );
    // Another learner: a Markov filter adds a state dimension to PADA's.
    let markov: Vec<String> = [
        "run", "--task", "leo", "--board", "f405", "--algo", "markov-lowpass", "--trials", "1", "--seconds", "5", "--out", &out("e"),
        "--weights", &leo,
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    refused(markov, &["--weights", "leo.wts", "written for another learner", "markov-lowpass"]);
    // And the same file goes in where it fits.
    let o = ok(&pada(&board(&["--weights", &pp], &out("f")).iter().map(String::as_str).collect::<Vec<_>>()));
    assert!(o.contains("weights: ") && o.contains("0 dropped"), "{o}");
}
