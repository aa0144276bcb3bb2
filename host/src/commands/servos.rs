//! `pada servos`: a robot's servos as virtual servos on a pseudo-terminal
//! (`--port PATH --robot R`), or `--scan` of a real port.
//!
//! ```text
//! pada servos --port /tmp/dxl --robot pendulum|PATH/robot.toml [--servo XM430-W350] [--baud 1000000] [--lockstep] [--fault SPEC]… [--seconds S] [--json]
//! pada servos --port /tmp/so101 --chain sts3215:1-6 [--baud 1000000] [--lockstep] [--fault SPEC]… [--seconds S] [--json]
//! pada servos --scan --port /dev/ttyUSB0 [--baud 57600,1000000] [--protocol 1|2] [--ids 0-252] [--timeout-ms 5] [--json]
//! pada servos --reboot ID --port /dev/ttyUSB0 [--baud 1000000] [--timeout-ms 5] [--json]
//! ```

use crate::console::{errln, outln};
use crate::error::{usage, CliError};
use crate::robot_arg::RobotArg;
use crate::servos::reboot;
use pada_core::dynamixel::control_table::x_series::HardwareError;
use crate::servos::scan::{self, ScanConfig};
use crate::servos::{pty::Pty, serve, Clock, VirtualBus};
use clap::Args;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

/// `pada servos`.
#[derive(Debug, Clone, Args)]
pub struct ServosArgs {
    /// The virtual servos' port: a path for the symbolic link to their
    /// pseudo-terminal (open it as you would open /dev/ttyUSB0). With
    /// --scan: the real port to scan.
    #[arg(long, value_name = "PATH")]
    pub port: PathBuf,
    /// The robot whose servos to emulate: a built-in robot (pendulum,
    /// pendulum-20hz, leo) or the path of a robot's robot.toml.
    #[arg(long, value_name = "R", value_parser = RobotArg::parser())]
    pub robot: Option<RobotArg>,
    /// A bare chain of servos instead of a robot's: MODEL:A-B or
    /// MODEL:A,B,… (sts3215:1-6 is an SO-101's six Feetech STS3215), each
    /// moving under its own position loop, no robot behind them.
    #[arg(long, value_name = "MODEL:IDS", conflicts_with_all = ["robot", "servo"])]
    pub chain: Option<String>,
    /// Every joint's servo of this model instead of the definition's (the
    /// pendulum on an X-series servo): RX-28, XM430-W350, XL430-W250,
    /// XL330-M288.
    #[arg(long, value_name = "MODEL")]
    pub servo: Option<String>,
    /// The servos' baud rate (with --scan: the rates to try, comma
    /// separated; default 57600,1000000,115200,2000000,3000000,4000000,9600).
    #[arg(long, value_name = "BPS")]
    pub baud: Option<String>,
    /// Lock step: the physics advance one control period at each SYNC
    /// WRITE instead of with the wall clock, so that a run over the port is
    /// reproducible whatever the machine's speed.
    #[arg(long)]
    pub lockstep: bool,
    /// A fault of `pada sil`'s kinds: drop, corrupt, delay, error-bits (on
    /// an X-series servo: a hardware alert with these bits), past-limit;
    /// KIND[:at=S][:for=S][:servo=ID][:ms=MS][:bits=NAME], bus time.
    #[arg(long = "fault", value_name = "SPEC")]
    pub faults: Vec<String>,
    /// Stop after this many wall-clock seconds (default: until Ctrl-C).
    #[arg(long, value_name = "S")]
    pub seconds: Option<f64>,
    /// Print the summary (with every servo event) as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// In real time, serve at the ordinary priority: no SCHED_FIFO, no
    /// locked memory (by default both are asked for; the summary says what
    /// was granted).
    #[arg(long)]
    pub no_realtime: bool,
    /// Scan the port instead: which IDs and models answer, at which rate
    /// and protocol.
    #[arg(long)]
    pub scan: bool,
    /// With --scan: only this protocol (1 or 2).
    #[arg(long, value_name = "1|2", value_parser = clap::value_parser!(u8).range(1..=2))]
    pub protocol: Option<u8>,
    /// With --scan: the Protocol 1.0 IDs to ping (default 0-253).
    #[arg(long, value_name = "A-B")]
    pub ids: Option<String>,
    /// Reboot the Protocol 2.0 servo of this ID on a real port instead:
    /// what clears a hardware alert (overload, overheating, …), which keeps
    /// its torque off until then. --baud is its rate (default 1000000).
    #[arg(long, value_name = "ID", value_parser = clap::value_parser!(u8).range(0..=252))]
    pub reboot: Option<u8>,
    /// With --scan or --reboot: how long to wait for an answer [ms].
    #[arg(long, value_name = "MS", default_value_t = 5, value_parser = clap::value_parser!(u64).range(1..=1000))]
    pub timeout_ms: u64,
}

/// Runs `pada servos`.
pub fn run(args: ServosArgs) -> Result<(), CliError> {
    if args.scan && args.reboot.is_some() {
        return Err(usage("--scan and --reboot are two tasks: give one"));
    }
    if args.scan {
        return run_scan(&args);
    }
    if let Some(id) = args.reboot {
        return run_reboot(&args, id);
    }
    for (flag, given) in [("--protocol", args.protocol.is_some()), ("--ids", args.ids.is_some())] {
        if given {
            return Err(usage(format!("{flag} goes with --scan")));
        }
    }
    if let Some(chain) = &args.chain {
        return run_chain(&args, chain);
    }
    let Some(mut robot) = args.robot.clone() else {
        return Err(usage("give --robot R (the robot whose servos to emulate; valid are pendulum, pendulum-20hz, leo, or the path of a robot.toml), --chain MODEL:IDS or --scan"));
    };
    if let Some(name) = &args.servo {
        let model = pada_core::servo::servo(name).map_err(|e| usage(format!("--servo: {e}")))?;
        robot = robot.with_servo(model).map_err(usage)?;
    }
    let bps = one_rate(args.baud.as_deref())?;
    if let Some(s) = args.seconds {
        if !(s.is_finite() && s > 0.0) {
            return Err(usage(format!("--seconds {s} is out of range: valid is > 0")));
        }
    }
    let faults = args.faults.iter().map(|f| crate::sil::fault::parse(f).map_err(usage)).collect::<Result<Vec<_>, _>>()?;
    let rig = robot.rig().map_err(usage)?;
    let clock = if args.lockstep { Clock::LockStep } else { Clock::RealTime };
    let mut bus = VirtualBus::new(robot.spec, rig, bps, clock, faults).map_err(usage)?;
    let pty = Pty::create(&args.port).map_err(|e| usage(format!("--port {}: cannot make the virtual port: {e}", args.port.display())))?;
    let models: Vec<String> = robot.spec.joints.iter().map(|j| format!("{} (ID {}, {})", j.name, j.id, j.servo.name)).collect();
    errln!(
        "servos: {} at {} bps on {} -> {} ({}): {}",
        robot.spec.name,
        bps,
        args.port.display(),
        pty.device(),
        if args.lockstep { "lock step: one period per SYNC WRITE" } else { "real time" },
        models.join(", ")
    );
    if robot.spec.encoder.is_some() {
        errln!("servos: the robot's encoder is the sensor device, ID {}", pada_firmware::sensor_device::SENSOR_ID);
    }
    let summary = serve_until_stopped(&mut bus, pty, &args, bps, robot.spec.name)?;
    if !args.json {
        errln!(
            "servos: ended ({}): {} packets, {} answers, {} periods (sync writes), {:.3} s of bus time in {:.1} s",
            summary.ended,
            summary.stats.packets,
            summary.stats.replies,
            summary.stats.sync_writes,
            summary.bus_s,
            summary.wall_s
        );
        errln!("servos: real time: {}", summary.realtime.summary());
    }
    Ok(())
}

/// Serves `bus` on `pty` until Ctrl-C, `--seconds` or a closed port; with
/// `--json`, prints the summary on stdout (the caller reports it otherwise).
fn serve_until_stopped(bus: &mut VirtualBus, pty: Pty, args: &ServosArgs, bps: u32, name: &str) -> Result<serve::ServeSummary, CliError> {
    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = stop.clone();
        let _ = ctrlc::set_handler(move || stop.store(true, Ordering::SeqCst));
    }
    let opts = serve::ServeOptions { bps, seconds: args.seconds, name, lock_step: args.lockstep, realtime: !args.no_realtime };
    let summary = serve::serve(bus, &pty, &stop, &opts)
        .map_err(|e| CliError::Runtime(anyhow::anyhow!("the virtual port failed: {e}")))?;
    drop(pty);
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&summary).map_err(|e| CliError::Runtime(e.into()))?)?;
    }
    Ok(summary)
}

/// The servos' one rate (`--baud`, default 1 000 000 bps).
fn one_rate(baud: Option<&str>) -> Result<u32, CliError> {
    match baud {
        None => Ok(1_000_000),
        Some(b) => b.parse::<u32>().ok().filter(|b| (9_600..=4_500_000).contains(b)).ok_or_else(|| {
            usage(format!("--baud {b}: not a baud rate; valid is one of the servos' rates, 9600 to 4500000 (e.g. 57600, 1000000)"))
        }),
    }
}

/// Refuses the flags of the virtual servos in `task` (--scan, --reboot),
/// which works on a real port (`why`).
fn refuse_virtual_flags(args: &ServosArgs, task: &str, why: &str) -> Result<(), CliError> {
    for (flag, given) in [
        ("--robot", args.robot.is_some()),
        ("--chain", args.chain.is_some()),
        ("--servo", args.servo.is_some()),
        ("--lockstep", args.lockstep),
        ("--fault", !args.faults.is_empty()),
        ("--seconds", args.seconds.is_some()),
        ("--no-realtime", args.no_realtime),
    ] {
        if given {
            return Err(usage(format!("{flag} does not go with {task} ({why})")));
        }
    }
    Ok(())
}

/// `--reboot ID`.
fn run_reboot(args: &ServosArgs, id: u8) -> Result<(), CliError> {
    refuse_virtual_flags(args, "--reboot", "it reboots one servo of a real port")?;
    for (flag, given) in [("--protocol", args.protocol.is_some()), ("--ids", args.ids.is_some())] {
        if given {
            return Err(usage(format!("{flag} does not go with --reboot (it reboots one servo of a real port)")));
        }
    }
    let bps = one_rate(args.baud.as_deref())?;
    crate::drive::port::check_access(&args.port).map_err(usage)?;
    let r = reboot::reboot(&args.port, bps, id, Duration::from_millis(args.timeout_ms)).map_err(usage)?;
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&r).map_err(|e| CliError::Runtime(e.into()))?)?;
    } else {
        let before = match r.hardware_error_before {
            0 => "no hardware error before".to_string(),
            bits => format!("hardware error before: {}", HardwareError(bits).names().collect::<Vec<_>>().join(", ")),
        };
        let model = scan::model_name(r.model_number, 2).unwrap_or("model pada does not know");
        outln!("servo {id} ({model}) rebooted at {bps} bps; {before}")?;
    }
    if r.alert_after {
        return Err(CliError::Runtime(anyhow::anyhow!(
            "servo {id} raised its alert again after the reboot: the cause persists (let it cool, check the supply and the load)"
        )));
    }
    Ok(())
}

/// The control period a bare chain's lock step ends at each SYNC WRITE
/// \[µs\] (a chain has no robot to give one).
const CHAIN_PERIOD_US: u64 = 20_000;

/// `pada servos --chain`: a bare chain of virtual servos.
fn run_chain(args: &ServosArgs, chain: &str) -> Result<(), CliError> {
    let spec = crate::servos::chain::parse(chain).map_err(usage)?;
    let bps = one_rate(args.baud.as_deref())?;
    if let Some(s) = args.seconds {
        if !(s.is_finite() && s > 0.0) {
            return Err(usage(format!("--seconds {s} is out of range: valid is > 0")));
        }
    }
    let faults = args.faults.iter().map(|f| crate::sil::fault::parse(f).map_err(usage)).collect::<Result<Vec<_>, _>>()?;
    let clock = if args.lockstep { Clock::LockStep } else { Clock::RealTime };
    let mut bus = VirtualBus::chain(&spec.ids, bps, clock, faults, CHAIN_PERIOD_US).map_err(usage)?;
    let pty = Pty::create(&args.port).map_err(|e| usage(format!("--port {}: cannot make the virtual port: {e}", args.port.display())))?;
    let name = format!("{} chain", spec.model.to_ascii_uppercase());
    errln!("servos: {name} (IDs {:?}) at {bps} bps on {} -> {}", spec.ids, args.port.display(), pty.device());
    let summary = serve_until_stopped(&mut bus, pty, &args, bps, &name)?;
    if !args.json {
        errln!("servos: ended ({}): {} packets, {} answers", summary.ended, summary.stats.packets, summary.stats.replies);
    }
    Ok(())
}

/// `--scan`.
fn run_scan(args: &ServosArgs) -> Result<(), CliError> {
    refuse_virtual_flags(args, "--scan", "it scans a real port")?;
    let rates = match args.baud.as_deref() {
        None => scan::RATES.to_vec(),
        Some(list) => list
            .split(',')
            .map(|b| b.trim().parse::<u32>().ok().filter(|b| (9_600..=4_500_000).contains(b)))
            .collect::<Option<Vec<u32>>>()
            .ok_or_else(|| usage(format!("--baud {list}: valid is a comma-separated list of rates from 9600 to 4500000")))?,
    };
    let ids = match args.ids.as_deref() {
        None => 0..=253,
        Some(r) => {
            let bad = || usage(format!("--ids {r}: valid is A-B with 0 <= A <= B <= 253"));
            let (a, b) = r.split_once('-').ok_or_else(bad)?;
            let (a, b) = (a.trim().parse::<u8>().map_err(|_| bad())?, b.trim().parse::<u8>().map_err(|_| bad())?);
            if a > b || b > 253 {
                return Err(bad());
            }
            a..=b
        }
    };
    let cfg = ScanConfig {
        rates,
        protocols: args.protocol.map_or(vec![2, 1], |p| vec![p]),
        ids,
        timeout: Duration::from_millis(args.timeout_ms),
    };
    crate::drive::port::check_access(&args.port).map_err(usage)?;
    let found = scan::scan(&args.port, &cfg, &mut |baud, protocol| errln!("scan: {baud} bps, Protocol {protocol}.0"))
        .map_err(|e| usage(format!("--port {}: {e}", args.port.display())))?;
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&found).map_err(|e| CliError::Runtime(e.into()))?)?;
        return Ok(());
    }
    if found.is_empty() {
        outln!("no servo answered on {} (rates {:?}, Protocol {:?})", args.port.display(), cfg.rates, cfg.protocols)?;
    }
    for f in &found {
        outln!(
            "{:>8} bps  Protocol {}.0  ID {:>3}  {} (model {}){}",
            f.baud,
            f.protocol,
            f.id,
            f.model.unwrap_or("unknown model"),
            f.model_number.map_or("?".to_string(), |m| m.to_string()),
            f.firmware.map_or(String::new(), |v| format!(", firmware {v}"))
        )?;
    }
    Ok(())
}
