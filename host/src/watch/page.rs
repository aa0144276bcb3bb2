//! The page: one HTML document with the plots inline as SVG, and a few
//! lines of script that replace its live part with `/live` once a second.
//! Nothing is loaded from anywhere else, so it works offline; without
//! script, it reloads itself every two seconds.

use super::plots::{EpisodePlot, FatiguePlot, ReturnsPlot};
use super::state::WatchState;
use crate::plot::to_svg;
use std::fmt::Write as _;

/// The page refreshes its live part this often \[ms\] (the target is
/// at least once a second).
pub const REFRESH_MS: u32 = 1000;

/// A stream silent this long is shown as stalled \[s\]: two refreshes, and
/// 40 control periods at the slowest rate (20 Hz), while a learning board
/// sends a `Step` every period.
pub const STALL_AFTER_S: f64 = 2.0;

/// What the page needs besides the state: how long ago data came.
#[derive(Debug, Clone, Copy)]
pub struct Clock {
    /// Seconds since `pada watch` started.
    pub wall_s: f64,
    /// Seconds since the last byte (`None`: nothing received yet).
    pub since_data_s: Option<f64>,
}

/// The plots' element ids, in page order.
pub const PLOT_IDS: [&str; 4] = [
    "plot-returns",
    "plot-damage",
    "plot-reengagements",
    "plot-episode",
];

/// Escapes text for HTML (`&`, `<`, `>`, `"`, `'`); five replacements do
/// not warrant a crate.
pub fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

const STYLE: &str = "
body { font-family: 'DejaVu Sans', sans-serif; margin: 0; background: #f4f4f4; color: #222; }
header { background: #203040; color: #fff; padding: 10px 16px; }
header h1 { font-size: 20px; margin: 0 0 4px 0; }
header .sub { font-size: 13px; color: #c8d4e0; }
.banner { padding: 8px 16px; font-weight: bold; }
.banner.stall { background: #ffd24d; }
.banner.ended { background: #c8d8f0; }
.banner.fault { background: #e04040; color: #fff; }
.banner.lost { background: #a0a0a0; color: #fff; }
.grid { display: grid; grid-template-columns: repeat(2, 640px); gap: 10px; padding: 10px 16px; }
figure.plot { margin: 0; width: 620px; height: 340px; background: #fff; padding: 10px; box-shadow: 0 1px 3px #bbb; }
.tables { display: flex; flex-wrap: wrap; gap: 16px; padding: 0 16px 16px 16px; align-items: flex-start; max-width: 1300px; }
table { border-collapse: collapse; background: #fff; font-size: 13px; box-shadow: 0 1px 3px #bbb; }
th, td { padding: 3px 8px; border-bottom: 1px solid #e4e4e4; text-align: left; }
td.n { text-align: right; font-variant-numeric: tabular-nums; }
caption { text-align: left; font-weight: bold; padding: 4px 0; }
";

/// The whole page.
pub fn page(state: &WatchState, clock: Clock) -> String {
    let live = live(state, clock);
    format!(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
<title>pada watch: {source}</title>\
<noscript><meta http-equiv=\"refresh\" content=\"2\"></noscript>\
<style>{STYLE}</style></head>\n<body>\n<main id=\"live\">{live}</main>\n\
<script>\n\
// Replaces the live part with the server's rendering once a second (one\n\
// request at a time; one that takes over 5 s is given up).\n\
const live = document.getElementById('live');\n\
let failures = 0, busy = false;\n\
async function refresh() {{\n\
  if (busy) return;\n\
  busy = true;\n\
  const abort = new AbortController();\n\
  const timer = setTimeout(() => abort.abort(), 5000);\n\
  try {{\n\
    const r = await fetch('/live', {{ cache: 'no-store', signal: abort.signal }});\n\
    if (!r.ok) throw new Error(r.status);\n\
    live.innerHTML = await r.text();\n\
    failures = 0;\n\
  }} catch (e) {{\n\
    if (++failures === 3) {{\n\
      const b = document.createElement('div');\n\
      b.className = 'banner lost';\n\
      b.textContent = 'lost the connection to pada watch (it has ended?): showing the last state';\n\
      live.prepend(b);\n\
    }}\n\
  }} finally {{\n\
    clearTimeout(timer);\n\
    busy = false;\n\
  }}\n\
}}\n\
setInterval(refresh, {REFRESH_MS});\n\
</script>\n</body></html>\n",
        source = escape(&state.source),
    )
}

/// The part of the page that changes: header, banners, plots, tables.
pub fn live(state: &WatchState, clock: Clock) -> String {
    let mut h = String::with_capacity(64 * 1024);
    let s = state;
    let policy = s
        .policy
        .as_ref()
        .map(|p| p.label.clone())
        .unwrap_or_else(|| "unknown (no Policy frame yet)".into());
    let state_name = match (&s.safety.state, s.mode) {
        (Some(st), _) => st.clone(),
        (None, Some(m)) => format!("{m} (from the steps; no State frame)"),
        (None, None) => "unknown".into(),
    };
    let _ = write!(
        h,
        "<header data-version=\"{}\"><h1>pada watch: {}</h1><div class=\"sub\">state <b id=\"state\">{}</b> · policy <b id=\"policy\">{}</b> · frames <b id=\"frames\">{}</b> · lost {} · gaps {} · {:.0} s watched</div></header>",
        s.version,
        escape(&s.source),
        escape(&state_name),
        escape(&policy),
        s.link.frames,
        s.bad_frames,
        s.link.seq_gaps,
        clock.wall_s,
    );
    if let Some(f) = &s.safety.fault {
        let _ = write!(
            h,
            "<div class=\"banner fault\" id=\"fault\">FAULT {}: {} at step {} ({} ms); torque is off</div>",
            escape(&f.cause),
            escape(&f.detail),
            f.step,
            f.time_ms
        );
    }
    match (&s.ended, clock.since_data_s) {
        (Some(why), _) => {
            let _ = write!(
                h,
                "<div class=\"banner ended\" id=\"ended\">the stream ended ({}); showing its final state</div>",
                escape(why)
            );
        }
        (None, Some(t)) if t >= STALL_AFTER_S => {
            let _ = write!(
                h,
                "<div class=\"banner stall\" id=\"stall\">no data for {t:.0} s</div>"
            );
        }
        (None, None) if clock.wall_s >= STALL_AFTER_S => {
            let _ = write!(
                h,
                "<div class=\"banner stall\" id=\"stall\">no data for {:.0} s (nothing received yet)</div>",
                clock.wall_s
            );
        }
        _ => {}
    }
    h.push_str("<div class=\"grid\">");
    let svgs = [
        to_svg(&ReturnsPlot(s)),
        to_svg(&FatiguePlot::damage(s)),
        to_svg(&FatiguePlot::reengagements(s)),
        to_svg(&EpisodePlot(s)),
    ];
    for (id, svg) in PLOT_IDS.iter().zip(svgs) {
        let svg =
            svg.unwrap_or_else(|e| format!("<p>cannot draw: {}</p>", escape(&format!("{e:#}"))));
        let _ = write!(h, "<figure class=\"plot\" id=\"{id}\">{svg}</figure>");
    }
    h.push_str("</div><div class=\"tables\">");
    tables(&mut h, s, &state_name);
    h.push_str("</div>");
    h
}

fn num(v: Option<f64>, digits: usize) -> String {
    match v {
        Some(v) if v.is_finite() => format!("{v:.digits$}"),
        _ => "–".into(),
    }
}

fn mtbf(v: Option<f64>) -> String {
    match v {
        Some(v) if v.is_finite() && v >= 1e6 => format!("{v:.3e} s"),
        Some(v) if v.is_finite() => format!("{v:.0} s"),
        _ => "∞ (no damage yet)".into(),
    }
}

fn tables(h: &mut String, s: &WatchState, state_name: &str) {
    // Learning and the policy.
    let l = &s.learning;
    let _ = write!(
        h,
        "<table id=\"learning\"><caption>Learning</caption>\
<tr><th>policy</th><td>{}</td></tr>\
<tr><th>learning episodes</th><td class=\"n\">{}</td></tr>\
<tr><th>test runs</th><td class=\"n\">{}</td></tr>\
<tr><th>learning time</th><td class=\"n\">{} s</td></tr>\
<tr><th>last test return</th><td class=\"n\">{}</td></tr>\
<tr><th>end performance (last {} runs)</th><td class=\"n\">{}</td></tr>\
<tr><th>rise time</th><td class=\"n\">{} s</td></tr>\
<tr><th>control period</th><td class=\"n\">{}</td></tr>\
<tr><th>claim table</th><td class=\"n\" id=\"table\">{}</td></tr></table>",
        escape(
            &s.policy
                .as_ref()
                .map_or("unknown".into(), |p| p.label.clone())
        ),
        s.latest.learning_episodes,
        s.latest.test_episodes,
        num(l.learning_time_s, 0),
        num(l.curve.last().map(|p| p.test_return), 1),
        l.end_window_runs,
        num(l.end_performance, 1),
        num(l.rise_time_s, 0),
        s.period_s
            .map(|p| format!("{:.1} ms ({})", p * 1e3, s.period_from.unwrap_or("")))
            .unwrap_or_else(|| "unknown".into()),
        s.latest.table.map_or("no claim table reported".into(), |t| format!(
            "{} of {} slots ({:.1} %), {} claims refused",
            t.claimed,
            t.slots,
            t.fraction * 100.0,
            t.claims_refused
        )),
    );
    // Fatigue and the MTBF.
    let f = &s.fatigue;
    let _ = write!(
        h,
        "<table id=\"fatigue\"><caption>Fatigue and predicted MTBF</caption>\
<tr><th>gearbox</th><th>damage J</th><th>re-engagements</th><th>MTBF, first {} actions</th><th>MTBF, whole run</th></tr>",
        f.window_actions
    );
    for (i, j) in f.joints.iter().enumerate() {
        let _ = write!(
            h,
            "<tr><td>joint {i}</td><td class=\"n\">{:.3e}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td></tr>",
            j.damage,
            j.reengagements,
            mtbf(j.window_mtbf_s),
            mtbf(j.mtbf_s)
        );
    }
    let provisional = if f.window_actions_seen < f.window_actions {
        format!(
            " (provisional: {} of {} actions)",
            f.window_actions_seen, f.window_actions
        )
    } else {
        String::new()
    };
    let _ = write!(
        h,
        "<tr><th>robot (weakest)</th><td></td><td></td><td class=\"n\" id=\"mtbf\">{}{}</td><td class=\"n\">{}</td></tr></table>",
        mtbf(f.robot_window_mtbf_s),
        provisional,
        mtbf(f.robot_mtbf_s)
    );
    // The link, the state and the faults.
    let k = &s.link;
    let _ = write!(
        h,
        "<table id=\"link\"><caption>Link and safety</caption>\
<tr><th>frames</th><td class=\"n\">{}</td></tr>\
<tr><th>bytes</th><td class=\"n\">{}</td></tr>\
<tr><th>sequence gaps (frames missing)</th><td class=\"n\">{} ({})</td></tr>\
<tr><th>CRC errors</th><td class=\"n\">{}</td></tr>\
<tr><th>COBS errors</th><td class=\"n\">{}</td></tr>\
<tr><th>oversize, too short, undecodable</th><td class=\"n\">{}, {}, {}</td></tr>\
<tr><th>state</th><td>{}</td></tr>\
<tr><th>fault</th><td>{}</td></tr>\
<tr><th>faults seen</th><td class=\"n\">{}</td></tr>",
        k.frames,
        k.bytes,
        k.seq_gaps,
        k.frames_missed,
        k.crc_errors,
        k.cobs_errors,
        k.oversize,
        k.too_short,
        k.decode_errors,
        escape(state_name),
        s.safety
            .fault
            .as_ref()
            .map_or("none".into(), |f| escape(&format!(
                "{}: {}",
                f.cause, f.detail
            ))),
        s.messages.fault,
    );
    for f in s.safety.history.iter().rev().take(5) {
        let _ = write!(
            h,
            "<tr><td>step {} ({} ms)</td><td>{}</td></tr>",
            f.step,
            f.time_ms,
            escape(&f.cause)
        );
    }
    h.push_str("</table>");
}
