//! A learned gait, recorded and drawn: the greedy policy of an agent run on
//! a fresh LEO, every control step as a stick figure, written as a strip
//! (SVG, PNG), an animation (SVG) and a trajectory (CSV). Used by
//! `pada render` and `pada paper leo`.

use crate::leo::constants::*;
use crate::leo::model::Body;
use crate::leo::rl::{LeoPlant, LeoTask};
use crate::experiment::task::{Plant, Task};
use crate::experiment::HostAgent;
use crate::plot::{plot_err, svg_to_png, FONT};
use pada_core::agent::{EpisodeEnd, Mode};
use plotters::prelude::*;
use rand_core::SeedableRng;

/// One drawn frame: line segments in world (x, z) and the time.
#[derive(Debug, Clone)]
pub struct Frame {
    /// Simulated time \[s\].
    pub time: f64,
    /// Segments (from, to) in metres.
    pub segments: Vec<([f32; 2], [f32; 2])>,
    /// Hip x \[m\] (the panel's centre).
    pub hip_x: f32,
    /// Walked distance so far \[m\].
    pub walked: f64,
}

/// The stick figure of the plant's current pose.
pub fn stick_figure(plant: &LeoPlant) -> Vec<([f32; 2], [f32; 2])> {
    let m = plant.env().model();
    let seg = |b: Body, a: [f32; 2], c: [f32; 2]| (m.body_point(b, a), m.body_point(b, c));
    let mut v = vec![
        seg(Body::Torso, TORSO_HIP_ANCHOR, TORSO_SHOULDER_ANCHOR),
        seg(Body::Arm, ARM_SHOULDER_ANCHOR, ARM_HAND),
    ];
    for (thigh, shank, foot) in [
        (Body::ThighLeft, Body::ShankLeft, Body::FootLeft),
        (Body::ThighRight, Body::ShankRight, Body::FootRight),
    ] {
        v.push(seg(thigh, THIGH_HIP_ANCHOR, THIGH_KNEE_ANCHOR));
        v.push(seg(shank, SHANK_KNEE_ANCHOR, SHANK_ANKLE_ANCHOR));
        v.push(seg(foot, FOOT_HEEL, FOOT_TOE));
    }
    v
}

/// Runs `agent`'s greedy policy on a fresh LEO for up to `seconds` (or
/// until it falls) and records every control step.
pub fn record_agent(agent: &mut HostAgent, seconds: f64) -> anyhow::Result<(Vec<Frame>, bool)> {
    let task = LeoTask::default();
    let spec = task.spec();
    agent.set_mode(Mode::Testing);
    let mut plant = task.plant();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(1);
    let mut obs = [0.0f32; 10];
    plant.reset(&mut rng, &mut obs);
    let err = |e: pada_core::error::StepError| anyhow::anyhow!("{e}");
    let mut d = agent.start_episode(&obs, &mut rng).map_err(err)?;
    let period = spec.control_period_s;
    let steps = ((seconds / period).round() as u32).max(1);
    let frame = |plant: &LeoPlant, k: u32| {
        let segments = stick_figure(plant);
        Frame {
            time: k as f64 * period,
            hip_x: segments[0].0[0],
            segments,
            walked: plant.walked_distance_m().unwrap_or(0.0),
        }
    };
    let mut frames = vec![frame(&plant, 0)];
    let mut fell = false;
    for k in 1..=steps {
        let s = plant.step(&d.output[..3], &mut obs);
        if let (true, Some(map)) = (plant.footstep(), spec.footstep_remap) {
            agent.remap_memory(&map);
        }
        frames.push(frame(&plant, k));
        if s.terminal {
            fell = true;
            agent
                .end_episode(s.reward, EpisodeEnd::Absorbing, &mut rng)
                .map_err(err)?;
            break;
        }
        d = agent.step(s.reward, &obs, &mut rng).map_err(err)?;
    }
    Ok((frames, fell))
}

/// The strip of `n` frames evenly spaced over `frames`, as SVG.
pub fn strip_svg(frames: &[Frame], n: usize, title: &str) -> anyhow::Result<String> {
    let n = n.min(frames.len()).max(1);
    let picks: Vec<&Frame> = (0..n)
        .map(|i| {
            &frames[if n == 1 {
                0
            } else {
                i * (frames.len() - 1) / (n - 1)
            }]
        })
        .collect();
    let (pw, ph) = (180u32, 230u32);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (pw * n as u32, ph + 40)).into_drawing_area();
        root.fill(&WHITE).map_err(plot_err)?;
        let (top, body) = root.split_vertically(40);
        top.draw(&Text::new(title.to_string(), (10, 10), (FONT, 18)))
            .map_err(plot_err)?;
        let panels = body.split_evenly((1, n));
        for (panel, f) in panels.iter().zip(picks) {
            let cx = f.hip_x;
            let mut chart = ChartBuilder::on(panel)
                .margin(4)
                .caption(
                    format!("t = {:.2} s, {:.2} m", f.time, f.walked),
                    (FONT, 13),
                )
                .build_cartesian_2d(cx - 0.3..cx + 0.3, -0.05f32..0.65f32)
                .map_err(plot_err)?;
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(cx - 0.3, 0.0), (cx + 0.3, 0.0)],
                    BLACK.stroke_width(1),
                )))
                .map_err(plot_err)?;
            for (i, (a, b)) in f.segments.iter().enumerate() {
                let c = segment_colour(i);
                chart
                    .draw_series(std::iter::once(PathElement::new(
                        vec![(a[0], a[1]), (b[0], b[1])],
                        c.stroke_width(4),
                    )))
                    .map_err(plot_err)?;
            }
        }
        root.present()
            .map_err(|e| anyhow::anyhow!("drawing SVG: {e}"))?;
    }
    Ok(svg)
}

/// Colour of segment `i` of [`stick_figure`]: torso and arm dark, left
/// leg blue, right leg red.
fn segment_colour(i: usize) -> RGBColor {
    match i {
        0 | 1 => RGBColor(40, 40, 40),
        2..=4 => RGBColor(30, 90, 200),
        _ => RGBColor(200, 50, 40),
    }
}

/// Every frame as an animated SVG that plays in real time and loops: one
/// group per frame, shown during its control period by a discrete SMIL
/// `visibility` animation. The view follows the hip; ground ticks every
/// 0.1 m show the motion. Written by hand because plotters draws still
/// images only.
pub fn animated_svg(frames: &[Frame], period: f64, title: &str) -> String {
    use std::fmt::Write as _;
    let (w, h, scale) = (480.0f32, 360.0f32, 600.0f32); // px, px, px per m
    let ground_y = h - 30.0;
    let n = frames.len().max(1);
    let dur = n as f64 * period;
    let mut svg = String::new();
    let _ = write!(
        svg,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\">\n\
         <rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n\
         <text x=\"8\" y=\"20\" font-family=\"sans-serif\" font-size=\"14\">{}</text>\n",
        xml_escape(title)
    );
    for (i, f) in frames.iter().enumerate() {
        let cx = f.hip_x;
        let px = |p: [f32; 2]| (w / 2.0 + (p[0] - cx) * scale, ground_y - p[1] * scale);
        let _ = write!(svg, "<g visibility=\"hidden\">");
        let (t0, t1) = (i as f64 / n as f64, (i + 1) as f64 / n as f64);
        let _ = write!(
            svg,
            "<animate attributeName=\"visibility\" calcMode=\"discrete\" values=\"hidden;visible;hidden\" \
             keyTimes=\"0;{t0:.6};{t1:.6}\" dur=\"{dur:.3}s\" repeatCount=\"indefinite\"/>"
        );
        let _ = write!(
            svg,
            "<line x1=\"0\" y1=\"{ground_y}\" x2=\"{w}\" y2=\"{ground_y}\" stroke=\"black\"/>"
        );
        let first = ((cx - w / 2.0 / scale) / 0.1).floor() as i32;
        for k in first..=first + (w / scale / 0.1) as i32 + 1 {
            let (x, _) = px([k as f32 * 0.1, 0.0]);
            let _ = write!(svg, "<line x1=\"{x:.1}\" y1=\"{ground_y}\" x2=\"{x:.1}\" y2=\"{:.1}\" stroke=\"gray\"/>", ground_y + 8.0);
        }
        for (j, (a, b)) in f.segments.iter().enumerate() {
            let ((x1, y1), (x2, y2)) = (px(*a), px(*b));
            let c = segment_colour(j);
            let _ = write!(
                svg,
                "<line x1=\"{x1:.1}\" y1=\"{y1:.1}\" x2=\"{x2:.1}\" y2=\"{y2:.1}\" stroke=\"rgb({},{},{})\" stroke-width=\"5\" stroke-linecap=\"round\"/>",
                c.0, c.1, c.2
            );
        }
        let _ = write!(
            svg,
            "<text x=\"8\" y=\"40\" font-family=\"sans-serif\" font-size=\"12\">t = {:.2} s, walked {:.2} m</text></g>\n",
            f.time, f.walked
        );
    }
    svg.push_str("</svg>\n");
    svg
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// The gait's files: `gait.svg` and `gait.png` (a strip of `strip_frames`
/// frames), `gait-animation.svg` (every control step, looping) and
/// `gait.csv` (time, hip x, walked distance per step).
pub fn gait_files(
    frames: &[Frame],
    strip_frames: usize,
    title: &str,
) -> anyhow::Result<Vec<(String, Vec<u8>)>> {
    let svg = strip_svg(frames, strip_frames, title)?;
    let png = svg_to_png(&svg)?;
    let animation = animated_svg(frames, CONTROL_PERIOD as f64, title);
    let mut csv = String::from("time_s,hip_x_m,walked_m\n");
    for f in frames {
        csv += &format!("{},{},{}\n", f.time, f.hip_x, f.walked);
    }
    Ok(vec![
        ("gait.svg".to_string(), svg.into_bytes()),
        ("gait.png".to_string(), png),
        ("gait-animation.svg".to_string(), animation.into_bytes()),
        ("gait.csv".to_string(), csv.into_bytes()),
    ])
}

/// The title line of a recorded gait.
pub fn gait_title(source: &str, frames: &[Frame], fell: bool) -> String {
    let (walked, time) = frames
        .last()
        .map(|f| (f.walked, f.time))
        .unwrap_or((0.0, 0.0));
    format!(
        "LEO, greedy policy of {source}: {walked:.2} m in {time:.2} s{}",
        if fell { ", fell" } else { "" }
    )
}
