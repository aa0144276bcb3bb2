//! The learned motion of a robot of files: the greedy policy of saved
//! weights run for one episode on a fresh body, every control step's pose
//! kept as the chain of each named point, the point of every reward term
//! with a target measured against it (a distance or squared distance, or
//! quadratic terms on a point's coordinates), and whether it holds there. Drawn as the
//! poses overlaid in the plane the robot moves in beside the distance over
//! time (SVG, PNG), and written as CSV. Used by `pada render --robot`.

use crate::experiment::task::{Plant, Task};
use crate::experiment::HostAgent;
use crate::plot::{plot_err, svg_to_png, FONT};
use pada_core::agent::{EpisodeEnd, Mode};
use pada_core::robot::vocabulary::{ChainJoint, Point, RewardTerm, Signal};
use pada_robot_file::RobotFile;
use pada_sim::urdf::UrdfTask;
use plotters::prelude::*;
use rand_core::SeedableRng;

/// A point that the reward pulls towards a target: a `distance` or
/// `distance_squared` term's (every axis), or the `quadratic` terms on one
/// point's coordinates together (the axes they name).
#[derive(Debug, Clone)]
pub struct Goal {
    /// The point's name in robot.toml.
    pub point: &'static str,
    /// Its index in the vocabulary's points.
    pub index: usize,
    /// The target in the base frame \[m\] (0 on an axis not pinned).
    pub target: [f32; 3],
    /// The axes the target pins (x, y, z); the distance is over these.
    pub axes: [bool; 3],
}

impl Goal {
    /// Its name in reports: the point's, with the pinned axes when not all
    /// three are (`tip`, `tip_xz`).
    pub fn label(&self) -> String {
        if self.axes == [true; 3] {
            self.point.to_string()
        } else {
            format!("{}_{}", self.point, axes_named(self).replace(", ", ""))
        }
    }

    /// The distance of `p` to the target over the pinned axes \[m\].
    pub fn distance(&self, p: [f32; 3]) -> f32 {
        (0..3).filter(|a| self.axes[*a]).map(|a| (p[a] - self.target[a]).powi(2)).sum::<f32>().sqrt()
    }
}

/// One control step of the greedy episode.
#[derive(Debug, Clone)]
pub struct MotionFrame {
    /// Simulated time \[s\].
    pub time: f64,
    /// Every joint's angle \[rad\].
    pub angles: Vec<f32>,
    /// For each named point, the base, each joint's origin on its way and
    /// the point itself, in the base frame \[m\].
    pub chains: Vec<Vec<[f32; 3]>>,
    /// Each goal's point's distance to its target \[m\].
    pub distances: Vec<f32>,
}

/// A recorded greedy episode.
#[derive(Debug, Clone)]
pub struct Motion {
    /// The robot's name.
    pub robot: &'static str,
    /// The goals, in the order of the reward's terms.
    pub goals: Vec<Goal>,
    /// Every step, the start pose first.
    pub frames: Vec<MotionFrame>,
    /// Whether an end of the robot's rules stopped the episode early.
    pub ended: bool,
    /// A joint past its soft limit that stopped it, as the board would
    /// have stopped (the fault's line).
    pub fault: Option<String>,
}

/// How well a goal was held over the last half of the episode.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HoldReport {
    /// The largest distance to the target over the last half \[m\].
    pub max_m: f32,
    /// The mean distance over the last half \[m\].
    pub mean_m: f32,
}

/// The goals of `file`'s reward: one per `distance` or `distance_squared`
/// term, in the order of the terms, then one per point whose coordinates
/// `quadratic` terms pull towards a target. (A `progress` term pulls along
/// an axis without a target: no goal.)
pub fn goals(file: &RobotFile) -> Vec<Goal> {
    let voc = file.vocabulary();
    let mut goals: Vec<Goal> = voc
        .rewards
        .iter()
        .filter_map(|r| match *r {
            RewardTerm::Distance { point, target, .. } | RewardTerm::DistanceSquared { point, target, .. } => {
                voc.points.get(point as usize).map(|p| Goal { point: p.name, index: point as usize, target, axes: [true; 3] })
            }
            _ => None,
        })
        .collect();
    let mut coordinates: Vec<Goal> = Vec::new();
    for r in voc.rewards {
        let RewardTerm::Quadratic { signal: Signal::Position { point, axis }, target, .. } = *r else { continue };
        let (Some(p), Some(a)) = (voc.points.get(point as usize), [0usize, 1, 2].get(axis as usize).copied()) else { continue };
        let at = match coordinates.iter().position(|g| g.index == point as usize) {
            Some(k) => k,
            None => {
                coordinates.push(Goal { point: p.name, index: point as usize, target: [0.0; 3], axes: [false; 3] });
                coordinates.len() - 1
            }
        };
        coordinates[at].target[a] = target;
        coordinates[at].axes[a] = true;
    }
    goals.extend(coordinates);
    goals
}

/// The base, every joint origin on the way to `point` and the point, for
/// `angles` (the forward kinematics the rules use, which the simulator
/// agrees with to 1e-5 m: pada-sim's urdf tests).
fn chain_of(point: &Point, angles: &[f32]) -> Vec<[f32; 3]> {
    let mut out = vec![[0.0; 3]];
    for k in 1..=point.chain.len() {
        let partial: &[ChainJoint] = &point.chain[..k];
        let origin = Point { name: point.name, chain: partial, offset: [0.0; 3] };
        out.push(origin.position(angles));
    }
    out.push(point.position(angles));
    out
}

/// Runs `agent` greedily on a fresh body of `task` for `seconds` (or until
/// an end of the rules) and records every step.
pub fn record(file: &RobotFile, task: &UrdfTask, agent: &mut HostAgent, seconds: f64) -> anyhow::Result<Motion> {
    let spec = task.spec();
    let voc = file.vocabulary();
    let goals = goals(file);
    agent.set_mode(Mode::Testing);
    let mut plant = task.plant();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(1);
    let mut obs = vec![0.0f32; spec.state.len()];
    plant.reset(&mut rng, &mut obs);
    let err = |e: pada_core::error::StepError| anyhow::anyhow!("{e}");
    let mut decision = agent.start_episode(&obs, &mut rng).map_err(err)?;
    let period = spec.control_period_s;
    let dims = spec.motor.dims();
    let joints = file.spec.joints.len();
    let frame = |plant: &<UrdfTask as Task>::Plant, k: u32| {
        let angles = plant.body().angles()[..joints].to_vec();
        let chains = voc.points.iter().map(|p| chain_of(p, &angles)).collect();
        let distances = goals
            .iter()
            .map(|g| g.distance(voc.points[g.index].position(&angles)))
            .collect();
        MotionFrame { time: k as f64 * period, angles, chains, distances }
    };
    let mut frames = vec![frame(&plant, 0)];
    let steps = ((seconds / period).round() as u32).max(1);
    let mut ended = false;
    let mut fault = None;
    for k in 1..=steps {
        let s = plant.step(&decision.output[..dims], &mut obs);
        frames.push(frame(&plant, k));
        if let Some(cause) = plant.fault() {
            fault = Some(crate::board::fault_line::fault_line(&cause, file.spec));
            break;
        }
        if s.terminal {
            ended = true;
            agent.end_episode(s.reward, EpisodeEnd::Absorbing, &mut rng).map_err(err)?;
            break;
        }
        decision = agent.step(s.reward, &obs, &mut rng).map_err(err)?;
    }
    Ok(Motion { robot: file.spec.name, goals, frames, ended, fault })
}

/// The axes a goal pins, `x, z`.
fn axes_named(g: &Goal) -> String {
    ["x", "y", "z"].iter().zip(g.axes).filter(|(_, on)| *on).map(|(a, _)| *a).collect::<Vec<_>>().join(", ")
}

impl Motion {
    /// How goal `g` was held over the last half of the frames.
    pub fn hold(&self, g: usize) -> HoldReport {
        let half = &self.frames[self.frames.len() / 2..];
        let d: Vec<f32> = half.iter().map(|f| f.distances[g]).collect();
        HoldReport {
            max_m: d.iter().copied().fold(0.0, f32::max),
            mean_m: d.iter().sum::<f32>() / d.len().max(1) as f32,
        }
    }

    /// One line per goal: its largest and mean distance over the last half,
    /// and whether it stayed within `tolerance_m`.
    pub fn hold_lines(&self, tolerance_m: f32) -> Vec<String> {
        (0..self.goals.len())
            .map(|g| {
                let h = self.hold(g);
                format!(
                    "{}: over the last half of {:.2} s, at most {:.2} cm from its target (mean {:.2} cm): {} {:.1} cm",
                    self.goals[g].label(),
                    self.frames.last().map_or(0.0, |f| f.time),
                    h.max_m * 100.0,
                    h.mean_m * 100.0,
                    if h.max_m <= tolerance_m { "held within" } else { "not held within" },
                    tolerance_m * 100.0
                )
            })
            .collect()
    }

    /// The trajectory as CSV: time, every joint's angle, every point's
    /// position and every goal's distance.
    pub fn csv(&self, file: &RobotFile) -> String {
        let voc = file.vocabulary();
        let mut head = vec!["time_s".to_string()];
        head.extend(file.spec.joints.iter().map(|j| format!("{}_rad", j.name)));
        for p in voc.points {
            head.extend(["x", "y", "z"].iter().map(|a| format!("{}_{a}_m", p.name)));
        }
        head.extend(self.goals.iter().map(|g| format!("{}_distance_m", g.label())));
        let mut out = head.join(",") + "\n";
        for f in &self.frames {
            let mut row = vec![format!("{}", f.time)];
            row.extend(f.angles.iter().map(|a| a.to_string()));
            for c in &f.chains {
                let p = c.last().copied().unwrap_or([0.0; 3]);
                row.extend(p.iter().map(|v| v.to_string()));
            }
            row.extend(f.distances.iter().map(|d| d.to_string()));
            out += &(row.join(",") + "\n");
        }
        out
    }

    /// The two base-frame axes along which the robot moves most (the
    /// plane to draw it in), lower index first.
    fn plane(&self) -> (usize, usize) {
        let mut spread = [0.0f32; 3];
        for a in 0..3 {
            let values = self.frames.iter().flat_map(|f| f.chains.iter().flatten().map(move |p| p[a]));
            let (lo, hi) = values.fold((f32::MAX, f32::MIN), |(l, h), v| (l.min(v), h.max(v)));
            spread[a] = hi - lo;
        }
        for g in &self.goals {
            for (a, s) in spread.iter_mut().enumerate().filter(|(a, _)| g.axes[*a]) {
                *s = s.max(g.target[a].abs());
            }
        }
        let mut axes = [0usize, 1, 2];
        axes.sort_by(|a, b| spread[*b].total_cmp(&spread[*a]));
        let (a, b) = (axes[0].min(axes[1]), axes[0].max(axes[1]));
        (a, b)
    }

    /// The figure: poses overlaid (light to dark as time goes on) with the
    /// targets and their tolerance circles, beside each goal's distance over
    /// time with the tolerance and the judged last half marked.
    pub fn svg(&self, tolerance_m: f32, title: &str) -> anyhow::Result<String> {
        const AXIS: [&str; 3] = ["x", "y", "z"];
        let (ha, va) = self.plane();
        let all = self.frames.iter().flat_map(|f| f.chains.iter().flatten().copied());
        // A goal's free axes take the point's last position (where the
        // target is drawn along them).
        let last = |g: &Goal| self.frames.last().and_then(|f| f.chains.get(g.index)).and_then(|c| c.last().copied()).unwrap_or([0.0; 3]);
        let shown_target = |g: &Goal| {
            let p = last(g);
            [0, 1, 2].map(|a| if g.axes[a] { g.target[a] } else { p[a] })
        };
        let pts: Vec<[f32; 3]> = all.chain(self.goals.iter().map(shown_target)).collect();
        let bound = |a: usize| {
            let (lo, hi) = pts.iter().fold((f32::MAX, f32::MIN), |(l, h), p| (l.min(p[a]), h.max(p[a])));
            (lo, hi)
        };
        let ((hl, hh), (vl, vh)) = (bound(ha), bound(va));
        // A square view with a margin, so that angles look like angles.
        let side = (hh - hl).max(vh - vl).max(0.01) * 1.15;
        let (hc, vc) = ((hl + hh) / 2.0, (vl + vh) / 2.0);
        let (hr, vr) = (hc - side / 2.0..hc + side / 2.0, vc - side / 2.0..vc + side / 2.0);

        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, (1000, 500)).into_drawing_area();
            root.fill(&WHITE).map_err(plot_err)?;
            let (top, body) = root.split_vertically(36);
            top.draw(&Text::new(title.to_string(), (10, 10), (FONT, 17))).map_err(plot_err)?;
            let (left, right) = body.split_horizontally(470);

            let mut poses = ChartBuilder::on(&left)
                .margin(10)
                .caption("poses (light: early, dark: late)", (FONT, 14))
                .x_label_area_size(36)
                .y_label_area_size(50)
                .build_cartesian_2d(hr, vr)
                .map_err(plot_err)?;
            poses
                .configure_mesh()
                .x_desc(format!("{} [m]", AXIS[ha]))
                .y_desc(format!("{} [m]", AXIS[va]))
                .light_line_style(WHITE)
                .draw()
                .map_err(plot_err)?;
            let n = self.frames.len();
            let shown = 16.min(n);
            for i in 0..shown {
                let k = if shown == 1 { 0 } else { i * (n - 1) / (shown - 1) };
                let shade = 210 - (180 * i / shown.max(1)) as u8;
                let colour = RGBColor(shade, shade, 255 - shade / 3);
                for chain in &self.frames[k].chains {
                    let line: Vec<(f32, f32)> = chain.iter().map(|p| (p[ha], p[va])).collect();
                    poses
                        .draw_series(std::iter::once(PathElement::new(line, colour.stroke_width(3))))
                        .map_err(plot_err)?;
                }
            }
            for g in &self.goals {
                let t = shown_target(g);
                let (x, y) = (t[ha], t[va]);
                if !(g.axes[ha] && g.axes[va]) {
                    // Pinned on one axis of the view: the target is a line
                    // across the other (and a band of the tolerance).
                    let (h0, h1, v0, v1) = (hc - side / 2.0, hc + side / 2.0, vc - side / 2.0, vc + side / 2.0);
                    let line = match (g.axes[ha], g.axes[va]) {
                        (true, false) => vec![(x, v0), (x, v1)],
                        (false, true) => vec![(h0, y), (h1, y)],
                        _ => continue,
                    };
                    poses
                        .draw_series(std::iter::once(PathElement::new(line, RED.stroke_width(2))))
                        .map_err(plot_err)?
                        .label(format!("{} target, ±{:.0} cm", g.label(), tolerance_m * 100.0))
                        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED.stroke_width(2)));
                    continue;
                }
                let ring: Vec<(f32, f32)> = (0..=48)
                    .map(|i| {
                        let a = i as f32 / 48.0 * std::f32::consts::TAU;
                        (x + tolerance_m * a.cos(), y + tolerance_m * a.sin())
                    })
                    .collect();
                poses
                    .draw_series(std::iter::once(PathElement::new(ring, RED.stroke_width(1))))
                    .map_err(plot_err)?
                    .label(format!("{} target, ±{:.0} cm", g.point, tolerance_m * 100.0))
                    .legend(|(x, y)| Circle::new((x + 10, y), 4, RED.stroke_width(1)));
                poses
                    .draw_series(std::iter::once(Cross::new((x, y), 5, RED.stroke_width(2))))
                    .map_err(plot_err)?;
            }
            poses
                .configure_series_labels()
                .position(SeriesLabelPosition::LowerLeft)
                .background_style(WHITE.mix(0.9))
                .border_style(BLACK)
                .label_font((FONT, 12))
                .draw()
                .map_err(plot_err)?;

            let t_end = self.frames.last().map_or(1.0, |f| f.time).max(1e-3);
            let d_max = self
                .frames
                .iter()
                .flat_map(|f| f.distances.iter().copied())
                .fold(tolerance_m * 1.5, f32::max)
                * 100.0
                * 1.05;
            let mut dist = ChartBuilder::on(&right)
                .margin(10)
                .caption("distance to the target", (FONT, 14))
                .x_label_area_size(36)
                .y_label_area_size(50)
                .build_cartesian_2d(0.0..t_end, 0.0..d_max as f64)
                .map_err(plot_err)?;
            let half = self.frames[n / 2].time;
            dist.draw_series(std::iter::once(Rectangle::new(
                [(half, 0.0), (t_end, d_max as f64)],
                RGBColor(235, 235, 235).filled(),
            )))
            .map_err(plot_err)?
            .label("judged: the last half")
            .legend(|(x, y)| Rectangle::new([(x, y - 5), (x + 20, y + 5)], RGBColor(235, 235, 235).filled()));
            // The grid over the shading, the data over the grid.
            dist.configure_mesh()
                .x_desc("time [s]")
                .y_desc("distance [cm]")
                .light_line_style(WHITE.mix(0.0))
                .draw()
                .map_err(plot_err)?;
            let tol = tolerance_m as f64 * 100.0;
            dist.draw_series(DashedLineSeries::new(vec![(0.0, tol), (t_end, tol)], 6, 4, RED.stroke_width(1)))
                .map_err(plot_err)?
                .label(format!("tolerance {tol:.0} cm"))
                .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED.stroke_width(1)));
            const LINES: [RGBColor; 4] = [RGBColor(30, 90, 200), RGBColor(0, 140, 60), RGBColor(160, 60, 160), RGBColor(40, 40, 40)];
            for (g, goal) in self.goals.iter().enumerate() {
                let colour = LINES[g % LINES.len()];
                dist.draw_series(LineSeries::new(
                    self.frames.iter().map(|f| (f.time, f.distances[g] as f64 * 100.0)),
                    colour.stroke_width(2),
                ))
                .map_err(plot_err)?
                .label(goal.label())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2)));
            }
            dist.configure_series_labels()
                .position(SeriesLabelPosition::UpperRight)
                .background_style(WHITE.mix(0.9))
                .border_style(BLACK)
                .label_font((FONT, 12))
                .draw()
                .map_err(plot_err)?;
            root.present().map_err(|e| anyhow::anyhow!("drawing SVG: {e}"))?;
        }
        Ok(svg)
    }

    /// motion.svg, motion.png and motion.csv.
    pub fn files(&self, file: &RobotFile, tolerance_m: f32, title: &str) -> anyhow::Result<Vec<(String, Vec<u8>)>> {
        let svg = self.svg(tolerance_m, title)?;
        let png = svg_to_png(&svg)?;
        Ok(vec![
            ("motion.svg".to_string(), svg.into_bytes()),
            ("motion.png".to_string(), png),
            ("motion.csv".to_string(), self.csv(file).into_bytes()),
        ])
    }
}
