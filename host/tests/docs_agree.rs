//! The docs say what the code does: every `pada` and `cargo xtask` command
//! in the README's and the guides' shell blocks exists with every flag it
//! passes (checked against the real `pada`'s `--help` and xtask's usage),
//! every version the docs state beside its constant's name is the
//! constant's value, and the host's LEO table is the size the README says.

mod common;
use common::*;
use std::collections::BTreeMap;
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn read(rel: &str) -> String {
    std::fs::read_to_string(root().join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

/// The documents whose shell blocks a user copies.
const GUIDES: [&str; 8] = [
    "README.md",
    "docs/commands.md",
    "docs/your-robot.md",
    "docs/board.md",
    "docs/sil.md",
    "docs/cluster.md",
    "examples/robots/arm2/README.md",
    "examples/robots/so101/README.md",
];

/// Every command line of the ```sh blocks of `doc`, comments cut, split at
/// `&&`, `|` and `;`.
fn shell_commands(doc: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut inside = false;
    for line in doc.lines() {
        let t = line.trim();
        if t.starts_with("```") {
            inside = !inside && (t == "```sh" || t == "```bash" || t == "```console");
            continue;
        }
        if !inside {
            continue;
        }
        let code = t.split(" #").next().unwrap_or("").trim_start_matches("$ ");
        for part in code.split("&&").flat_map(|p| p.split('|')).flat_map(|p| p.split(';')) {
            let p = part.trim();
            if !p.is_empty() && !p.starts_with('#') {
                out.push(p.to_string());
            }
        }
    }
    out
}

/// `pada`'s subcommands that have subcommands of their own.
fn nested(sub: &str) -> bool {
    matches!(sub, "paper" | "leo")
}

#[test]
fn every_documented_pada_command_and_flag_exists() {
    let mut help: BTreeMap<String, String> = BTreeMap::new();
    let mut checked = 0;
    for doc in GUIDES {
        for cmd in shell_commands(&read(doc)) {
            let words: Vec<&str> = cmd.split_whitespace().collect();
            let Some(start) = words.iter().position(|w| *w == "pada" || w.ends_with("/pada")) else { continue };
            // `cd firmware` and the like, or `pada` as an argument.
            if start != 0 && words[0] != "target/release/pada" {
                continue;
            }
            let rest = &words[start + 1..];
            let Some(sub) = rest.first().filter(|w| !w.starts_with('-')) else { continue };
            let mut path = vec![sub.to_string()];
            if nested(sub) {
                if let Some(s2) = rest.get(1).filter(|w| !w.starts_with('-') && !w.starts_with('[')) {
                    path.push(s2.to_string());
                }
            }
            let key = path.join(" ");
            let text = help.entry(key.clone()).or_insert_with(|| {
                let mut args: Vec<&str> = path.iter().map(String::as_str).collect();
                args.push("--help");
                let out = pada(&args);
                assert_eq!(out.status.code(), Some(0), "{doc}: `pada {key}` is not a command: {cmd}");
                String::from_utf8_lossy(&out.stdout).into_owned()
            });
            for flag in rest.iter().filter(|w| w.starts_with("--")) {
                let flag = flag.trim_start_matches('[').split(['=', ']', '|']).next().unwrap_or(flag);
                assert!(text.contains(flag), "{doc}: `pada {key}` has no {flag} (in: {cmd})");
                checked += 1;
            }
        }
    }
    assert!(checked > 40, "too few flags found in the docs ({checked}): the parser is broken");
}

#[test]
fn every_documented_xtask_command_and_flag_exists() {
    let src = read("xtask/src/args.rs");
    let usage = &src[src.find("const USAGE").expect("xtask's USAGE")..];
    let usage = &usage[..usage.find("\";").unwrap_or(usage.len())];
    let mut checked = 0;
    for doc in GUIDES.iter().chain(&["firmware/README.md"]) {
        for cmd in shell_commands(&read(doc)) {
            let Some(rest) = cmd.strip_prefix("cargo xtask ") else { continue };
            let words: Vec<&str> = rest.split_whitespace().collect();
            let task = words[0];
            assert!(usage.contains(&format!("\n  {task}")), "{doc}: `cargo xtask {task}` is not a task: {cmd}");
            for flag in words.iter().take_while(|w| **w != "--").filter(|w| w.starts_with("--")) {
                assert!(usage.contains(*flag), "{doc}: `cargo xtask {task}` has no {flag} (in: {cmd})");
                checked += 1;
            }
        }
    }
    assert!(checked > 5, "too few xtask flags found ({checked})");
}

/// The number nearest before `name` on each line of `text` that names it.
fn stated_before(text: &str, name: &str) -> Vec<(usize, u32)> {
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let mut from = 0;
        while let Some(at) = line[from..].find(name) {
            let before = &line[..from + at];
            let digits: String = before
                .chars()
                .rev()
                .skip_while(|c| !c.is_ascii_digit())
                .take_while(|c| c.is_ascii_digit())
                .collect::<Vec<_>>()
                .into_iter()
                .rev()
                .collect();
            if let Ok(n) = digits.parse() {
                out.push((i + 1, n));
            }
            from += at + name.len();
        }
    }
    out
}

#[test]
fn the_versions_the_docs_state_are_the_codes() {
    let constants: [(&str, u32); 4] = [
        ("`PROTOCOL_VERSION`", pada_core::wire::PROTOCOL_VERSION as u32),
        ("`FORMAT_VERSION`", pada_core::checkpoint::FORMAT_VERSION as u32),
        ("`STATE_VERSION`", pada_core::checkpoint::STATE_VERSION as u32),
        ("`CONFIG_HASH_VERSION`", pada_core::profile::CONFIG_HASH_VERSION),
    ];
    let mut stated = 0;
    for doc in ["docs/core.md", "firmware/README.md", "docs/wear/README.md", "docs/sil.md", "README.md"] {
        let text = read(doc);
        for (name, value) in constants {
            for (line, n) in stated_before(&text, name) {
                assert_eq!(n, value, "{doc}:{line} states {name} {n}; the code's is {value}");
                stated += 1;
            }
        }
    }
    assert!(stated >= 4, "the docs state only {stated} versions beside their constants");
}

#[test]
fn the_hosts_leo_table_is_the_size_the_readme_says() {
    let leo = pada_core::robot::registry::find("leo").expect("LEO is a built-in robot").spec;
    let p = pada_core::profile::Board::Host.profile(leo).expect("the host has a LEO profile");
    let slots = p.weights().expect("a sized table");
    let mib = p.table_bytes().unwrap() >> 20;
    let log2 = slots.trailing_zeros();
    assert!(slots.is_power_of_two());
    let readme = read("README.md");
    let row = readme.lines().find(|l| l.starts_with("| `host` |")).expect("the README's board table has a host row");
    assert!(
        row.contains(&format!("2^{log2} slots")) && row.contains(&format!("{mib} MiB")),
        "README's host row says {row:?}; the code's LEO table is 2^{log2} slots, {mib} MiB"
    );
}
