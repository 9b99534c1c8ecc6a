//! `[supervisor]`: the cycle and its processes.

use super::{keys, Key, Kind, Section::Supervisor, Status};
use crate::IoMode;

keys! {
    GROUP {
        section: Supervisor,
        title: "[supervisor]",
        intro: "The real-time cycle: its period, CPU and priority; the feedback-loss rule; \
                how spawned I/O processes are scheduled; where the daemon keeps its files.",
    }
    CYCLE_US: Key::new(Supervisor, "cycle_us", Kind::Integer)
        .int(1000)
        .range(50.0, 100_000.0)
        .unit("µs")
        .fixed()
        .meaning("Period of the real-time cycle; also the EtherCAT bus cycle (at least 100 µs there).")
        .example("1000");
    CPU: Key::new(Supervisor, "cpu", Kind::Integer)
        .int(1)
        .bounded("a CPU this machine has online")
        .fixed()
        .meaning("The CPU the real-time thread is pinned to (isolate it: `isolcpus`, `nohz_full`).")
        .example("1");
    PRIORITY: Key::new(Supervisor, "priority", Kind::Integer)
        .int(80)
        .range(1.0, 99.0)
        .fixed()
        .meaning("`SCHED_FIFO` priority of the real-time thread; where it is not permitted the \
                  thread runs normally, with a warning.")
        .example("80");
    IO: Key::new(Supervisor, "io", Kind::Choice(|| super::names_of(IoMode::NAMES)))
        .text("sim")
        .fixed()
        .meaning("Without `[[io]]` tables: `\"sim\"` spawns one I/O process named `io` with the \
                  simulated plants; `\"external\"` waits for one started by someone else \
                  (a systemd unit). Ignored, with a warning, when `[[io]]` tables are given.")
        .example("\"external\"");
    SERVICE_PREFIX: Key::new(Supervisor, "service_prefix", Kind::Text)
        .text("motion")
        .bounded("1..=32 characters of A-Z a-z 0-9 _ -")
        .fixed()
        .meaning("Prefix of every iceoryx2 service and shared-memory file of this machine; two \
                  supervisors with different prefixes never share a file.")
        .example("\"cell2\"");
    FEEDBACK_TIMEOUT_MS: Key::new(Supervisor, "feedback_timeout_ms", Kind::Number)
        .num(10.0)
        // At least a millisecond, at most a second: a larger value would
        // switch the detection of a dead I/O process off.
        .range(1.0, 1000.0)
        .unit("ms")
        .meaning("The feedback-loss rule: a leaky bucket of missing-feedback time trips above \
                  this; homing then aborts with ERR 12 / EXERR 40 and a moving axis stops. A \
                  dead I/O process is caught within this plus a cycle; isolated gaps never trip.")
        .example("10");
    STALE_CYCLES: Key::new(Supervisor, "stale_cycles", Kind::Integer)
        .unset("see `feedback_timeout_ms`")
        .bounded("cycles × cycle_us within the range of `feedback_timeout_ms`")
        .status(Status::Deprecated("read as `feedback_timeout_ms` = cycles × cycle, with a warning"))
        .meaning("The feedback-loss rule in cycles, as older configurations state it; not together \
                  with `feedback_timeout_ms`.")
        .example("10");
    FEEDBACK_LOSS_DRAIN: Key::new(Supervisor, "feedback_loss_drain", Kind::Number)
        .num(0.25)
        .range(0.0, 1.0)
        .meaning("Share of the time with fresh feedback that drains the feedback-loss bucket: with \
                  0.25, losing more than a fifth of the cycles for long trips the rule.")
        .example("0.25");
    IO_WATCHDOG_CYCLES: Key::new(Supervisor, "io_watchdog_cycles", Kind::Integer)
        .derived("50, or as many cycles as fit in 1000 ms when that is fewer")
        .bounded("1..=⌊1000 ms / cycle⌋")
        .unit("cycles")
        .meaning("Cycles without a command after which `motion-io` stops every axis and disables \
                  its drive (the supervisor died or hangs).")
        .example("50");
    LOCK_MEMORY: Key::new(Supervisor, "lock_memory", Kind::Bool)
        .flag(true)
        .meaning("`mlockall` the daemon, so no page fault can delay the cycle.")
        .example("true");
    CPU_DMA_LATENCY_US: Key::new(Supervisor, "cpu_dma_latency_us", Kind::Integer)
        .int(0)
        .at_most(10_000.0)
        .unit("µs")
        .meaning("Hold `/dev/cpu_dma_latency` at this value while running (0: no deep idle states, \
                  as cyclictest does); negative: leave the idle states alone.")
        .example("0");
    IO_PRIORITY: Key::new(Supervisor, "io_priority", Kind::Integer)
        .derived("`priority` − 10 (at least 1)")
        .range(0.0, 99.0)
        .meaning("`SCHED_FIFO` priority of a spawned `motion-io`; 0: normal scheduling. Below the \
                  cycle, above the kernel's IRQ threads (50).")
        .example("70");
    IO_CPU: Key::new(Supervisor, "io_cpu", Kind::Integer)
        .int(-1)
        .bounded("a CPU this machine has online, or -1")
        .meaning("CPU of a spawned `motion-io`; -1: the cycle's CPU, where it answers while the \
                  cycle sleeps.")
        .example("-1");
    RUNTIME_DIR: Key::new(Supervisor, "runtime_dir", Kind::Text)
        .unset("`/run/motion` for root (and for the user owning it), else `/tmp/motion-UID`")
        .bounded("an absolute path of at most 19 characters")
        .meaning("Where the daemon writes its session file and iceoryx2 keeps its files; owned by \
                  the daemon's user, no one else may write to it.")
        .example("\"/run/motion\"");
    STATE_DIR: Key::new(Supervisor, "state_dir", Kind::Text)
        .unset("systemd's `$STATE_DIRECTORY`, else `/var/lib/motion` for root, else `~/.local/state/motion`")
        .bounded("an absolute path of at most 200 characters without `..`")
        .fixed()
        .meaning("Where the homing record and the stored references of absolute axes live.")
        .example("\"/var/lib/motion\"");
}
