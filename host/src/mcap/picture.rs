//! `pada capture --file X.mcap --scene-png OUT.png`: frames of a
//! recording's `/scene` channel drawn side by side, side view (x forwards,
//! z up), from the `foxglove.SceneUpdate` line primitives themselves —
//! what Foxglove's 3D panel shows, flattened, for a reader without the
//! app.

use crate::plot::{plot_err, svg_to_png, FONT};
use plotters::prelude::*;
use serde::Deserialize;

#[derive(Deserialize)]
struct P {
    x: f64,
    z: f64,
}

#[derive(Deserialize)]
struct C {
    r: f64,
    g: f64,
    b: f64,
}

#[derive(Deserialize)]
struct Line {
    points: Vec<P>,
    color: C,
    thickness: f64,
}

#[derive(Deserialize)]
struct Entity {
    lines: Vec<Line>,
}

#[derive(Deserialize)]
struct Update {
    entities: Vec<Entity>,
}

/// One drawn frame: its time, its step and episode, and its lines.
struct Frame {
    step: u32,
    episode: (u32, bool),
    lines: Vec<Line>,
}

/// What a frame's `/step` said (the `/scene` message follows it).
#[derive(Deserialize)]
struct StepHead {
    step: u32,
    episode: u32,
    mode: String,
}

/// The PNG of `n` frames evenly spaced over `span` messages of the
/// recording's `/scene` channel, with `title` above them: the first `span`
/// of the last test episode that has as many (a test run shows the
/// learned gait), else the last `span`.
pub fn scene_strip_png(mcap: &[u8], n: usize, span: usize, title: &str) -> Result<Vec<u8>, String> {
    let mut frames = Vec::new();
    let mut head = StepHead { step: 0, episode: 0, mode: String::new() };
    let stream = ::mcap::MessageStream::new(mcap).map_err(|e| format!("not a valid MCAP file ({e})"))?;
    for m in stream {
        let m = m.map_err(|e| format!("not a valid MCAP file ({e})"))?;
        if m.channel.topic == "/step" {
            head = serde_json::from_slice(&m.data).map_err(|e| format!("a /step message is not pada.Step ({e})"))?;
            continue;
        }
        if m.channel.topic != "/scene" {
            continue;
        }
        let u: Update = serde_json::from_slice(&m.data).map_err(|e| format!("a /scene message is not a SceneUpdate ({e})"))?;
        for e in u.entities {
            frames.push(Frame {
                step: head.step,
                episode: (head.episode, head.mode == "testing"),
                lines: e.lines,
            });
        }
    }
    if frames.is_empty() {
        return Err("the recording has no /scene messages (no Hello of a known robot)".into());
    }
    let span = span.max(1);
    // The start of each test episode with at least `span` frames.
    let mut best = None;
    let mut i = 0;
    while i < frames.len() {
        let j = frames[i..].iter().position(|f| f.episode != frames[i].episode).map_or(frames.len(), |k| i + k);
        if frames[i].episode.1 && j - i >= span {
            best = Some(i);
        }
        i = j;
    }
    let tail = match best {
        Some(i) => &frames[i..i + span],
        None => &frames[frames.len().saturating_sub(span)..],
    };
    let n = n.clamp(1, tail.len());
    let picks: Vec<&Frame> = (0..n).map(|i| &tail[if n == 1 { 0 } else { i * (tail.len() - 1) / (n - 1) }]).collect();
    let svg = draw(&picks, title).map_err(|e| format!("{e:#}"))?;
    svg_to_png(&svg).map_err(|e| format!("{e:#}"))
}

fn draw(picks: &[&Frame], title: &str) -> anyhow::Result<String> {
    // One scale for every panel: the widest frame's half-width, and the
    // height of all of them.
    let pts = || picks.iter().flat_map(|f| f.lines.iter().flat_map(|l| l.points.iter()));
    let (zmin, zmax) = pts().fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.z), b.max(p.z)));
    // Each panel centred on the robot: the floor (a line at z = 0 that
    // spans the scene) is left out of the centre and the width, or a
    // robot far from the floor line's middle is cut off at the edge.
    let on_floor = |l: &&Line| l.points.iter().all(|p| p.z.abs() < 1e-9);
    let centre = |f: &Frame| {
        let (lo, hi) = f
            .lines
            .iter()
            .filter(|l| !on_floor(l))
            .flat_map(|l| l.points.iter())
            .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.x), b.max(p.x)));
        ((lo + hi) / 2.0, (hi - lo) / 2.0)
    };
    let half = picks.iter().map(|f| centre(f).1).fold(0.0, f64::max).max(zmax - zmin) * 0.6;
    let pad = (zmax - zmin) * 0.08;
    let (pw, ph) = (200u32, 260u32);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (pw * picks.len() as u32, ph + 50)).into_drawing_area();
        root.fill(&WHITE).map_err(plot_err)?;
        let (top, body) = root.split_vertically(50);
        top.draw(&Text::new(title.to_string(), (10, 8), (FONT, 15))).map_err(plot_err)?;
        for (panel, f) in body.split_evenly((1, picks.len())).iter().zip(picks) {
            let (cx, _) = centre(f);
            let mut chart = ChartBuilder::on(panel)
                .margin(6)
                .caption(format!("step {}", f.step), (FONT, 13))
                .build_cartesian_2d(cx - half..cx + half, zmin - pad..zmin - pad + 2.0 * half)
                .map_err(plot_err)?;
            for l in &f.lines {
                let c = RGBColor((l.color.r * 255.0) as u8, (l.color.g * 255.0) as u8, (l.color.b * 255.0) as u8);
                let width = if l.thickness < 0.008 { 2 } else { 4 };
                chart
                    .draw_series(std::iter::once(PathElement::new(
                        l.points.iter().map(|p| (p.x, p.z)).collect::<Vec<_>>(),
                        c.stroke_width(width),
                    )))
                    .map_err(plot_err)?;
            }
        }
        root.present().map_err(|e| anyhow::anyhow!("drawing SVG: {e}"))?;
    }
    Ok(svg)
}
