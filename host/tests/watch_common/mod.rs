//! What the `pada watch` tests share: the real binary started as a user
//! starts it, its printed addresses, a real HTTP client (ureq), SIGINT,
//! and recorded streams from `pada run --telemetry`.

#![allow(dead_code)]

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, Output, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// A running `pada watch`.
pub struct Watch {
    /// The process (stdout piped for `--json`).
    pub child: Option<Child>,
    /// The page's address, as printed (`http://127.0.0.1:PORT/`).
    pub url: String,
    /// The telemetry address for `--listen`, as printed (`tcp:…`).
    pub listen: Option<String>,
    /// Everything it printed on stderr so far.
    pub stderr: Arc<Mutex<Vec<String>>>,
}

impl Watch {
    /// Starts `pada watch ARGS --serve 127.0.0.1:0` and waits for its URL
    /// (and, with `--listen`, its telemetry address).
    pub fn start(args: &[&str]) -> Watch {
        Watch::start_with(args, Stdio::null())
    }

    /// [`Watch::start`] with `stdin` as its standard input.
    pub fn start_with(args: &[&str], stdin: Stdio) -> Watch {
        let mut child = Command::new(env!("CARGO_BIN_EXE_pada"))
            .arg("watch")
            .args(args)
            .args(["--serve", "127.0.0.1:0"])
            .stdin(stdin)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("pada watch starts");
        let stderr = child.stderr.take().unwrap();
        let lines = Arc::new(Mutex::new(Vec::new()));
        {
            let lines = lines.clone();
            std::thread::spawn(move || {
                for line in BufReader::new(stderr).lines().map_while(Result::ok) {
                    lines.lock().unwrap().push(line);
                }
            });
        }
        let mut w = Watch {
            child: Some(child),
            url: String::new(),
            listen: None,
            stderr: lines,
        };
        let wants_listen = args.contains(&"--listen");
        let deadline = Instant::now() + Duration::from_secs(30);
        loop {
            {
                let lines = w.stderr.lock().unwrap();
                for l in lines.iter() {
                    if let Some(rest) = l.strip_prefix("watch: http://") {
                        let addr = rest.split('/').next().unwrap();
                        w.url = format!("http://{addr}/");
                    }
                    if let Some(rest) = l.strip_prefix("watch: waiting for a telemetry sender on ")
                    {
                        w.listen = Some(rest.trim().to_string());
                    }
                }
            }
            if !w.url.is_empty() && (!wants_listen || w.listen.is_some()) {
                return w;
            }
            if let Some(status) = w.child.as_mut().unwrap().try_wait().unwrap() {
                panic!(
                    "pada watch exited early ({status}): {:?}",
                    w.stderr.lock().unwrap()
                );
            }
            assert!(
                Instant::now() < deadline,
                "no URL printed: {:?}",
                w.stderr.lock().unwrap()
            );
            std::thread::sleep(Duration::from_millis(20));
        }
    }

    /// GET `path` (e.g. `api/state`): status and body.
    pub fn get(&self, path: &str) -> (u16, String) {
        get(&format!("{}{path}", self.url))
    }

    /// `/api/state`, parsed.
    pub fn state(&self) -> serde_json::Value {
        let (status, body) = self.get("api/state");
        assert_eq!(status, 200, "{body}");
        serde_json::from_str(&body).expect("/api/state is JSON")
    }

    /// Polls `/api/state` until `done` holds (at most `secs` seconds).
    pub fn wait_for(
        &self,
        secs: u64,
        what: &str,
        done: impl Fn(&serde_json::Value) -> bool,
    ) -> serde_json::Value {
        let deadline = Instant::now() + Duration::from_secs(secs);
        loop {
            let s = self.state();
            if done(&s) {
                return s;
            }
            assert!(
                Instant::now() < deadline,
                "{what}: not within {secs} s; last state: {}",
                short(&s)
            );
            std::thread::sleep(Duration::from_millis(100));
        }
    }

    /// Sends SIGINT (Ctrl-C) and waits for the exit.
    pub fn interrupt(mut self) -> Output {
        let child = self.child.take().unwrap();
        let pid = rustix::process::Pid::from_child(&child);
        rustix::process::kill_process(pid, rustix::process::Signal::INT).expect("SIGINT");
        let out = child.wait_with_output().unwrap();
        // The stderr reader may still be draining.
        std::thread::sleep(Duration::from_millis(100));
        out
    }

    /// Its stderr so far, one string.
    pub fn stderr_text(&self) -> String {
        self.stderr.lock().unwrap().join("\n")
    }
}

impl Drop for Watch {
    fn drop(&mut self) {
        if let Some(mut c) = self.child.take() {
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}

/// A client that returns 4xx and 5xx as statuses, not errors.
pub fn agent() -> ureq::Agent {
    ureq::Agent::config_builder()
        .http_status_as_error(false)
        .timeout_global(Some(Duration::from_secs(20)))
        .build()
        .into()
}

/// GET `url`: status and body.
pub fn get(url: &str) -> (u16, String) {
    let mut r = agent()
        .get(url)
        .call()
        .unwrap_or_else(|e| panic!("GET {url}: {e}"));
    let status = r.status().as_u16();
    let body = r
        .body_mut()
        .with_config()
        .limit(64 << 20)
        .read_to_string()
        .unwrap();
    (status, body)
}

/// The state without its long series, for messages.
pub fn short(s: &serde_json::Value) -> String {
    let mut s = s.clone();
    if let Some(o) = s.as_object_mut() {
        o.remove("learning");
        o.remove("fatigue");
        o.remove("last_episode");
    }
    s.to_string()
}

/// `pada run --task TASK --algo pada --trials 1 --seconds S --telemetry
/// TARGET --json` with its output in `out`; the run's output.
pub fn pada_run(task: &str, seconds: &str, telemetry: &str, out: &Path) -> Output {
    let o = Command::new(env!("CARGO_BIN_EXE_pada"))
        .args([
            "run",
            "--task",
            task,
            "--algo",
            "pada",
            "--trials",
            "1",
            "--threads",
            "1",
            "--seconds",
            seconds,
            "--json",
            "--telemetry",
            telemetry,
            "--out",
        ])
        .arg(out)
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "pada run: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

