//! `pada watch` in a real browser: Debian's Chromium, headless, loads the
//! page of a live `pada run --task leo --telemetry tcp:…` and is asked,
//! through the DevTools protocol, for the plots in its DOM and for two
//! screenshots taken seconds apart without reloading. The plots must be
//! there (SVG with drawn elements, non-blank pixels in each plot's box)
//! and each must change between the screenshots while learning goes on.
//!
//! The DevTools client is three calls (`Runtime.evaluate`,
//! `Page.captureScreenshot`, over one WebSocket with tungstenite) written
//! here: a full client crate generates the whole protocol at build time
//! for them. `cargo xtask test` installs Chromium (`.ci/install chromium`).

mod watch_common;

use base64::Engine as _;
use std::io::{BufRead, BufReader};
use std::net::TcpStream;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};
use tungstenite::stream::MaybeTlsStream;
use tungstenite::{Message, WebSocket};
use watch_common::Watch;

const CHROMIUM: &str = "/usr/bin/chromium";

/// Chromium, killed when dropped.
struct Browser {
    child: Child,
    _profile: tempfile::TempDir,
    devtools_port: u16,
}

impl Drop for Browser {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

impl Browser {
    /// Headless Chromium on `url`, with the flags that keep it off the
    /// (closed) network, a fresh profile and DevTools on a free port.
    fn open(url: &str) -> Browser {
        assert!(
            std::path::Path::new(CHROMIUM).exists(),
            "{CHROMIUM} is missing: `cargo xtask test` installs it (as root; or run `sudo .ci/install chromium`)"
        );
        let profile = tempfile::tempdir().unwrap();
        let mut child = Command::new(CHROMIUM)
            .args([
                "--headless",
                "--no-sandbox",
                "--disable-gpu",
                "--disable-quic",
                "--no-first-run",
                "--disable-background-networking",
                "--disable-component-update",
                "--disable-sync",
                "--hide-scrollbars",
                "--force-device-scale-factor=1",
                "--window-size=1320,1500",
                "--remote-debugging-port=0",
            ])
            .arg(format!("--user-data-dir={}", profile.path().display()))
            .arg(url)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .expect("chromium starts");
        let stderr = child.stderr.take().unwrap();
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(stderr).lines().map_while(Result::ok) {
                if let Some(rest) = line.strip_prefix("DevTools listening on ws://127.0.0.1:") {
                    let port: u16 = rest.split('/').next().unwrap().parse().unwrap();
                    let _ = tx.send(port);
                }
            }
        });
        let devtools_port = rx
            .recv_timeout(Duration::from_secs(60))
            .expect("chromium prints its DevTools address");
        Browser {
            child,
            _profile: profile,
            devtools_port,
        }
    }

    /// The DevTools connection to the page showing `url`.
    fn page(&self, url: &str) -> Page {
        let list = format!("http://127.0.0.1:{}/json/list", self.devtools_port);
        let deadline = Instant::now() + Duration::from_secs(30);
        let ws = loop {
            let (_, body) = watch_common::get(&list);
            let targets: serde_json::Value = serde_json::from_str(&body).unwrap();
            let found = targets.as_array().unwrap().iter().find(|t| {
                t["type"] == "page" && t["url"].as_str().is_some_and(|u| u.starts_with(url))
            });
            if let Some(t) = found {
                break t["webSocketDebuggerUrl"].as_str().unwrap().to_string();
            }
            assert!(Instant::now() < deadline, "no page for {url}: {body}");
            std::thread::sleep(Duration::from_millis(100));
        };
        let (socket, _) = tungstenite::connect(ws.as_str()).expect("DevTools WebSocket");
        Page { socket, next_id: 1 }
    }
}

/// One page's DevTools session.
struct Page {
    socket: WebSocket<MaybeTlsStream<TcpStream>>,
    next_id: u64,
}

impl Page {
    /// Sends a command and returns its result (events in between are
    /// skipped).
    fn call(&mut self, method: &str, params: serde_json::Value) -> serde_json::Value {
        let id = self.next_id;
        self.next_id += 1;
        let msg = serde_json::json!({ "id": id, "method": method, "params": params });
        self.socket.send(Message::text(msg.to_string())).unwrap();
        loop {
            let Message::Text(text) = self.socket.read().unwrap() else {
                continue;
            };
            let v: serde_json::Value = serde_json::from_str(text.as_str()).unwrap();
            if v["id"] == id {
                assert!(v["error"].is_null(), "{method}: {v}");
                return v["result"].clone();
            }
        }
    }

    /// Evaluates a JavaScript expression that returns JSON text.
    fn eval(&mut self, js: &str) -> serde_json::Value {
        let r = self.call(
            "Runtime.evaluate",
            serde_json::json!({ "expression": js, "returnByValue": true }),
        );
        let text = r["result"]["value"].as_str().unwrap_or("null").to_string();
        serde_json::from_str(&text).unwrap()
    }

    /// A PNG screenshot of the viewport.
    fn screenshot(&mut self) -> Vec<u8> {
        let r = self.call(
            "Page.captureScreenshot",
            serde_json::json!({ "format": "png" }),
        );
        base64::engine::general_purpose::STANDARD
            .decode(r["data"].as_str().unwrap())
            .unwrap()
    }
}

/// What the DOM says about each plot: its box and what its SVG holds.
const PLOTS_JS: &str = r#"JSON.stringify({
  version: document.querySelector('header') && document.querySelector('header').dataset.version,
  plots: [...document.querySelectorAll('figure.plot')].map(f => {
    const r = f.getBoundingClientRect();
    return { id: f.id, x: r.x, y: r.y, w: r.width, h: r.height,
             svg: f.querySelectorAll('svg').length,
             drawn: f.querySelectorAll('polyline, path, circle, rect, line').length };
  })
})"#;

struct Shot {
    pixmap: resvg::tiny_skia::Pixmap,
}

impl Shot {
    fn new(png: &[u8]) -> Shot {
        Shot {
            pixmap: resvg::tiny_skia::Pixmap::decode_png(png).expect("a PNG screenshot"),
        }
    }

    /// RGBA pixels inside a box.
    fn region(&self, p: &serde_json::Value) -> Vec<[u8; 4]> {
        let f = |k: &str| p[k].as_f64().unwrap().round() as i64;
        let (x0, y0, w, h) = (f("x"), f("y"), f("w"), f("h"));
        let (pw, ph) = (self.pixmap.width() as i64, self.pixmap.height() as i64);
        let mut out = Vec::new();
        for y in y0.max(0)..(y0 + h).min(ph) {
            for x in x0.max(0)..(x0 + w).min(pw) {
                let c = self.pixmap.pixel(x as u32, y as u32).unwrap();
                out.push([c.red(), c.green(), c.blue(), c.alpha()]);
            }
        }
        out
    }
}

#[test]
fn chromium_shows_the_plots_of_a_live_run_and_they_change_as_it_learns() {
    let dir = tempfile::tempdir().unwrap();
    let w = Watch::start(&["--listen", "tcp:127.0.0.1:0"]);
    let target = w.listen.clone().unwrap();
    // LEO with telemetry runs at a few times real time in this unoptimised
    // test build (each Episode frame carries the checksum of the 2^22
    // weights), so 2400 s of learning keeps it going for the whole test.
    let mut run = Command::new(env!("CARGO_BIN_EXE_pada"))
        .args([
            "run",
            "--task",
            "leo",
            "--algo",
            "pada",
            "--delta",
            "0.1667",
            "--trials",
            "1",
            "--threads",
            "1",
            "--seconds",
            "2400",
            "--telemetry",
            &target,
            "--out",
        ])
        .arg(dir.path().join("run"))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    struct Kill<'a>(&'a mut Child);
    impl Drop for Kill<'_> {
        fn drop(&mut self) {
            let _ = self.0.kill();
            let _ = self.0.wait();
        }
    }
    let run = Kill(&mut run);
    // Every plot has something to draw: two test runs and a finished
    // episode.
    let first = w.wait_for(300, "two test runs", |s| {
        s["learning"]["curve"]
            .as_array()
            .is_some_and(|c| c.len() >= 2)
            && !s["last_episode"].is_null()
    });
    assert!(
        first["ended"].is_null(),
        "the run ended before the browser looked"
    );

    let browser = Browser::open(&w.url);
    let mut page = browser.page(&w.url);
    let deadline = Instant::now() + Duration::from_secs(30);
    // (The target can still show about:blank for a moment.)
    let loaded =
        "JSON.stringify(document.readyState === 'complete' && location.href.startsWith('http') \
                  && document.querySelectorAll('figure.plot').length === 4)";
    while page.eval(loaded) != true {
        assert!(Instant::now() < deadline, "the page did not load");
        std::thread::sleep(Duration::from_millis(100));
    }
    let dom1 = page.eval(PLOTS_JS);
    let shot1 = page.screenshot();
    // Count the live part's replacements from now on.
    page.eval(
        "window.__t0 = performance.now(); window.__updates = 0; \
         new MutationObserver(() => window.__updates++) \
           .observe(document.getElementById('live'), { childList: true }); 'null'",
    );

    // Learning goes on: wait for another test run and another finished
    // episode, and for the page to have refreshed itself (it is never
    // reloaded here).
    let curve1 = first["learning"]["curve"].as_array().unwrap().len();
    let steps1 = first["learning"]["learning_steps"].as_u64().unwrap();
    let state = w.wait_for(300, "more learning", |s| {
        s["learning"]["curve"].as_array().unwrap().len() > curve1
            && s["learning"]["learning_steps"].as_u64().unwrap() > steps1 + 300
    });
    std::thread::sleep(Duration::from_millis(2500));
    let dom2 = page.eval(PLOTS_JS);
    let shot2 = page.screenshot();
    let rate = page.eval(
        "JSON.stringify({ updates: window.__updates, s: (performance.now() - window.__t0) / 1000 })",
    );
    let out = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    std::fs::write(out.join("watch-browser-1.png"), &shot1).unwrap();
    std::fs::write(out.join("watch-browser-2.png"), &shot2).unwrap();
    assert!(
        state["ended"].is_null(),
        "learning stopped before the second screenshot"
    );
    drop(run);

    // The live part was replaced in place (a newer state version).
    assert_ne!(
        dom1["version"], dom2["version"],
        "the page did not refresh itself"
    );
    // About once a second: the bound allows for a loaded machine, where a
    // refresh still in flight makes the page skip a tick.
    let (updates, secs) = (
        rate["updates"].as_f64().unwrap(),
        rate["s"].as_f64().unwrap(),
    );
    println!("the page replaced its live part {updates} times in {secs:.1} s");
    assert!(
        secs > 2.0 && updates >= (secs / 2.0).floor(),
        "{updates} refreshes in {secs:.1} s"
    );
    let (a, b) = (Shot::new(&shot1), Shot::new(&shot2));
    let ids = [
        "plot-returns",
        "plot-damage",
        "plot-reengagements",
        "plot-episode",
    ];
    for (i, id) in ids.iter().enumerate() {
        for dom in [&dom1, &dom2] {
            let p = &dom["plots"][i];
            assert_eq!(p["id"], *id, "{dom}");
            assert_eq!(p["svg"], 1, "{id}: no SVG in the DOM");
            assert!(
                p["drawn"].as_u64().unwrap() >= 10,
                "{id}: nothing drawn: {p}"
            );
            assert!(
                p["w"].as_f64().unwrap() >= 300.0 && p["h"].as_f64().unwrap() >= 200.0,
                "{p}"
            );
        }
        // Each screenshot's box is where its DOM says (a banner can move
        // the plots down between the two).
        let (r1, r2) = (a.region(&dom1["plots"][i]), b.region(&dom2["plots"][i]));
        assert!(
            !r1.is_empty() && r1.len() == r2.len(),
            "{id} is off the screenshot"
        );
        let ink = |r: &[[u8; 4]]| {
            r.iter()
                .filter(|c| c[0] < 200 || c[1] < 200 || c[2] < 200)
                .count() as f64
                / r.len() as f64
        };
        assert!(
            ink(&r1) > 0.01 && ink(&r2) > 0.01,
            "{id}: blank ({}, {})",
            ink(&r1),
            ink(&r2)
        );
        let changed = r1.iter().zip(&r2).filter(|(x, y)| x != y).count();
        assert!(
            changed > 100,
            "{id}: only {changed} pixels changed between the screenshots"
        );
    }
}
