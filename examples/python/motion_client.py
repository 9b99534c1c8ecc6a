#!/usr/bin/env python3
"""A client of a running motion-supervisor written with nothing but the
`iceoryx2` package from PyPI (the same version as the Rust crate, 0.10.0).

It reads the status of every axis from the status service and, through
the control service, homes an axis (following it until it is done), enables,
disables or resets drives, jogs an axis (hold to run: the lease is renewed
while the jog runs) and moves one (following the move to its end).

    pip install iceoryx2==0.10.0
    python3 motion_client.py --prefix motion              # status
    python3 motion_client.py --prefix motion --home X     # home X, wait, print result
    python3 motion_client.py --prefix motion --enable X
    python3 motion_client.py --prefix motion --jog X --speed -2 --for 1.5
    python3 motion_client.py --prefix motion --move X --to 12.5
    python3 motion_client.py --prefix motion --reset X

The supervised setpoint stream has its own example: stream_sine.py.

The supervisor is found through its session file ({runtime_dir}/{prefix}.session,
readable only by the supervisor's user): it names the iceoryx2 domain and the
session key every request must carry. The message layouts mirror
crates/control/src/message.rs (layout 3); iceoryx2 checks type name, size and
alignment when the services are opened, so a wrong mirror fails loudly.

Exit codes: 0 done (--home: the axis homed with PC set; --move: at its
target; --jog: ended without an axis fault), 1 refused or failed, 3 no
supervisor running under the prefix.
"""

import argparse
import ctypes
import json
import os
import sys
import time

import iceoryx2 as iox2

NAME_LEN = 32
MAX_AXES = 64
MAX_IOS = 16
MESSAGE_LEN = 256
DATA_LEN = 32 * 1024
PHASE_LEN = 16

LAYOUT = 3
REQ_HOME = 1
REQ_STOP = 2
REQ_ENABLE, REQ_DISABLE, REQ_RESET = 9, 10, 11
REQ_JOG, REQ_JOG_RENEW, REQ_MOVE = 12, 13, 14
REQ_STREAM_ACQUIRE, REQ_STREAM_RELEASE = 15, 16
FLAG_RELATIVE, FLAG_SUPERSEDE, FLAG_END = 8, 16, 32
RESULT_ACCEPTED = 0
NO_INDEX = 0xFFFF

ST_EN, ST_DN, ST_ER, ST_IP, ST_PC = 1, 2, 4, 8, 16
ST_HOMING, ST_HOMED, ST_FEEDBACK, ST_EVENT, ST_STOPPING = 32, 64, 2048, 4096, 8192
SX_IN_SEQUENCE = 4
MS_SERVO_ACTION, MS_JOGGING, MS_MOVING, MS_STREAMING = 1, 2, 4, 8
MS_LIMIT_NEGATIVE, MS_LIMIT_POSITIVE, MS_FAULTED, MS_COMMAND = 16, 32, 64, 128
OP_IP, OP_PC, OP_REFUSED = 1, 2, 4


class ControlRequest(ctypes.Structure):
    _fields_ = [
        ("layout_version", ctypes.c_uint32),
        ("kind", ctypes.c_uint32),
        ("key", ctypes.c_uint64 * 2),
        ("request_id", ctypes.c_uint64),
        ("flags", ctypes.c_uint32),
        ("axis_count", ctypes.c_uint32),
        ("offset", ctypes.c_uint64),
        ("timeout_s", ctypes.c_double),
        ("position", ctypes.c_double),
        ("speed", ctypes.c_double),
        ("accel", ctypes.c_double),
        ("decel", ctypes.c_double),
        ("token", ctypes.c_uint64),
        ("node_id", ctypes.c_uint64 * 2),
        ("lease_ms", ctypes.c_uint32),
        ("reserved", ctypes.c_uint32),
        ("owner", ctypes.c_uint8 * NAME_LEN),
        ("axes", (ctypes.c_uint8 * NAME_LEN) * MAX_AXES),
    ]

    @staticmethod
    def type_name() -> str:
        return "motion_control::ControlRequest@3"


class AxisAnswer(ctypes.Structure):
    _fields_ = [
        ("name", ctypes.c_uint8 * NAME_LEN),
        ("accepted", ctypes.c_uint8),
        ("reason", ctypes.c_uint8),
        ("err", ctypes.c_uint16),
        ("exerr", ctypes.c_uint16),
        ("index", ctypes.c_uint16),
        ("op_id", ctypes.c_uint32),
        ("reserved", ctypes.c_uint32),
    ]


class ControlResponse(ctypes.Structure):
    _fields_ = [
        ("layout_version", ctypes.c_uint32),
        ("kind", ctypes.c_uint32),
        ("session", ctypes.c_uint32),
        ("result", ctypes.c_uint32),
        ("request_id", ctypes.c_uint64),
        ("axis_count", ctypes.c_uint32),
        ("data_len", ctypes.c_uint32),
        ("offset", ctypes.c_uint64),
        ("total", ctypes.c_uint64),
        ("cycle", ctypes.c_uint64),
        ("token", ctypes.c_uint64),
        ("message", ctypes.c_uint8 * MESSAGE_LEN),
        ("axes", AxisAnswer * MAX_AXES),
        ("data", ctypes.c_uint8 * DATA_LEN),
    ]

    @staticmethod
    def type_name() -> str:
        return "motion_control::ControlResponse@3"


class AxisStatusEntry(ctypes.Structure):
    _fields_ = [
        ("name", ctypes.c_uint8 * NAME_LEN),
        ("phase", ctypes.c_uint8 * PHASE_LEN),
        ("io", ctypes.c_uint8),
        ("warnings", ctypes.c_uint8),
        ("bits", ctypes.c_uint16),
        ("err", ctypes.c_uint16),
        ("exerr", ctypes.c_uint16),
        ("drive_error_code", ctypes.c_uint16),
        ("home_mode", ctypes.c_uint8),
        ("home_sequence", ctypes.c_uint8),
        ("home_direction", ctypes.c_uint8),
        ("aborted_by", ctypes.c_uint8),
        ("extra", ctypes.c_uint8),
        ("reserved1", ctypes.c_uint8),
        ("position", ctypes.c_double),
        ("raw", ctypes.c_double),
        ("velocity", ctypes.c_double),
        ("torque", ctypes.c_double),
        ("event_raw", ctypes.c_double),
        ("elapsed_s", ctypes.c_double),
        ("timeout_s", ctypes.c_double),
        ("search_travel", ctypes.c_double),
        ("search_limit", ctypes.c_double),
        ("lost_after_s", ctypes.c_double),
        ("skew", ctypes.c_double),
        ("feedback_gap_s", ctypes.c_double),
        ("drift", ctypes.c_double),
        ("switch_to_marker", ctypes.c_double),
        ("cmd_position", ctypes.c_double),
        ("op_id", ctypes.c_uint32),
        ("op_err", ctypes.c_uint16),
        ("op_exerr", ctypes.c_uint16),
        ("motion", ctypes.c_uint16),
        ("op_kind", ctypes.c_uint8),
        ("op_flags", ctypes.c_uint8),
        ("last_stop", ctypes.c_uint8),
        ("reserved2", ctypes.c_uint8 * 3),
        ("owner", ctypes.c_uint8 * NAME_LEN),
    ]


class IoStatusEntry(ctypes.Structure):
    _fields_ = [
        ("name", ctypes.c_uint8 * NAME_LEN),
        ("attached", ctypes.c_uint8),
        ("reserved", ctypes.c_uint8 * 7),
        ("frames_received", ctypes.c_uint64),
        ("frames_missing", ctypes.c_uint64),
        ("frames_refused", ctypes.c_uint64),
        ("attachments", ctypes.c_uint64),
        ("gaps", ctypes.c_uint64 * 4),
        ("longest_gap_cycles", ctypes.c_uint64),
        ("gap_cycles", ctypes.c_uint64),
        ("spawn_restarts", ctypes.c_uint32),
        ("spawn_retry_s", ctypes.c_float),
        ("start_error", ctypes.c_uint8 * 128),
    ]


class StreamStatusEntry(ctypes.Structure):
    _fields_ = [
        ("frames", ctypes.c_uint64),
        ("setpoints", ctypes.c_uint64),
        ("refused_layout", ctypes.c_uint64),
        ("refused_key", ctypes.c_uint64),
        ("refused_count", ctypes.c_uint64),
        ("refused_token", ctypes.c_uint64),
        ("refused_sequence", ctypes.c_uint64),
        ("refused_axis", ctypes.c_uint64),
        ("acquired", ctypes.c_uint32),
        ("owners", ctypes.c_uint32),
    ]


class StatusFrame(ctypes.Structure):
    _fields_ = [
        ("layout_version", ctypes.c_uint32),
        ("session", ctypes.c_uint32),
        ("sequence", ctypes.c_uint64),
        ("cycle", ctypes.c_uint64),
        ("uptime_ns", ctypes.c_uint64),
        ("cycle_us", ctypes.c_uint32),
        ("axis_count", ctypes.c_uint32),
        ("io_count", ctypes.c_uint32),
        ("reserved", ctypes.c_uint32),
        ("axes", AxisStatusEntry * MAX_AXES),
        ("ios", IoStatusEntry * MAX_IOS),
        ("stream", StreamStatusEntry),
    ]

    @staticmethod
    def type_name() -> str:
        return "motion_control::StatusFrame@3"


def text(arr) -> str:
    return bytes(arr).split(b"\0", 1)[0].decode("utf-8", "replace")


def default_runtime_dir() -> str:
    return "/run/motion" if os.geteuid() == 0 else f"/tmp/motion-{os.geteuid()}"


class NoSupervisor(Exception):
    pass


class Supervisor:
    """The supervisor running under `prefix`, joined through its session file."""

    def __init__(self, prefix: str, runtime_dir: str):
        path = os.path.join(runtime_dir, f"{prefix}.session")
        try:
            with open(path) as f:
                session = json.load(f)
        except FileNotFoundError:
            raise NoSupervisor(f"no motion-supervisor runs with service prefix {prefix!r} (no {path})")
        if not os.path.exists(f"/proc/{session['pid']}"):
            raise NoSupervisor(f"the supervisor of {path} (pid {session['pid']}) has ended")
        key = session["key"]
        self.key = (int(key[:16], 16), int(key[16:], 16))
        self.session = int(session["id"], 16)
        cfg = iox2.config.default()
        cfg.global_cfg.prefix = iox2.FileName.new(f"{prefix}.{session['id']}.")
        cfg.global_cfg.root_path = iox2.Path.new(runtime_dir.rstrip("/") + "/")
        self.node = (
            iox2.NodeBuilder.new()
            .name(iox2.NodeName.new("python-client"))
            .config(cfg)
            .signal_handling_mode(iox2.SignalHandlingMode.Disabled)
            .create(iox2.ServiceType.Ipc)
        )
        control = (
            self.node.service_builder(iox2.ServiceName.new(f"{prefix}/control"))
            .request_response(ControlRequest, ControlResponse)
            .open()
        )
        self.client = control.client_builder().create()
        status = (
            self.node.service_builder(iox2.ServiceName.new(f"{prefix}/status"))
            .publish_subscribe(StatusFrame)
            .open()
        )
        self.subscriber = status.subscriber_builder().create()
        self.next_id = 1

    def status(self, timeout: float = 2.0) -> StatusFrame:
        """The newest status frame (waits for one)."""
        until = time.monotonic() + timeout
        while True:
            newest = None
            while True:
                sample = self.subscriber.receive()
                if sample is None:
                    break
                newest = StatusFrame.from_buffer_copy(sample.payload().contents)
                sample.delete()
            if newest is not None:
                if newest.session != self.session:
                    raise RuntimeError("a status frame of another supervisor session")
                return newest
            if time.monotonic() > until:
                raise TimeoutError("no status frame")
            time.sleep(0.005)

    def request(self, kind: int, axes, timeout: float = 3.0, **params) -> ControlResponse:
        """One control request with the session key; its response. `params`
        are fields of the request (position, speed, accel, decel, token,
        lease_ms, flags); an operation parameter not given is NaN: the
        axis's default."""
        req = ControlRequest()
        req.layout_version = LAYOUT
        req.kind = kind
        req.position = req.speed = req.accel = req.decel = float("nan")
        for k, v in params.items():
            setattr(req, k, v)
        req.key[0], req.key[1] = self.key
        req.request_id = self.next_id
        self.next_id += 1
        req.axis_count = len(axes)
        for i, name in enumerate(axes):
            raw = name.encode()[:NAME_LEN]
            ctypes.memmove(req.axes[i], raw, len(raw))
        pending = self.client.send_copy(req)
        until = time.monotonic() + timeout
        while time.monotonic() < until:
            response = pending.receive()
            if response is not None:
                r = ControlResponse.from_buffer_copy(response.payload().contents)
                response.delete()
                if r.request_id == req.request_id:
                    return r
            time.sleep(0.002)
        raise TimeoutError("no answer from the control service")


def show(frame: StatusFrame) -> None:
    ios = [text(frame.ios[k].name) for k in range(frame.io_count)]
    for k in range(frame.io_count):
        io = frame.ios[k]
        print(f"io {text(io.name)}: {'attached' if io.attached else 'NOT attached'}")
    for i in range(frame.axis_count):
        a = frame.axes[i]
        bits = " ".join(n for n, b in (("EN", ST_EN), ("DN", ST_DN), ("ER", ST_ER), ("IP", ST_IP), ("PC", ST_PC)) if a.bits & b)
        pos = f"{a.position:.4f}" if a.bits & ST_FEEDBACK else "-"
        print(
            f"{text(a.name):<8} io {ios[a.io]:<6} phase {text(a.phase):<12} [{bits}] "
            f"homed {'yes' if a.bits & ST_HOMED else 'no'} ERR {a.err}/{a.exerr} position {pos}"
        )


def refused(what: str, r: ControlResponse) -> int:
    """A refused request: why, and each axis's reason and codes."""
    print(f"{what} refused: {text(r.message)}", file=sys.stderr)
    for k in range(r.axis_count):
        a = r.axes[k]
        if not a.accepted and a.reason:
            print(f"  {text(a.name)}: reason {a.reason} ERR {a.err}/{a.exerr}", file=sys.stderr)
    return 1


def axis_entry(frame: StatusFrame, index: int) -> AxisStatusEntry:
    return frame.axes[index]


def follow(sup: Supervisor, r: ControlResponse, timeout: float) -> list:
    """Follows the accepted axes of answer `r` until each one's operation
    (by its id) has ended and the axis is at rest; their final entries."""
    axes = [(r.axes[k].index, r.axes[k].op_id) for k in range(r.axis_count) if r.axes[k].accepted and r.axes[k].index != NO_INDEX]
    busy_bits = MS_JOGGING | MS_MOVING | MS_STREAMING
    until = time.monotonic() + timeout
    while time.monotonic() < until:
        frame = sup.status()
        if frame.cycle >= r.cycle:
            entries = [axis_entry(frame, i) for i, _ in axes]
            if all(
                e.op_id != op or not ((e.op_flags & OP_IP) or (e.bits & ST_STOPPING) or (e.motion & busy_bits))
                for e, (_, op) in zip(entries, axes)
            ):
                return [(e, op) for e, (_, op) in zip(entries, axes)]
        time.sleep(0.02)
    raise TimeoutError("the operation did not end in time")


def operation(sup: Supervisor, what: str, kind: int, axis: str, **params) -> int:
    """enable / disable / reset: one request, every axis's answer."""
    r = sup.request(kind, [axis] if axis else [], **params)
    if r.result != RESULT_ACCEPTED:
        return refused(what, r)
    names = [text(r.axes[k].name) for k in range(r.axis_count)]
    print(f"{what}: {' '.join(names)}")
    return 0


def move(sup: Supervisor, axis: str, target: float, relative: bool, speed: float, timeout: float) -> int:
    """MAM: move, follow, exit 0 only at the target (PC)."""
    r = sup.request(REQ_MOVE, [axis], position=target, speed=speed, flags=FLAG_RELATIVE if relative else 0)
    if r.result != RESULT_ACCEPTED:
        return refused("move", r)
    ok = True
    for e, op in follow(sup, r, timeout):
        pc = e.op_id == op and bool(e.op_flags & OP_PC)
        ok = ok and pc and not e.bits & ST_ER
        print(f"{text(e.name)}: PC {int(pc)} ER {int(bool(e.bits & ST_ER))} ERR {e.err}/{e.exerr} position {e.position:.6f}")
    return 0 if ok else 1


def jog(sup: Supervisor, axis: str, speed: float, duration: float) -> int:
    """MAJ, hold to run: a 500 ms lease renewed every 100 ms for `duration`
    seconds, then the jog is ended (only this jog) and followed to rest."""
    r = sup.request(REQ_JOG, [axis], speed=speed, lease_ms=500)
    if r.result != RESULT_ACCEPTED:
        return refused("jog", r)
    token = r.token
    until = time.monotonic() + duration
    while time.monotonic() < until:
        time.sleep(0.1)
        renewal = sup.request(REQ_JOG_RENEW, [], token=token)
        if renewal.result != RESULT_ACCEPTED:
            print("the jog ended by itself (stop, limit, fault)")
            break
    sup.request(REQ_JOG_RENEW, [], token=token, flags=FLAG_END)
    ok = True
    for e, _ in follow(sup, r, 30.0):
        ok = ok and not e.bits & ST_ER
        print(f"{text(e.name)}: ER {int(bool(e.bits & ST_ER))} ERR {e.err}/{e.exerr} position {e.position:.6f}")
    return 0 if ok else 1


def home(sup: Supervisor, axis: str, timeout: float) -> int:
    r = sup.request(REQ_HOME, [axis])
    if r.result != RESULT_ACCEPTED:
        print(f"home {axis} refused: {text(r.message)}", file=sys.stderr)
        return 1
    print(f"home {axis}: accepted (cycle {r.cycle})")
    until = time.monotonic() + timeout
    while time.monotonic() < until:
        frame = sup.status()
        if frame.cycle < r.cycle:
            continue
        for i in range(frame.axis_count):
            a = frame.axes[i]
            if text(a.name) != axis:
                continue
            if not (a.extra & SX_IN_SEQUENCE) and not (a.bits & (ST_IP | ST_STOPPING)):
                ok = bool(a.bits & ST_PC) and bool(a.bits & ST_HOMED) and not a.bits & ST_ER
                event = f"{a.event_raw:.6f}" if a.bits & ST_EVENT else "-"
                print(
                    f"{axis}: {'homed' if ok else 'NOT homed'}: PC {int(bool(a.bits & ST_PC))} "
                    f"ER {int(bool(a.bits & ST_ER))} ERR {a.err}/{a.exerr} event_raw {event} "
                    f"position {a.position:.6f} raw {a.raw:.6f} in {a.elapsed_s:.3f} s"
                )
                return 0 if ok else 1
        time.sleep(0.02)
    print(f"{axis}: no result within {timeout} s", file=sys.stderr)
    return 1


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--prefix", default="motion", help="the supervisor's service prefix")
    p.add_argument("--runtime-dir", default=default_runtime_dir(), help="where its session file is")
    p.add_argument("--home", metavar="AXIS", help="home AXIS and wait for the result")
    p.add_argument("--enable", metavar="AXIS", help="MSO: enable the drive of AXIS")
    p.add_argument("--disable", metavar="AXIS", help="MSF: disable the drive of AXIS")
    p.add_argument("--reset", metavar="AXIS", help="MAFR: clear the axis fault of AXIS")
    p.add_argument("--jog", metavar="AXIS", help="MAJ: jog AXIS at --speed for --for seconds")
    p.add_argument("--move", metavar="AXIS", help="MAM: move AXIS --to P (or --by D)")
    p.add_argument("--speed", type=float, default=float("nan"))
    p.add_argument("--to", type=float)
    p.add_argument("--by", type=float)
    p.add_argument("--for", dest="duration", type=float, default=1.0)
    p.add_argument("--timeout", type=float, default=60.0)
    a = p.parse_args()
    iox2.set_log_level_from_env_or(iox2.LogLevel.Warn)
    try:
        sup = Supervisor(a.prefix, a.runtime_dir)
    except NoSupervisor as e:
        print(e, file=sys.stderr)
        return 3
    show(sup.status())
    if a.home:
        return home(sup, a.home, a.timeout)
    for what, kind, axis in (("enable", REQ_ENABLE, a.enable), ("disable", REQ_DISABLE, a.disable), ("reset", REQ_RESET, a.reset)):
        if axis:
            return operation(sup, what, kind, axis)
    if a.jog:
        return jog(sup, a.jog, a.speed, a.duration)
    if a.move:
        relative = a.to is None
        return move(sup, a.move, a.by if relative else a.to, relative, a.speed, a.timeout)
    return 0


if __name__ == "__main__":
    sys.exit(main())
