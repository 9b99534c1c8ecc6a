"""The client: joins a running motion-supervisor through its session file
and speaks its control, status and setpoint services with the `iceoryx2`
package from PyPI (the same version as the Rust crate, 0.10.0).

    sup = Supervisor("motion")
    frame = sup.status()                  # the newest StatusFrame
    r = sup.home(["X"])                   # a ControlResponse
    entry = sup.wait_homed("X", r)        # X's AxisStatusEntry once done
    sup.enable(["X"]); sup.move("X", 12.5); sup.stop(); sup.unhome(["X"])
    with sup.jog("X", speed=-2.0) as jog:  # hold to run
        jog.hold(1.5)                      # renews the lease for 1.5 s
    with sup.stream(["X"], owner="me") as s:
        s.publish([(s.index["X"], 1.0, 0.0)])

An operation's answer is a ControlResponse: `accepted(r)` says whether it
was accepted for every axis, `refusals(r)` why not.
"""

import ctypes
import json
import os
import time

import iceoryx2 as iox2

from .layout import (
    CONTROL_LAYOUT, FLAG_END, FLAG_PARALLEL, FLAG_RELATIVE, FLAG_SUPERSEDE,
    NAME_LEN, NO_INDEX,
    REQ_DISABLE, REQ_ENABLE, REQ_HOME, REQ_JOG, REQ_JOG_RENEW, REQ_MOVE,
    REQ_RESET, REQ_STOP, REQ_STREAM_ACQUIRE, REQ_STREAM_RELEASE, REQ_UNHOME,
    RESULT_ACCEPTED, SETPOINT_LAYOUT, SP_VELOCITY,
    ControlRequest, ControlResponse, SetpointFrame,
    StatusFrame, put_text, text,
)
from .paths import default_runtime_dir


class NoSupervisor(Exception):
    """No supervisor runs under the prefix (no session file, or its
    process has ended)."""


def accepted(r: ControlResponse) -> bool:
    return r.result == RESULT_ACCEPTED


def refusals(r: ControlResponse) -> list:
    """(axis, reason, ERR, EXERR) of every refused axis of an answer."""
    return [
        (text(a.name), a.reason, a.err, a.exerr)
        for a in r.axes[: r.axis_count]
        if not a.accepted and a.reason
    ]


class Supervisor:
    """The supervisor running under `prefix`, joined through its session
    file ({runtime_dir}/{prefix}.session, readable only by its user): it
    names the iceoryx2 domain and the key every request must carry."""

    def __init__(self, prefix: str = "motion", runtime_dir: str = None, node_name: str = "python-client"):
        runtime_dir = runtime_dir or default_runtime_dir()
        path = os.path.join(runtime_dir, f"{prefix}.session")
        try:
            with open(path) as f:
                session = json.load(f)
        except FileNotFoundError:
            raise NoSupervisor(f"no motion-supervisor runs with service prefix {prefix!r} (no {path})")
        if not os.path.exists(f"/proc/{session['pid']}"):
            raise NoSupervisor(f"the supervisor of {path} (pid {session['pid']}) has ended")
        self.prefix = prefix
        key = session["key"]
        self.key = (int(key[:16], 16), int(key[16:], 16))
        self.session = int(session["id"], 16)
        cfg = iox2.config.default()
        cfg.global_cfg.prefix = iox2.FileName.new(f"{prefix}.{session['id']}.")
        cfg.global_cfg.root_path = iox2.Path.new(runtime_dir.rstrip("/") + "/")
        self.node = (
            iox2.NodeBuilder.new()
            .name(iox2.NodeName.new(node_name))
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
        status = self.node.service_builder(iox2.ServiceName.new(f"{prefix}/status")).publish_subscribe(StatusFrame).open()
        self.subscriber = status.subscriber_builder().create()
        self.next_id = 1

    # ---- the services ----------------------------------------------------
    def status(self, timeout: float = 2.0) -> StatusFrame:
        """The newest status frame (waits up to `timeout` s for one)."""
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

    def request(self, kind: int, axes=(), timeout: float = 3.0, **params) -> ControlResponse:
        """One control request with the session key; its response. `params`
        are fields of the request (position, speed, accel, decel, token,
        lease_ms, flags, timeout_s, node_id, owner); an operation parameter
        not given is NaN: the axis's default. No axes: every axis."""
        req = ControlRequest()
        req.layout_version = CONTROL_LAYOUT
        req.kind = kind
        req.position = req.speed = req.accel = req.decel = float("nan")
        for k, v in params.items():
            setattr(req, k, v)
        req.key[0], req.key[1] = self.key
        req.request_id = self.next_id
        self.next_id += 1
        req.axis_count = len(axes)
        for i, name in enumerate(axes):
            if len(name.encode()) > NAME_LEN:
                raise ValueError(f"axis name {name!r} is longer than {NAME_LEN} bytes")
            put_text(req.axes[i], name)
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

    # ---- homing ----------------------------------------------------------
    def home(self, axes=(), parallel: bool = False, timeout_s: float = 0.0) -> ControlResponse:
        """Home the axes (none: every axis, in home order)."""
        return self.request(REQ_HOME, axes, flags=FLAG_PARALLEL if parallel else 0, timeout_s=timeout_s)

    def stop(self, axes=()) -> ControlResponse:
        """MAS: stop the axes (none: every axis)."""
        return self.request(REQ_STOP, axes)

    def unhome(self, axes=()) -> ControlResponse:
        """Clear HomedStatus of the axes (none: every axis)."""
        return self.request(REQ_UNHOME, axes)

    def wait_homed(self, axis: str, r: ControlResponse, timeout: float = 60.0):
        """The status entry of `axis` once the home sequence answered by `r`
        has ended (homed or not: `entry.homed`, `entry.pc`, `entry.er`);
        TimeoutError if not in
        `timeout` s."""
        until = time.monotonic() + timeout
        while time.monotonic() < until:
            frame = self.status()
            if frame.cycle >= r.cycle:
                for a in frame.axes[: frame.axis_count]:
                    if text(a.name) == axis and not (a.in_sequence or a.ip or a.stopping):
                        return a
            time.sleep(0.02)
        raise TimeoutError(f"{axis}: no result within {timeout} s")

    # ---- the operations --------------------------------------------------
    def enable(self, axes=()) -> ControlResponse:
        """MSO: enable the drives (none: every axis), holding position."""
        return self.request(REQ_ENABLE, axes)

    def disable(self, axes=()) -> ControlResponse:
        """MSF: disable the drives (none: every axis)."""
        return self.request(REQ_DISABLE, axes)

    def reset(self, axes=()) -> ControlResponse:
        """MAFR: clear the axis faults (none: every axis)."""
        return self.request(REQ_RESET, axes)

    def move(self, axis: str, position: float, relative: bool = False, speed: float = float("nan"),
             accel: float = float("nan"), decel: float = float("nan"), supersede: bool = False) -> ControlResponse:
        """MAM: a trapezoidal move to `position` (relative: by it); NaN
        speed/accel/decel: the axis's homing values."""
        flags = (FLAG_RELATIVE if relative else 0) | (FLAG_SUPERSEDE if supersede else 0)
        return self.request(REQ_MOVE, [axis], position=position, speed=speed, accel=accel, decel=decel, flags=flags)

    def jog(self, axis: str, speed: float, lease_ms: int = 500, accel: float = float("nan"),
            decel: float = float("nan")) -> "Jog":
        """MAJ, hold to run: a Jog whose lease the caller renews
        (`Jog.renew`, `Jog.hold`); it stops when the renewals stop."""
        return Jog(self, self.request(REQ_JOG, [axis], speed=speed, lease_ms=lease_ms, accel=accel, decel=decel))

    def stream(self, axes, owner: str = "python") -> "SetpointStream":
        """Takes `axes` over for the supervised setpoint stream."""
        return SetpointStream(self, axes, owner)

    def follow(self, r: ControlResponse, timeout: float = 60.0) -> list:
        """Follows the accepted axes of answer `r` until each one's operation
        (by its id) has ended and the axis is at rest: [(entry, op_id)]."""
        axes = [(a.index, a.op_id) for a in r.axes[: r.axis_count] if a.accepted and a.index != NO_INDEX]
        until = time.monotonic() + timeout
        while time.monotonic() < until:
            frame = self.status()
            if frame.cycle >= r.cycle:
                entries = [(frame.axes[i], op) for i, op in axes]
                if all(e.op_id != op or not (e.op_ip or e.stopping or e.in_motion)
                       for e, op in entries):
                    return entries
            time.sleep(0.02)
        raise TimeoutError("the operation did not end in time")


class Jog:
    """A running jog (hold to run): `renew()` within every lease, `end()`
    (or leaving the `with` block) stops only this jog."""

    def __init__(self, sup: Supervisor, answer: ControlResponse):
        self.sup = sup
        self.answer = answer
        self.token = answer.token
        self.ended = not accepted(answer)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.end()

    def renew(self) -> bool:
        """Renews the lease; False when the jog ended by itself (stop,
        limit, fault)."""
        if self.ended:
            return False
        self.ended = not accepted(self.sup.request(REQ_JOG_RENEW, [], token=self.token))
        return not self.ended

    def hold(self, seconds: float, every: float = 0.1) -> bool:
        """Keeps the jog running for `seconds`, renewing every `every` s;
        False when it ended by itself before."""
        until = time.monotonic() + seconds
        while time.monotonic() < until:
            time.sleep(min(every, max(0.0, until - time.monotonic())))
            if not self.renew():
                return False
        return True

    def end(self) -> None:
        """Ends this jog (a stop of this jog only)."""
        if accepted(self.answer):
            self.sup.request(REQ_JOG_RENEW, [], token=self.token, flags=FLAG_END)
        self.ended = True


class SetpointStream:
    """Axes taken over for the supervised setpoint stream: `publish`
    setpoints (the supervisor interpolates between them, checks each, and
    follows them within the axis's max_speed and stream_acceleration on its
    own clock, whatever `t_ns` claims), `release()` (or leaving the `with`
    block) gives the axes back: they stop at once. Publish at least every
    stream_timeout_ms (default 50 ms): an axis stops (ERR 1019 / EXERR 5)
    when no setpoint has arrived for that long, however far ahead the last
    one lay. If the program dies or hangs, the supervisor stops the axes."""

    def __init__(self, sup: Supervisor, axes, owner: str):
        self.sup = sup
        service = (
            sup.node.service_builder(iox2.ServiceName.new(f"{sup.prefix}/setpoints"))
            .publish_subscribe(SetpointFrame)
            .open()
        )
        self.publisher = service.publisher_builder().create()
        node_id = sup.node.id.value
        owner_field = (ctypes.c_uint8 * NAME_LEN)()
        put_text(owner_field, owner)
        self.answer = sup.request(
            REQ_STREAM_ACQUIRE,
            list(axes),
            node_id=(ctypes.c_uint64 * 2)(node_id & (2**64 - 1), node_id >> 64),
            owner=owner_field,
        )
        self.token = self.answer.token
        #: axis name -> the index its setpoints address
        self.index = {}
        if accepted(self.answer):
            mapping = json.loads(bytes(self.answer.data[: self.answer.data_len]).decode())
            self.index = {a["name"]: a["index"] for a in mapping["axes"]}
        self.seq = 0
        self.released = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.release()

    def publish(self, setpoints, t_ns: int = None) -> None:
        """One frame: `setpoints` are (index, position, velocity or None)
        of owned axes, at time `t_ns` of this program's monotonic clock
        (only differences count; a later time buys no speed)."""
        frame = SetpointFrame()
        frame.layout_version = SETPOINT_LAYOUT
        frame.session = self.sup.session
        frame.key[0], frame.key[1] = self.sup.key
        frame.token = self.token
        self.seq += 1
        frame.seq = self.seq
        frame.t_ns = time.monotonic_ns() if t_ns is None else t_ns
        frame.count = len(setpoints)
        for e, (index, position, velocity) in zip(frame.axes, setpoints):
            e.axis = index
            e.position = position
            if velocity is not None:
                e.flags = SP_VELOCITY
                e.velocity = velocity
        self.publisher.send_copy(frame)

    def release(self) -> ControlResponse:
        """Gives the axes back (the stream ends, the axes stop); the answer
        (refused: the stream was over already)."""
        if self.released is None:
            self.released = self.sup.request(REQ_STREAM_RELEASE, [], token=self.token)
            self.publisher.delete()
        return self.released
