//! LEO as a runner task: `pada run --task leo` end to end, the weights file
//! (round trip, refusal of another configuration, of a corrupted file) and
//! `pada render`.

use pada::experiment::build_agent;
use pada::leo::rl::{leo_params, LeoTask};
use pada::experiment::task::Task;
use pada::weights::{decode, encode, load, save, WeightsHeader};
use pada_core::claim_table::{Claim, Occupancy};
use pada_core::fixed::Q16;
use pada_core::weights::WeightStore;
use pada_core::policy::PolicyKind;
use std::process::Command;

fn pada(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_pada"))
        .args(args)
        .output()
        .expect("pada runs")
}

#[test]
fn run_task_leo_json_end_to_end_then_render() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let w = dir.path().join("leo.pdw");
    let o = pada(&[
        "run",
        "--task",
        "leo",
        "--algo",
        "pada",
        "--delta",
        "0.34",
        "--trials",
        "1",
        "--seconds",
        "60",
        "--json",
        "--out",
        out.to_str().unwrap(),
        "--save-weights",
        w.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["task"], "leo");
    assert_eq!(v["parameters"]["gamma"].as_f64().unwrap() as f32, 0.9962);
    assert!(v["end_walked_m"]["mean"].is_number(), "{v}");
    assert!(v["end_speed_m_s"]["mean"].is_number(), "{v}");
    assert!(v["learning_falls"]["mean"].as_f64().unwrap() >= 0.0);
    let steps = v["per_trial"][0]["learning_steps"].as_u64().unwrap();
    assert!((1800..1800 + 750).contains(&steps), "{steps}");
    let curve = std::fs::read_to_string(out.join("trial-000.csv")).unwrap();
    assert!(curve
        .starts_with("test_run,learning_time_s,learning_episodes,return,walked_m,fell,duration_s"));

    let r = dir.path().join("render");
    let o = pada(&[
        "render",
        "--task",
        "leo",
        "--policy",
        w.to_str().unwrap(),
        "--out",
        r.to_str().unwrap(),
        "--seconds",
        "1",
        "--frames",
        "4",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in ["gait.svg", "gait.png", "gait.csv", "gait-animation.svg"] {
        let len = std::fs::metadata(r.join(f)).unwrap().len();
        assert!(len > 100, "{f}: {len} bytes");
    }
    let png = std::fs::read(r.join("gait.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
    // The animation: one group per recorded step (the CSV's rows), each
    // shown in its own slice of one loop, in order.
    let csv_rows = std::fs::read_to_string(r.join("gait.csv")).unwrap().lines().count() - 1;
    let anim = std::fs::read_to_string(r.join("gait-animation.svg")).unwrap();
    assert_eq!(anim.matches("<g visibility=\"hidden\">").count(), csv_rows);
    let starts: Vec<f64> = anim
        .split("keyTimes=\"0;")
        .skip(1)
        .map(|t| t.split(';').next().unwrap().parse().unwrap())
        .collect();
    assert_eq!(starts.len(), csv_rows);
    assert!(starts.windows(2).all(|w| w[0] < w[1] && w[1] < 1.0), "{starts:?}");
}

#[test]
fn render_refuses_a_weights_file_of_another_task() {
    // A pendulum agent's weights are not LEO's: refused, naming the field.
    let dir = tempfile::tempdir().unwrap();
    let w = dir.path().join("pendulum.pdw");
    let o = pada(&[
        "run", "--task", "pendulum", "--algo", "sarsa", "--trials", "1", "--seconds", "6",
        "--out", dir.path().join("run").to_str().unwrap(), "--save-weights", w.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = pada(&["render", "--policy", w.to_str().unwrap(), "--out", dir.path().join("r").to_str().unwrap()]);
    assert!(!o.status.success());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("another configuration") && e.contains("task"), "{e}");
}

#[test]
fn weights_round_trip_and_refusals() {
    let task = LeoTask::default();
    let spec = task.spec();
    let policy = PolicyKind::Pada { delta: 1.0 / 3.0 };
    let mut agent = build_agent(spec, policy).unwrap();
    agent.reset_weights(&mut rand_pcg::Pcg64::new(0xcafe_f00d_d15e_a5e5, 0x0a02_bdbf_7bb3_c0a7));
    // LEO's table is a claim table: claim some features and move their
    // weights; the rest read their initial weights.
    let keys: Vec<u32> = (0..500u32).map(|i| i.wrapping_mul(0x9E37_79B1)).collect();
    for (i, &k) in keys.iter().enumerate() {
        if let Claim::Slot { slot, .. } = agent.weights_mut().claim(k) {
            agent.weights_mut().add(slot as usize, Q16(i as i32 * 7 - 100_000), 0);
        }
    }
    agent.rehash();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("w.pdw");
    save(&path, spec, policy, true, &agent).unwrap();
    let (h, loaded) = load(&path, spec).unwrap();
    assert_eq!(h.policy, policy);
    assert!(h.switched);
    assert_eq!(loaded.weights_checksum(), agent.weights_checksum());
    assert_eq!(loaded.weights().occupancy(), Some(Occupancy { longest_probe: 0, ..agent.weights().occupancy().unwrap() }));
    assert_eq!(loaded.state().table_seed, agent.state().table_seed);
    for k in keys.iter().copied().chain([1, 2, 3]) {
        assert_eq!(loaded.weights().read(k), agent.weights().read(k), "feature {k:#x}");
    }

    // Another configuration: γ differs.
    let other = LeoTask::new(pada_core::agent::SarsaParams {
        gamma: 0.99,
        ..leo_params()
    });
    let e = load(&path, other.spec())
        .err()
        .expect("refused")
        .to_string();
    assert!(
        e.contains("gamma") && e.contains("another configuration"),
        "{e}"
    );

    // A corrupted byte in the weights.
    let mut bytes = std::fs::read(&path).unwrap();
    let k = bytes.len() / 2;
    bytes[k] ^= 0x40;
    std::fs::write(&path, &bytes).unwrap();
    let e = load(&path, spec).err().expect("refused").to_string();
    assert!(e.contains("corrupted") && e.contains("checksum"), "{e}");

    // Not a weights file; another version.
    assert!(decode(b"hello world, not weights")
        .unwrap_err()
        .to_string()
        .contains("magic"));
    let header = WeightsHeader { entry_bytes: 4, ..WeightsHeader::new(spec, policy, false, 2) };
    let mut b = encode(&header, &[Q16(1), Q16(2)][..]).unwrap();
    assert_eq!(decode(&b).unwrap().1, &[1, 0, 0, 0, 2, 0, 0, 0][..]);
    b[7] = b'9';
    assert!(decode(&b).unwrap_err().to_string().contains("version"));
    // A file of the layout before the claim table: one line that says so.
    b[7] = b'1';
    let e = decode(&b).unwrap_err().to_string();
    assert!(e.contains("version 1") && e.contains("without claim tags"), "{e}");
}
