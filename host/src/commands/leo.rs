//! `pada leo passive`: the LEO model's passive rollout (0 V on the learned
//! joints, the auto-actuated joints on), step by step, for checking the
//! model against another simulator or the robot.

use std::io::Write;

use clap::{Args, Subcommand};

use crate::error::{usage, CliError};
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
    }
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
