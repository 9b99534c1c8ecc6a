#!/usr/bin/env python3
"""A client of a running motion-supervisor written with nothing but the
`iceoryx2` package from PyPI (the same version as the Rust crate, 0.10.0).

It reads the status of every axis from the status service and, with --home,
homes an axis through the control service and follows it until it is done.

    pip install iceoryx2==0.10.0
    python3 motion_client.py --prefix motion              # status
    python3 motion_client.py --prefix motion --home X     # home X, wait, print result

The supervisor is found through its session file ({runtime_dir}/{prefix}.session,
readable only by the supervisor's user): it names the iceoryx2 domain and the
session key every request must carry. The message layouts mirror
crates/control/src/message.rs (layout 2; the status frame @3); iceoryx2 checks type name, size and
alignment when the services are opened, so a wrong mirror fails loudly.

Exit codes: 0 done (with --home: the axis homed with PC set), 1 refused or
failed, 3 no supervisor running under the prefix.
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

REQ_HOME = 1
RESULT_ACCEPTED = 0

ST_EN, ST_DN, ST_ER, ST_IP, ST_PC = 1, 2, 4, 8, 16
ST_HOMING, ST_HOMED, ST_FEEDBACK, ST_EVENT, ST_STOPPING = 32, 64, 2048, 4096, 8192
SX_IN_SEQUENCE = 4


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
        ("axes", (ctypes.c_uint8 * NAME_LEN) * MAX_AXES),
    ]

    @staticmethod
    def type_name() -> str:
        return "motion_control::ControlRequest@2"


class AxisAnswer(ctypes.Structure):
    _fields_ = [
        ("name", ctypes.c_uint8 * NAME_LEN),
        ("accepted", ctypes.c_uint8),
        ("reason", ctypes.c_uint8),
        ("err", ctypes.c_uint16),
        ("exerr", ctypes.c_uint16),
        ("reserved", ctypes.c_uint8 * 2),
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
        ("message", ctypes.c_uint8 * MESSAGE_LEN),
        ("axes", AxisAnswer * MAX_AXES),
        ("data", ctypes.c_uint8 * DATA_LEN),
    ]

    @staticmethod
    def type_name() -> str:
        return "motion_control::ControlResponse@2"


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

    def request(self, kind: int, axes, timeout: float = 3.0) -> ControlResponse:
        """One control request with the session key; its response."""
        req = ControlRequest()
        req.layout_version = 2
        req.kind = kind
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
    return 0


if __name__ == "__main__":
    sys.exit(main())
