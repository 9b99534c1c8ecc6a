"""The client: joins a running motion-supervisor through its session file
and speaks its control, status and setpoint services with the `iceoryx2`
package from PyPI (the same version as the Rust crate, 0.10.0).

    sup = Supervisor("motion")
    frame = sup.status()                  # the newest StatusFrame
    r = sup.home(["X"])                   # a ControlResponse
    entry = sup.wait_homed("X", r)        # X's AxisStatusEntry once done
    sup.enable(["X"]); sup.move("X", 12.5); sup.stop(); sup.unhome(["X"])
    sup.move("X", 2.0, relative=True, speed=5.0)
    sup.gear("Y", master="X", ratio=-0.5)  # Y follows X until a stop
    with sup.jog("X", speed=-2.0) as jog:  # hold to run
        jog.hold(1.5)                      # renews the lease for 1.5 s
    with sup.stream(["X"], owner="me") as s:
        s.publish([(s.index["X"], 1.0, 0.0)])

An operation's parameters are the engine's: `OPERATIONS` (read from
`layout.json`, which the Rust side writes from the operations' specs)
names each operation's parameters in order, with their kinds, units and
defaults; `move`, `jog` and `operate` take them positionally or by name,
and a parameter left out (or None, or NaN) is the axis's default.

An operation's answer is a ControlResponse: `accepted(r)` says whether it
was accepted for every axis, `refusals(r)` why not.
"""

import ctypes
import json
import math
import os
import time

import iceoryx2 as iox2

from .check import load_description
from .layout import (
    CONTROL_LAYOUT, FLAG_END, FLAG_PARALLEL, NAME_LEN, NO_INDEX, OP_SLOTS,
    REQ_HOME, REQ_JOG_RENEW, REQ_OPERATE, REQ_STOP, REQ_STREAM_ACQUIRE,
    REQ_STREAM_RELEASE, REQ_UNHOME, RESULT_ACCEPTED, SETPOINT_LAYOUT,
    SP_VELOCITY, ControlRequest, ControlResponse, SetpointFrame, StatusFrame,
    put_text, text,
)
from .paths import default_runtime_dir

#: The operations a client may ask for, by name, as the engine declares
#: them: {"op": number, "all_by_default": bool, "held": bool, "params":
#: [{"name", "kind", "slot" | "bit" | "name_field", "unit", "default",
#: "doc", ...}]}.
OPERATIONS = {o["name"]: o for o in load_description()["operations"]}


def carried(op: str, args=(), params=None) -> dict:
    """The request fields of operation `op` (`op`, `switches`, `values`,
    `name`) from its parameters, positional (`args`, in the spec's order)
    and by name (`params`), each put where the spec carries it. A
    parameter left out, None or NaN is not given (the axis's default
    applies); one that must be given, unknown or given twice is a
    TypeError; a choice that is none of its choices a ValueError."""
    spec = OPERATIONS[op]
    names = [p["name"] for p in spec["params"]]
    if len(args) > len(names):
        raise TypeError(f"{op}() takes at most {len(names)} parameters ({', '.join(names)})")
    given = dict(zip(names, args))
    for k, v in (params or {}).items():
        if k not in names:
            raise TypeError(f"{op}() has no parameter {k!r} (it has: {', '.join(names) or 'none'})")
        if k in given:
            raise TypeError(f"{op}() got {k!r} twice")
        given[k] = v
    values = (ctypes.c_double * OP_SLOTS)(*([float("nan")] * OP_SLOTS))
    fields = {"op": spec["op"], "switches": 0, "values": values}
    for p in spec["params"]:
        v = given.get(p["name"])
        if v is None or (isinstance(v, float) and math.isnan(v)):
            if p["kind"] in ("number", "choice", "axis"):
                raise TypeError(f"{op}() needs {p['name']} ({p['doc']})")
            continue
        if p["kind"] == "switch":
            fields["switches"] |= (1 << p["bit"]) if v else 0
        elif p["kind"] in ("number", "optional"):
            values[p["slot"]] = float(v)
        elif p["kind"] == "choice":
            values[p["slot"]] = float(p["choices"].index(v))
        elif p["kind"] == "pair":
            values[p["slot"]], values[p["slot"] + 1] = (float(x) for x in v)
        elif p["kind"] == "axis":
            name = (ctypes.c_uint8 * NAME_LEN)()
            put_text(name, v)
            fields["name"] = name
    return fields


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

    def request(self, kind: int, axes=(), timeout: float = 3.0, **fields) -> ControlResponse:
        """One control request with the session key; its response. `fields`
        are fields of the request (flags, timeout_s, token, node_id, name;
        an operation's op, switches, values: see `operate`). No axes: every
        axis."""
        req = ControlRequest()
        req.layout_version = CONTROL_LAYOUT
        req.kind = kind
        for k, v in fields.items():
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
    def operate(self, op: str, axes=(), *args, **params) -> ControlResponse:
        """Operation `op` (a name of `OPERATIONS`) for `axes` with its
        parameters (see `carried`); no axes: every axis for an operation
        that says so (`all_by_default`), else refused."""
        return self.request(REQ_OPERATE, list(axes), **carried(op, args, params))

    def enable(self, axes=()) -> ControlResponse:
        """MSO: enable the drives (none: every axis), holding position."""
        return self.operate("enable", axes)

    def disable(self, axes=()) -> ControlResponse:
        """MSF: disable the drives (none: every axis)."""
        return self.operate("disable", axes)

    def reset(self, axes=()) -> ControlResponse:
        """MAFR: clear the axis faults (none: every axis)."""
        return self.operate("reset", axes)

    def move(self, axis: str, *args, **params) -> ControlResponse:
        """MAM: a move of `axis` (an S-curve with `jerk` above 0); the
        parameters are the engine's (`OPERATIONS["move"]`, in order: the
        target first) — `move("X", 12.5)`, `move("X", 2, relative=True,
        speed=5)`, `move("X", 40, jerk=20000)`."""
        return self.operate("move", [axis], *args, **params)

    def change(self, axis: str, **params) -> ControlResponse:
        """MCD: new dynamics for the jog or move `axis` runs now (the
        engine's `OPERATIONS["change"]`: speed, accel, decel, jerk; each
        left out keeps the running motion's) — `change("X", speed=5)`."""
        return self.operate("change", [axis], **params)
    def redefine(self, axis: str, *args, **params) -> ControlResponse:
        """MRP: homed and at rest, the position of `axis` (or a gantry)
        becomes `value` — or moves by it with `relative=True` — without
        motion; its soft limits stay where they are on the machine. The
        parameters are the engine's (`OPERATIONS["redefine"]`) —
        `redefine("X", 0.0)`, `redefine("X", 5.0, relative=True)`."""
        return self.operate("redefine", [axis], *args, **params)

    def jog(self, axis: str, *args, **params) -> "Jog":
        """MAJ, hold to run: a Jog of `axis` whose lease the caller renews
        (`Jog.renew`, `Jog.hold`); it stops when the renewals stop. The
        parameters are the engine's (`OPERATIONS["jog"]`): speed, lease
        (s), accel, decel, jerk — `jog("X", -2.0)`."""
        return Jog(self, self.operate("jog", [axis], *args, **params))

    def arm(self, axis: str, input: str = "switch", edge: str = "rising",
            window=None) -> ControlResponse:
        """MAR: latch `axis`'s position at the next `edge` ("rising":
        becoming actuated, or "falling") of `input` ("switch": the home
        switch, or "marker"), only inside `window` (lo, hi) if given; during
        whatever motion. The position is the status entry's
        `registration_position` once `registration_armed` drops
        (`wait_registered`)."""
        return self.operate("arm", [axis], input=input, edge=edge, window=window)

    def disarm(self, axes=()) -> ControlResponse:
        """MDR: disarm the registrations (none: every axis)."""
        return self.operate("disarm", axes)

    def wait_registered(self, axis: str, answer: ControlResponse, timeout: float = 60.0):
        """After `arm`'s `answer`: the latched axis position once the
        registration is no longer armed (None: disarmed without one)."""
        until = time.monotonic() + timeout
        while time.monotonic() < until:
            frame = self.status()
            if frame.cycle > answer.cycle:
                for a in frame.axes[: frame.axis_count]:
                    if text(a.name) == axis and not a.registration_armed:
                        p = a.registration_position
                        return None if p is None or math.isnan(p) else p
            time.sleep(0.02)
        raise TimeoutError(f"{axis}: nothing latched within {timeout} s")

    def gear(self, slave: str, *args, **params) -> ControlResponse:
        """MAG: from now on `slave` follows its master's position change
        times the ratio until a stop, disable or fault of either ends it.
        The parameters are the engine's (`OPERATIONS["gear"]`): master,
        ratio, actual, clutch — `gear("Y", "X", -0.5)`,
        `gear("Y", master="X", ratio=2, actual=True, clutch=100)`."""
        return self.operate("gear", [slave], *args, **params)

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
            name=owner_field,
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
