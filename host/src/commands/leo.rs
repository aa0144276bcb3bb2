//! `pada leo passive`: the LEO model's passive rollout (0 V on the learned
//! joints, the auto-actuated joints on), step by step, for checking the
//! model against another simulator or the robot; `pada leo compare`: the
//! model driven open loop by a reference trajectory's voltages, and its
//! difference from the reference joint by joint.

use std::io::Write;

use clap::{Args, Subcommand};

use std::path::PathBuf;

use crate::error::{usage, CliError};
use crate::leo::compare::{
    compare as run_comparison, Comparison, Drive, Reference, ANGLE_NAMES, TOUCHDOWN_MATCH_STEPS,
};
use crate::leo::model::ModelOptions;
use crate::leo::passive::{passive_rollout, PassiveRollout, MAX_PASSIVE_SECONDS};

/// `pada leo`.
#[derive(Debug, Clone, Args)]
pub struct LeoArgs {
    /// What to do with the LEO model.
    #[command(subcommand)]
    pub command: LeoCommand,
}

/// The `pada leo` subcommands.
#[derive(Debug, Clone, Subcommand)]
pub enum LeoCommand {
    /// The passive rollout from the reference start: 0 V on the learned
    /// joints (stance hip, swing hip, swing knee), the shoulder, stance knee
    /// and ankles under their P controllers. Per control step (1/30 s): the
    /// time, the torso angle φ and its rate, every joint angle, the ankle
    /// voltages and the reward; at the end whether and when the robot fell
    /// (|φ| > 1 rad or the stance thigh past 0.36π), after how many steps,
    /// and the return.
    Passive(PassiveArgs),
    /// Drive pada's LEO open loop with a reference trajectory's voltages
    /// (the authors' framework's CSV export of one episode, see
    /// docs/reference/leo-ab.md) from the same start, and compare per
    /// control step: the torso angle and every joint angle (pada −
    /// reference), the contacts and each touchdown. Prints the error per
    /// joint over time and a summary: the largest error until the
    /// reference's first touchdown and over the whole run, and every
    /// touchdown's step in both.
    Compare(CompareArgs),
}

/// `pada leo compare`.
#[derive(Debug, Clone, Args)]
pub struct CompareArgs {
    /// The reference trajectory (CSV; e.g. tests/data/leo-ab/*.csv).
    #[arg(long, value_name = "FILE")]
    pub reference: PathBuf,
    /// What the reference drives: `applied` gives every servo the voltage
    /// the reference applied (the physics alone is compared); `learned`
    /// gives only the three learned voltages and lets pada's task compute
    /// the held joints and the stance.
    #[arg(long, value_parser = drive_parser(), default_value = "applied")]
    pub drive: Drive,
    /// Print the comparison as JSON (keys: drive, provenance, substeps,
    /// solver_iterations, start_error, steps, first_touchdown,
    /// max_error_until_touchdown, max_error, touchdowns,
    /// extra_pada_touchdowns, reference_fall, pada_fall; angle arrays in
    /// the order torso, shoulder, hip_left, hip_right, knee_left,
    /// knee_right, ankle_left, ankle_right).
    #[arg(long)]
    pub json: bool,
    /// Write a figure of both trajectories (one panel per angle) to FILE;
    /// .svg or .png by its extension.
    #[arg(long, value_name = "FILE")]
    pub figure: Option<PathBuf>,
    /// Physics steps per control period (default: the model's; 1..=1000).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub substeps: Option<u32>,
    /// Rapier solver iterations per physics step (default: the model's;
    /// 1..=100).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=100))]
    pub solver_iterations: Option<u32>,
}

/// `pada leo passive`.
#[derive(Debug, Clone, Args)]
pub struct PassiveArgs {
    /// Simulated time to run if the robot does not fall first [s]
    /// (0 < seconds <= 3600).
    #[arg(long, value_name = "S", default_value_t = 2.0)]
    pub seconds: f64,
    /// Print the rollout as JSON (keys: steps, fell, fall_time_s,
    /// fall_steps, return, substeps, solver_iterations, seconds, blow_ups).
    #[arg(long)]
    pub json: bool,
    /// Physics steps per control period (default: the model's; 1..=1000).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub substeps: Option<u32>,
    /// Rapier solver iterations per physics step (default: the model's;
    /// 1..=100).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=100))]
    pub solver_iterations: Option<u32>,
}

/// Runs `pada leo`.
pub fn run(args: LeoArgs) -> Result<(), CliError> {
    match args.command {
        LeoCommand::Passive(a) => passive(a),
        LeoCommand::Compare(a) => compare(a),
    }
}

fn compare(args: CompareArgs) -> Result<(), CliError> {
    let figure_format = match &args.figure {
        None => None,
        Some(p) => match p.extension().and_then(|e| e.to_str()) {
            Some("svg") => Some(false),
            Some("png") => Some(true),
            _ => {
                return Err(usage(format!(
                    "--figure {}: the file must end in .svg or .png",
                    p.display()
                )))
            }
        },
    };
    let text = std::fs::read_to_string(&args.reference).map_err(|e| {
        usage(format!(
            "--reference {}: cannot read it: {e}",
            args.reference.display()
        ))
    })?;
    let reference = Reference::parse(&text)
        .map_err(|e| usage(format!("--reference {}: {e}", args.reference.display())))?;
    let mut options = ModelOptions::default();
    if let Some(n) = args.substeps {
        options.substeps = n;
    }
    if let Some(n) = args.solver_iterations {
        options.solver_iterations = n as usize;
    }
    let comparison = run_comparison(&reference, args.drive, options)
        .map_err(|e| CliError::Runtime(anyhow::anyhow!("{e}")))?;
    if let (Some(path), Some(png)) = (&args.figure, figure_format) {
        let title = args.reference.file_stem().map_or_else(
            || "reference".to_string(),
            |s| s.to_string_lossy().into_owned(),
        );
        let figure = crate::plot::compare::ComparisonFigure {
            comparison: &comparison,
            title,
        };
        let svg = crate::plot::to_svg(&figure)?;
        let bytes = if png {
            crate::plot::svg_to_png(&svg)?
        } else {
            svg.into_bytes()
        };
        crate::output::write_atomic(path, &bytes)
            .map_err(|e| CliError::Runtime(anyhow::anyhow!("writing {}: {e:#}", path.display())))?;
    }
    let text = if args.json {
        let mut s = serde_json::to_string_pretty(&comparison)
            .map_err(|e| CliError::Runtime(anyhow::anyhow!("cannot encode the comparison: {e}")))?;
        s.push('\n');
        s
    } else {
        comparison_table(&comparison)
    };
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes())
        .and_then(|()| out.flush())
        .map_err(|e| {
            CliError::Runtime(anyhow::anyhow!(
                "cannot write the comparison to stdout: {e}"
            ))
        })
}

/// The comparison as a table of errors per step and a summary.
fn comparison_table(c: &Comparison) -> String {
    let mut s = format!(
        "LEO against a reference, driven by its {} voltages; {} physics steps x {} solver \
         iteration(s) per 1/30 s\n",
        c.drive.name(),
        c.substeps,
        c.solver_iterations
    );
    for line in &c.provenance {
        s.push_str(&format!("reference: {line}\n"));
    }
    s.push_str("angle error pada - reference [rad]\n");
    s.push_str("step  t [s] ");
    for name in ANGLE_NAMES {
        s.push_str(&format!(" {name:>11}"));
    }
    s.push_str(" | contacts pada/ref (LT LH RT RH) | stance pada/ref\n");
    let flags =
        |c: &[bool; 4]| -> String { c.iter().map(|&b| if b { '1' } else { '0' }).collect() };
    let leg = |left: bool| if left { "L" } else { "R" };
    for st in &c.steps {
        s.push_str(&format!("{:4} {:6.3} ", st.step, st.time_s));
        for e in st.angle_error {
            s.push_str(&format!(" {e:+11.4}"));
        }
        s.push_str(&format!(
            " | {} / {} | {} / {}\n",
            flags(&st.pada_contacts),
            flags(&st.reference_contacts),
            leg(st.pada_stance_left),
            leg(st.reference_stance_left)
        ));
    }
    s.push_str("start error [rad]:            ");
    for e in c.start_error {
        s.push_str(&format!(" {e:+11.4}"));
    }
    s.push_str(&format!(
        "\nlargest |error| until the reference's first touchdown ({}):",
        c.first_touchdown
            .map_or_else(|| "none: every step".to_string(), |t| format!("step {t}"))
    ));
    for e in c.max_error_until_touchdown {
        s.push_str(&format!(" {e:.4}"));
    }
    s.push_str("\nlargest |error| over every step:");
    for e in c.max_error {
        s.push_str(&format!(" {e:.4}"));
    }
    s.push('\n');
    for t in &c.touchdowns {
        match (t.pada_step, t.difference) {
            (Some(p), Some(d)) => s.push_str(&format!(
                "touchdown {} foot: reference step {}, pada step {p} ({d:+})\n",
                t.foot, t.reference_step
            )),
            _ => s.push_str(&format!(
                "touchdown {} foot: reference step {}, none in pada within {TOUCHDOWN_MATCH_STEPS} steps\n",
                t.foot, t.reference_step
            )),
        }
    }
    for (foot, step) in &c.extra_pada_touchdowns {
        s.push_str(&format!(
            "touchdown {foot} foot in pada at step {step}, none in the reference\n"
        ));
    }
    let fall = |f: Option<usize>| f.map_or_else(|| "no".to_string(), |n| format!("after step {n}"));
    s.push_str(&format!(
        "fell: reference {}, pada {}\n",
        fall(c.reference_fall),
        fall(c.pada_fall)
    ));
    s
}

fn passive(args: PassiveArgs) -> Result<(), CliError> {
    if !(args.seconds.is_finite() && args.seconds > 0.0 && args.seconds <= MAX_PASSIVE_SECONDS) {
        return Err(usage(format!(
            "--seconds {} is out of range: valid is 0 < seconds <= {MAX_PASSIVE_SECONDS}",
            args.seconds
        )));
    }
    let mut options = ModelOptions::default();
    if let Some(n) = args.substeps {
        options.substeps = n;
    }
    if let Some(n) = args.solver_iterations {
        options.solver_iterations = n as usize;
    }
    let rollout = passive_rollout(options, args.seconds)
        .map_err(|e| CliError::Runtime(anyhow::anyhow!("{e}")))?;
    let text = if args.json {
        let mut s = serde_json::to_string_pretty(&rollout)
            .map_err(|e| CliError::Runtime(anyhow::anyhow!("cannot encode the rollout: {e}")))?;
        s.push('\n');
        s
    } else {
        table(&rollout)
    };
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes())
        .and_then(|()| out.flush())
        .map_err(|e| CliError::Runtime(anyhow::anyhow!("cannot write the rollout to stdout: {e}")))
}

/// The rollout as a text table and a closing line.
fn table(r: &PassiveRollout) -> String {
    let mut s = format!(
        "LEO passive rollout: 0 V on the learned joints, the held joints on; \
         {} physics steps x {} solver iteration(s) per 1/30 s\n",
        r.substeps, r.solver_iterations
    );
    s.push_str(
        "step  t [s]  phi [rad] phi' [rad/s] | shoulder  hip L   hip R  knee L  knee R  \
         ankle L ankle R [rad] | U ankle L  U ankle R [V] |  reward\n",
    );
    for p in &r.steps {
        let q = &p.joint_angles_rad;
        s.push_str(&format!(
            "{:4} {:6.3} {:+9.4} {:+11.3} | {:+8.4} {:+7.4} {:+7.4} {:+7.4} {:+7.4} {:+8.4} {:+7.4}       | {:+9.3} {:+10.3}     | {:+7.2}\n",
            p.step,
            p.time_s,
            p.torso_angle_rad,
            p.torso_rate_rad_s,
            q.shoulder,
            q.hip_left,
            q.hip_right,
            q.knee_left,
            q.knee_right,
            q.ankle_left,
            q.ankle_right,
            p.ankle_voltages_v.left,
            p.ankle_voltages_v.right,
            p.reward,
        ));
    }
    match (r.fall_time_s, r.fall_steps) {
        (Some(t), Some(n)) => s.push_str(&format!(
            "fell after {n} steps ({t:.3} s); return {:.2}\n",
            r.total_return
        )),
        _ => s.push_str(&format!(
            "did not fall in {:.3} s ({} steps); return {:.2}\n",
            r.steps.last().map_or(0.0, |p| p.time_s),
            r.steps.len(),
            r.total_return
        )),
    }
    if r.blow_ups > 0 {
        s.push_str(&format!("the simulation blew up {} time(s)\n", r.blow_ups));
    }
    s
}

/// The parser of `--drive`: [`Drive`]'s names.
fn drive_parser() -> impl clap::builder::TypedValueParser<Value = Drive> {
    use clap::builder::TypedValueParser;
    clap::builder::PossibleValuesParser::new(Drive::ALL.map(|d| d.name()))
        .try_map(|name| Drive::ALL.into_iter().find(|d| d.name() == name).ok_or("unknown drive"))
}
