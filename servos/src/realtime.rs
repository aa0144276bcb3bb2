//! A real-time control thread: what `pada drive`'s periods and `pada
//! servos`' loop ask of the operating system so that a busy PC (a build on
//! every core) cannot hold them back, and what it granted.
//!
//! - **Priority:** the calling thread under `SCHED_FIFO` at [`PRIORITY`].
//!   A FIFO thread runs as soon as it wakes, ahead of every ordinary
//!   (`SCHED_OTHER`) thread, whatever their load. 49 is just below the
//!   kernel's threaded interrupt handlers (50 on a PREEMPT_RT kernel), so
//!   the USB adapter's interrupts still come first. Only this thread: the
//!   telemetry thread, started before, keeps the ordinary policy, and
//!   [`Realtime::leave`] returns to it before the checkpoint is written.
//! - **Locked memory:** `mlockall(MCL_CURRENT | MCL_FUTURE)`, so that no
//!   period waits for a page to come back from swap or to be faulted in.
//!   Under a finite `RLIMIT_MEMLOCK` without `CAP_IPC_LOCK`, `MCL_FUTURE`
//!   would make a later allocation past the limit fail (and abort the run
//!   with torque on), so there only the pages mapped now are locked.
//! - **CPU affinity:** not set. A FIFO thread preempts an ordinary one on
//!   whichever core it wakes; pinning it would only forbid it the other
//!   cores when one is taken by another FIFO thread (the virtual servos').
//!
//! Whatever is refused, the run goes on without it and says so: the
//! report's lines name what was refused, why (the error), and what grants
//! it. The platform is a trait so that the refused path is tested with a
//! fake that refuses, besides the real child without the capabilities.

use serde::Serialize;

/// The `SCHED_FIFO` priority of a control thread (1–99).
pub const PRIORITY: u8 = 49;

/// What one request came to.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(tag = "status", content = "detail", rename_all = "kebab-case")]
pub enum Grant {
    /// Granted as asked.
    Granted(String),
    /// Granted in part (what, and why not all).
    Partial(String),
    /// Refused: why, and what would grant it.
    Refused(String),
    /// Not asked for (`--no-realtime`, lock step, or by design).
    NotAsked(String),
}

impl Grant {
    /// Whether it was granted in full.
    pub fn granted(&self) -> bool {
        matches!(self, Grant::Granted(_))
    }

    /// `granted`, `granted in part`, `refused`, `not asked`.
    pub fn word(&self) -> &'static str {
        match self {
            Grant::Granted(_) => "granted",
            Grant::Partial(_) => "granted in part",
            Grant::Refused(_) => "refused",
            Grant::NotAsked(_) => "not asked",
        }
    }

    fn detail(&self) -> &str {
        match self {
            Grant::Granted(d) | Grant::Partial(d) | Grant::Refused(d) | Grant::NotAsked(d) => d,
        }
    }
}

/// What the operating system granted the control thread.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct RealtimeReport {
    /// `SCHED_FIFO` at [`PRIORITY`].
    pub priority: Grant,
    /// `mlockall`.
    pub locked_memory: Grant,
    /// Pinning to a core (never asked; the module says why).
    pub cpu_affinity: Grant,
}

impl RealtimeReport {
    /// The report of a run that asked for nothing (`why`).
    pub fn not_asked(why: &str) -> RealtimeReport {
        RealtimeReport {
            priority: Grant::NotAsked(why.to_string()),
            locked_memory: Grant::NotAsked(why.to_string()),
            cpu_affinity: Grant::NotAsked(why.to_string()),
        }
    }

    /// One line: `priority granted, locked memory refused, CPU affinity not
    /// asked`.
    pub fn summary(&self) -> String {
        format!("priority {}, locked memory {}, CPU affinity {}", self.priority.word(), self.locked_memory.word(), self.cpu_affinity.word())
    }

    /// One line per request with its detail: `priority: granted (SCHED_FIFO
    /// 49)`, …
    pub fn lines(&self) -> Vec<String> {
        [("priority", &self.priority), ("locked memory", &self.locked_memory), ("CPU affinity", &self.cpu_affinity)]
            .iter()
            .map(|(what, g)| format!("{what}: {} ({})", g.word(), g.detail()))
            .collect()
    }
}

/// What a control thread can ask of its platform (Linux: [`Linux`]; a
/// fake in the tests).
pub trait Platform {
    /// The calling thread under `SCHED_FIFO` at `priority`; the refusal's
    /// text.
    fn set_fifo(&mut self, priority: u8) -> Result<(), String>;
    /// The calling thread back under the ordinary policy.
    fn set_normal(&mut self) -> Result<(), String>;
    /// `RLIMIT_MEMLOCK` \[bytes\]; `None`: unlimited.
    fn memlock_limit(&self) -> Option<u64>;
    /// Whether the process may lock past that limit (`CAP_IPC_LOCK`).
    fn may_lock_past_limit(&self) -> bool;
    /// `mlockall(MCL_CURRENT)`, with `MCL_FUTURE` if `future`.
    fn lock_all(&mut self, future: bool) -> Result<(), String>;
}

/// How to grant the priority when it was refused.
const PRIORITY_HELP: &str = "it needs root, CAP_SYS_NICE or an rtprio limit: `sudo setcap cap_sys_nice,cap_ipc_lock+ep $(which pada)`, or `@realtime - rtprio 99` in /etc/security/limits.d/ for a group you are in";

/// How to lift the locked-memory limit.
const MEMLOCK_HELP: &str = "CAP_IPC_LOCK or `@realtime - memlock unlimited` in /etc/security/limits.d/ lifts the limit";

/// The control thread's real-time state, entered by [`Realtime::enter`].
pub struct Realtime<P: Platform> {
    platform: P,
    fifo: bool,
    report: RealtimeReport,
}

impl<P: Platform> Realtime<P> {
    /// Asks `platform` for a real-time calling thread (nothing if not
    /// `wanted`: `why_not` says why); goes on whatever it grants.
    pub fn enter(mut platform: P, wanted: bool, why_not: &str) -> Realtime<P> {
        if !wanted {
            return Realtime { platform, fifo: false, report: RealtimeReport::not_asked(why_not) };
        }
        let priority = match platform.set_fifo(PRIORITY) {
            Ok(()) => Grant::Granted(format!("SCHED_FIFO {PRIORITY}")),
            Err(e) => Grant::Refused(format!("SCHED_FIFO {PRIORITY}: {e}; {PRIORITY_HELP}")),
        };
        let fifo = priority.granted();
        let limit = platform.memlock_limit();
        let locked_memory = if limit.is_none() || platform.may_lock_past_limit() {
            match platform.lock_all(true) {
                Ok(()) => Grant::Granted("mlockall: the pages mapped now and later".to_string()),
                Err(e) => Grant::Refused(format!("mlockall: {e}")),
            }
        } else {
            let kib = limit.unwrap_or(0) / 1024;
            match platform.lock_all(false) {
                Ok(()) => Grant::Partial(format!(
                    "mlockall: the pages mapped now, not later ones (RLIMIT_MEMLOCK {kib} KiB without CAP_IPC_LOCK: an allocation past it would fail); {MEMLOCK_HELP}"
                )),
                Err(e) => Grant::Refused(format!("mlockall: {e} (RLIMIT_MEMLOCK {kib} KiB without CAP_IPC_LOCK); {MEMLOCK_HELP}")),
            }
        };
        let cpu_affinity = Grant::NotAsked("any core: a FIFO thread preempts ordinary ones wherever it wakes".to_string());
        Realtime { platform, fifo, report: RealtimeReport { priority, locked_memory, cpu_affinity } }
    }

    /// What was granted.
    pub fn report(&self) -> &RealtimeReport {
        &self.report
    }

    /// The calling thread back under the ordinary policy (before the
    /// checkpoint and the files are written, which may block on the disk).
    /// Locked memory stays locked: the process ends soon after.
    pub fn leave(&mut self) {
        if self.fifo {
            // Refused only if the thread is gone; the run ends either way.
            let _ = self.platform.set_normal();
            self.fifo = false;
        }
    }
}

/// The real platform: Linux's scheduler, `mlockall` and limits.
#[cfg(target_os = "linux")]
pub struct Linux;

#[cfg(target_os = "linux")]
impl Platform for Linux {
    fn set_fifo(&mut self, priority: u8) -> Result<(), String> {
        use thread_priority::{RealtimeThreadSchedulePolicy, ThreadPriority, ThreadSchedulePolicy};
        let p = ThreadPriority::try_from(priority).map_err(str::to_string)?;
        let policy = ThreadSchedulePolicy::Realtime(RealtimeThreadSchedulePolicy::Fifo);
        thread_priority::set_thread_priority_and_policy(thread_priority::thread_native_id(), p, policy).map_err(|e| match e {
            thread_priority::Error::OS(code) => std::io::Error::from_raw_os_error(code).to_string(),
            e => format!("{e:?}"),
        })
    }

    fn set_normal(&mut self) -> Result<(), String> {
        use thread_priority::{NormalThreadSchedulePolicy, ThreadPriority, ThreadSchedulePolicy};
        let policy = ThreadSchedulePolicy::Normal(NormalThreadSchedulePolicy::Other);
        thread_priority::set_thread_priority_and_policy(thread_priority::thread_native_id(), ThreadPriority::Min, policy)
            .map_err(|e| format!("{e:?}"))
    }

    fn memlock_limit(&self) -> Option<u64> {
        rustix::process::getrlimit(rustix::process::Resource::Memlock).current
    }

    fn may_lock_past_limit(&self) -> bool {
        rustix::thread::capabilities(None).is_ok_and(|c| c.effective.contains(rustix::thread::CapabilitySet::IPC_LOCK))
    }

    fn lock_all(&mut self, future: bool) -> Result<(), String> {
        use rustix::mm::MlockAllFlags;
        let flags = if future { MlockAllFlags::CURRENT | MlockAllFlags::FUTURE } else { MlockAllFlags::CURRENT };
        rustix::mm::mlockall(flags).map_err(|e| std::io::Error::from(e).to_string())
    }
}

/// The real platform where it is not Linux: everything refused, said so.
#[cfg(not(target_os = "linux"))]
pub struct Linux;

#[cfg(not(target_os = "linux"))]
impl Platform for Linux {
    fn set_fifo(&mut self, _: u8) -> Result<(), String> {
        Err("only on Linux".to_string())
    }
    fn set_normal(&mut self) -> Result<(), String> {
        Ok(())
    }
    fn memlock_limit(&self) -> Option<u64> {
        None
    }
    fn may_lock_past_limit(&self) -> bool {
        false
    }
    fn lock_all(&mut self, _: bool) -> Result<(), String> {
        Err("only on Linux".to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A platform that grants or refuses as told, and records what it was
    /// asked.
    #[derive(Default)]
    struct Fake {
        refuse_fifo: bool,
        refuse_lock: bool,
        limit: Option<u64>,
        capability: bool,
        asked: Vec<String>,
    }

    impl Platform for &mut Fake {
        fn set_fifo(&mut self, priority: u8) -> Result<(), String> {
            self.asked.push(format!("fifo {priority}"));
            if self.refuse_fifo {
                Err("Operation not permitted (os error 1)".to_string())
            } else {
                Ok(())
            }
        }
        fn set_normal(&mut self) -> Result<(), String> {
            self.asked.push("normal".to_string());
            Ok(())
        }
        fn memlock_limit(&self) -> Option<u64> {
            self.limit
        }
        fn may_lock_past_limit(&self) -> bool {
            self.capability
        }
        fn lock_all(&mut self, future: bool) -> Result<(), String> {
            self.asked.push(format!("lock future={future}"));
            if self.refuse_lock {
                Err("Cannot allocate memory (os error 12)".to_string())
            } else {
                Ok(())
            }
        }
    }

    #[test]
    fn granted_is_fifo_and_every_page_locked_and_leave_returns_to_the_ordinary_policy() {
        let mut fake = Fake { limit: Some(8 << 20), capability: true, ..Fake::default() };
        let mut rt = Realtime::enter(&mut fake, true, "");
        assert_eq!(rt.report().priority, Grant::Granted("SCHED_FIFO 49".to_string()));
        assert!(rt.report().locked_memory.granted());
        assert!(matches!(rt.report().cpu_affinity, Grant::NotAsked(_)));
        rt.leave();
        rt.leave();
        assert_eq!(fake.asked, ["fifo 49", "lock future=true", "normal"]);
    }

    #[test]
    fn refused_is_said_with_the_error_and_what_grants_it_and_the_run_goes_on() {
        let mut fake = Fake { refuse_fifo: true, refuse_lock: true, limit: None, ..Fake::default() };
        let mut rt = Realtime::enter(&mut fake, true, "");
        let r = rt.report().clone();
        let Grant::Refused(why) = &r.priority else { panic!("{r:?}") };
        assert!(why.contains("SCHED_FIFO 49: Operation not permitted") && why.contains("CAP_SYS_NICE"), "{why}");
        let Grant::Refused(why) = &r.locked_memory else { panic!("{r:?}") };
        assert!(why.contains("Cannot allocate memory"), "{why}");
        let lines = r.lines();
        assert!(lines[0].starts_with("priority: refused (SCHED_FIFO 49: Operation not permitted"), "{lines:?}");
        assert!(lines[1].starts_with("locked memory: refused (mlockall: Cannot allocate memory"), "{lines:?}");
        assert_eq!(r.summary(), "priority refused, locked memory refused, CPU affinity not asked");
        rt.leave();
        assert_eq!(fake.asked, ["fifo 49", "lock future=true"], "nothing to leave when FIFO was refused");
    }

    #[test]
    fn a_finite_limit_without_the_capability_locks_only_the_pages_mapped_now() {
        let mut fake = Fake { limit: Some(8 << 20), capability: false, ..Fake::default() };
        let rt = Realtime::enter(&mut fake, true, "");
        let Grant::Partial(why) = &rt.report().locked_memory else { panic!("{:?}", rt.report()) };
        assert!(why.contains("RLIMIT_MEMLOCK 8192 KiB"), "{why}");
        assert_eq!(fake.asked, ["fifo 49", "lock future=false"]);
        let mut fake = Fake { limit: Some(64 << 10), refuse_lock: true, ..Fake::default() };
        let rt = Realtime::enter(&mut fake, true, "");
        let Grant::Refused(why) = &rt.report().locked_memory else { panic!("{:?}", rt.report()) };
        assert!(why.contains("RLIMIT_MEMLOCK 64 KiB") && why.contains("memlock unlimited"), "{why}");
    }

    #[test]
    fn not_wanted_asks_nothing() {
        let mut fake = Fake::default();
        let rt = Realtime::enter(&mut fake, false, "--no-realtime");
        assert_eq!(rt.report(), &RealtimeReport::not_asked("--no-realtime"));
        assert_eq!(rt.report().lines()[0], "priority: not asked (--no-realtime)");
        assert!(fake.asked.is_empty());
    }

    #[test]
    fn the_report_in_json_names_each_status() {
        let r = RealtimeReport {
            priority: Grant::Granted("SCHED_FIFO 49".to_string()),
            locked_memory: Grant::Refused("mlockall: x".to_string()),
            cpu_affinity: Grant::NotAsked("any core".to_string()),
        };
        let j = serde_json::to_value(&r).unwrap();
        assert_eq!(j["priority"]["status"], "granted");
        assert_eq!(j["locked_memory"]["status"], "refused");
        assert_eq!(j["cpu_affinity"]["status"], "not-asked");
        assert_eq!(j["priority"]["detail"], "SCHED_FIFO 49");
    }
}
