#!/usr/bin/env python3
"""Streams a sine to one axis through the supervisor's supervised setpoint
stream, with nothing but the `iceoryx2` package from PyPI (0.10.0).

    pip install iceoryx2==0.10.0
    python3 stream_sine.py --prefix motion --axis X --amplitude 2 --hz 0.5 --seconds 4

What a program does to move axes (see README, "The setpoint stream"):

1. join the supervisor's domain through its session file (motion_client.py's
   Supervisor: the key, the session id, the control and status services);
2. open `{prefix}/setpoints` with a publisher of its own node;
3. take the axis over with a stream-acquire request naming that node's id
   (REQ_STREAM_ACQUIRE): the answer carries the owner token, and its data
   maps the axis name to the index its setpoints address;
4. publish SetpointFrames (layout 1: key, token, an increasing seq, its own
   time t_ns, one entry per axis) — here at --rate Hz; the supervisor
   interpolates between them to its cycle and checks every one (finite,
   inside the travel limits, within max_speed and stream_acceleration, in
   time order, not older than stream_timeout_ms);
5. give the axis back (REQ_STREAM_RELEASE): the stream ends, the axis stops.

The sine starts at the axis's position and at rest (p = p0 + A (1 - cos
2 pi f t)): the first setpoint is where the axis stands, and no step of
velocity exceeds the axis's stream_acceleration. If this program dies, the
supervisor stops the axis: the setpoints stop (ERR 1019 / 5 after
stream_timeout_ms) and the owner's node is gone (checked every 100 ms).

Exit codes: 0 streamed to the end and released, 1 refused or stopped with an
error, 3 no supervisor running under the prefix.
"""

import argparse
import ctypes
import json
import math
import sys
import time

import iceoryx2 as iox2

from motion_client import (
    MAX_AXES,
    MS_COMMAND,
    MS_STREAMING,
    REQ_STREAM_ACQUIRE,
    REQ_STREAM_RELEASE,
    RESULT_ACCEPTED,
    ST_ER,
    ST_FEEDBACK,
    NoSupervisor,
    Supervisor,
    default_runtime_dir,
    follow,
    refused,
    text,
)

SETPOINT_LAYOUT = 1
SP_VELOCITY = 1


class SetpointAxis(ctypes.Structure):
    _fields_ = [
        ("axis", ctypes.c_uint32),
        ("flags", ctypes.c_uint32),
        ("position", ctypes.c_double),
        ("velocity", ctypes.c_double),
    ]


class SetpointFrame(ctypes.Structure):
    """crates/frames/src/setpoint.rs (layout 1)."""

    _fields_ = [
        ("layout_version", ctypes.c_uint32),
        ("session", ctypes.c_uint32),
        ("key", ctypes.c_uint64 * 2),
        ("token", ctypes.c_uint64),
        ("seq", ctypes.c_uint64),
        ("t_ns", ctypes.c_uint64),
        ("count", ctypes.c_uint32),
        ("reserved", ctypes.c_uint32),
        ("axes", SetpointAxis * MAX_AXES),
    ]

    @staticmethod
    def type_name() -> str:
        return "motion_frames::SetpointFrame@layout1"


def acquire(sup: Supervisor, axis: str, prefix: str):
    """The publisher, owner token and axis index of a stream of `axis`."""
    service = (
        sup.node.service_builder(iox2.ServiceName.new(f"{prefix}/setpoints"))
        .publish_subscribe(SetpointFrame)
        .open()
    )
    publisher = service.publisher_builder().create()
    node_id = sup.node.id.value
    r = sup.request(
        REQ_STREAM_ACQUIRE,
        [axis],
        node_id=(ctypes.c_uint64 * 2)(node_id & (2**64 - 1), node_id >> 64),
        owner=(ctypes.c_uint8 * 32)(*b"stream_sine".ljust(32, b"\0")),
    )
    if r.result != RESULT_ACCEPTED:
        return None, r, None
    mapping = json.loads(bytes(r.data[: r.data_len]).decode())
    return publisher, r, mapping["axes"][0]["index"]


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--prefix", default="motion")
    p.add_argument("--runtime-dir", default=default_runtime_dir())
    p.add_argument("--axis", required=True)
    p.add_argument("--amplitude", type=float, default=1.0, help="units")
    p.add_argument("--hz", type=float, default=0.5, help="sine frequency")
    p.add_argument("--seconds", type=float, default=4.0)
    p.add_argument("--rate", type=float, default=100.0, help="setpoints per second")
    a = p.parse_args()
    iox2.set_log_level_from_env_or(iox2.LogLevel.Warn)
    try:
        sup = Supervisor(a.prefix, a.runtime_dir)
    except NoSupervisor as e:
        print(e, file=sys.stderr)
        return 3
    frame0 = sup.status()
    names = [text(frame0.axes[i].name) for i in range(frame0.axis_count)]
    if a.axis not in names:
        print(f"no axis {a.axis} (axes: {', '.join(names)})", file=sys.stderr)
        return 1
    publisher, r, index = acquire(sup, a.axis, a.prefix)
    if publisher is None:
        return refused("stream", r)
    token = r.token
    start = frame0.axes[index]
    p0 = start.cmd_position if start.motion & MS_COMMAND else start.position
    frame = SetpointFrame()
    frame.layout_version = SETPOINT_LAYOUT
    frame.session = sup.session
    frame.key[0], frame.key[1] = sup.key
    frame.token = token
    frame.count = 1
    frame.axes[0].axis = index
    frame.axes[0].flags = SP_VELOCITY
    w = 2.0 * math.pi * a.hz
    period = 1.0 / a.rate
    t0 = time.monotonic_ns()
    worst = 0.0
    seq = 0
    n = int(a.seconds * a.rate) + 1
    ok = True
    for k in range(n):
        t = k * period
        while time.monotonic_ns() < t0 + int(t * 1e9):
            time.sleep(0.0005)
        seq += 1
        frame.seq = seq
        frame.t_ns = t0 + int(t * 1e9)
        frame.axes[0].position = p0 + a.amplitude * (1.0 - math.cos(w * t))
        frame.axes[0].velocity = a.amplitude * w * math.sin(w * t)
        publisher.send_copy(frame)
        if k % 10 == 0:
            st = sup.status().axes[index]
            if st.bits & ST_FEEDBACK and st.motion & MS_COMMAND:
                worst = max(worst, abs(st.cmd_position - st.position))
            if k > 0 and not st.motion & MS_STREAMING:
                print(f"{a.axis}: the stream stopped: ERR {st.err}/{st.exerr}", file=sys.stderr)
                ok = False
                break
    time.sleep(0.05)
    # Released: follow the stream ends' operations (their ids are in the
    # answer) to rest; refused: the stream was over already (an error).
    rel = sup.request(REQ_STREAM_RELEASE, [], token=token)
    for e, _ in follow(sup, rel if rel.result == RESULT_ACCEPTED else r, 30.0):
        ok = ok and not e.bits & ST_ER
        print(
            f"{text(e.name)}: ER {int(bool(e.bits & ST_ER))} ERR {e.err}/{e.exerr} "
            f"position {e.position:.6f} (started at {p0:.6f}); "
            f"largest following error seen {worst:.6f}"
        )
    publisher.delete()
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
